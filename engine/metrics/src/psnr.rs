//! Peak signal-to-noise ratio.

use super::{assert_same_size, Rgb32Image};

/// A finite stand-in for the infinite PSNR of identical images, for plots, CSV
/// averages and [`frames_to_recover`](super::frames_to_recover). 100 dB is an RMS error
/// of 1e-5, far below 8-bit quantisation (≈ 59 dB), so no real difference reaches it.
pub const PSNR_CAP: f64 = 100.0;

/// PSNR in dB of `b` against `a`, for display values in `[0,1]` (peak 1), usually
/// the output of [`tonemap_srgb`](super::tonemap_srgb): `10 log10(1 / MSE)` with the
/// MSE taken over all pixels and all three channels alike (no colour weighting).
///
/// Identical images give `f64::INFINITY`, which is the honest value; callers that
/// plot or average should use `psnr(a, b).min(PSNR_CAP)`. Accumulates in `f64`.
/// Panics if the sizes differ. An empty image counts as identical.
pub fn psnr(a: &Rgb32Image, b: &Rgb32Image) -> f64 {
    assert_same_size("psnr", a, b);
    let n = a.data.len() * 3;
    if n == 0 {
        return f64::INFINITY;
    }
    let sse: f64 = a
        .data
        .iter()
        .zip(&b.data)
        .map(|(p, q)| {
            (0..3)
                .map(|c| {
                    let d = f64::from(p[c]) - f64::from(q[c]);
                    d * d
                })
                .sum::<f64>()
        })
        .sum();
    if sse == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (n as f64 / sse).log10()
}

#[cfg(test)]
mod tests {
    use super::super::test_rng::{add_noise, test_image};
    use super::*;

    #[test]
    fn identical_is_infinite() {
        let a = test_image(32, 24);
        assert_eq!(psnr(&a, &a), f64::INFINITY);
        assert_eq!(psnr(&a, &a).min(PSNR_CAP), PSNR_CAP);
    }

    #[test]
    fn gaussian_noise_matches_analytic_value() {
        // Mid grey, so sigma = 0.05 noise is 10 sigma away from the [0,1] bounds and
        // nothing would be clipped: the expected MSE is exactly sigma².
        let a = Rgb32Image::filled(256, 256, [0.5; 3]);
        for (sigma, seed) in [(0.05, 1), (0.01, 2), (0.1, 3)] {
            let b = add_noise(&a, sigma, seed);
            let expected = 10.0 * (1.0 / (sigma * sigma)).log10();
            let got = psnr(&a, &b);
            assert!(
                (got - expected).abs() < 0.1,
                "sigma {sigma}: psnr {got:.3} dB, analytic {expected:.3} dB"
            );
        }
    }

    #[test]
    fn known_constant_offset() {
        let a = Rgb32Image::filled(8, 8, [0.25; 3]);
        let b = Rgb32Image::filled(8, 8, [0.35; 3]);
        // MSE = 0.01 -> 20 dB.
        assert!((psnr(&a, &b) - 20.0).abs() < 1e-5);
        assert_eq!(psnr(&a, &b), psnr(&b, &a));
    }
}
