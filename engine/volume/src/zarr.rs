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
//!
//! Reads are bounded by the volume read, whatever the metadata says: metadata files are
//! read up to [`MAX_METADATA_BYTES`]; a chunk (or shard) may hold at most
//! [`CHUNK_OVER_READ`] times the voxels read (or [`MIN_CHUNK_ELEMENTS`] where that is
//! more: chunks are decoded whole); the read may touch at most [`MAX_CHUNKS`] chunks (a
//! shard's inner chunks counted); files are read only if they are regular files, and no
//! byte range past a file's end or longer than a chunk is read; blosc and zstd data may
//! not state a decoded size past its chunk's (see `zarr/bounded.rs`).

mod bounded;
mod chunks;
mod omero;

use super::error::VolumeError;
use super::samples::{Samples, Stored};
use super::series::{channel_list, Source, SourceChannel, SourceInfo, Window, Windowed};
use super::{name_of, validate_spacing, Volume, MAX_DIM, MAX_VOXELS};
use crate::bytes::human_bytes;
use bounded::BoundedStore;
use chunks::{absent_chunks, check_chunks};
use ome_zarr_metadata::v0_4::{Axis, AxisType, CoordinateTransform, CoordinateTransformScale};
use ome_zarr_metadata::AnyOmeFields;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use zarrs::array::Array;
use zarrs::group::Group;

/// Largest metadata file read (`zarr.json`, `.zattrs`, `.zarray`, `.zgroup`): an
/// image's are a few KiB.
pub const MAX_METADATA_BYTES: u64 = 16 << 20;

/// Most chunks one read may touch, a shard's inner chunks counted, and most inner chunks
/// a shard may hold (its index, 16 bytes per chunk, is read whole). A 4096×4096×128
/// volume in 32³ chunks is 65,536; past this, chunks are so small that reading would
/// take minutes of file opens.
pub const MAX_CHUNKS: u64 = 1 << 18;

/// How many times the voxels read a chunk or shard may hold: chunks are decoded whole,
/// so the channels or time points a chunk holds beside the one read are decoded too.
pub const CHUNK_OVER_READ: u64 = 4;

/// Elements a chunk may hold whatever the volume read (a 256³ chunk), so small volumes
/// may keep usual chunk sizes.
pub const MIN_CHUNK_ELEMENTS: u64 = 1 << 24;

type Store = BoundedStore;

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
    /// The axis of type `channel` (or named `c`), and of type `time` (or named `t`).
    channel_axis: Option<usize>,
    time_axis: Option<usize>,
    /// `omero.channels`: labels, colours and display windows (`omero.rs`).
    omero: Vec<SourceChannel>,
}

fn malformed(path: &Path, field: &str, problem: impl Into<String>) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.into(),
        problem: problem.into(),
    }
}

pub(crate) fn load(path: &Path, budget: Option<u64>) -> Result<Volume, VolumeError> {
    bounded::register_bounded_codecs();
    let (image, index) = image_and_level(path, budget)?;
    for (axis, &len) in image.axes.iter().zip(&level_shape(path, &image, index)?) {
        if len > 1 && !is_spatial(axis) {
            log::warn!(
                "{}: axis {} has {len} entries; rendering the first (open it as a series \
                 for its channels and time points: `dvr info`)",
                path.display(),
                axis.name
            );
        }
    }
    read_level(path, &image, index, [0, 0], None).map(|(v, _)| v)
}

/// The image (and level) `path` names: its group and the level's index (the finest
/// that fits `budget`, or the level `path` is).
fn image_and_level(path: &Path, budget: Option<u64>) -> Result<(Image, usize), VolumeError> {
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
    Ok((image, index))
}

/// The shape of level `index`'s array, checked against the image's axes: as many
/// dimensions, none of length 0.
fn level_shape(path: &Path, image: &Image, index: usize) -> Result<Vec<u64>, VolumeError> {
    let level = &image.levels[index];
    let array = open_array(image, level, MAX_METADATA_BYTES, None)?;
    let shape = array.shape().to_vec();
    if shape.len() != image.axes.len() {
        return Err(malformed(
            path,
            "shape",
            format!(
                "level {} has {} dimensions, the image's axes {}",
                level.path,
                shape.len(),
                image.axes.len()
            ),
        ));
    }
    for (i, (axis, &len)) in image.axes.iter().zip(&shape).enumerate() {
        if len == 0 {
            let what = if Some(i) == image.time_axis {
                " (the T axis is empty: no time points)"
            } else {
                ""
            };
            return Err(malformed(
                path,
                "shape",
                format!(
                    "level {}: axis {} has no entries{what}",
                    level.path, axis.name
                ),
            ));
        }
    }
    Ok(shape)
}

