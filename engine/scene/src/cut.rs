//! Cuts into the volume: up to [`MAX_CLIP_PLANES`] clip planes (`[[clip]]`) and one crop
//! box (`[crop]`), each switchable. Medium that a cut removes is empty to every ray the
//! renderer traces (camera, scattered and shadow rays alike), so light enters through
//! the cut and the cut face shows as the surface of the medium behind it.
//!
//! ```toml
//! [[clip]]
//! point = [0.0, 0.0, 0.05]   # a point on the plane, world units
//! normal = [0.0, 0.0, 1.0]   # the half-space behind the normal is removed
//! enabled = true             # optional, default true
//!
//! [crop]
//! min = [-0.5, -0.2, -0.5]   # corners in the volume's frame, [-0.5, 0.5] on each axis
//! max = [0.5, 0.5, 0.1]
//! units = "box"              # optional: "box" (the default) or "voxels" (voxel indices)
//! enabled = true             # optional, default true
//! ```
//!
//! What remains is the intersection of the volume's box, the crop box and the half-space
//! in front of every enabled plane: one convex region, so a ray meets it in one interval
//! and the renderer traces only that interval. Animated by `[[animation.clip]]` (index,
//! frame, any of point, normal, enabled) and `[[animation.crop]]` (frame, any of min,
//! max, enabled): points, normals and corners interpolate like the camera (the normal is
//! renormalised), `enabled` switches at its keyframe.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};

/// Clip planes a scene, and the renderer's frame block, hold.
pub const MAX_CLIP_PLANES: usize = 6;

/// Farthest a clip plane's point may be from the volume's centre (world units); past
/// it a plane is either clear of the volume or removes all of it.
pub const MAX_CLIP_DISTANCE: f64 = 1e3;

fn yes() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
}

/// `[[clip]]`: removes the half-space behind `normal` through `point`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipPlane {
    /// A point on the plane, in world units.
    pub point: DVec3,
    /// Points into what is kept; need not be unit length, only not zero.
    pub normal: DVec3,
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub enabled: bool,
}

impl ClipPlane {
    /// The plane as (unit normal, offset): x is kept where `normal · x + offset >= 0`.
    pub fn equation(&self) -> (DVec3, f64) {
        let n = self.normal.normalize_or(DVec3::Z);
        (n, -n.dot(self.point))
    }

    /// Flipped: what was removed is kept and the other way round.
    pub fn flipped(&self) -> Self {
        Self {
            normal: -self.normal,
            ..*self
        }
    }

    pub(crate) fn check(&self, ctx: &Ctx, field: &str) -> Result<(), SceneError> {
        ctx.near_origin(
            &format!("{field}.point"),
            self.point,
            MAX_CLIP_DISTANCE,
            "the volume is 1 unit across",
        )?;
        ctx.unit_vector(&format!("{field}.normal"), self.normal)
    }
}

/// What a crop box's corners are measured in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CropUnits {
    /// The volume's frame: −0.5 to 0.5 along each axis, whatever its shape.
    #[default]
    Box,
    /// Voxel indices: 0 to the volume's size along each axis (a voxel's far face at
    /// its index + 1).
    Voxels,
}

impl CropUnits {
    fn is_box(&self) -> bool {
        *self == Self::Box
    }
}

/// `[crop]`: keeps what is inside the box from `min` to `max`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CropBox {
    pub min: DVec3,
    pub max: DVec3,
    #[serde(default, skip_serializing_if = "CropUnits::is_box")]
    pub units: CropUnits,
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub enabled: bool,
}

impl CropBox {
    /// The box in the volume's frame (−0.5 to 0.5 per axis) for a volume of `dims`
    /// voxels.
    pub fn in_box_frame(&self, dims: [u32; 3]) -> (DVec3, DVec3) {
        match self.units {
            CropUnits::Box => (self.min, self.max),
            CropUnits::Voxels => {
                let d = DVec3::from(dims.map(|n| f64::from(n.max(1))));
                (self.min / d - 0.5, self.max / d - 0.5)
            }
        }
    }

    pub(crate) fn check(&self, ctx: &Ctx, field: &str) -> Result<(), SceneError> {
        for (name, v) in [("min", self.min), ("max", self.max)] {
            ctx.finite3(&format!("{field}.{name}"), v)?;
            let (lo, hi, what) = match self.units {
                CropUnits::Box => (-0.5, 0.5, "the volume's frame, -0.5 to 0.5 per axis"),
                CropUnits::Voxels => (0.0, 1e6, "voxel indices, 0 or more"),
            };
            if v.min_element() < lo || v.max_element() > hi {
                return Err(
                    ctx.invalid(format!("{field}.{name}"), format!("{v} is outside {what}"))
                );
            }
        }
        for (axis, (lo, hi)) in ["x", "y", "z"]
            .iter()
            .zip(self.min.to_array().into_iter().zip(self.max.to_array()))
        {
            if lo > hi {
                return Err(ctx.invalid(
                    format!("{field}.min"),
                    format!("min.{axis} = {lo} is greater than max.{axis} = {hi}"),
                ));
            }
        }
        Ok(())
    }
}

/// The planes and the crop box of one view (disabled ones included, as written).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Cut {
    pub planes: Vec<ClipPlane>,
    pub crop: Option<CropBox>,
}

impl Cut {
    /// Whether anything is cut (an enabled plane or crop box).
    pub fn active(&self) -> bool {
        self.planes.iter().any(|p| p.enabled) || self.crop.is_some_and(|c| c.enabled)
    }

