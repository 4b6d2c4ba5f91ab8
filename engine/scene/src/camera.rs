//! `[camera]` as written (in f64, degrees) and [`Camera`], the per-frame camera the GPU
//! code uses (f32, radians, with its matrices).
//!
//! Conventions: world space is right-handed (see [`super::volume`]). The view matrix
//! maps world space to a right-handed, y-up view space looking down −z. The projection
//! is Vulkan's: clip-space y points *down* (NDC y = −1 is the top row of the image),
//! depth runs from 0 at [`CAMERA_NEAR`] to 1 at [`CAMERA_FAR`]. So a pixel `(x, y)` of a
//! `w × h` image (row 0 at the top) has NDC `(2(x+0.5)/w − 1, 2(y+0.5)/h − 1)`, and the
//! primary ray through it is `inverse(view_proj) · (ndc, depth, 1)` for two depths.

use glam::{DVec3, Mat4, Vec3};
use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};

/// Near plane in world units (the volume spans 1 unit, so this clips nothing visible).
pub const CAMERA_NEAR: f32 = 0.01;
/// Far plane in world units.
pub const CAMERA_FAR: f32 = 100.0;
/// Farthest the camera and its target may be from the volume's centre: half the far
/// plane, so the volume is always inside the view frustum's depth range.
pub const MAX_CAMERA_DISTANCE: f64 = (CAMERA_FAR as f64) / 2.0;

/// Vertical field of view when a scene does not give one.
pub const DEFAULT_FOV_Y_DEGREES: f64 = 40.0;

fn default_up() -> DVec3 {
    DVec3::Z
}

fn default_fov() -> f64 {
    DEFAULT_FOV_Y_DEGREES
}

/// `[camera]`: where the camera is at rest (animation tracks override it per frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Eye position in world units.
    pub position: DVec3,
    /// The point looked at; default the volume's centre (the origin).
    #[serde(default)]
    pub target: DVec3,
    /// Up direction; default `+z` (superior for medical volumes). Need not be unit or
    /// orthogonal to the view direction, only not parallel to it.
    #[serde(default = "default_up")]
    pub up: DVec3,
    /// Vertical field of view in degrees, in (0, 180). Default 40.
    #[serde(default = "default_fov")]
    pub fov_y_degrees: f64,
}

impl Default for CameraSpec {
    /// In front of the volume (+y), a little to the right and above, 1.6 units out.
    fn default() -> Self {
        Self {
            position: DVec3::new(0.45, 1.5, 0.35),
            target: DVec3::ZERO,
            up: DVec3::Z,
            fov_y_degrees: DEFAULT_FOV_Y_DEGREES,
        }
    }
}

impl CameraSpec {
    pub(crate) fn check(&self, ctx: &Ctx, field: &str) -> Result<(), SceneError> {
        let why = "the volume is 1 unit across and the far plane 100 units away";
        ctx.near_origin(
            &format!("{field}.position"),
            self.position,
            MAX_CAMERA_DISTANCE,
            why,
        )?;
        ctx.near_origin(
            &format!("{field}.target"),
            self.target,
            MAX_CAMERA_DISTANCE,
            why,
        )?;
        ctx.unit_vector(&format!("{field}.up"), self.up)?;
        check_fov(ctx, &format!("{field}.fov_y_degrees"), self.fov_y_degrees)?;
        let dir = self.target - self.position;
        if dir.length_squared() < 1e-12 {
            return Err(ctx.invalid(format!("{field}.target"), "equals the camera position"));
        }
        if dir.normalize().cross(self.up.normalize()).length_squared() < 1e-8 {
            return Err(ctx.invalid(format!("{field}.up"), "is parallel to the view direction"));
        }
        Ok(())
    }

    /// The per-frame camera (f32, radians).
    pub fn camera(&self) -> Camera {
        Camera {
            position: self.position.as_vec3(),
            target: self.target.as_vec3(),
            up: self.up.normalize_or(DVec3::Z).as_vec3(),
            fov_y: self.fov_y_degrees.to_radians() as f32,
        }
    }
}

pub(crate) fn check_fov(ctx: &Ctx, field: &str, fov: f64) -> Result<(), SceneError> {
    if fov.is_finite() && fov > 0.0 && fov < 180.0 {
        Ok(())
    } else {
        Err(ctx.invalid(field, format!("{fov} must be in (0, 180) degrees")))
    }
}

/// The camera of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    /// Unit up vector.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
}

impl Camera {
    /// Unit vector from the eye towards the target.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.position).normalize_or(Vec3::NEG_Z)
    }

    /// World → view: right-handed, y up, looking down −z.
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.target, self.up)
    }

    /// View → clip for Vulkan (y down, depth 0..1 between [`CAMERA_NEAR`] and
    /// [`CAMERA_FAR`]). `aspect` is width / height; a non-positive or non-finite aspect
    /// is treated as 1 rather than producing a degenerate matrix.
    pub fn proj(&self, aspect: f32) -> Mat4 {
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let fov = self.fov_y.clamp(1e-4, std::f32::consts::PI - 1e-4);
        glam::camera::rh::proj::vulkan::perspective(fov, aspect, CAMERA_NEAR, CAMERA_FAR)
    }

    /// World → clip: `proj(aspect) · view()`.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.proj(aspect) * self.view()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        CameraSpec::default().camera()
    }

    #[test]
    fn target_projects_to_the_centre() {
        let c = cam();
        let clip = c.view_proj(16.0 / 9.0) * c.target.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5, "{ndc}");
        assert!(ndc.z > 0.0 && ndc.z < 1.0, "depth {}", ndc.z);
    }

    #[test]
    fn vulkan_conventions_y_down_depth_increasing() {
        let c = cam();
        let vp = c.view_proj(1.0);
        let ndc = |p: Vec3| vp.project_point3(p);
        // A point above the target (along up) is in the top half: negative NDC y.
        assert!(ndc(c.target + 0.1 * c.up).y < 0.0);
        // Right of the view direction (forward × up) maps to positive NDC x.
        let right = c.forward().cross(c.up).normalize();
        assert!(ndc(c.target + 0.1 * right).x > 0.0);
        // Farther along the view ray means greater depth.
        assert!(ndc(c.target + 0.3 * c.forward()).z > ndc(c.target).z);
        // The near plane maps to depth 0.
        assert!(ndc(c.position + CAMERA_NEAR * c.forward()).z.abs() < 1e-4);
    }

    #[test]
    fn fov_is_the_vertical_angle() {
        let c = cam();
        let vp = c.view_proj(2.0);
        // A direction at half the fov above the forward axis lands on the top edge.
        let right = c.forward().cross(c.up).normalize();
        let true_up = right.cross(c.forward());
        let dir = c.forward() * (c.fov_y / 2.0).cos() + true_up * (c.fov_y / 2.0).sin();
        let p = vp.project_point3(c.position + dir);
        assert!((p.y + 1.0).abs() < 1e-4, "{p}");
    }

    #[test]
    fn default_camera_is_1_6_units_out() {
        let d = CameraSpec::default();
        assert!((d.position.length() - 1.6).abs() < 0.02);
        assert!((cam().fov_y - 40f32.to_radians()).abs() < 1e-6);
    }
}
