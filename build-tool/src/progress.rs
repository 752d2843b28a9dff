//! Progress of a long phase (optimizing, a run's report, an evaluation panel), shown
//! on stderr: an animated bar when stderr is a terminal, plain lines otherwise (CI
//! logs, `| tee`, scripts), which an animated bar would leave empty.
//!
//! Plain lines look like
//! `optimize: epoch 1200/5000 (24%), set 1/2, loss 1.234e-5, ETA 38 s`: one when the
//! phase starts, then one whenever [`LINE_INTERVAL`] has passed since the last, and a
//! last `optimize: done, 5000 epochs in 52.1 s`. Progress never touches stdout or
//! the results; every method may be called from several threads at once.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Time between two plain progress lines: frequent enough to show a run is alive
/// in a CI log, rare enough that an hour-long run writes a few hundred lines.
pub const LINE_INTERVAL: Duration = Duration::from_secs(5);

/// The progress of one phase of `total` steps of `unit` (`epoch`, `set`, ...).
pub struct Progress {
    phase: String,
    unit: String,
    total: u64,
    done: AtomicU64,
    started: Instant,
    display: Display,
    /// Context shown with the count (`set 1/2`) and the latest message (`loss ..`).
    text: Mutex<(String, String)>,
}

enum Display {
    /// An animated bar on a terminal.
    Bar(ProgressBar),
    /// Plain lines into `sink`, at most one per `interval` between the first and
    /// the last.
    Lines {
        sink: Mutex<Box<dyn Write + Send>>,
        interval: Duration,
        last: Mutex<Instant>,
    },
}

impl Progress {
    /// Progress of `phase` over `total` steps of `unit` on stderr: a bar when stderr
    /// is a terminal, else plain lines every [`LINE_INTERVAL`].
    pub fn stderr(phase: &str, total: u64, unit: &str) -> Self {
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} {phase} {{prefix}} [{{bar:30}}] {{pos}}/{{len}} {unit}s  {{msg}}  ETA {{eta}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            Self::with_display(phase, total, unit, Display::Bar(bar))
        } else {
            Self::lines(
                phase,
                total,
                unit,
                Box::new(std::io::stderr()),
                LINE_INTERVAL,
            )
        }
    }

    /// Progress written as plain lines into `sink`, at most one per `interval`
    /// (plus the first and the last).
    pub fn lines(
        phase: &str,
        total: u64,
        unit: &str,
        sink: Box<dyn Write + Send>,
        interval: Duration,
    ) -> Self {
        let display = Display::Lines {
            sink: Mutex::new(sink),
            interval,
            last: Mutex::new(Instant::now()),
        };
        let p = Self::with_display(phase, total, unit, display);
        p.write_line(&p.status_line(0));
        p
    }

    fn with_display(phase: &str, total: u64, unit: &str, display: Display) -> Self {
        Self {
            phase: phase.into(),
            unit: unit.into(),
            total,
            done: AtomicU64::new(0),
            started: Instant::now(),
            display,
            text: Mutex::new((String::new(), String::new())),
        }
    }

    /// Sets the context shown beside the count (`set 1/2`, `ours N=64`).
    pub fn set_context(&self, context: impl Into<String>) {
        let context = context.into();
        if let Display::Bar(bar) = &self.display {
            bar.set_prefix(context.clone());
        }
        lock(&self.text).0 = context;
    }

    /// Sets the latest message (`loss 1.2e-5`), shown with the next line.
    pub fn set_message(&self, message: impl Into<String>) {
        let message = message.into();
        if let Display::Bar(bar) = &self.display {
            bar.set_message(message.clone());
        }
        lock(&self.text).1 = message;
    }

    /// Counts `steps` more finished steps.
    pub fn inc(&self, steps: u64) {
        let done = self.done.fetch_add(steps, Ordering::Relaxed) + steps;
        match &self.display {
            Display::Bar(bar) => bar.inc(steps),
            Display::Lines { interval, last, .. } => {
                let due = {
                    let mut last = lock(last);
                    let due = last.elapsed() >= *interval;
                    if due {
                        *last = Instant::now();
                    }
                    due
                };
                if due && done < self.total {
                    self.write_line(&self.status_line(done));
                }
            }
        }
    }

    /// Ends the phase: clears the bar, or writes the `done` line.
    pub fn finish(&self) {
        match &self.display {
            Display::Bar(bar) => bar.finish_and_clear(),
            Display::Lines { .. } => {
                let done = self.done.load(Ordering::Relaxed);
                self.write_line(&format!(
                    "{}: done, {done} {}{} in {:.1} s",
                    self.phase,
                    self.unit,
                    if done == 1 { "" } else { "s" },
                    self.started.elapsed().as_secs_f64()
                ))
            }
        }
    }

    /// Ends the phase with `phase: summary` in place of the `done` line, on a
    /// terminal too (a line that belongs in the log).
    pub fn finish_with(&self, summary: &str) {
        let line = format!("{}: {summary}", self.phase);
        match &self.display {
            Display::Bar(bar) => {
                bar.finish_and_clear();
                eprintln!("{line}");
            }
            Display::Lines { .. } => self.write_line(&line),
        }
    }

    /// `phase: unit done/total (pct%)[, context][, message][, ETA s]`; the ETA
    /// extrapolates the mean rate so far.
    fn status_line(&self, done: u64) -> String {
        let (context, message) = lock(&self.text).clone();
        let pct = (100 * done).checked_div(self.total).unwrap_or(100);
        let mut line = format!(
            "{}: {} {done}/{} ({pct}%)",
            self.phase, self.unit, self.total
        );
        for part in [context, message] {
            if !part.is_empty() {
                line.push_str(", ");
                line.push_str(&part);
            }
        }
        if done > 0 && done < self.total {
            let elapsed = self.started.elapsed().as_secs_f64();
            let eta = elapsed * (self.total - done) as f64 / done as f64;
            line.push_str(&format!(", ETA {eta:.0} s"));
        }
        line
    }

    fn write_line(&self, line: &str) {
        if let Display::Lines { sink, .. } = &self.display {
            // Progress is advisory: a closed stderr must not stop the run.
            let _ = writeln!(lock(sink), "{line}");
        }
    }
}

