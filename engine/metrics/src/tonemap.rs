//! The project's one tone map: linear HDR radiance to sRGB display values.

use super::Rgb32Image;

/// The exposure every frame is tone-mapped at where it is shown or scored: the PNGs'
/// (`image_io::PNG_EXPOSURE`) and so the metrics'.
pub const DISPLAY_EXPOSURE: f32 = 1.0;

/// Tone-maps linear HDR radiance to sRGB-encoded display values in `[0,1]`.
///
/// Per channel `c`:
///
/// 1. `x = max(exposure * c, 0)` — exposure is a plain linear scale (1.0 = as rendered;
///    a value of 2 is one stop brighter). Negative values (possible with some
///    denoisers' reconstructions) become black; NaN becomes black too.
/// 2. `y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)` — Narkowicz's 2015 fit of
///    the ACES filmic curve, the same curve FLIP's HDR mode uses. It is strictly
///    increasing for `x >= 0` (the numerator of its derivative, `1.408 x² + 0.7028 x +
///    0.0042`, is positive), keeps shadows nearly linear (slope ≈ 0.21 at 0) and rolls
///    highlights off smoothly, so noise in bright regions is still visible instead of
///    being clipped away. Input 1.0 maps to 0.80; 0.18 ("mid grey") to 0.27.
/// 3. `y = min(y, 1)` — the curve's asymptote is 2.51 / 2.43 > 1 (1 is crossed at
///    an input of ≈ 7.24), so it is clamped; +∞ maps to white.
/// 4. The sRGB OETF (IEC 61966-2-1): `12.92 y` below 0.0031308, else
///    `1.055 y^(1/2.4) - 0.055`.
///
/// Applied per channel (not on luminance) on purpose: it is what real-time renderers
/// ship, it cannot push a channel out of range, and both reference and test go through
/// the same map, so hue shifts in saturated highlights are shared and cancel in the
/// metrics.
pub fn tonemap_srgb(img: &Rgb32Image, exposure: f32) -> Rgb32Image {
    let data = img
        .data
        .iter()
        .map(|p| p.map(|c| linear_to_srgb(aces_narkowicz(exposure * c).min(1.0))))
        .collect();
    Rgb32Image::new(img.width, img.height, data)
}

/// Narkowicz's ACES fit; NaN and negatives map to 0, +∞ to NaN, which the caller's
/// `f32::min(_, 1.0)` turns into 1 (`min` returns the non-NaN operand).
fn aces_narkowicz(x: f32) -> f32 {
    // `f32::max` returns the non-NaN operand, so NaN becomes 0 here.
    let x = x.max(0.0);
    (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
}

/// The sRGB OETF; input is clamped to `[0,1]` first.
pub(crate) fn linear_to_srgb(y: f32) -> f32 {
    let y = y.clamp(0.0, 1.0);
    if y >= 1.0 {
        // The formula gives 0.99999994 in f32; white must stay exactly white.
        1.0
    } else if y <= 0.003_130_8 {
        12.92 * y
    } else {
        1.055 * y.powf(1.0 / 2.4) - 0.055
    }
}

/// Clamps to `[0,1]`, mapping NaN to 0 (`f32::clamp` would keep NaN, which would then
/// poison filtered neighbourhoods and means).
pub(crate) fn clamp_unit(v: f32) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(0.0, 1.0)
    }
}

/// The inverse of [`linear_to_srgb`] (the sRGB EOTF), for values in `[0,1]`.
pub(crate) fn srgb_to_linear(s: f32) -> f32 {
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map_one(c: f32, exposure: f32) -> f32 {
        tonemap_srgb(&Rgb32Image::filled(1, 1, [c; 3]), exposure).data[0][0]
    }

    #[test]
    fn monotonic_and_in_unit_range() {
        let mut prev = -1.0f32;
        // 0 .. 1000 on a log-ish scale, plus exact zero.
        let mut c = 0.0f32;
        while c < 1000.0 {
            let y = map_one(c, 1.0);
            assert!((0.0..=1.0).contains(&y), "tonemap({c}) = {y} out of [0,1]");
            assert!(y >= prev, "tonemap not monotonic at {c}: {y} < {prev}");
            // Strictly increasing until the clamp at ~7.2.
            if c > 0.0 && c < 5.0 {
                assert!(y > prev, "tonemap flat at {c}");
            }
            prev = y;
            c = if c == 0.0 { 1e-4 } else { c * 1.05 };
        }
        assert_eq!(map_one(0.0, 1.0), 0.0);
        assert_eq!(map_one(1e6, 1.0), 1.0);
    }

    #[test]
    fn exposure_scales_input_and_non_finite_values_are_tamed() {
        assert!((map_one(0.5, 2.0) - map_one(1.0, 1.0)).abs() < 1e-6);
        assert_eq!(map_one(-3.0, 1.0), 0.0);
        assert_eq!(map_one(f32::NAN, 1.0), 0.0);
        assert_eq!(map_one(f32::INFINITY, 1.0), 1.0);
        // Documented anchor: 1.0 -> 0.80 linear before the OETF.
        let y = aces_narkowicz(1.0);
        assert!((y - 0.8038).abs() < 1e-3, "{y}");
    }

    #[test]
    fn srgb_transfer_round_trips() {
        for i in 0..=100 {
            let s = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(s)) - s).abs() < 1e-5);
        }
    }
}
