//! Structural similarity (SSIM), Wang, Bovik, Sheikh & Simoncelli, "Image Quality
//! Assessment: From Error Visibility to Structural Similarity", IEEE TIP 13(4), 2004.

use super::{assert_same_size, Rgb32Image};

/// Window standard deviation (pixels), as in the paper.
const SIGMA: f64 = 1.5;
/// Window radius: an 11×11 window, as in the paper.
const RADIUS: usize = 5;
/// Stabilising constants `C1 = (K1 L)²`, `C2 = (K2 L)²` with dynamic range `L = 1`.
const K1: f64 = 0.01;
const K2: f64 = 0.03;

/// Mean SSIM of `b` against `a` (symmetric), for display values in `[0,1]`, usually
/// the output of [`tonemap_srgb`](super::tonemap_srgb).
///
/// Follows the paper's reference settings: an 11×11 circular-symmetric Gaussian window
/// with σ = 1.5 (normalised to sum 1), `K1 = 0.01`, `K2 = 0.03`, `L = 1`, and the mean of
/// the SSIM map over the *valid* region only — windows that fit entirely inside the
/// image, so no padding invents structure at the borders (the map is
/// `(w - 10) × (h - 10)`). It is computed on luma, `Y' = 0.2126 R' + 0.7152 G' +
/// 0.0722 B'` (Rec. 709 weights on the sRGB-encoded values), as the paper (and most
/// published numbers) evaluate grey-scale images; colour errors are FLIP's job.
///
/// No downsampling is applied (the paper's MATLAB code downsamples large images
/// by `round(min(w,h) / 256)`; at the 256×256 evaluation size that factor is 1 anyway).
/// Images smaller than 11 pixels in either direction use the largest window that
/// fits (same σ, truncated). Identical images give exactly 1. Accumulates in `f64`;
/// the window is separable, so the cost is 2 × 11 taps × 5 moments per pixel.
/// Panics if the sizes differ.
pub fn ssim(a: &Rgb32Image, b: &Rgb32Image) -> f64 {
    assert_same_size("ssim", a, b);
    let (w, h) = (a.width as usize, a.height as usize);
    if w == 0 || h == 0 {
        return 1.0;
    }
    let radius = RADIUS.min((w.min(h) - 1) / 2);
    let kernel = gaussian_window(radius);
    let taps = kernel.len();
    let (ow, oh) = (w + 1 - taps, h + 1 - taps);

    let luma = |img: &Rgb32Image| -> Vec<f64> {
        img.data
            .iter()
            .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
            .collect()
    };
    let x = luma(a);
    let y = luma(b);

    // Horizontal pass: the five moments x, y, x², y², xy, filtered along rows into
    // `ow`-wide planes; then the vertical pass runs row-wise over those planes so both
    // inner loops are contiguous and vectorise.
    let mut horiz = vec![[0.0f64; 5]; ow * h];
    for row in 0..h {
        let xr = &x[row * w..(row + 1) * w];
        let yr = &y[row * w..(row + 1) * w];
        let out = &mut horiz[row * ow..(row + 1) * ow];
        for (k, &wk) in kernel.iter().enumerate() {
            for (o, (&xv, &yv)) in out.iter_mut().zip(xr[k..].iter().zip(&yr[k..])) {
                o[0] += wk * xv;
                o[1] += wk * yv;
                o[2] += wk * xv * xv;
                o[3] += wk * yv * yv;
                o[4] += wk * xv * yv;
            }
        }
    }

    let c1 = (K1 * 1.0) * (K1 * 1.0);
    let c2 = (K2 * 1.0) * (K2 * 1.0);
    let mut acc = vec![[0.0f64; 5]; ow];
    let mut total = 0.0f64;
    for row in 0..oh {
        acc.iter_mut().for_each(|v| *v = [0.0; 5]);
        for (k, &wk) in kernel.iter().enumerate() {
            let src = &horiz[(row + k) * ow..(row + k + 1) * ow];
            for (o, s) in acc.iter_mut().zip(src) {
                for m in 0..5 {
                    o[m] += wk * s[m];
                }
            }
        }
        for m in &acc {
            let (mx, my) = (m[0], m[1]);
            let vx = m[2] - mx * mx;
            let vy = m[3] - my * my;
            let cxy = m[4] - mx * my;
            total += ((2.0 * mx * my + c1) * (2.0 * cxy + c2))
                / ((mx * mx + my * my + c1) * (vx + vy + c2));
        }
    }
    total / (ow * oh) as f64
}

/// Normalised 1-D Gaussian of σ = [`SIGMA`] with `2 radius + 1` taps; the 2-D window is
/// its outer product.
fn gaussian_window(radius: usize) -> Vec<f64> {
    let r = radius as f64;
    let g: Vec<f64> = (0..=2 * radius)
        .map(|i| {
            let d = i as f64 - r;
            (-d * d / (2.0 * SIGMA * SIGMA)).exp()
        })
        .collect();
    let sum: f64 = g.iter().sum();
    g.into_iter().map(|v| v / sum).collect()
}

#[cfg(test)]
mod tests {
    use super::super::test_rng::{add_noise, test_image};
    use super::*;

    fn shifted(img: &Rgb32Image, dx: usize) -> Rgb32Image {
        let (w, h) = (img.width as usize, img.height as usize);
        let data = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| img.data[y * w + (x + dx).min(w - 1)])
            .collect();
        Rgb32Image::new(img.width, img.height, data)
    }

    #[test]
    fn identical_is_one() {
        let a = test_image(64, 48);
        assert_eq!(ssim(&a, &a), 1.0);
        // Also for a flat image (zero variance, where only C1/C2 keep it finite).
        let f = Rgb32Image::filled(20, 20, [0.3; 3]);
        assert_eq!(ssim(&f, &f), 1.0);
    }

    #[test]
    fn shift_and_noise_lower_ssim() {
        let a = test_image(64, 48);
        let s = ssim(&a, &shifted(&a, 2));
        assert!(s < 0.99, "shifted ssim {s}");
        let low = ssim(&a, &add_noise(&a, 0.02, 7));
        let high = ssim(&a, &add_noise(&a, 0.08, 7));
        assert!(
            low < 1.0 && high < low,
            "noise 0.02: {low}, noise 0.08: {high}"
        );
        assert!(high > 0.0);
        // Symmetric (up to rounding: the cross term is summed as x·y vs y·x).
        assert!((ssim(&a, &shifted(&a, 2)) - ssim(&shifted(&a, 2), &a)).abs() < 1e-12);
    }

    #[test]
    fn matches_closed_form_for_constant_images() {
        // Flat images: variances are 0, SSIM = (2 mx my + C1) / (mx² + my² + C1).
        let a = Rgb32Image::filled(16, 16, [0.4; 3]);
        let b = Rgb32Image::filled(16, 16, [0.6; 3]);
        let (mx, my, c1) = (0.4f64, 0.6f64, K1 * K1);
        let expected = (2.0 * mx * my + c1) / (mx * mx + my * my + c1);
        // Luma of a grey f32 is not bit-exact 0.4, hence the tolerance.
        assert!((ssim(&a, &b) - expected).abs() < 1e-6);
    }

    #[test]
    fn tiny_images_do_not_panic() {
        let a = test_image(5, 9);
        let b = add_noise(&a, 0.05, 3);
        let v = ssim(&a, &b);
        assert!(v.is_finite() && v < 1.0);
        assert_eq!(ssim(&a, &a), 1.0);
    }
}
