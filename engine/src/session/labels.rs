//! Label edits and picking on a session: a label's colour, opacity and visibility (one
//! label, or every label at once for show all / hide all), and what lies under a pixel
//! (the label and the intensity at the features pass's first hit).

use super::{invalid_edit, Result, Session};
use crate::renderer::labels::voxel_of;
use crate::renderer::{FrameRequest, FEATURE_IMAGES};
use crate::scene::labels::look_of;
use glam::Vec3;

/// How far (voxels, per axis) a pick looks around the first hit for the label that
/// makes the surface: the filter's reach (`volume::labels::SMOOTHING_SIGMA` is 1 voxel).
const PICK_REACH: i64 = 2;

/// A change to label `value` (`None`: every label of the map).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LabelEdit {
    pub value: Option<u16>,
    pub colour: Option<[f32; 3]>,
    pub opacity: Option<f32>,
    pub visible: Option<bool>,
}

/// What lies under a pixel: the first hit of the features pass (where the accumulated
/// opacity reaches its threshold, or the expected first collision through thin medium).
#[derive(Debug, Clone, PartialEq)]
pub struct Pick {
    /// World position of the hit.
    pub position: [f32; 3],
    /// The voxel holding it (x, y, z on the volume's grid).
    pub voxel: [u32; 3],
    /// The volume's value there, in data units (the first channel's with several).
    pub intensity: f32,
    /// The label there (0: no label, or no label map) and its name.
    pub label: u16,
    pub label_name: Option<String>,
}

impl Session {
    pub(super) fn edit_label(&mut self, edit: LabelEdit) -> Result<()> {
        if self.setup.labels.is_none() {
            return Err(invalid_edit(
                "label",
                "the scene has no label map (give one with [labels] file = \"...\")".into(),
            ));
        }
        let field = |f: &str| match edit.value {
            Some(v) => format!("label[{v}].{f}"),
            None => format!("labels.{f}"),
        };
        if let Some(c) = edit.colour {
            if !c.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)) {
                return Err(invalid_edit(
                    &field("colour"),
                    format!("{c:?} must be in [0, 1]"),
                ));
            }
        }
        if let Some(o) = edit.opacity {
            if !(o.is_finite() && (0.0..=1.0).contains(&o)) {
                return Err(invalid_edit(
                    &field("opacity"),
                    format!("{o} must be in [0, 1]"),
                ));
            }
        }
        let views = &mut self.view.labels;
        let targets: Vec<usize> = match edit.value {
            None => (0..views.len()).filter(|&i| views[i].value != 0).collect(),
            Some(v) => match views.binary_search_by_key(&v, |l| l.value) {
                Ok(i) => vec![i],
                Err(i) if v == 0 => {
                    let mode = self
                        .setup
                        .labels
                        .as_ref()
                        .map_or(Default::default(), |l| l.mode);
                    views.insert(i, crate::scene::labels::unlabelled(mode));
                    vec![i]
                }
                Err(_) => {
                    let values: Vec<u16> = views.iter().map(|l| l.value).collect();
                    return Err(invalid_edit(
                        "label",
                        format!("label {v} is not in the map (it has {values:?})"),
                    ));
                }
            },
        };
        for i in targets {
            let l = &mut views[i];
            if let Some(c) = edit.colour {
                l.colour = c;
            }
            if let Some(o) = edit.opacity {
                l.opacity = o;
            }
            if let Some(v) = edit.visible {
                l.visible = v;
            }
        }
        Ok(())
    }

    /// What lies under pixel (x, y) of the rendered image (row 0 at the top): renders
    /// one frame of the current view with its surface features read back. `None` where
    /// the ray meets nothing visible.
    pub fn pick(&mut self, x: u32, y: u32) -> Result<Option<Pick>> {
        let size = self.setup.config.size;
        if x >= size.width || y >= size.height {
            return Err(invalid_edit(
                "pick",
                format!(
                    "pixel ({x}, {y}) is outside the {}x{} image",
                    size.width, size.height
                ),
            ));
        }
        let request = FrameRequest {
            readback: true,
            features: true,
            ..Default::default()
        };
        let mut done: Vec<_> = self.frame(&request, None)?.into_iter().collect();
        done.extend(self.flush()?);
        let Some(position) = done.last().and_then(|r| {
            r.images
                .iter()
                .find(|(n, _)| n == FEATURE_IMAGES[0])
                .map(|(_, img)| img[(y * size.width + x) as usize])
        }) else {
            return Ok(None);
        };
        if position[3] < 0.5 {
            return Ok(None);
        }
        let p = Vec3::new(position[0], position[1], position[2]);
        let volume = &self.setup.volume;
        let (world, dims) = (volume.world_size, volume.dims);
        let clamp = |v: [i64; 3]| [0, 1, 2].map(|a| v[a].clamp(0, i64::from(dims[a]) - 1) as u32);
        let mut voxel = clamp(voxel_of(p, world, dims));
        let (label, label_name) = match &self.setup.labels {
            Some(labels) => {
                // A label's surface is its filtered mask's, which reaches past its
                // voxels: the label that makes the surface is that of the nearest shown
                // voxel within the filter's reach.
                let views = &self.view.labels;
                let mode = labels.mode;
                let at = |v: [i64; 3]| labels.map.at(v[0], v[1], v[2]);
                let centre = voxel_of(p, world, dims);
                let q = (p / Vec3::from(world) + 0.5) * Vec3::from(dims.map(|d| d as f32));
                let r = PICK_REACH;
                let mut best: Option<(f32, [i64; 3])> = None;
                for dz in -r..=r {
                    for dy in -r..=r {
                        for dx in -r..=r {
                            let v = [centre[0] + dx, centre[1] + dy, centre[2] + dz];
                            let l = look_of(views, mode, at(v));
                            if !l.visible || l.opacity <= 0.0 {
                                continue;
                            }
                            let d = (Vec3::from(v.map(|c| c as f32 + 0.5)) - q).length_squared();
                            if best.is_none_or(|(b, _)| d < b) {
                                best = Some((d, v));
                            }
                        }
                    }
                }
                if let Some((_, v)) = best {
                    voxel = clamp(v);
                }
                let value = at(voxel.map(i64::from));
                let name = views
                    .iter()
                    .find(|l| l.value == value)
                    .map(|l| l.name.clone());
                (value, name)
            }
            None => (0, None),
        };
        let intensity = volume.data_value(voxel).unwrap_or(f32::NAN);
        Ok(Some(Pick {
            position: p.to_array(),
            voxel,
            intensity,
            label,
            label_name,
        }))
    }
}
