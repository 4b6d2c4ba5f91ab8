//! The chunks a read decodes, checked against the bounds of `zarr.rs` before any is
//! read, and the chunks a read finds absent (read as the fill value).

use std::ops::Range;
use std::path::Path;

use super::{
    malformed, voxel_bytes, Level, Store, CHUNK_OVER_READ, MAX_CHUNKS, MIN_CHUNK_ELEMENTS,
};
use crate::VolumeError;
use zarrs::array::{Array, ArraySubset};

/// How many of the chunks under `ranges` have no stored data. Only the chunks the
/// ranges touch are visited (time and channel axes past index 0 are not).
pub(super) fn absent_chunks(
    array: &Array<Store>,
    ranges: &[Range<u64>],
) -> Result<u64, VolumeError> {
    let chunk: Vec<u64> = array
        .chunk_shape(&vec![0; ranges.len()])
        .map(|s| s.iter().map(|c| c.get()).collect())
        .unwrap_or_default();
    if chunk.len() != ranges.len() {
        return Ok(0); // an irregular grid: nothing to count by
    }
    let spans: Vec<Range<u64>> = ranges
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

fn array_store_has(array: &Array<Store>, key: &zarrs::storage::StoreKey) -> bool {
    use zarrs::storage::ReadableStorageTraits;
    array.storage().size_key(key).ok().flatten().is_some()
}

/// Checks the chunks a read of `ranges` decodes against [`MAX_CHUNKS`],
/// [`CHUNK_OVER_READ`] and [`MIN_CHUNK_ELEMENTS`], before any is read: the chunk grid's
/// chunks and, through each `sharding_indexed` codec, the inner chunks of its shards.
/// Returns the most bytes one chunk or shard holds once decoded.
pub(super) fn check_chunks(
    path: &Path,
    level: &Level,
    array: &Array<Store>,
    ranges: &[Range<u64>],
) -> Result<u64, VolumeError> {
    let bad =
        |problem: String| malformed(path, "chunks", format!("level {}: {problem}", level.path));
    let read: u64 = ranges.iter().map(|r| r.end - r.start).product();
    let most_elements = read.saturating_mul(CHUNK_OVER_READ).max(MIN_CHUNK_ELEMENTS);
    let grid = array
        .chunks_in_array_subset(&ArraySubset::new_with_ranges(ranges))
        .ok()
        .flatten()
        .ok_or_else(|| bad("the chunk grid does not cover the array".into()))?;
    let mut chunks = grid
        .shape()
        .iter()
        .try_fold(1u64, |a, &c| a.checked_mul(c))
        .filter(|&c| c <= MAX_CHUNKS)
        .ok_or_else(|| {
            bad(format!(
                "the volume read spans {:?} chunks, more than {MAX_CHUNKS} (chunks this \
                 small make reading take minutes)",
                grid.shape()
            ))
        })?;
    // The largest chunk along each axis (a rectangular grid's differ).
    let mut shape = Vec::with_capacity(ranges.len());
    for d in 0..ranges.len() {
        let mut largest = 0;
        let mut index = grid.start().to_vec();
        for i in grid.start()[d]..grid.start()[d] + grid.shape()[d] {
            index[d] = i;
            let c = array.chunk_shape(&index).map_err(|e| bad(e.to_string()))?;
            largest = largest.max(c[d].get());
        }
        shape.push(largest);
    }
    let json = serde_json::to_value(array.metadata()).unwrap_or_default();
    let mut largest_elements = 0u64;
    let mut codecs = json.get("codecs").cloned().unwrap_or_default();
    loop {
        let elements = shape
            .iter()
            .try_fold(1u64, |a, &c| a.checked_mul(c))
            .filter(|&e| e <= most_elements)
            .ok_or_else(|| {
                bad(format!(
                    "a chunk of shape {shape:?} holds more than {most_elements} elements \
                     ({CHUNK_OVER_READ} times the {read} voxels read, or \
                     {MIN_CHUNK_ELEMENTS}): chunks are decoded whole"
                ))
            })?;
        largest_elements = largest_elements.max(elements);
        // The next level: the inner chunks of a sharding codec (after the transposes
        // that reorder the shard's axes before it).
        let mut inner = None;
        for codec in codecs.as_array().map(Vec::as_slice).unwrap_or_default() {
            let config = &codec["configuration"];
            match codec["name"].as_str() {
                Some("transpose") => {
                    let order: Option<Vec<usize>> = config["order"].as_array().and_then(|o| {
                        o.iter()
                            .map(|i| i.as_u64().and_then(|i| usize::try_from(i).ok()))
                            .collect()
                    });
                    match order {
                        Some(o) if o.len() == shape.len() && o.iter().all(|&i| i < shape.len()) => {
                            shape = o.iter().map(|&i| shape[i]).collect();
                        }
                        _ => {
                            return Err(bad(format!(
                                "a transpose order {} for {} axes",
                                config["order"],
                                shape.len()
                            )))
                        }
                    }
                }
                Some("sharding_indexed") => {
                    let inner_shape: Option<Vec<u64>> = config["chunk_shape"]
                        .as_array()
                        .and_then(|s| s.iter().map(serde_json::Value::as_u64).collect());
                    match inner_shape {
                        Some(s) if s.len() == shape.len() && s.iter().all(|&c| c > 0) => {
                            inner = Some((s, config["codecs"].clone()));
                        }
                        _ => {
                            return Err(bad(format!(
                                "a shard's inner chunk shape {} for {} axes",
                                config["chunk_shape"],
                                shape.len()
                            )))
                        }
                    }
                    break;
                }
                _ => {}
            }
        }
        let Some((inner_shape, inner_codecs)) = inner else {
            break;
        };
        let per_shard = shape
            .iter()
            .zip(&inner_shape)
            .try_fold(1u64, |a, (&s, &c)| a.checked_mul(s.div_ceil(c)))
            .filter(|&n| n <= MAX_CHUNKS)
            .ok_or_else(|| {
                bad(format!(
                    "shards of shape {shape:?} in inner chunks of {inner_shape:?}: more than \
                     {MAX_CHUNKS} inner chunks per shard"
                ))
            })?;
        chunks = chunks
            .checked_mul(per_shard)
            .filter(|&c| c <= MAX_CHUNKS)
            .ok_or_else(|| {
                bad(format!(
                    "the volume read spans more than {MAX_CHUNKS} inner chunks of {inner_shape:?}"
                ))
            })?;
        shape = inner_shape;
        codecs = inner_codecs;
    }
    Ok(largest_elements * voxel_bytes(array))
}
