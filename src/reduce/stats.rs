//! Order statistics for the maps: exact percentiles by selection.
//!
//! Percentiles use linear interpolation between order statistics
//! (position p·(n−1), numpy's default "linear" method), computed exactly:
//! within a cell by sorting its values, over the whole run by selection
//! passes (`select`), both through [`position`] so they agree bit for bit.

/// The `p`-quantile (0 ≤ p ≤ 1) of sorted `values` by linear interpolation.
///
/// # Panics
/// If `values` is empty.
pub fn quantile_sorted(values: &[f64], p: f64) -> f64 {
    assert!(!values.is_empty(), "quantile of an empty set");
    let (lo, hi, frac) = position(values.len(), p);
    values[lo] + (values[hi] - values[lo]) * frac
}

/// The ranks (lo, hi) between which the `p`-quantile of `n` > 0 sorted
/// values lies, and the fraction of the way from lo to hi.
pub fn position(n: usize, p: f64) -> (usize, usize, f64) {
    let pos = p.clamp(0.0, 1.0) * (n - 1) as f64;
    let lo = pos.floor() as usize;
    (lo, pos.ceil() as usize, pos - lo as f64)
}

/// Quantiles of unsorted values (sorts a copy).
pub fn quantiles(values: &[f64], ps: &[f64]) -> Vec<f64> {
    let mut v = values.to_vec();
    v.sort_unstable_by(f64::total_cmp);
    ps.iter().map(|&p| quantile_sorted(&v, p)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_numpy_linear() {
        // numpy.percentile([1, 2, 3, 4], [10, 90]) = [1.3, 3.7]
        let q = quantiles(&[4.0, 1.0, 3.0, 2.0], &[0.1, 0.9]);
        assert!((q[0] - 1.3).abs() < 1e-12 && (q[1] - 3.7).abs() < 1e-12);
        assert_eq!(quantiles(&[5.0], &[0.1, 0.9]), vec![5.0, 5.0]);
    }
}