    pub(crate) fn check(&self, ctx: &Ctx) -> Result<(), SceneError> {
        if self.planes.len() > MAX_CLIP_PLANES {
            return Err(ctx.invalid(
                "clip",
                format!(
                    "{} clip planes; at most {MAX_CLIP_PLANES}",
                    self.planes.len()
                ),
            ));
        }
        for (i, p) in self.planes.iter().enumerate() {
            p.check(ctx, &format!("clip[{i}]"))?;
        }
        if let Some(c) = &self.crop {
            c.check(ctx, "crop")?;
        }
        Ok(())
    }

    /// Whether a world-space box (`lo`..`hi`) lies wholly in removed space, for a volume
    /// of `world` size and `dims` voxels: outside the crop box, or behind one plane. A
    /// box this says no to may still be empty in a corner cut by two planes; it is only
    /// skipped when one cut alone removes it.
    pub fn removes(&self, lo: DVec3, hi: DVec3, world: DVec3, dims: [u32; 3]) -> bool {
        if let Some(c) = self.crop.filter(|c| c.enabled) {
            let (min, max) = c.in_box_frame(dims);
            let (min, max) = (min * world, max * world);
            if hi.cmplt(min).any() || lo.cmpgt(max).any() {
                return true;
            }
        }
        self.planes.iter().filter(|p| p.enabled).any(|p| {
            let (n, w) = p.equation();
            // The corner farthest along the normal: if even it is behind, all are.
            let far = DVec3::select(n.cmpge(DVec3::ZERO), hi, lo);
            n.dot(far) + w < 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(point: [f64; 3], normal: [f64; 3]) -> ClipPlane {
        ClipPlane {
            point: DVec3::from(point),
            normal: DVec3::from(normal),
            enabled: true,
        }
    }

    #[test]
    fn a_plane_removes_boxes_wholly_behind_it() {
        let world = DVec3::ONE;
        let dims = [64; 3];
        let cut = Cut {
            planes: vec![plane([0.0, 0.0, 0.1], [0.0, 0.0, 1.0])],
            crop: None,
        };
        let lo = DVec3::new(-0.5, -0.5, -0.5);
        assert!(cut.removes(lo, DVec3::new(0.5, 0.5, 0.05), world, dims));
        assert!(!cut.removes(lo, DVec3::new(0.5, 0.5, 0.15), world, dims));
        let off = Cut {
            planes: vec![ClipPlane {
                enabled: false,
                ..cut.planes[0]
            }],
            crop: None,
        };
        assert!(!off.removes(lo, DVec3::new(0.5, 0.5, 0.05), world, dims));
        assert!(!off.active() && cut.active());
    }

    #[test]
    fn a_crop_box_removes_what_it_does_not_overlap_in_either_units() {
        let world = DVec3::new(1.0, 0.5, 0.5);
        let dims = [100, 50, 50];
        for crop in [
            CropBox {
                min: DVec3::new(0.0, -0.5, -0.5),
                max: DVec3::splat(0.5),
                units: CropUnits::Box,
                enabled: true,
            },
            CropBox {
                min: DVec3::new(50.0, 0.0, 0.0),
                max: DVec3::new(100.0, 50.0, 50.0),
                units: CropUnits::Voxels,
                enabled: true,
            },
        ] {
            let cut = Cut {
                planes: Vec::new(),
                crop: Some(crop),
            };
            // The world box spans x in [-0.5, 0.5]; the crop keeps x >= 0.
            let y = DVec3::new(0.0, 0.25, 0.25);
            assert!(cut.removes(
                DVec3::new(-0.5, -0.25, -0.25),
                DVec3::new(-0.1, 0.0, 0.0) + y,
                world,
                dims
            ));
            assert!(!cut.removes(DVec3::new(-0.1, -0.25, -0.25), y, world, dims));
        }
    }

    #[test]
    fn bad_cuts_are_errors_naming_the_field() {
        let ctx = Ctx {
            origin: "t",
            base: None,
        };
        let zero = Cut {
            planes: vec![plane([0.0; 3], [0.0; 3])],
            crop: None,
        };
        let e = zero.check(&ctx).unwrap_err().to_string();
        assert!(e.contains("clip[0].normal") && e.contains("zero"), "{e}");
        let nan = Cut {
            planes: vec![plane([f64::NAN, 0.0, 0.0], [0.0, 0.0, 1.0])],
            crop: None,
        };
        assert!(nan
            .check(&ctx)
            .unwrap_err()
            .to_string()
            .contains("clip[0].point"));
        let many = Cut {
            planes: vec![plane([0.0; 3], [0.0, 0.0, 1.0]); 7],
            crop: None,
        };
        assert!(many
            .check(&ctx)
            .unwrap_err()
            .to_string()
            .contains("at most 6"));
        let inverted = Cut {
            planes: Vec::new(),
            crop: Some(CropBox {
                min: DVec3::new(0.2, 0.0, 0.0),
                max: DVec3::new(0.1, 0.3, 0.3),
                units: CropUnits::Box,
                enabled: true,
            }),
        };
        let e = inverted.check(&ctx).unwrap_err().to_string();
        assert!(
            e.contains("crop.min") && e.contains("greater than max.x"),
            "{e}"
        );
        let outside = Cut {
            planes: Vec::new(),
            crop: Some(CropBox {
                min: DVec3::splat(-0.7),
                max: DVec3::splat(0.5),
                units: CropUnits::Box,
                enabled: true,
            }),
        };
        assert!(outside
            .check(&ctx)
            .unwrap_err()
            .to_string()
            .contains("outside"));
    }
}
