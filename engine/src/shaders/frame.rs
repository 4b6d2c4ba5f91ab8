//! What every volume shader shares: the per-frame uniform block (`FrameBlock` in
//! `include/frame.glsl`), its lights, and the integer codes the GLSL `#define`s for light
//! kinds, environment modes, estimators and phase functions
//! (`include/specialization.glsl`). The constants are declared once, here, with the GLSL
//! file that holds each twin; `tests::glsl_defines_match` reads those files and fails on
//! any constant that differs or exists on one side only.

use super::GpuBlock;
use crate::gpu_block;
use glam::{IVec4, Mat4, UVec4, Vec3, Vec4};

/// Declares the shared constants and [`GLSL_DEFINES`], the table the test compares with
/// the GLSL, from one list.
macro_rules! glsl_defines {
    ($($file:literal { $($(#[$meta:meta])* $name:ident : $ty:ty = $value:expr),* $(,)? })*) => {
        $($($(#[$meta])* pub const $name: $ty = $value;)*)*

        /// (GLSL file under `shaders/glsl/include/`, name, value) of every constant above.
        pub const GLSL_DEFINES: &[(&str, &str, f64)] =
            &[$($(($file, stringify!($name), $name as f64)),*),*];
    };
}

glsl_defines! {
    "frame.glsl" {
        /// Lights the frame block holds: as many as a scene may have.
        MAX_LIGHTS: usize = crate::scene::MAX_LIGHTS,
        /// Clip planes the frame block holds: as many as a scene's cut may have.
        MAX_CLIP_PLANES: usize = crate::scene::MAX_CLIP_PLANES,
        /// Entries of a channel's opacity row in the frame block: the LUTs' own.
        LUT_SIZE: usize = crate::transfer::LUT_SIZE,
        /// `GpuLight::position_kind.w`: what the light is.
        LIGHT_POINT: f32 = 0.0,
        LIGHT_AREA: f32 = 1.0,
        LIGHT_ENV: f32 = 2.0,
        /// `GpuLight::radiance.w` of an environment light: where its radiance comes from.
        ENV_CONSTANT: f32 = 0.0,
        ENV_GRADIENT: f32 = 1.0,
        ENV_MAP: f32 = 2.0,
    }
    "specialization.glsl" {
        /// Values of the `ESTIMATOR` specialisation constant.
        ESTIMATOR_DELTA: i32 = 0,
        ESTIMATOR_RAY_MARCH: i32 = 1,
        /// Values of the `PHASE` specialisation constant.
        PHASE_ISOTROPIC: i32 = 0,
        PHASE_HG: i32 = 1,
        PHASE_HYBRID: i32 = 2,
        /// Values of the `LABELS` specialisation constant.
        LABELS_NONE: i32 = 0,
        LABELS_TINT: i32 = 1,
        LABELS_SOLID: i32 = 2,
    }
}

gpu_block! {
    /// `struct Light` in frame.glsl: four vec4s whose meaning depends on the kind.
    pub struct GpuLight {
        /// xyz position (area: centre), w kind ([`LIGHT_POINT`], …).
        pub position_kind: Vec4,
        /// rgb colour × intensity (environment: top colour), w environment mode.
        pub radiance: Vec4,
        /// Area: half-extent vector along u; environment: bottom colour, w intensity.
        pub u_axis: Vec4,
        /// Area: half-extent vector along v.
        pub v_axis: Vec4,
    }
}

gpu_block! {
    /// `FrameBlock` in frame.glsl. Its vec4 lanes hold unrelated values (the GLSL names
    /// them so); [`FrameBlock::new`] is the one place that knows which lane holds what,
    /// so build it from [`FrameParams`] rather than lane by lane.
    pub struct FrameBlock {
        pub view_proj: Mat4,
        pub inv_view_proj: Mat4,
        pub prev_view_proj: Mat4,
        pub camera_pos: Vec4,
        pub box_min: Vec4,
        pub box_max: Vec4,
        pub dims: IVec4,
        pub counts: IVec4,
        pub params: Vec4,
        pub seeds: UVec4,
        pub lights: [GpuLight; MAX_LIGHTS],
        /// What the cut keeps: the crop box in world space (within the volume's box).
        pub crop_min: Vec4,
        pub crop_max: Vec4,
        /// `counts.z` planes: xyz unit normal, w offset (kept where `n·x + w >= 0`).
        pub clip: [Vec4; MAX_CLIP_PLANES],
        /// With a label map: x the one opacity every shown label has, 0 when they differ.
        pub labels: Vec4,
        /// Several channels: entry i, lane c is channel c's opacity at density
        /// `i / (LUT_SIZE − 1)`.
        pub channel_opacity: ChannelOpacity,
    }
}

/// Which random numbers a path-tracing dispatch draws: the RNG hashes this index (the
/// frame block's `counts.y`) with the pixel, the sample and the seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleStream {
    /// Frame `n` of the animation draws stream `n`.
    Frame(u64),
    /// A reference draws from the top of the index range down: `i32::MAX − n` after `n`
    /// frames, far from any stream an animation reaches, so a reference never shares
    /// random numbers with the noisy frames it is compared with.
    Reference { after_frames: u64 },
}

impl SampleStream {
    /// The index the shaders read (`frame.counts.y`).
    pub fn index(self) -> i32 {
        match self {
            SampleStream::Frame(n) => n as i32,
            SampleStream::Reference { after_frames } => i32::MAX - after_frames as i32,
        }
    }
}

/// The values of one frame's [`FrameBlock`], by name.
#[derive(Clone, Copy, Debug)]
pub struct FrameParams<'a> {
    pub view_proj: Mat4,
    /// Last frame's view-projection (this frame's on the first frame).
    pub prev_view_proj: Mat4,
    pub camera: Vec3,
    /// Half the volume's world size: the volume box is centred at the origin.
    pub half_size: Vec3,
    /// Extinction per unit opacity (1/world unit).
    pub density_scale: f32,
    /// Largest extinction in the volume (the global majorant).
    pub majorant_max: f32,
    pub volume_dims: [u32; 3],
    /// Edge of a majorant-grid brick in voxels.
    pub brick: u32,
    /// At most [`MAX_LIGHTS`] (scenes and the renderer refuse more).
    pub lights: &'a [GpuLight],
    pub stream: SampleStream,
    pub max_bounces: u32,
    /// Bounce from which Russian roulette may end a path.
    pub rr_depth: u32,
    /// Ray-marching step in world units.
    pub step: f32,
    pub hg_g: f32,
    /// Accumulated opacity at which the surface-features pass stops.
    pub feature_threshold: f32,
    /// Standard deviation of the Gaussian pixel filter, in pixels.
    pub filter_sigma: f32,
    pub seed: u32,
    /// The crop box in world space, within the volume's box (the box itself when
    /// nothing is cropped).
    pub crop: (Vec3, Vec3),
    /// Enabled clip planes (xyz unit normal, w offset), at most [`MAX_CLIP_PLANES`].
    pub clip: &'a [Vec4],
    /// Several channels: their opacity rows, lane by lane.
    pub channel_opacity: &'a ChannelOpacity,
    /// With a label map: the one opacity every shown label has, 0 when they differ (see
    /// `LabelLook::shown_opacity`).
    pub label_opacity: f32,
}

/// Most channels one medium holds: a volume texel's four components (and the lanes of
/// [`ChannelOpacity`]), as many as a scene may have.
pub use crate::scene::MAX_CHANNELS;

/// The channels' opacity rows interleaved, as the frame block holds them: entry i, lane
/// c is channel c's opacity at density `i / (LUT_SIZE − 1)`.
#[repr(transparent)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ChannelOpacity(pub [Vec4; LUT_SIZE]);

impl Default for ChannelOpacity {
    fn default() -> Self {
        Self([Vec4::ZERO; LUT_SIZE])
    }
}

impl ChannelOpacity {
    /// From `opacity`, the channels' rows of [`LUT_SIZE`] entries laid end to end (at
    /// most [`MAX_CHANNELS`]; lanes past them are 0).
    pub fn from_rows(opacity: &[f32]) -> Self {
        let mut t = Self::default();
        for (c, row) in opacity.chunks(LUT_SIZE).take(MAX_CHANNELS).enumerate() {
            for (entry, &a) in t.0.iter_mut().zip(row) {
                entry[c] = a;
            }
        }
        t
    }
}

impl FrameBlock {
    /// Packs `p` into the lanes frame.glsl declares. Lanes no shader reads (`seeds.y`,
    /// `seeds.w`) are zero.
    pub fn new(p: &FrameParams) -> Self {
        let mut lights = [GpuLight::default(); MAX_LIGHTS];
        for (dst, src) in lights.iter_mut().zip(p.lights) {
            *dst = *src;
        }
        let [x, y, z] = p.volume_dims.map(|d| d as i32);
        let mut clip = [Vec4::ZERO; MAX_CLIP_PLANES];
        for (dst, src) in clip.iter_mut().zip(p.clip) {
            *dst = *src;
        }
        Self {
            view_proj: p.view_proj,
            inv_view_proj: p.view_proj.inverse(),
            prev_view_proj: p.prev_view_proj,
            camera_pos: p.camera.extend(1.0),
            box_min: (-p.half_size).extend(p.density_scale),
            box_max: p.half_size.extend(p.majorant_max),
            dims: IVec4::new(x, y, z, p.brick as i32),
            counts: IVec4::new(
                p.lights.len().min(MAX_LIGHTS) as i32,
                p.stream.index(),
                p.clip.len().min(MAX_CLIP_PLANES) as i32,
                p.max_bounces as i32,
            ),
            params: Vec4::new(p.step, p.hg_g, p.feature_threshold, p.filter_sigma),
            seeds: UVec4::new(p.seed, 0, p.rr_depth, 0),
            lights,
            crop_min: p.crop.0.extend(0.0),
            crop_max: p.crop.1.extend(0.0),
            clip,
            labels: Vec4::new(p.label_opacity, 0.0, 0.0, 0.0),
            channel_opacity: *p.channel_opacity,
        }
    }
}

/// The name of [`FrameBlock`]'s GLSL block, which pipelines check it against.
pub const FRAME_BLOCK: &str = "FrameBlock";

const _: () = assert!(std::mem::size_of::<GpuLight>() == 64);
const _: () = assert!(<FrameBlock as GpuBlock>::FIELDS.len() == 16);

#[cfg(test)]
mod tests {
    use super::*;

    /// `#define NAME number` lines of a GLSL file (include guards have no value).
    fn numeric_defines(glsl: &str) -> Vec<(String, f64)> {
        glsl.lines()
            .filter_map(|l| {
                let mut words = l.split_whitespace();
                (words.next()? == "#define").then_some(())?;
                let name = words.next()?;
                let value = words.next()?.parse().ok()?;
                Some((name.to_string(), value))
            })
            .collect()
    }

    #[test]
    fn glsl_defines_match() {
        let files = [
            (
                "frame.glsl",
                include_str!("../../../shaders/glsl/include/frame.glsl"),
            ),
            (
                "specialization.glsl",
                include_str!("../../../shaders/glsl/include/specialization.glsl"),
            ),
        ];
        for (file, text) in files {
            let glsl = numeric_defines(text);
            let rust: Vec<(&str, f64)> = GLSL_DEFINES
                .iter()
                .filter(|(f, ..)| *f == file)
                .map(|&(_, n, v)| (n, v))
                .collect();
            for (name, value) in &rust {
                let twin = glsl.iter().find(|(n, _)| n == name);
                assert_eq!(
                    twin.map(|t| t.1),
                    Some(*value),
                    "{name}: Rust says {value}, {file} says {twin:?}"
                );
            }
            for (name, value) in &glsl {
                assert!(
                    rust.iter().any(|(n, _)| n == name),
                    "{file} defines {name} = {value}, which engine/src/shaders/frame.rs lacks"
                );
            }
        }
        assert!(GLSL_DEFINES.len() >= 12);
    }

    #[test]
    fn reference_streams_count_down_from_the_top() {
        assert_eq!(SampleStream::Frame(7).index(), 7);
        assert_eq!(
            SampleStream::Reference { after_frames: 0 }.index(),
            i32::MAX
        );
        assert_eq!(
            SampleStream::Reference { after_frames: 3 }.index(),
            i32::MAX - 3
        );
    }

    #[test]
    fn frame_block_puts_values_in_their_lanes() {
        let light = GpuLight {
            position_kind: Vec4::new(1.0, 2.0, 3.0, LIGHT_AREA),
            ..Default::default()
        };
        // Two channels' opacity rows: channel c's entry i holds 1000·c + i.
        let rows: Vec<f32> = (0..2 * LUT_SIZE)
            .map(|k| (1000 * (k / LUT_SIZE) + k % LUT_SIZE) as f32)
            .collect();
        let b = FrameBlock::new(&FrameParams {
            view_proj: Mat4::IDENTITY,
            prev_view_proj: Mat4::IDENTITY,
            camera: Vec3::new(0.0, 0.0, 2.0),
            half_size: Vec3::splat(0.5),
            density_scale: 100.0,
            majorant_max: 7.0,
            volume_dims: [8, 9, 10],
            brick: 4,
            lights: &[light],
            stream: SampleStream::Frame(5),
            max_bounces: 6,
            rr_depth: 3,
            step: 0.01,
            hg_g: 0.2,
            feature_threshold: 0.5,
            filter_sigma: 0.5,
            seed: 11,
            crop: (Vec3::splat(-0.25), Vec3::splat(0.5)),
            clip: &[Vec4::new(0.0, 0.0, 1.0, -0.1)],
            channel_opacity: &ChannelOpacity::from_rows(&rows),
            label_opacity: 0.75,
        });
        assert_eq!(b.labels, Vec4::new(0.75, 0.0, 0.0, 0.0));
        assert_eq!(b.channel_opacity.0[3], Vec4::new(3.0, 1003.0, 0.0, 0.0));
        assert_eq!(
            b.channel_opacity.0[LUT_SIZE - 1].y,
            1000.0 + (LUT_SIZE - 1) as f32
        );
        assert_eq!(b.counts, IVec4::new(1, 5, 1, 6));
        assert_eq!(b.crop_min.truncate(), Vec3::splat(-0.25));
        assert_eq!(b.clip[0], Vec4::new(0.0, 0.0, 1.0, -0.1));
        assert_eq!(b.clip[1], Vec4::ZERO);
        assert_eq!(b.seeds, UVec4::new(11, 0, 3, 0));
        assert_eq!(b.dims, IVec4::new(8, 9, 10, 4));
        assert_eq!(b.box_min, Vec4::new(-0.5, -0.5, -0.5, 100.0));
        assert_eq!(b.box_max.w, 7.0);
        assert_eq!(b.lights[0], light);
        assert_eq!(b.lights[1], GpuLight::default());
    }
}
