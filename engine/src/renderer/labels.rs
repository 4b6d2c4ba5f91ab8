//! A scene's label map on the renderer's side: loaded from `[labels]`, put on the
//! volume's grid, its labels' views made from the table and the `[[label]]` sections,
//! and the filtered look ([`LabelLook`]) the renderer uploads, made again only when a
//! label's look changes (or whether the TF leaves a zero voxel empty). Picking reads the
//! map and the volume under a world point.

use super::uploads::VolumeUpload;
use crate::scene::labels::{look_of, unlabelled};
use crate::scene::{LabelMode, LabelView, Scene};
use crate::transfer::TfLut;
use crate::volume::labels::{EmptySpace, LabelLook, LabelMap, LabelTable};
use crate::volume::{PatientTransform, VolumeError};
use glam::Vec3;
use std::sync::{Arc, Mutex};

/// A label map on the volume's grid, with the last look made from it.
pub struct SceneLabels {
    pub map: LabelMap,
    pub mode: LabelMode,
    brick: u32,
    grid: [u32; 3],
    /// Tint mode: the voxels whose fields are all 0 (the first time point's, for a
    /// series), which hold no medium under a TF transparent at 0.
    zero: Option<EmptySpace>,
    channels: usize,
    cache: Mutex<Option<(LookKey, Arc<LabelLook>)>>,
}

/// What a look is made from: the labels' views and whether zero voxels are empty.
type LookKey = (Vec<LabelView>, bool);

impl std::fmt::Debug for SceneLabels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneLabels")
            .field("map", &self.map.path)
            .field("mode", &self.mode)
            .finish()
    }
}

/// What `[labels]` gives: the map on the grid and its labels' views as they start.
pub fn load(
    scene: &Scene,
    volume: &VolumeUpload,
    to_patient: &PatientTransform,
) -> Result<Option<(SceneLabels, Vec<LabelView>)>, VolumeError> {
    let Some(spec) = &scene.labels else {
        return Ok(None);
    };
    let (map, own_table) = match (&spec.file, &spec.builtin) {
        (Some(file), _) => {
            let (map, own_table) = LabelMap::load_with_table(file)?;
            if map.dims != volume.dims {
                check_placed(scene, &map.path, map.dims, volume.dims)?;
            }
            (map.onto(volume.dims, to_patient), own_table)
        }
        (None, Some(name)) => {
            let dataset = match &scene.volume.source {
                crate::scene::VolumeSource::Builtin { dataset, .. } => Some(dataset.name()),
                _ => None,
            };
            if dataset != Some(name.as_str()) {
                return Err(VolumeError::Unsupported {
                    path: name.into(),
                    reason: format!(
                        "labels.builtin = {name:?} labels the built-in {name} volume; this scene's volume is {}",
                        dataset.map_or("a file".to_string(), |d| format!("the built-in {d}"))
                    ),
                });
            }
            let (map, table) = LabelMap::builtin(name, volume.dims, to_patient)?;
            (map, Some(table))
        }
        (None, None) => {
            return Err(VolumeError::Unsupported {
                path: "labels".into(),
                reason: "[labels] names neither a file nor a built-in".into(),
            })
        }
    };
    let origin = map.path.clone();
    let mut table = match (&spec.table, own_table) {
        (Some(path), _) => LabelTable::load(path)?,
        (None, Some(t)) => t,
        (None, None) => LabelTable::default(),
    };
    let present = map.present();
    let missing = table.complete(&present);
    if spec.table.is_some() && !missing.is_empty() {
        log::warn!(
            "label map {}: values {missing:?} are not in the table {}; they take palette colours",
            origin.display(),
            spec.table
                .as_ref()
                .map_or(String::new(), |t| t.display().to_string())
        );
    }
    let mut views: Vec<LabelView> = table
        .labels
        .iter()
        .filter(|l| present.binary_search(&l.value).is_ok())
        .map(|l| LabelView {
            value: l.value,
            name: l.name.clone(),
            colour: l.colour,
            opacity: l.opacity,
            visible: l.visible,
        })
        .collect();
    for (i, s) in scene.label_sections.iter().enumerate() {
        match views.binary_search_by_key(&s.value, |v| v.value) {
            Ok(k) => views[k] = views[k].clone().with(s),
            Err(k) if s.value == 0 => views.insert(k, unlabelled(spec.mode).with(s)),
            Err(_) => {
                return Err(VolumeError::Unsupported {
                    path: origin.clone(),
                    reason: format!(
                        "label[{i}].value = {}: the map has no such label (it has {})",
                        s.value,
                        list(&present)
                    ),
                })
            }
        }
    }
    for (i, k) in scene.animation.label.iter().enumerate() {
        if views.binary_search_by_key(&k.value, |v| v.value).is_err() {
            return Err(VolumeError::Unsupported {
                path: origin.clone(),
                reason: format!(
                    "animation.label[{i}].value = {}: the map has no such label (it has {})",
                    k.value,
                    list(&present)
                ),
            });
        }
    }
    let zero = match spec.mode {
        LabelMode::Tint => volume.zero_voxels().and_then(|z| EmptySpace::new(&map, z)),
        LabelMode::Solid => None,
    };
    let labels = SceneLabels {
        map,
        mode: spec.mode,
        brick: volume.bricks.brick,
        grid: volume.bricks.grid,
        zero,
        channels: volume.channels() as usize,
        cache: Mutex::new(None),
    };
    Ok(Some((labels, views)))
}

