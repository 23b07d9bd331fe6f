//! Gaussian smoothing of per-point values along a path, by arc length.
//!
//! Place in the pipeline: between the measured gaps and the moved path in the gap compensation
//! ([`super::compensate_pass`]). A displacement sensor's noise is uncorrelated from reading to
//! reading while real gap errors (a shifted or tilted part, waviness) change over millimetres;
//! a Gaussian of standard deviation σ (mm of arc length) keeps variations longer than a few σ
//! and averages the noise away, so the noise does not become path noise. Weights are
//! normalised over the points that exist, so a constant stays constant up to the path's ends.
//! A closed path (first and last point in the same place) is smoothed around its loop.

/// Kernel reach in standard deviations: beyond 4σ the weight is below 0.04 %.
const REACH: f64 = 4.0;

/// `values` (one per point at arc length `s`, non-decreasing) smoothed by a Gaussian of
/// standard deviation `sigma` mm; `closed` paths wrap around (their last point repeats the
/// first and gets its value). `sigma = 0` returns the values unchanged.
pub fn gaussian(values: &[f64], s: &[f64], sigma: f64, closed: bool) -> Vec<f64> {
    let n = values.len().min(s.len());
    if sigma <= 0.0 || n < 2 {
        return values.to_vec();
    }
    // On a closed path the last point is the first one again: smooth the others on a loop.
    let (m, period) = if closed && n >= 3 {
        (n - 1, Some(s[n - 1] - s[0]))
    } else {
        (n, None)
    };
    let reach = REACH * sigma;
    let weight = |d: f64| (-0.5 * (d / sigma).powi(2)).exp();
    let mut out = Vec::with_capacity(n);
    for i in 0..m {
        let (mut sum, mut total) = (values[i], 1.0);
        // Walk both ways until the kernel's reach (or once around a loop).
        for dir in [1isize, -1] {
            for step in 1..m {
                let j = match period {
                    Some(_) => (i as isize + dir * step as isize).rem_euclid(m as isize) as usize,
                    None => {
                        let j = i as isize + dir * step as isize;
                        if j < 0 || j >= m as isize {
                            break;
                        }
                        j as usize
                    }
                };
                let mut d = (s[j] - s[i]).abs();
                if let Some(p) = period {
                    // The distance the walk has covered, going `dir` around the loop.
                    let ahead = (s[j] - s[i]).rem_euclid(p);
                    d = if dir > 0 { ahead } else { (p - ahead) % p };
                }
                // Half the loop each way, the far point once.
                let half = if dir > 0 { 2 * step > m } else { 2 * step >= m };
                if d > reach || (period.is_some() && half) {
                    break;
                }
                let w = weight(d);
                sum += w * values[j];
                total += w;
            }
        }
        out.push(sum / total);
    }
    if m < n {
        out.push(out[0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn a_sine_is_damped_by_the_gaussians_transfer_function() {
        // exp(−2π²σ²/λ²) for a sine of wavelength λ on a loop of whole periods (to the 1e-4
        // the kernel's cut at 4σ leaves).
        let (lambda, sigma, len) = (4.0, 0.5, 40.0);
        let n = 4001;
        let s: Vec<f64> = (0..n).map(|i| len * i as f64 / (n - 1) as f64).collect();
        let v: Vec<f64> = s.iter().map(|x| (2.0 * PI * x / lambda).sin()).collect();
        let out = gaussian(&v, &s, sigma, true);
        let expected = (-2.0 * PI * PI * sigma * sigma / (lambda * lambda)).exp();
        for (i, x) in s.iter().enumerate() {
            let want = expected * (2.0 * PI * x / lambda).sin();
            assert!((out[i] - want).abs() < 3e-4, "{i}: {} vs {want}", out[i]);
        }
    }

    #[test]
    fn constants_stay_constant_and_zero_sigma_changes_nothing() {
        let s: Vec<f64> = (0..50).map(|i| 0.1 * i as f64).collect();
        let v = vec![0.25; 50];
        for closed in [false, true] {
            let out = gaussian(&v, &s, 0.3, closed);
            assert!(out.iter().all(|x| (x - 0.25).abs() < 1e-15));
        }
        let ramp: Vec<f64> = s.iter().map(|x| x * x).collect();
        assert_eq!(gaussian(&ramp, &s, 0.0, false), ramp);
        // A ramp's inside is unchanged (symmetric kernel); its ends are pulled inward.
        let lin: Vec<f64> = s.clone();
        // (σ such that no point sits right at the kernel's reach, where rounding decides.)
        let out = gaussian(&lin, &s, 0.23, false);
        assert!((out[25] - lin[25]).abs() < 1e-12);
        assert!(out[0] > lin[0]);
    }
}
