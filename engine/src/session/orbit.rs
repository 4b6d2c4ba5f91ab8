//! The mouse's camera: orbit about a target, pan, zoom, reset and fly-to-fit, with the
//! explorer's semantics (a session's `Orbit`, `Pan` and `Zoom` edits, from the explorer's
//! mouse, its `--script`, Python's `orbit`/`pan`/`zoom` and the notebook viewer alike).
//!
//! The state is a target, a distance and two angles about the scene's `up` axis (yaw
//! around it, pitch above the plane normal to it), kept in f64 like a scene file's
//! `[camera]`, so [`OrbitCamera::spec`] is exactly what a recorded session writes and
//! replays (`dvr capture` then renders the same matrices).

use crate::scene::{CameraSpec, MAX_CAMERA_DISTANCE};
use glam::DVec3;

/// Radians of orbit per pixel dragged.
pub const ORBIT_PER_PIXEL: f64 = 0.01;
/// Distance factor per wheel step (zooming in divides by it).
pub const ZOOM_PER_STEP: f64 = 1.1;
/// Pitch stays this far from the poles (the view must not become parallel to `up`).
const PITCH_LIMIT: f64 = 89.0 * std::f64::consts::PI / 180.0;
const MIN_DISTANCE: f64 = 0.02;
/// Short of the farthest a camera may be from the volume's centre, so zooming out
/// leaves room to pan.
const MAX_DISTANCE: f64 = 0.8 * MAX_CAMERA_DISTANCE;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: DVec3,
    pub distance: f64,
    /// Angle about `up`, radians, measured from the basis vector `e1` towards `e2`.
    pub yaw: f64,
    /// Elevation above the plane normal to `up`, radians.
    pub pitch: f64,
    pub fov_y_degrees: f64,
    /// Unit world up (the scene's).
    pub up: DVec3,
    home: (DVec3, f64, f64, f64, f64),
}

/// The six views of the patient a medical viewer offers: the side the camera is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anatomical {
    Anterior,
    Posterior,
    Left,
    Right,
    Superior,
    Inferior,
}

impl Anatomical {
    /// Every view, in the order the explorer's keys 1–6 take them.
    pub const ALL: [Anatomical; 6] = [
        Anatomical::Anterior,
        Anatomical::Posterior,
        Anatomical::Left,
        Anatomical::Right,
        Anatomical::Superior,
        Anatomical::Inferior,
    ];

    /// Its name as the explorer, scripts and Python write it.
    pub fn name(self) -> &'static str {
        match self {
            Anatomical::Anterior => "anterior",
            Anatomical::Posterior => "posterior",
            Anatomical::Left => "left",
            Anatomical::Right => "right",
            Anatomical::Superior => "superior",
            Anatomical::Inferior => "inferior",
        }
    }

    /// The view named `name` (case-insensitive; `None` for any other word).
    pub fn from_name(name: &str) -> Option<Anatomical> {
        let lower = name.to_ascii_lowercase();
        Self::ALL.into_iter().find(|a| a.name() == lower)
    }

    /// The unit vector from the patient towards the camera, in RAS world space.
    pub fn direction(self) -> DVec3 {
        match self {
            Anatomical::Anterior => DVec3::Y,
            Anatomical::Posterior => DVec3::NEG_Y,
            Anatomical::Left => DVec3::NEG_X,
            Anatomical::Right => DVec3::X,
            Anatomical::Superior => DVec3::Z,
            Anatomical::Inferior => DVec3::NEG_Z,
        }
    }
}

/// An orthonormal basis (e1, e2) of the plane normal to `up`, with e1 × e2 = up.
fn basis(up: DVec3) -> (DVec3, DVec3) {
    let reference = if up.cross(DVec3::X).length_squared() > 1e-6 {
        DVec3::X
    } else {
        DVec3::Y
    };
    let e2 = up.cross(reference).normalize();
    let e1 = e2.cross(up);
    (e1, e2)
}

