//! Image-quality metrics for `dvr eval`: denoised frames against high-sample references.
//!
//! Everything here runs on the CPU on plain `f32` RGB images, so evaluation does not
//! depend on the GPU it runs on and the numbers can be checked against reference
//! implementations (FLIP against NVIDIA's `flip-evaluator`, see `tools/check_flip.py`).
//!
//! # Pipeline
//!
//! Renderers produce linear HDR radiance. Every metric is computed on *display*
//! values, because that is what a viewer compares and because linear-HDR PSNR is
//! dominated by a few bright pixels:
//!
//! 1. [`tonemap_srgb`] maps both the method's frame and the reference with the same
//!    exposure to sRGB-encoded values in `[0,1]`. It is the one tone map of the project:
//!    the PNGs written by `dvr eval` use it too, so what is measured is what is shown.
//! 2. [`psnr`], [`ssim`], [`flip`], [`temporal_error`] and [`outlier_fraction`] take
//!    those tone-mapped images.
//! 3. [`frames_to_recover`] post-processes a per-frame PSNR series around a sudden
//!    scene change (light jump, transfer-function jump, ...).
//!
//! All pairwise metrics panic if the two images differ in size: that is a bug in the
//! caller, not a measurement.

mod flip;
mod outliers;
mod psnr;
mod recovery;
mod score;
mod ssim;
mod temporal;
mod tonemap;

pub use flip::{flip, flip_colormap, FlipReference, FlipResult, DEFAULT_PPD};
pub use outliers::outlier_fraction;
pub use psnr::{psnr, PSNR_CAP};
pub use recovery::{frames_to_recover, RECOVERY_BASELINE_FRAMES};
pub use score::{display, score, FrameReference, Scores};
pub use ssim::ssim;
pub use temporal::temporal_error;
pub use tonemap::{tonemap_srgb, DISPLAY_EXPOSURE};

/// A three-channel `f32` image: linear HDR radiance as rendered, or sRGB-encoded
/// display values in `[0,1]` after [`tonemap_srgb`] (the type does not say which; the
/// functions document what they expect).
///
/// Row-major, top row first, `data.len() == width * height`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgb32Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<[f32; 3]>,
}

impl Rgb32Image {
    /// Wraps `data`; panics if its length is not `width * height`.
    pub fn new(width: u32, height: u32, data: Vec<[f32; 3]>) -> Self {
        assert_eq!(
            data.len(),
            width as usize * height as usize,
            "Rgb32Image: data length does not match {width}x{height}"
        );
        Self {
            width,
            height,
            data,
        }
    }

    /// An image of one colour.
    pub fn filled(width: u32, height: u32, value: [f32; 3]) -> Self {
        Self::new(width, height, vec![value; width as usize * height as usize])
    }

    /// Decodes 8-bit sRGB bytes (`RGBRGB...`, e.g. a PNG) to values in `[0,1]`.
    pub fn from_srgb8(width: u32, height: u32, bytes: &[u8]) -> Self {
        assert_eq!(
            bytes.len(),
            width as usize * height as usize * 3,
            "Rgb32Image::from_srgb8: byte length does not match {width}x{height}"
        );
        let data = bytes
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]].map(|c| f32::from(c) / 255.0))
            .collect();
        Self::new(width, height, data)
    }

    /// Quantises display values in `[0,1]` (the output of [`tonemap_srgb`]) to 8-bit
    /// bytes `RGBRGB...` for PNG writing, rounding to nearest; out-of-range values clamp.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.data
            .iter()
            .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
            .collect()
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// True for a 0-pixel image.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

/// Panics unless `a` and `b` have the same size; `what` names the metric.
fn assert_same_size(what: &str, a: &Rgb32Image, b: &Rgb32Image) {
    assert!(
        a.width == b.width && a.height == b.height,
        "{what}: image sizes differ ({}x{} vs {}x{})",
        a.width,
        a.height,
        b.width,
        b.height
    );
    debug_assert_eq!(a.data.len(), a.width as usize * a.height as usize);
    debug_assert_eq!(b.data.len(), b.width as usize * b.height as usize);
}

