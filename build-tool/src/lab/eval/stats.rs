//! Aggregation of per-realization values: the mean with its standard error (for
//! discrepancies) and the root-mean-square error against a reference with its
//! standard error (for integration, paper Fig. 7).

use serde::Serialize;

/// An aggregate over `realizations` independent values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Aggregate {
    /// The mean (or the RMSE, for [`rmse`]).
    pub value: f64,
    /// Its standard error; 0 with a single realization.
    pub stderr: f64,
    /// Number of values aggregated.
    pub realizations: usize,
}

/// Mean and sample variance (`n - 1` denominator; 0 for fewer than two values),
/// summed in order (deterministic).
fn mean_var(values: &[f64]) -> (f64, f64) {
    let n = values.len();
    if n == 0 {
        return (f64::NAN, 0.0);
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = if n > 1 {
        values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64
    } else {
        0.0
    };
    (mean, var)
}

/// The mean of `values` and its standard error `s / sqrt(R)` (`s` the sample
/// standard deviation). NaN mean for an empty slice.
pub fn mean(values: &[f64]) -> Aggregate {
    let (m, var) = mean_var(values);
    Aggregate {
        value: m,
        stderr: (var / values.len().max(1) as f64).sqrt(),
        realizations: values.len(),
    }
}

/// Root-mean-square error of the estimates against `reference`:
/// `RMSE = sqrt((1/R) sum_r (e_r - I)^2)`, with the standard error of the mean
/// squared error `se2 = sd((e_r - I)^2) / sqrt(R)` carried to the root by the delta
/// method, `se = se2 / (2 RMSE)` (`se2` itself if the RMSE is 0).
pub fn rmse(estimates: &[f64], reference: f64) -> Aggregate {
    let sq: Vec<f64> = estimates.iter().map(|e| (e - reference).powi(2)).collect();
    let m = mean(&sq);
    let r = m.value.max(0.0).sqrt();
    Aggregate {
        value: r,
        stderr: if r > 0.0 {
            m.stderr / (2.0 * r)
        } else {
            m.stderr
        },
        realizations: estimates.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_stderr_by_hand() {
        // mean 2.5, sample variance ((1.5^2 + 0.5^2) * 2) / 3 = 5/3.
        let a = mean(&[1.0, 2.0, 3.0, 4.0]);
        assert!((a.value - 2.5).abs() < 1e-15);
        assert!((a.stderr - (5.0f64 / 3.0 / 4.0).sqrt()).abs() < 1e-15);
        assert_eq!(a.realizations, 4);
        let one = mean(&[7.0]);
        assert_eq!((one.value, one.stderr, one.realizations), (7.0, 0.0, 1));
    }

    #[test]
    fn rmse_by_hand() {
        // Errors against 1: -1, 1, 2, 0 -> squares 1, 1, 4, 0 -> MSE 1.5.
        let a = rmse(&[0.0, 2.0, 3.0, 1.0], 1.0);
        assert!((a.value - 1.5f64.sqrt()).abs() < 1e-15);
        // Squares have mean 1.5 and sample variance (0.25 + 0.25 + 6.25 + 2.25) / 3 = 3.
        let se2 = (3.0f64 / 4.0).sqrt();
        assert!((a.stderr - se2 / (2.0 * 1.5f64.sqrt())).abs() < 1e-15);
        assert_eq!(a.realizations, 4);
        // Exact estimates: RMSE 0, no error.
        let z = rmse(&[0.5, 0.5], 0.5);
        assert_eq!((z.value, z.stderr), (0.0, 0.0));
        // A constant bias is all error.
        let b = rmse(&[0.75, 0.75, 0.75], 0.5);
        assert!((b.value - 0.25).abs() < 1e-15 && b.stderr == 0.0);
    }
}
