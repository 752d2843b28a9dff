//! Compensated summation used by the metrics' reductions.

/// Neumaier (improved Kahan–Babuška) running sum: the error of the total stays at a
/// few ulps of the largest partial sum, independent of the number of terms.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Neumaier {
    sum: f64,
    comp: f64,
}

impl Neumaier {
    /// Adds one term.
    #[inline]
    pub(crate) fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.comp += (self.sum - t) + v;
        } else {
            self.comp += (v - t) + self.sum;
        }
        self.sum = t;
    }

    /// The compensated total.
    #[inline]
    pub(crate) fn total(&self) -> f64 {
        self.sum + self.comp
    }
}

/// Compensated sum of a sequence, in order.
pub(crate) fn sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut s = Neumaier::default();
    for v in values {
        s.add(v);
    }
    s.total()
}
