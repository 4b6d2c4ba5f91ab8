//! OME-Zarr images (OME-NGFF 0.4 on Zarr v2, OME-Zarr 0.5 on Zarr v3), read through the
//! `zarrs` and `ome_zarr_metadata` crates.
//!
//! `--scene`/`[volume] file` names either the image's group (`image.zarr`: the finest
//! resolution level that fits one 3D texture is read, and the log says which) or one
//! level's array inside it (`image.zarr/2`: that level). The image is the group's first
//! `multiscales` entry; its last three axes are the spatial ones, in the order z, y, x
//! (as the specification requires), so the array's C order is dvr's x-fastest order as
//! it is. Other axes (time, channel) are read at index 0, with a warning when they are
//! longer. The spacing is the level's `scale` times the image's, in millimetres (from
//! the axes' units; none given is taken as millimetres, with a note). A chunk that is
//! absent is the array's fill value, as Zarr defines it (writers skip chunks that hold
//! only the fill value): the log counts them.

use super::error::VolumeError;
use super::samples::{Samples, Stored};
use super::{name_of, Volume, MAX_DIM, MAX_VOXELS};
use crate::bytes::human_bytes;
use ome_zarr_metadata::v0_4::{Axis, AxisType, CoordinateTransform, CoordinateTransformScale};
use ome_zarr_metadata::AnyOmeFields;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;

/// Whether `path` is a Zarr group or array (a folder with Zarr v2 or v3 metadata).
pub(crate) fn is_zarr(path: &Path) -> bool {
    path.is_dir()
        && [".zattrs", ".zgroup", ".zarray", "zarr.json"]
            .iter()
            .any(|f| path.join(f).is_file())
}

/// One resolution level of the image.
struct Level {
    path: String,
    /// Voxel size along the last three (spatial) axes, z, y, x, in the axes' units.
    scale_zyx: [f64; 3],
}

/// The image's metadata: its levels (finest first), axes and the group's folder.
struct Image {
    group: PathBuf,
    axes: Vec<Axis>,
    levels: Vec<Level>,
}

fn malformed(path: &Path, field: &str, problem: impl Into<String>) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.into(),
        problem: problem.into(),
    }
}

pub(crate) fn load(path: &Path, budget: Option<u64>) -> Result<Volume, VolumeError> {
    // A level's array names its group as its parent folder.
    let is_array = path.join(".zarray").is_file() || array_metadata_v3(path);
    let (group, wanted) = match (is_array, path.parent(), path.file_name()) {
        (true, Some(parent), Some(name)) => (parent, Some(name.to_string_lossy().into_owned())),
        (true, _, _) => {
            return Err(malformed(
                path,
                "multiscales",
                "an array outside an OME-Zarr image",
            ))
        }
        (false, _, _) => (path, None),
    };
    let image = read_image(group)?;
    let index = match &wanted {
        Some(name) => image
            .levels
            .iter()
            .position(|l| l.path.trim_matches('/') == name)
            .ok_or_else(|| {
                malformed(
                    path,
                    "multiscales",
                    format!(
                        "{name} is not one of the image's levels ({})",
                        level_names(&image)
                    ),
                )
            })?,
        None => finest_that_fits(&image, budget)?,
    };
    read_level(path, &image, index)
}