fn is_spatial(a: &Axis) -> bool {
    a.r#type == Some(AxisType::Space) || ["x", "y", "z"].contains(&a.name.as_str())
}

/// Opens an OME-Zarr image (or one level) as a series: its channel and time axes, and
/// `omero.channels`; the finest level within the volume limits.
pub(crate) fn open_series(path: &Path) -> Result<Box<dyn Source>, VolumeError> {
    bounded::register_bounded_codecs();
    let (image, index) = image_and_level(path, None)?;
    let shape = level_shape(path, &image, index)?;
    let n = shape.len();
    let dims_u64 = [shape[n - 1], shape[n - 2], shape[n - 3]];
    let dims = super::validate_dims(path, dims_u64.map(|d| i64::try_from(d).unwrap_or(i64::MAX)))?;
    let count = |a: Option<usize>| a.map_or(1, |a| shape[a]);
    let meta = channel_list(path, count(image.channel_axis), image.omero.clone())?;
    let info = SourceInfo {
        path: path.to_path_buf(),
        name: name_of(&image.group),
        dims,
        orientation: None,
        channels: meta,
        times: usize::try_from(count(image.time_axis)).unwrap_or(usize::MAX),
    };
    Ok(Box::new(ZarrSeries { info, image, index }))
}

struct ZarrSeries {
    info: SourceInfo,
    image: Image,
    index: usize,
}