/// A label map on another grid than the volume's is put on it through both files'
/// patient transforms: refused, naming the file without one, when either states none
/// (a raw file, a built-in procedural volume), since nothing then says how the grids
/// meet.
fn check_placed(
    scene: &Scene,
    file: &std::path::Path,
    map_dims: [u32; 3],
    volume_dims: [u32; 3],
) -> Result<(), VolumeError> {
    use crate::scene::VolumeSource;
    let stated = |p: &std::path::Path| -> Result<bool, VolumeError> {
        crate::volume::labels::states_orientation(p)
    };
    let volume_file = match &scene.volume.source {
        VolumeSource::File { path, raw: None } => Some(path.as_path()),
        VolumeSource::Files { paths } => paths.first().map(|p| p.as_path()),
        VolumeSource::File { raw: Some(_), .. } | VolumeSource::Builtin { .. } => None,
    };
    let unplaced = if !stated(file)? {
        Some("the label map states no patient transform (affine)".to_string())
    } else {
        match volume_file {
            Some(p) if stated(p)? => None,
            Some(p) => Some(format!(
                "the volume {} states no patient transform",
                p.display()
            )),
            None => Some("the volume (built-in or raw) has no patient transform".into()),
        }
    };
    match unplaced {
        None => Ok(()),
        Some(why) => Err(VolumeError::Unsupported {
            path: file.to_path_buf(),
            reason: format!(
                "a label map of {map_dims:?} voxels for a volume of {volume_dims:?}: {why}, so nothing says how the grids meet (give the map on the volume's grid, or files with affines)"
            ),
        }),
    }
}

fn list(values: &[u16]) -> String {
    let head: Vec<String> = values.iter().take(12).map(u16::to_string).collect();
    let more = values.len().saturating_sub(12);
    match more {
        0 => head.join(", "),
        n => format!("{} and {n} more", head.join(", ")),
    }
}

impl SceneLabels {
    /// The look of the map under `views` with the TF's `lut` (the last one again when
    /// neither the views nor whether the LUT is transparent at 0 have changed).
    pub fn look(&self, views: &[LabelView], lut: &TfLut) -> Arc<LabelLook> {
        let zero_is_empty = self.zero.is_some() && lut.transparent_at_zero(self.channels);
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(((v, z), look)) = cache.as_ref() {
            if v == views && *z == zero_is_empty {
                return look.clone();
            }
        }
        let mode = self.mode;
        let of = |value| look_of(views, mode, value);
        // The shape follows visibility alone: a colour or opacity edit keeps it.
        let same_shown = cache.as_ref().is_some_and(|((v, _), _)| {
            v.len() == views.len()
                && v.iter()
                    .zip(views)
                    .all(|(a, b)| (a.value, a.visible) == (b.value, b.visible))
        });
        let shape = match cache.as_ref() {
            Some((_, last)) if same_shown => last.shape.clone(),
            _ => LabelLook::shape_of(&self.map, of),
        };
        let empty = self.zero.as_ref().filter(|_| zero_is_empty);
        let look = Arc::new(LabelLook::with_shape(
            &self.map, of, self.brick, self.grid, shape, empty,
        ));
        *cache = Some(((views.to_vec(), zero_is_empty), look.clone()));
        look
    }

    /// The label value at world point `p` of a volume spanning `world` units centred on
    /// the origin (0 outside).
    pub fn at(&self, p: Vec3, world: [f32; 3]) -> u16 {
        let v = voxel_of(p, world, self.map.dims);
        self.map.at(v[0], v[1], v[2])
    }
}

/// The voxel holding world point `p` (unclamped).
pub fn voxel_of(p: Vec3, world: [f32; 3], dims: [u32; 3]) -> [i64; 3] {
    let uvw = p / Vec3::from(world) + 0.5;
    let v = uvw * Vec3::from(dims.map(|d| d as f32));
    [v.x, v.y, v.z].map(|c| c.floor() as i64)
}