/// Whether `path/zarr.json` describes an array (Zarr v3).
fn array_metadata_v3(path: &Path) -> bool {
    std::fs::read_to_string(path.join("zarr.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| v["node_type"] == "array")
}

fn level_names(image: &Image) -> String {
    let names: Vec<&str> = image.levels.iter().map(|l| l.path.as_str()).collect();
    names.join(", ")
}

fn store(path: &Path) -> Result<Arc<FilesystemStore>, VolumeError> {
    FilesystemStore::new(path)
        .map(Arc::new)
        .map_err(|e| malformed(path, "zarr store", e.to_string()))
}

/// The group's OME metadata, checked: its first multiscales image, three spatial axes
/// last, a scale per level.
fn read_image(group: &Path) -> Result<Image, VolumeError> {
    let group_node = Group::open(store(group)?, "/")
        .map_err(|e| malformed(group, "zarr group", e.to_string()))?;
    let attributes = serde_json::Value::Object(group_node.attributes().clone());
    let ome: AnyOmeFields = serde_json::from_value(attributes).map_err(|e| {
        malformed(
            group,
            "multiscales",
            format!("not OME-Zarr 0.4 or 0.5 image metadata ({e})"),
        )
    })?;
    let multiscales = match ome {
        AnyOmeFields::V0_4(m) => m.multiscales.map(|v| {
            v.into_iter()
                .map(|i| (i.axes, i.datasets, i.coordinate_transformations))
                .collect::<Vec<_>>()
        }),
        AnyOmeFields::V0_5(m) => m.multiscales.map(|v| {
            v.into_iter()
                .map(|i| (i.axes, i.datasets, i.coordinate_transformations))
                .collect::<Vec<_>>()
        }),
    };
    let Some((axes, datasets, global)) = multiscales.and_then(|v| v.into_iter().next()) else {
        return Err(malformed(
            group,
            "multiscales",
            "the group holds no multiscales image",
        ));
    };
    let n = axes.len();
    let spatial =
        |a: &Axis| a.r#type == Some(AxisType::Space) || ["x", "y", "z"].contains(&a.name.as_str());
    if n < 3 || !axes[n - 3..].iter().all(spatial) || axes[..n - 3].iter().any(spatial) {
        let names: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
        return Err(malformed(
            group,
            "axes",
            format!(
                "axes [{}]: dvr renders 3D volumes, whose last three axes are spatial (z, y, x)",
                names.join(", ")
            ),
        ));
    }
    let global_scale = match &global {
        Some(t) => scale_of(group, t, n)?,
        None => vec![1.0; n],
    };
    let mut levels = Vec::new();
    for d in datasets {
        let s = scale_of(group, &d.coordinate_transformations, n)?;
        let zyx = |i: usize| s[n - 3 + i] * global_scale[n - 3 + i];
        let scale_zyx = [zyx(0), zyx(1), zyx(2)];
        if scale_zyx.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(malformed(
                group,
                "coordinateTransformations",
                format!("level {}: scale {scale_zyx:?} is not positive", d.path),
            ));
        }
        levels.push(Level {
            path: d.path,
            scale_zyx,
        });
    }
    if levels.is_empty() {
        return Err(malformed(
            group,
            "datasets",
            "the image lists no resolution level",
        ));
    }
    Ok(Image {
        group: group.to_path_buf(),
        axes,
        levels,
    })
}

/// The product of the `scale` transformations in `transforms` (one per axis).
fn scale_of(
    group: &Path,
    transforms: &[CoordinateTransform],
    n: usize,
) -> Result<Vec<f64>, VolumeError> {
    let mut scale = vec![1.0; n];
    for t in transforms {
        match t {
            CoordinateTransform::Scale(CoordinateTransformScale::List { scale: s }) => {
                if s.len() != n {
                    return Err(malformed(
                        group,
                        "coordinateTransformations",
                        format!("a scale of {} values for {n} axes", s.len()),
                    ));
                }
                for (a, b) in scale.iter_mut().zip(s) {
                    *a *= f64::from(*b);
                }
            }
            CoordinateTransform::Scale(CoordinateTransformScale::Path { path }) => {
                return Err(VolumeError::Unsupported {
                    path: group.to_path_buf(),
                    reason: format!(
                        "a scale stored in {} (only listed scales are read)",
                        path.display()
                    ),
                })
            }
            CoordinateTransform::Identity | CoordinateTransform::Translation(_) => {}
        }
    }
    Ok(scale)
}

/// Millimetres per unit of a spatial axis; `None` for a unit that is not a length.
fn millimetres_per_unit(axis: &Axis) -> Option<f64> {
    let Some(unit) = &axis.unit else {
        return Some(1.0);
    };
    let name = serde_json::to_value(unit).ok()?;
    let factor = match name.as_str()? {
        "angstrom" => 1e-7,
        "picometer" => 1e-9,
        "nanometer" => 1e-6,
        "micrometer" => 1e-3,
        "millimeter" => 1.0,
        "centimeter" => 10.0,
        "decimeter" => 100.0,
        "meter" => 1e3,
        "inch" => 25.4,
        "foot" => 304.8,
        _ => return None,
    };
    Some(factor)
}

/// The first level (the finest) that a volume in memory holds (`MAX_DIM` per side,
/// `MAX_VOXELS`) and, when the renderer has a `budget`, whose voxels fit it, so it is
/// rendered as one dense texture. Where no level fits the budget, the coarsest one the
/// limits allow is read (and paged through the brick pool). The log says which level was
/// read and why the finer ones were not.
fn finest_that_fits(image: &Image, budget: Option<u64>) -> Result<usize, VolumeError> {
    let mut sizes = Vec::new();
    let mut within_limits = None;
    for (i, level) in image.levels.iter().enumerate() {
        let array = open_array(image, level)?;
        let dims = spatial_dims(&array);
        let bytes = dims.iter().product::<u64>() * voxel_bytes(&array);
        sizes.push(format!(
            "{}: {}x{}x{}, {}",
            level.path,
            dims[0],
            dims[1],
            dims[2],
            human_bytes(bytes)
        ));
        let voxels: u64 = dims.iter().product();
        if !(dims.iter().all(|&d| d <= u64::from(MAX_DIM)) && voxels <= MAX_VOXELS) {
            continue;
        }
        within_limits = Some(i);
        if budget.is_none_or(|b| bytes <= b) {
            if i > 0 {
                log::warn!(
                    "{}: reading resolution level {}; the finer ones ({}) exceed {}",
                    image.group.display(),
                    sizes[i],
                    sizes[..i].join("; "),
                    match budget {
                        Some(b) => format!("the memory budget ({}) or one volume in memory ({MAX_DIM} per side, {MAX_VOXELS} voxels)", human_bytes(b)),
                        None => format!("one volume in memory ({MAX_DIM} per side, {MAX_VOXELS} voxels)"),
                    }
                );
            }
            return Ok(i);
        }
    }
    if let Some(i) = within_limits {
        log::warn!(
            "{}: no resolution level fits the memory budget ({}): reading the coarsest, {}, \
             paged through the brick pool",
            image.group.display(),
            human_bytes(budget.unwrap_or(0)),
            sizes[i]
        );
        return Ok(i);
    }
    Err(VolumeError::BadDims {
        path: image.group.clone(),
        dims: Vec::new(),
        reason: format!(
            "no resolution level fits one volume texture ({MAX_DIM} per side, {MAX_VOXELS} voxels): {}",
            sizes.join(", ")
        ),
    })
}

/// The array's data type, as Zarr v3 names it (displayed as "<v3 name> / <v2 name>"
/// where the two differ: the v3 name is first).
fn dtype_name(array: &Array<FilesystemStore>) -> String {
    let shown = array.data_type().to_string();
    shown.split(" / ").next().unwrap_or_default().to_string()
}

/// Bytes a voxel of `array` takes once read (16-bit types stay 16-bit).
fn voxel_bytes(array: &Array<FilesystemStore>) -> u64 {
    match dtype_name(array).as_str() {
        "uint8" => 1,
        "uint16" | "int16" => 2,
        _ => 4,
    }
}

fn open_array(image: &Image, level: &Level) -> Result<Array<FilesystemStore>, VolumeError> {
    let path = image.group.join(level.path.trim_matches('/'));
    Array::open(
        store(&image.group)?,
        &format!("/{}", level.path.trim_matches('/')),
    )
    .map_err(|e| malformed(&path, "zarr array", e.to_string()))
}

/// x, y, z sizes of an array whose last three axes are z, y, x.
fn spatial_dims(array: &Array<FilesystemStore>) -> [u64; 3] {
    let s = array.shape();
    let n = s.len();
    if n < 3 {
        return [0; 3];
    }
    [s[n - 1], s[n - 2], s[n - 3]]
}

fn read_level(path: &Path, image: &Image, index: usize) -> Result<Volume, VolumeError> {
    let level = &image.levels[index];
    let array = open_array(image, level)?;
    let shape = array.shape().to_vec();
    let n = image.axes.len();
    if shape.len() != n {
        return Err(malformed(
            path,
            "shape",
            format!(
                "level {} has {} dimensions, the image's axes {n}",
                level.path,
                shape.len()
            ),
        ));
    }
    for (axis, &len) in image.axes.iter().zip(&shape).take(n - 3) {
        if len > 1 {
            log::warn!(
                "{}: axis {} has {len} entries; rendering the first",
                path.display(),
                axis.name
            );
        }
    }
    let [x, y, z] = spatial_dims(&array);
    let dims_i64 = [x as i64, y as i64, z as i64];
    let dims = super::validate_dims(path, dims_i64)?;
    let ranges: Vec<std::ops::Range<u64>> = shape
        .iter()
        .enumerate()
        .map(|(i, &len)| if i < n - 3 { 0..len.min(1) } else { 0..len })
        .collect();
    let absent = absent_chunks(&array, &ranges)?;
    if absent > 0 {
        log::warn!(
            "{}: {absent} chunk(s) have no file and read as the array's fill value (Zarr's \
             rule for chunks a writer skipped; if the dataset was copied, files may be missing)",
            path.display()
        );
    }
    let dtype = dtype_name(&array);
    let subset = ranges.as_slice();
    let samples = match dtype.as_str() {
        "uint8" => Samples::U8(read(path, &array, subset)?),
        "uint16" => Samples::U16(read(path, &array, subset)?),
        "int16" => Samples::I16(read(path, &array, subset)?),
        "float32" => Samples::F32(read(path, &array, subset)?),
        other => {
            return Err(VolumeError::UnsupportedType {
                path: path.to_path_buf(),
                datatype: other.to_string(),
                supported: "uint8, uint16, int16, float32",
            })
        }
    };
    let mut spacing = [0.0f32; 3];
    for (i, s) in spacing.iter_mut().enumerate() {
        // spacing is x, y, z; scale and axes run z, y, x.
        let axis = &image.axes[n - 1 - i];
        let mm = millimetres_per_unit(axis).ok_or_else(|| {
            malformed(
                path,
                "axes",
                format!("axis {}: its unit is not a length", axis.name),
            )
        })?;
        *s = (level.scale_zyx[2 - i] * mm) as f32;
    }
    if image.axes[n - 3..].iter().all(|a| a.unit.is_none()) {
        log::info!(
            "{}: the axes have no unit; spacing read as millimetres",
            path.display()
        );
    }
    let name = name_of(&image.group);
    Volume::from_stored(path, name, dims, spacing, Stored::plain(samples))
}

/// The elements of `subset`, decoded, in C order.
fn read<T: zarrs::array::ElementOwned>(
    path: &Path,
    array: &Array<FilesystemStore>,
    subset: &[std::ops::Range<u64>],
) -> Result<Vec<T>, VolumeError> {
    array
        .retrieve_array_subset::<Vec<T>>(&subset)
        .map_err(|e| malformed(path, "chunks", e.to_string()))
}

/// How many of the chunks under `ranges` have no stored data. Only the chunks the
/// ranges touch are visited (time and channel axes past index 0 are not).
fn absent_chunks(
    array: &Array<FilesystemStore>,
    ranges: &[std::ops::Range<u64>],
) -> Result<u64, VolumeError> {
    let chunk: Vec<u64> = array
        .chunk_shape(&vec![0; ranges.len()])
        .map(|s| s.iter().map(|c| c.get()).collect())
        .unwrap_or_default();
    if chunk.len() != ranges.len() {
        return Ok(0); // an irregular grid: nothing to count by
    }
    let spans: Vec<std::ops::Range<u64>> = ranges
        .iter()
        .zip(&chunk)
        .map(|(r, &c)| r.start / c..r.end.div_ceil(c))
        .collect();
    let mut absent = 0;
    let mut index: Vec<u64> = spans.iter().map(|s| s.start).collect();
    if spans.iter().any(|s| s.is_empty()) {
        return Ok(0);
    }
    'all: loop {
        if !array_store_has(array, &array.chunk_key(&index)) {
            absent += 1;
        }
        for d in (0..spans.len()).rev() {
            index[d] += 1;
            if index[d] < spans[d].end {
                continue 'all;
            }
            index[d] = spans[d].start;
        }
        break;
    }
    Ok(absent)
}

fn array_store_has(array: &Array<FilesystemStore>, key: &zarrs::storage::StoreKey) -> bool {
    use zarrs::storage::ReadableStorageTraits;
    array.storage().size_key(key).ok().flatten().is_some()
}
