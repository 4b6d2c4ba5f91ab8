//! The metrics of one frame of one method against its reference, all on tone-mapped
//! sRGB display values (the same tone map and exposure as the PNGs): what `dvr eval`
//! reports and what the Python package's `dvr.metrics` computes.

use super::DISPLAY_EXPOSURE as EXPOSURE;
use super::{
    psnr, ssim, temporal_error, tonemap_srgb, FlipReference, Rgb32Image, DEFAULT_PPD, PSNR_CAP,
};

/// A reference frame prepared for scoring every method against it.
pub struct FrameReference {
    pub display: Rgb32Image,
    flip: FlipReference,
}

/// A linear HDR frame as the metrics and the page see it: tone-mapped at [`EXPOSURE`].
pub fn display(hdr: &Rgb32Image) -> Rgb32Image {
    tonemap_srgb(hdr, EXPOSURE)
}

impl FrameReference {
    pub fn new(hdr: &Rgb32Image) -> Self {
        let display = display(hdr);
        let flip = FlipReference::new(&display, DEFAULT_PPD);
        Self { display, flip }
    }
}

/// One method's scores on one frame.
pub struct Scores {
    /// dB, capped at [`PSNR_CAP`] (identical images).
    pub psnr: f64,
    pub ssim: f64,
    /// Mean LDR-FLIP error.
    pub flip: f64,
    /// `None` on the first frame (no previous frame to compare changes with).
    pub temporal_error: Option<f64>,
    pub flip_map: Vec<f32>,
    /// The method's frame as displayed (tone-mapped).
    pub display: Rgb32Image,
}

/// Scores `hdr` (a method's linear output) against `reference`; `previous` holds the
/// method's and the reference's displayed previous frames when there is one.
pub fn score(
    reference: &FrameReference,
    hdr: &Rgb32Image,
    previous: Option<(&Rgb32Image, &Rgb32Image)>,
) -> Scores {
    let display = display(hdr);
    let flip = reference.flip.compare(&display);
    Scores {
        psnr: psnr(&reference.display, &display).min(PSNR_CAP),
        ssim: ssim(&reference.display, &display),
        flip: flip.mean,
        temporal_error: previous.map(|(prev_test, prev_ref)| {
            temporal_error(prev_test, &display, prev_ref, &reference.display)
        }),
        flip_map: flip.error_map,
        display,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: u32, h: u32, k: f32) -> Rgb32Image {
        let data = (0..w * h)
            .map(|i| {
                let v = k * (i % w) as f32 / w as f32;
                [v, 0.5 * v, 0.25]
            })
            .collect();
        Rgb32Image::new(w, h, data)
    }

    #[test]
    fn identical_frames_score_perfectly() {
        let img = ramp(24, 16, 2.0);
        let r = FrameReference::new(&img);
        let s = score(&r, &img, None);
        assert_eq!(s.psnr, PSNR_CAP);
        assert_eq!(s.ssim, 1.0);
        assert_eq!(s.flip, 0.0);
        assert!(s.temporal_error.is_none());
        assert_eq!(s.flip_map.len(), 24 * 16);
        let again = score(&r, &img, Some((&s.display, &r.display)));
        assert_eq!(again.temporal_error, Some(0.0));
    }

    #[test]
    fn a_darker_frame_scores_worse() {
        let r = FrameReference::new(&ramp(24, 16, 2.0));
        let s = score(&r, &ramp(24, 16, 1.0), None);
        assert!(
            s.psnr.is_finite() && s.psnr > 0.0 && s.psnr < 40.0,
            "{}",
            s.psnr
        );
        assert!(s.ssim < 1.0 && s.flip > 0.0);
    }
}