impl OrbitCamera {
    /// The camera of a scene's `[camera]` (or its state at a frame); reset returns here.
    pub fn from_spec(spec: &CameraSpec) -> Self {
        let up = spec.up.normalize_or(DVec3::Z);
        let (e1, e2) = basis(up);
        let offset = spec.position - spec.target;
        let distance = offset.length().max(MIN_DISTANCE);
        let h = offset.dot(up);
        let planar = offset - up * h;
        let yaw = planar.dot(e2).atan2(planar.dot(e1));
        let pitch = (h / distance)
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-PITCH_LIMIT, PITCH_LIMIT);
        let home = (spec.target, distance, yaw, pitch, spec.fov_y_degrees);
        Self {
            target: spec.target,
            distance,
            yaw,
            pitch,
            fov_y_degrees: spec.fov_y_degrees,
            up,
            home,
        }
    }

    /// Moves to `spec` (a camera set outright), keeping where [`OrbitCamera::reset`]
    /// returns to.
    pub fn set_spec(&mut self, spec: &CameraSpec) {
        let home = self.home;
        *self = Self::from_spec(spec);
        self.home = home;
    }

    pub fn position(&self) -> DVec3 {
        let (e1, e2) = basis(self.up);
        let dir = (e1 * self.yaw.cos() + e2 * self.yaw.sin()) * self.pitch.cos()
            + self.up * self.pitch.sin();
        self.target + dir * self.distance
    }

    /// As a scene's `[camera]`.
    pub fn spec(&self) -> CameraSpec {
        CameraSpec {
            position: self.position(),
            target: self.target,
            up: self.up,
            fov_y_degrees: self.fov_y_degrees,
        }
    }

    /// Unit vectors to the right of and up in the view.
    fn view_axes(&self) -> (DVec3, DVec3) {
        let forward = (self.target - self.position()).normalize();
        let right = forward.cross(self.up).normalize();
        (right, right.cross(forward))
    }

    /// A left-drag of (dx, dy) pixels: dragging right turns the volume to the right
    /// (the camera moves left around it), dragging down tilts its top towards the
    /// viewer.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * ORBIT_PER_PIXEL;
        self.pitch = (self.pitch + dy * ORBIT_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// A right/middle-drag of (dx, dy) pixels in a view `viewport_height` pixels high:
    /// the point under the cursor follows it (at the target's depth).
    pub fn pan(&mut self, dx: f64, dy: f64, viewport_height: f64) {
        let world_per_pixel = 2.0 * self.distance * (0.5 * self.fov_y_degrees.to_radians()).tan()
            / viewport_height.max(1.0);
        let (right, view_up) = self.view_axes();
        self.target += (-dx * right + dy * view_up) * world_per_pixel;
    }

    /// Looks at the target from `side` of the patient, keeping the distance: world
    /// space is patient RAS (see `dvr_volume`'s `orientation.rs`), so `Anterior` puts
    /// the camera on +y. Views along `up` stop at the pitch limit, a hair off the pole.
    pub fn view_from(&mut self, side: Anatomical) {
        let dir = side.direction();
        let (e1, e2) = basis(self.up);
        let planar = dir - self.up * dir.dot(self.up);
        if planar.length_squared() > 1e-12 {
            self.yaw = planar.dot(e2).atan2(planar.dot(e1));
        }
        self.pitch = dir
            .dot(self.up)
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Wheel steps: positive zooms in.
    pub fn zoom(&mut self, steps: f64) {
        self.distance =
            (self.distance / ZOOM_PER_STEP.powf(steps)).clamp(MIN_DISTANCE, MAX_DISTANCE);
    }

    /// Back to where the camera started.
    pub fn reset(&mut self) {
        (
            self.target,
            self.distance,
            self.yaw,
            self.pitch,
            self.fov_y_degrees,
        ) = self.home;
    }

    /// Flies to fit a box centred at the origin with half-extents `half` (the volume)
    /// into a view of `aspect` (width / height), keeping the viewing direction.
    pub fn fit(&mut self, half: DVec3, aspect: f64) {
        let radius = half.length();
        let half_fov_y = 0.5 * self.fov_y_degrees.to_radians();
        let half_fov_x = (half_fov_y.tan() * aspect.max(1e-3)).atan();
        let half_fov = half_fov_y.min(half_fov_x);
        self.target = DVec3::ZERO;
        self.distance = (radius / half_fov.sin() * 1.02).clamp(MIN_DISTANCE, MAX_DISTANCE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> OrbitCamera {
        OrbitCamera::from_spec(&CameraSpec::default())
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    #[test]
    fn round_trips_the_scene_camera() {
        let spec = CameraSpec::default();
        let c = OrbitCamera::from_spec(&spec);
        assert!(close(c.position(), spec.position), "{}", c.position());
        assert_eq!(c.spec().target, spec.target);
        assert_eq!(c.spec().fov_y_degrees, spec.fov_y_degrees);
    }

    #[test]
    fn orbit_keeps_target_and_distance_and_stops_short_of_the_pole() {
        let mut c = cam();
        let (t, d) = (c.target, (c.position() - c.target).length());
        c.orbit(120.0, -40.0);
        assert_eq!(c.target, t);
        assert!(((c.position() - c.target).length() - d).abs() < 1e-9);
        // Dragging right moves the camera clockwise seen from above (yaw decreases).
        assert!(c.yaw < cam().yaw);
        c.orbit(0.0, 1e6);
        let f = (c.target - c.position()).normalize();
        assert!(f.cross(c.up).length() > 1e-3, "view became parallel to up");
    }

    #[test]
    fn pan_moves_the_target_in_the_view_plane() {
        let mut c = cam();
        let before = c;
        let forward = (before.target - before.position()).normalize();
        c.pan(50.0, 0.0, 500.0);
        let moved = c.target - before.target;
        assert!(moved.length() > 1e-3);
        assert!(moved.dot(forward).abs() < 1e-9, "pan changed depth");
        assert!((c.distance - before.distance).abs() < 1e-12);
        // Dragging right moves the scene right: the target moves left of the view.
        let right = forward.cross(c.up);
        assert!(moved.dot(right) < 0.0);
        // The pixel scale matches the view: a full-height drag moves by the view height.
        let mut d = cam();
        d.pan(0.0, 500.0, 500.0);
        let height = 2.0 * d.distance * (0.5 * d.fov_y_degrees.to_radians()).tan();
        assert!(((d.target - before.target).length() - height).abs() < 1e-9);
    }

    #[test]
    fn zoom_scales_distance_and_reset_restores() {
        let mut c = cam();
        let d = c.distance;
        c.zoom(2.0);
        assert!((c.distance - d / 1.21).abs() < 1e-9);
        c.zoom(-1000.0);
        assert_eq!(c.distance, MAX_DISTANCE);
        c.orbit(10.0, 10.0);
        c.pan(3.0, 4.0, 100.0);
        c.reset();
        assert_eq!(c, cam());
    }

    #[test]
    fn each_anatomical_view_puts_the_camera_on_that_side() {
        for side in Anatomical::ALL {
            let mut c = cam();
            c.orbit(123.0, -45.0);
            let before = c.distance;
            c.view_from(side);
            let towards_camera = (c.position() - c.target).normalize();
            assert!(
                towards_camera.dot(side.direction()) > 0.999,
                "{side:?}: camera towards {towards_camera}"
            );
            assert_eq!(c.distance, before, "{side:?} keeps the distance");
            assert_eq!(
                Anatomical::from_name(&side.name().to_uppercase()),
                Some(side)
            );
        }
        assert_eq!(Anatomical::from_name("front"), None);
        // An anterior view of RAS space has the patient's right on the image's left.
        let mut c = cam();
        c.view_from(Anatomical::Anterior);
        let vp = c.spec().camera().view_proj(1.0);
        let right = vp.project_point3(glam::Vec3::new(0.3, 0.0, 0.0));
        assert!(
            right.x < 0.0,
            "the patient's right is on the image's left: {right}"
        );
    }

    #[test]
    fn fit_shows_every_corner_of_the_volume() {
        let half = DVec3::new(0.5, 0.4, 0.3);
        for aspect in [0.5, 1.0, 2.0] {
            let mut c = cam();
            c.pan(80.0, -30.0, 200.0);
            c.zoom(8.0);
            c.fit(half, aspect);
            let vp = c.spec().camera().view_proj(aspect as f32);
            let mut widest = 0.0f32;
            for i in 0..8 {
                let s = |bit: i32| if i & bit != 0 { 1.0 } else { -1.0 };
                let corner = DVec3::new(s(1) * half.x, s(2) * half.y, s(4) * half.z);
                let ndc = vp.project_point3(corner.as_vec3());
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{aspect}: {ndc}");
                widest = widest.max(ndc.x.abs()).max(ndc.y.abs());
            }
            assert!(widest > 0.5, "fit leaves the volume tiny ({widest})");
        }
    }
}