impl Source for ZarrSeries {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed {
        read_level(
            &self.info.path,
            &self.image,
            self.index,
            [channel as u64, time as u64],
            window,
        )
    }
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

/// The store of the image's folder, reading at most `max_read` bytes at a time.
fn store(path: &Path, max_read: u64) -> Result<Arc<Store>, VolumeError> {
    BoundedStore::new(path, max_read)
        .map(Arc::new)
        .map_err(|e| malformed(path, "zarr store", e))
}

/// The group's OME metadata, checked: its first multiscales image, three spatial axes
/// last, a scale per level.
fn read_image(group: &Path) -> Result<Image, VolumeError> {
    let group_node = Group::open(store(group, MAX_METADATA_BYTES)?, "/")
        .map_err(|e| malformed(group, "zarr group", e.to_string()))?;
    // `omero` is read by `omero.rs` and a label image's `image-label` by
    // `labels/ome.rs`, leniently (the metadata crate requires every channel's colour and
    // full window, which writers often leave out, and refuses the `image-label` that
    // ome-zarr-py writes for 0.5).
    let mut attributes = serde_json::Value::Object(group_node.attributes().clone());
    for key in ["omero", "image-label"] {
        if let Some(a) = attributes.as_object_mut() {
            a.remove(key);
        }
        if let Some(a) = attributes.get_mut("ome").and_then(|o| o.as_object_mut()) {
            a.remove(key);
        }
    }
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
    let omero = omero::channels(group, group_node.attributes())?;
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
    let find = |ty: AxisType, name: &str| -> Result<Option<usize>, VolumeError> {
        let found: Vec<usize> = (0..n - 3)
            .filter(|&i| axes[i].r#type == Some(ty.clone()) || axes[i].name == name)
            .collect();
        if found.len() > 1 {
            return Err(malformed(
                group,
                "axes",
                format!("{} axes of type {name}: at most one", found.len()),
            ));
        }
        Ok(found.first().copied())
    };
    let channel_axis = find(AxisType::Channel, "c")?;
    let time_axis = find(AxisType::Time, "t")?;
    Ok(Image {
        group: group.to_path_buf(),
        axes,
        levels,
        channel_axis,
        time_axis,
        omero,
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
        let array = open_array(image, level, MAX_METADATA_BYTES, None)?;
        let dims = spatial_dims(&array);
        // Saturating: a level's sides may be any u64.
        let voxels = dims.iter().fold(1u64, |a, &d| a.saturating_mul(d));
        let bytes = voxels.saturating_mul(voxel_bytes(&array));
        sizes.push(format!(
            "{}: {}x{}x{}, {}",
            level.path,
            dims[0],
            dims[1],
            dims[2],
            human_bytes(bytes)
        ));
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
fn dtype_name(array: &Array<Store>) -> String {
    let shown = array.data_type().to_string();
    shown.split(" / ").next().unwrap_or_default().to_string()
}

/// Bytes a voxel of `array` takes once read (16-bit types stay 16-bit).
fn voxel_bytes(array: &Array<Store>) -> u64 {
    match dtype_name(array).as_str() {
        "uint8" => 1,
        "uint16" | "int16" => 2,
        _ => 4,
    }
}

/// A level's array, read through a store that reads at most `max_read` bytes at a time
/// (and, where given, `blosc_chunk_bytes`: see [`BoundedStore::with_blosc_chunks`]).
fn open_array(
    image: &Image,
    level: &Level,
    max_read: u64,
    blosc_chunk_bytes: Option<u64>,
) -> Result<Array<Store>, VolumeError> {
    let path = image.group.join(level.path.trim_matches('/'));
    let mut store = store(&image.group, max_read)?;
    if let Some(bytes) = blosc_chunk_bytes {
        store = Arc::new(
            BoundedStore::new(&image.group, max_read)
                .map_err(|e| malformed(&image.group, "zarr store", e))?
                .with_blosc_chunks(bytes),
        );
    }
    Array::open(store, &format!("/{}", level.path.trim_matches('/')))
        .map_err(|e| malformed(&path, "zarr array", e.to_string()))
}

/// x, y, z sizes of an array whose last three axes are z, y, x.
fn spatial_dims(array: &Array<Store>) -> [u64; 3] {
    let s = array.shape();
    let n = s.len();
    if n < 3 {
        return [0; 3];
    }
    [s[n - 1], s[n - 2], s[n - 3]]
}

/// Level `index` at channel `at[0]` and time point `at[1]` (other non-spatial axes at
/// index 0), normalised through `window` where given.
fn read_level(
    path: &Path,
    image: &Image,
    index: usize,
    at: [u64; 2],
    window: Option<(f64, f64)>,
) -> Result<(Volume, (f64, f64)), VolumeError> {
    let level = &image.levels[index];
    let shape = level_shape(path, image, index)?;
    let array = open_array(image, level, MAX_METADATA_BYTES, None)?;
    let n = image.axes.len();
    let dims_i64 = spatial_dims(&array).map(|d| i64::try_from(d).unwrap_or(i64::MAX));
    let dims = super::validate_dims(path, dims_i64)?;
    let dtype = dtype_name(&array);
    if !["uint8", "uint16", "int16", "float32"].contains(&dtype.as_str()) {
        return Err(VolumeError::UnsupportedType {
            path: path.to_path_buf(),
            datatype: dtype,
            supported: "uint8, uint16, int16, float32",
        });
    }
    let ranges: Vec<Range<u64>> = shape
        .iter()
        .enumerate()
        .map(|(i, &len)| {
            if Some(i) == image.channel_axis {
                at[0]..at[0] + 1
            } else if Some(i) == image.time_axis {
                at[1]..at[1] + 1
            } else if i < n - 3 {
                0..len.min(1)
            } else {
                0..len
            }
        })
        .collect();
    if ranges.iter().zip(&shape).any(|(r, &len)| r.end > len) {
        return Err(malformed(
            path,
            "shape",
            format!(
                "channel {} or time point {} is past the axes' {shape:?}",
                at[0], at[1]
            ),
        ));
    }
    let largest_chunk = check_chunks(path, level, &array, &ranges)?;
    // Reopened through a store that reads no more than the largest chunk at a time (with
    // a little over for headers and incompressible data, and a shard's index). A Zarr v2
    // blosc compressor is decoded by zarrs' own codec: its headers are checked as read.
    let json = serde_json::to_value(array.metadata()).unwrap_or_default();
    let v2_blosc = json["zarr_format"] == 2 && json["compressor"]["id"] == "blosc";
    let largest_read = largest_chunk + largest_chunk / 8 + 16 * MAX_CHUNKS + (1 << 20);
    let array = open_array(
        image,
        level,
        largest_read.max(MAX_METADATA_BYTES),
        v2_blosc.then_some(largest_chunk),
    )?;
    let absent = absent_chunks(&array, &ranges)?;
    if absent > 0 {
        log::warn!(
            "{}: {absent} chunk(s) have no file and read as the array's fill value (Zarr's \
             rule for chunks a writer skipped; if the dataset was copied, files may be missing)",
            path.display()
        );
    }
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
    let mut spacing = [0.0f64; 3];
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
        *s = level.scale_zyx[2 - i] * mm;
    }
    let spacing = validate_spacing(path, "coordinateTransformations (scale)", spacing)?;
    if image.axes[n - 3..].iter().all(|a| a.unit.is_none()) {
        log::info!(
            "{}: the axes have no unit; spacing read as millimetres",
            path.display()
        );
    }
    let name = name_of(&image.group);
    Volume::from_stored_in(path, name, dims, spacing, Stored::plain(samples), window)
}

/// The elements of `subset`, decoded, in C order.
fn read<T: zarrs::array::ElementOwned>(
    path: &Path,
    array: &Array<Store>,
    subset: &[Range<u64>],
) -> Result<Vec<T>, VolumeError> {
    array
        .retrieve_array_subset::<Vec<T>>(&subset)
        .map_err(|e| malformed(path, "chunks", e.to_string()))
}

#[cfg(test)]
mod tests;
