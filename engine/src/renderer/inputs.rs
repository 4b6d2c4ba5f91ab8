//! What a frame takes (camera, lights, TF; what to produce) and what it gives back.

use super::present::Screenshot;
use super::uploads::LutUpload;
use crate::gpu::timestamps::PassTiming;
use crate::scene::Cut;
use crate::shaders::frame::GpuLight;
use glam::{Mat4, Vec3, Vec4};

/// A camera as the renderer needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMatrices {
    pub view: Mat4,
    pub proj: Mat4,
    pub position: Vec3,
}

impl CameraMatrices {
    /// A perspective camera in Vulkan conventions: right-handed view space, clip-space y
    /// pointing down (image row 0 at the top), depth in [0, 1].
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_y: f32, aspect: f32) -> Self {
        let f = (target - eye).normalize();
        let s = f.cross(up).normalize();
        let u = s.cross(f);
        let view = Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
        );
        let (near, far) = (0.01f32, 100.0f32);
        let h = 1.0 / (0.5 * fov_y).tan();
        let proj = Mat4::from_cols(
            Vec4::new(h / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -h, 0.0, 0.0), // y down in Vulkan clip space
            Vec4::new(0.0, 0.0, far / (near - far), -1.0),
            Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
        );
        Self {
            view,
            proj,
            position: eye,
        }
    }
}

/// The per-frame state of an animation.
#[derive(Clone, Debug)]
pub struct FrameInputs {
    pub camera: CameraMatrices,
    pub lights: Vec<GpuLight>,
    /// The transfer function this frame (uploaded only when it differs from the last).
    pub lut: LutUpload,
    /// The clip planes and crop box.
    pub cut: Cut,
    /// The time point of a series this frame shows (`None`: the volume as set up).
    pub time: Option<SeriesTime>,
    /// The label map's look this frame (uploaded when it differs from the last;
    /// `None`: no label map).
    pub labels: Option<LabelLookRef>,
}

/// A label look as a frame input: equal when it is the same one (a look is made again
/// only when a label's look changed).
#[derive(Clone, Debug)]
pub struct LabelLookRef(pub std::sync::Arc<crate::volume::labels::LabelLook>);

impl PartialEq for LabelLookRef {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A time point of a series: the renderer uploads the volume it names when it differs
/// from the one on the device.
#[derive(Clone, Debug)]
pub struct SeriesTime {
    pub timeline: std::sync::Arc<super::timeline::Timeline>,
    /// Fractional: the two time points around it interpolated.
    pub time: f64,
}

impl PartialEq for SeriesTime {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.timeline, &other.timeline) && self.time == other.time
    }
}

/// What one frame should produce.
#[derive(Clone, Debug, Default)]
pub struct FrameRequest {
    /// Read the outputs of these methods back to the host ("noisy" is the raw radiance).
    pub readback: bool,
    /// Restart every history (a cut).
    pub reset: bool,
    /// Also render the guide images of single-frame denoisers and read them back with the
    /// methods' outputs (as [`aux_features::ALBEDO`] and [`aux_features::NORMAL`]; needs
    /// `readback`).
    ///
    /// [`aux_features::ALBEDO`]: crate::passes::aux_features::ALBEDO
    /// [`aux_features::NORMAL`]: crate::passes::aux_features::NORMAL
    pub aux: bool,
    /// Also read back the surface features (world position, normal with the distance
    /// along the ray, TF albedo; [`FEATURE_IMAGES`]), rendering them if no denoiser
    /// needs them (needs `readback`).
    pub features: bool,
}

/// The names [`FrameRequest::features`] reads the surface features back as, each RGBA
/// (surface_features.comp): position (w = 1 where the ray met the threshold surface or,
/// through semi-transparent medium, at the expected first collision), normal (w =
/// distance along the ray) and albedo (w = 1), both on the threshold surface only.
pub const FEATURE_IMAGES: [&str; 3] = ["features.position", "features.normal", "features.albedo"];

/// Results of a completed frame.
#[derive(Clone, Debug, Default)]
pub struct FrameResult {
    pub index: u64,
    pub timings: Vec<PassTiming>,
    /// (method, rgba pixels) for each method when readback was requested.
    pub images: Vec<(String, Vec<[f32; 4]>)>,
    /// The presented image, UI included, when its readback was requested.
    pub screenshot: Option<Screenshot>,
}