/// Deterministic pseudo-random numbers for the metric tests (no `rand` dependency).
#[cfg(test)]
pub(crate) mod test_rng {
    /// SplitMix64: tiny, good enough statistical quality for test noise.
    pub struct Rng(u64);

    impl Rng {
        pub fn new(seed: u64) -> Self {
            Self(seed)
        }

        pub fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }

        /// Uniform in `(0,1]`.
        pub fn uniform(&mut self) -> f64 {
            ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
        }

        /// Standard normal (Box–Muller).
        pub fn normal(&mut self) -> f64 {
            let (u1, u2) = (self.uniform(), self.uniform());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }

    /// A smooth, coloured, edge-rich test image in `[0,1]`.
    pub fn test_image(width: u32, height: u32) -> super::Rgb32Image {
        let mut data = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let u = x as f32 / (width - 1) as f32;
                let v = y as f32 / (height - 1) as f32;
                let square = ((x / 8) + (y / 8)) % 2 == 0;
                let s = if square { 0.25 } else { 0.0 };
                data.push([
                    0.1 + 0.6 * u + s,
                    0.2 + 0.5 * v + 0.5 * s,
                    0.7 - 0.5 * u * v + 0.1 * (x as f32 * 0.9).sin(),
                ]);
            }
        }
        super::Rgb32Image::new(width, height, data)
    }

    /// `img` plus independent Gaussian noise of standard deviation `sigma` per channel.
    pub fn add_noise(img: &super::Rgb32Image, sigma: f64, seed: u64) -> super::Rgb32Image {
        let mut rng = Rng::new(seed);
        let data = img
            .data
            .iter()
            .map(|p| p.map(|c| c + (sigma * rng.normal()) as f32))
            .collect();
        super::Rgb32Image::new(img.width, img.height, data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb8_round_trip() {
        let bytes: Vec<u8> = (0..=255u8).flat_map(|v| [v, 255 - v, v / 2]).collect();
        let img = Rgb32Image::from_srgb8(16, 16, &bytes);
        assert_eq!(img.to_srgb8(), bytes);
    }

    /// Per-frame cost at the evaluation size. Not a pass/fail test: run with
    /// `cargo test --release -p dvr-engine --lib metrics::tests::timing -- --ignored --nocapture`.
    #[test]
    #[ignore = "timing report; run in release with --ignored --nocapture"]
    fn timing_256x256() {
        use std::hint::black_box;
        use std::time::Instant;
        let hdr = test_rng::test_image(256, 256);
        let noisy = test_rng::add_noise(&hdr, 0.05, 1);
        let a = tonemap_srgb(&hdr, 1.0);
        let b = tonemap_srgb(&noisy, 1.0);
        let time = |name: &str, iters: u32, f: &mut dyn FnMut()| {
            f();
            let t = Instant::now();
            for _ in 0..iters {
                f();
            }
            let ms = t.elapsed().as_secs_f64() * 1e3 / f64::from(iters);
            println!("{name:>16}: {ms:8.3} ms / 256x256 frame");
        };
        time("tonemap_srgb", 50, &mut || {
            black_box(tonemap_srgb(black_box(&noisy), 1.0));
        });
        time("psnr", 200, &mut || {
            black_box(psnr(black_box(&a), black_box(&b)));
        });
        time("ssim", 50, &mut || {
            black_box(ssim(black_box(&a), black_box(&b)));
        });
        time("flip", 20, &mut || {
            black_box(flip(black_box(&a), black_box(&b), DEFAULT_PPD));
        });
        let prepared = FlipReference::new(&a, DEFAULT_PPD);
        time("flip (prepared)", 20, &mut || {
            black_box(prepared.compare(black_box(&b)));
        });
        time("temporal_error", 200, &mut || {
            black_box(temporal_error(&a, &b, &b, &a));
        });
    }

    #[test]
    #[should_panic(expected = "image sizes differ")]
    fn size_mismatch_panics() {
        let a = Rgb32Image::filled(4, 4, [0.5; 3]);
        let b = Rgb32Image::filled(4, 5, [0.5; 3]);
        psnr(&a, &b);
    }
}
