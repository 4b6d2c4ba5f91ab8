//! Temporal error: flicker and lag relative to the reference animation.

use super::{assert_same_size, Rgb32Image};

/// Mean absolute difference between the method's frame-to-frame change and the
/// reference's:
///
/// `mean over pixels and channels of |(cur_test - prev_test) - (cur_ref - prev_ref)|`.
///
/// Inputs are display values (tone-mapped with [`tonemap_srgb`](super::tonemap_srgb)
/// and the same exposure for all four). Per-frame metrics such as PSNR cannot see
/// temporal artefacts: a denoiser that flickers (changes where the reference does not)
/// or lags (does not change where the reference does, e.g. ghosting after a light
/// jump) can score well frame by frame yet look bad in motion; this measures exactly
/// that. It is 0 when the method changes exactly as the reference does, even if both
/// frames carry the same static bias. Panics if any size differs.
pub fn temporal_error(
    prev_test: &Rgb32Image,
    cur_test: &Rgb32Image,
    prev_ref: &Rgb32Image,
    cur_ref: &Rgb32Image,
) -> f64 {
    assert_same_size("temporal_error", prev_test, cur_test);
    assert_same_size("temporal_error", prev_test, prev_ref);
    assert_same_size("temporal_error", prev_test, cur_ref);
    let n = prev_test.data.len() * 3;
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = prev_test
        .data
        .iter()
        .zip(&cur_test.data)
        .zip(prev_ref.data.iter().zip(&cur_ref.data))
        .map(|((pt, ct), (pr, cr))| {
            (0..3)
                .map(|c| {
                    let dt = f64::from(ct[c]) - f64::from(pt[c]);
                    let dr = f64::from(cr[c]) - f64::from(pr[c]);
                    (dt - dr).abs()
                })
                .sum::<f64>()
        })
        .sum();
    sum / n as f64
}

#[cfg(test)]
mod tests {
    use super::super::test_rng::{add_noise, test_image};
    use super::*;

    fn offset(img: &Rgb32Image, d: f32) -> Rgb32Image {
        let data = img.data.iter().map(|p| p.map(|c| c + d)).collect();
        Rgb32Image::new(img.width, img.height, data)
    }

    #[test]
    fn zero_when_method_changes_like_reference() {
        let prev_ref = test_image(40, 30);
        let cur_ref = offset(&prev_ref, 0.1);
        // Same change on top of a static bias: no temporal error.
        let prev_test = offset(&prev_ref, 0.03);
        let cur_test = offset(&cur_ref, 0.03);
        let e = temporal_error(&prev_test, &cur_test, &prev_ref, &cur_ref);
        assert!(e.abs() < 1e-7, "{e}");
    }

    #[test]
    fn positive_for_flicker_and_for_lag() {
        let prev_ref = test_image(40, 30);
        let cur_ref = offset(&prev_ref, 0.1);
        // Lag: the method does not follow the reference's change at all.
        let lag = temporal_error(&prev_ref, &prev_ref, &prev_ref, &cur_ref);
        assert!((lag - 0.1).abs() < 1e-6, "{lag}");
        // Flicker: the reference is static, the method's noise changes every frame.
        let a = add_noise(&prev_ref, 0.02, 1);
        let b = add_noise(&prev_ref, 0.02, 2);
        let flicker = temporal_error(&a, &b, &prev_ref, &prev_ref);
        // E|N(0, 2 sigma²)| = 2 sigma / sqrt(pi) ≈ 0.0226.
        assert!((flicker - 0.0226).abs() < 0.002, "{flicker}");
    }
}
