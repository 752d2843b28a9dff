//! The annealing shared by every descent: the sigmoid's sharpness ramps linearly
//! from a soft start to a sharp end while the step size decays on a cosine.

/// A descent's annealing over `epochs` epochs (or steps).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    /// Epochs in all (at least 1 for a descent that moves).
    pub epochs: usize,
    /// Sigmoid sharpness at the first and at the last epoch, in inverse point
    /// spacings.
    pub alpha: (f64, f64),
    /// The step size of the last epoch over that of the first, in `(0, 1]`.
    pub final_learning_rate_ratio: f64,
}

impl Schedule {
    /// `(alpha, lr_ratio)` of epoch `epoch`: [`epoch_schedule`].
    pub fn at(&self, epoch: usize) -> (f64, f64) {
        epoch_schedule(
            epoch,
            self.epochs,
            self.alpha,
            self.final_learning_rate_ratio,
        )
    }
}

/// The annealing of epoch `epoch` of `epochs`: with `t = epoch / (epochs - 1)` (1
/// for a single epoch), the sigmoid sharpness `alpha_start + (alpha_end -
/// alpha_start) t` (in inverse point spacings) and the step ratio `final + (1 -
/// final) (1 + cos(pi t)) / 2` (cosine decay from 1 to `final`).
pub fn epoch_schedule(
    epoch: usize,
    epochs: usize,
    (alpha_start, alpha_end): (f64, f64),
    final_learning_rate_ratio: f64,
) -> (f64, f64) {
    let t = if epochs > 1 {
        epoch as f64 / (epochs - 1) as f64
    } else {
        1.0
    };
    let alpha = alpha_start + (alpha_end - alpha_start) * t;
    let cosine = 0.5 * (1.0 + (std::f64::consts::PI * t).cos());
    let lr_ratio = final_learning_rate_ratio + (1.0 - final_learning_rate_ratio) * cosine;
    (alpha, lr_ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epoch_schedule_anneals_from_start_to_end() {
        let a = (8.0, 128.0);
        assert_eq!(epoch_schedule(0, 11, a, 0.02), (8.0, 1.0));
        assert_eq!(epoch_schedule(10, 11, a, 0.02), (128.0, 0.02));
        assert_eq!(epoch_schedule(0, 1, a, 0.02), (128.0, 0.02));
        // Halfway: alpha at the midpoint, the step halfway between 1 and the end.
        let (alpha, lr) = epoch_schedule(5, 11, a, 0.02);
        assert!((alpha - 68.0).abs() < 1e-12 && (lr - 0.51).abs() < 1e-12);
    }
}
