//! Isolated outliers: pixels whose error against the reference stands far above the
//! error around them. A filter that spreads one bad sample into a block (the à-trous
//! of SVGF fed a pixel that mixed with the wrong class), or keeps a firefly, leaves
//! them; noise spread evenly, or a blur, does not. Thin features rendered wrong (a
//! vessel one pixel wide shown as dots) count too: their error is local as well.
//!
//! A pixel counts when its error e (the mean absolute difference of the three display
//! channels, from [`tonemap_srgb`](super::tonemap_srgb)) exceeds `k` times the median
//! error of its 5×5 window (itself included; clamped at the image's edge) and is large
//! enough to see (`floor`, in display units). The median ignores a block of up to 12
//! pixels inside the window, so blocks of up to 3×3 are found in full and larger ones
//! along their edges.

use super::{assert_same_size, Rgb32Image};

/// Half the side of the window whose median error a pixel is compared with.
pub const WINDOW_RADIUS: i64 = 2;

/// The share of pixels of `out` that are isolated outliers against `reference` (both
/// display values in `[0, 1]`), see the module's comment. Panics if the sizes differ.
pub fn outlier_fraction(out: &Rgb32Image, reference: &Rgb32Image, k: f32, floor: f32) -> f64 {
    assert_same_size("outlier_fraction", out, reference);
    let (w, h) = (out.width as i64, out.height as i64);
    if w == 0 || h == 0 {
        return 0.0;
    }
    let error: Vec<f32> = out
        .data
        .iter()
        .zip(&reference.data)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).sum::<f32>() / 3.0)
        .collect();
    let mut window = Vec::with_capacity(25);
    let mut count = 0usize;
    for y in 0..h {
        for x in 0..w {
            let e = error[(y * w + x) as usize];
            if e <= floor {
                continue;
            }
            window.clear();
            for dy in -WINDOW_RADIUS..=WINDOW_RADIUS {
                for dx in -WINDOW_RADIUS..=WINDOW_RADIUS {
                    let (qx, qy) = ((x + dx).clamp(0, w - 1), (y + dy).clamp(0, h - 1));
                    window.push(error[(qy * w + qx) as usize]);
                }
            }
            let mid = window.len() / 2;
            let median = *window.select_nth_unstable_by(mid, f32::total_cmp).1;
            if e > k * median {
                count += 1;
            }
        }
    }
    count as f64 / (w * h) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> Rgb32Image {
        let data = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| [f(x, y); 3])
            .collect();
        Rgb32Image::new(w, h, data)
    }

    #[test]
    fn blocks_and_fireflies_count_and_even_noise_or_blur_does_not() {
        let reference = image(32, 32, |x, _| 0.3 + 0.01 * x as f32);
        // A 3×3 block and a single firefly on an otherwise exact image: 10 pixels.
        let blocks = image(32, 32, |x, y| {
            let r = 0.3 + 0.01 * x as f32;
            let block = (10..13).contains(&x) && (10..13).contains(&y);
            if block || (x, y) == (25, 5) {
                r + 0.4
            } else {
                r
            }
        });
        let f = outlier_fraction(&blocks, &reference, 4.0, 0.05);
        assert!((f - 10.0 / 1024.0).abs() < 1e-9, "{f}");
        // An even offset (a blur's bias) and mild noise everywhere: nothing.
        let offset = image(32, 32, |x, _| 0.45 + 0.01 * x as f32);
        assert_eq!(outlier_fraction(&offset, &reference, 4.0, 0.05), 0.0);
        let noisy = image(32, 32, |x, y| {
            0.3 + 0.01 * x as f32 + 0.08 * (((x * 7 + y * 13) % 5) as f32 / 4.0 - 0.5)
        });
        assert_eq!(outlier_fraction(&noisy, &reference, 4.0, 0.05), 0.0);
        // Below the floor nothing counts, however isolated.
        assert_eq!(outlier_fraction(&blocks, &reference, 4.0, 0.5), 0.0);
    }
}
