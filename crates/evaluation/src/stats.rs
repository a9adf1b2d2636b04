//! The statistics every experiment, report and comparison prints: medians and type-7
//! quantiles of the finite values.

/// The median of the finite values of `values` (the mean of the middle two for an even
/// count); `None` when there are none.
pub fn median(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) })
}

/// The `p`-quantile (`0 ≤ p ≤ 1`) of the finite values of `values` by linear interpolation
/// between closest ranks (Hyndman & Fan type 7, [`roadmap::metrics::quantile`]); `None` when
/// there are none or `p` is outside `[0, 1]`.
pub fn quantile(values: &[f64], p: f64) -> Option<f64> {
    let finite: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    roadmap::metrics::quantile(&finite, p)
}

/// Lower quartile, median and upper quartile ([`quantile`] at 0.25, 0.5, 0.75).
pub fn quartiles(values: &[f64]) -> Option<[f64; 3]> {
    Some([quantile(values, 0.25)?, quantile(values, 0.5)?, quantile(values, 0.75)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_quantiles_of_finite_values() {
        assert_eq!(median([]), None);
        assert_eq!(median([f64::NAN]), None);
        assert_eq!(median([3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median([4.0, 1.0, 2.0, 3.0, f64::INFINITY]), Some(2.5));
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.25), Some(1.75));
        assert_eq!(quantile(&[1.0, f64::NAN], 0.5), Some(1.0));
        assert_eq!(quantile(&[1.0], 1.5), None);
        assert_eq!(quartiles(&[1.0, 2.0, 3.0, 4.0, 5.0]), Some([2.0, 3.0, 4.0]));
    }
}
