//! Nanoseconds per sample of several methods timed in turn, round after round
//! ([`Rounds`]): the runtime's figures of `build-tool bench` and their ratios to
//! the incumbent.
//!
//! Timing each method alone, one after the other (the best of three runs each),
//! let the machine's state drift between a method and the incumbent it is
//! divided by: the environment sampler's incumbent, which waits on memory, read
//! 327 to 596 ns per sample in four runs of the same bench on the 2-core machine
//! while the sampler read 692 to 758, so its ratio moved from 1.27x to 2.26x.
//! Interleaved, every round times every method under about the same state, and
//! the median over rounds leaves out the rounds a burst of other work disturbed.

use std::hint::black_box;
use std::time::Instant;

/// Rounds each method is timed in; its figure is the median.
pub const ROUNDS: u32 = 9;

/// Methods to time, each a closure of the sample number (`0..count`, split
/// among the rounds in order), in the order they are added.
#[derive(Default)]
pub struct Rounds<'a> {
    methods: Vec<Method<'a>>,
}

/// One method of [`Rounds`].
struct Method<'a> {
    name: String,
    count: u32,
    call: Box<dyn FnMut(u32) + 'a>,
}

impl<'a> Rounds<'a> {
    /// No methods yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `call`, timed on `count` calls in all (`count / ROUNDS` a round, at
    /// least one), under `name`.
    pub fn add(&mut self, name: impl Into<String>, count: u32, call: impl FnMut(u32) + 'a) {
        self.methods.push(Method {
            name: name.into(),
            count,
            call: Box::new(call),
        });
    }

    /// Times every method once per round, in the order added, for [`ROUNDS`]
    /// rounds (round `r` of a method calls it on sample numbers `r c` to
    /// `(r + 1) c - 1`, `c` its calls a round), and returns each method's name
    /// and median nanoseconds per call, in the order added.
    pub fn run(mut self) -> Vec<(String, f64)> {
        let mut times = vec![Vec::with_capacity(ROUNDS as usize); self.methods.len()];
        for round in 0..ROUNDS {
            for (m, t) in self.methods.iter_mut().zip(&mut times) {
                let per = (m.count / ROUNDS).max(1);
                let start = Instant::now();
                for s in round * per..(round + 1) * per {
                    (m.call)(black_box(s));
                }
                t.push(start.elapsed().as_secs_f64() * 1e9 / per as f64);
            }
        }
        self.methods
            .into_iter()
            .zip(times)
            .map(|(m, t)| (m.name, median(t)))
            .collect()
    }
}

/// The middle value of `v` (the mean of the two middle ones for an even count;
/// NaN for none).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every method is called on each of its sample numbers once, in order,
    /// round by round and interleaved with the others; the figures come back
    /// named in the order added.
    #[test]
    fn methods_take_turns_over_their_sample_numbers() {
        let calls = std::cell::RefCell::new(Vec::new());
        let mut rounds = Rounds::new();
        rounds.add("a", 2 * ROUNDS, |s| calls.borrow_mut().push(('a', s)));
        rounds.add("b", ROUNDS, |s| calls.borrow_mut().push(('b', s)));
        let rows = rounds.run();
        let names: Vec<&str> = rows.iter().map(|r| r.0.as_str()).collect();
        assert_eq!(names, ["a", "b"]);
        assert!(rows.iter().all(|r| r.1 >= 0.0 && r.1.is_finite()));
        let want: Vec<(char, u32)> = (0..ROUNDS)
            .flat_map(|r| [('a', 2 * r), ('a', 2 * r + 1), ('b', r)])
            .collect();
        assert_eq!(*calls.borrow(), want);
    }

    #[test]
    fn the_median_is_the_middle_value() {
        assert_eq!(median(vec![5.0, 1.0, 3.0]), 3.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(Vec::new()).is_nan());
    }
}