/// Locks `m`, also after a panic elsewhere (the guarded text stays usable).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// A sink the test can read back.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            lock(&self.0).extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    impl Shared {
        fn text(&self) -> String {
            String::from_utf8(lock(&self.0).clone()).unwrap()
        }
    }

    #[test]
    fn plain_lines_give_count_percentage_context_message_and_a_done_line() {
        let sink = Shared::default();
        let p = Progress::lines(
            "optimize",
            4,
            "epoch",
            Box::new(sink.clone()),
            Duration::ZERO,
        );
        p.set_context("set 1/1");
        p.set_message("loss 1.5e-3");
        p.inc(1);
        p.inc(3);
        p.finish();
        let text = sink.text();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert_eq!(lines[0], "optimize: epoch 0/4 (0%)");
        assert!(
            lines[1].starts_with("optimize: epoch 1/4 (25%), set 1/1, loss 1.5e-3, ETA "),
            "{text}"
        );
        // The last step is reported by the done line, not a 100% status line.
        assert!(
            lines[2].starts_with("optimize: done, 4 epochs in "),
            "{text}"
        );
    }

    #[test]
    fn plain_lines_are_rate_limited() {
        let sink = Shared::default();
        let p = Progress::lines("report", 1000, "set", Box::new(sink.clone()), LINE_INTERVAL);
        for _ in 0..1000 {
            p.inc(1);
        }
        p.finish_with("1000 sets measured");
        // Only the first and the last line within one interval.
        assert_eq!(
            sink.text(),
            "report: set 0/1000 (0%)\nreport: 1000 sets measured\n"
        );
    }
}
