//! Normalisation of stored samples to the `[0, 1]` density the renderer samples.
//!
//! The GPU reads the volume as an R8/R16 unorm or R32F texture and indexes transfer
//! functions by that value, so every loader must agree on what 0 and 1 mean. The rule
//! (also in the module docs of [`super`]):
//!
//! 1. Stored values are first rescaled to physical units, `p = slope * v + intercept`
//!    (per slice for DICOM series whose rescale varies).
//! 2. The **window** `[lo, hi]` (physical units) maps to `[0, 1]`:
//!    - integer data: let `T` be the type's range in physical units (for DICOM the
//!      `BitsStored` range) and `D = [min, max]` the data's actual range. If
//!      `max > min` and `max - min < (T.hi - T.lo) / 4` (a 12-bit CT stored in 16 bits
//!      uses 1/16 of it), the window is `D`; otherwise it is `T`, so files of the same
//!      type keep comparable values.
//!    - float data: NaN/Inf is an error. If all values lie in `[0, 1]` the window is
//!      `[0, 1]` (the values already are densities); otherwise it is `[min, max]`; a
//!      constant outside `[0, 1]` uses `[min(0, c), max(1, c)]`. When a few outliers
//!      set that range (the 0.1–99.9 percentile range of the rest spans less than
//!      1/1000 of it, so the rest would map to one grey), the window is the range of
//!      the values within ten such spans of that percentile range, the outliers are
//!      clamped to 0 or 1, and a warning says how many they are.
//! 3. Output type follows the stored width: 8-bit stays `U8`, 16-bit (signed or not)
//!    becomes `U16` (rounded into `0..=65535`), float becomes `F32` clamped to `[0, 1]`.

use std::path::Path;

use super::error::VolumeError;
use super::samples::{Affine, Rescale, Samples, Stored};
use super::VolumeData;

/// Normalised data and the physical window that maps to `[0, 1]`.
#[derive(Debug)]
pub(crate) struct Normalised {
    pub data: VolumeData,
    pub window: [f32; 2],
    /// The window as computed, before rounding to f32: what a series hands back for its
    /// later time points, so that they map through exactly the same table.
    pub exact_window: (f64, f64),
}

/// Applies the windowing rule of this module to `stored` (x fastest, `dims` already
/// validated), or, where `fixed` is given, that window (a series' channel keeps the
/// window of its first time point, so its time points do not flicker: `series.rs`).
pub(crate) fn normalise(
    path: &Path,
    dims: [u32; 3],
    stored: Stored,
    fixed: Option<(f64, f64)>,
) -> Result<Normalised, VolumeError> {
    let slice_len = dims[0] as usize * dims[1] as usize;
    let voxels = slice_len * dims[2] as usize;
    let kind = stored.samples.kind();
    if stored.samples.len() != voxels {
        let b = kind.bytes() as u64;
        return Err(VolumeError::SizeMismatch {
            path: path.to_path_buf(),
            dims,
            format: kind.name(),
            expected: voxels as u64 * b,
            found: stored.samples.len() as u64 * b,
        });
    }
    if let Samples::F32(v) = &stored.samples {
        check_finite(path, dims, v)?;
    }
    if let Some(window) = fixed {
        return Ok(Normalised {
            data: apply_window(stored, slice_len, window),
            window: [window.0 as f32, window.1 as f32],
            exact_window: window,
        });
    }
    let data_range = physical_range(&stored.samples, slice_len, &stored.rescale);
    let window = match (&stored.type_range, &stored.samples) {
        (Some(type_range), _) => integer_window(*type_range, data_range, &stored.rescale, dims[2]),
        (None, Samples::F32(v)) => {
            let min_max = float_window(data_range);
            match outlier_window(v, slice_len, &stored.rescale, min_max) {
                Some((window, clamped)) => {
                    log::warn!(
                        "{}: {clamped} of {voxels} voxels lie far outside the others' range \
                         and would set the window [{:e}, {:e}], flattening the rest to one \
                         value; the window is [{:e}, {:e}] and those voxels are clamped to \
                         0 or 1",
                        path.display(),
                        min_max.0,
                        min_max.1,
                        window.0,
                        window.1
                    );
                    window
                }
                None => min_max,
            }
        }
        (None, _) => float_window(data_range),
    };
    let data = apply_window(stored, slice_len, window);
    Ok(Normalised {
        data,
        window: [window.0 as f32, window.1 as f32],
        exact_window: window,
    })
}

fn check_finite(path: &Path, dims: [u32; 3], v: &[f32]) -> Result<(), VolumeError> {
    let count = v.iter().filter(|x| !x.is_finite()).count();
    if count == 0 {
        return Ok(());
    }
    let i = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
    let (nx, ny) = (dims[0] as usize, dims[1] as usize);
    let first = [
        (i % nx) as u32,
        ((i / nx) % ny) as u32,
        (i / (nx * ny)) as u32,
    ];
    Err(VolumeError::NonFinite {
        path: path.to_path_buf(),
        count: count as u64,
        first,
    })
}

/// Min and max of a slice of stored values, as f64.
fn stored_minmax(s: &Samples, range: std::ops::Range<usize>) -> Option<(f64, f64)> {
    fn ord<T: Ord + Copy + Into<f64>>(v: &[T]) -> Option<(f64, f64)> {
        let lo = v.iter().copied().min()?;
        let hi = v.iter().copied().max()?;
        Some((lo.into(), hi.into()))
    }
    match s {
        Samples::U8(v) => ord(&v[range]),
        Samples::U16(v) => ord(&v[range]),
        Samples::I16(v) => ord(&v[range]),
        Samples::F32(v) => {
            let v = &v[range];
            let first = *v.first()?;
            let (lo, hi) = v
                .iter()
                .fold((first, first), |(lo, hi), &x| (lo.min(x), hi.max(x)));
            Some((lo as f64, hi as f64))
        }
    }
}

/// The data's range in physical units (after the per-slice rescale).
fn physical_range(s: &Samples, slice_len: usize, rescale: &Rescale) -> (f64, f64) {
    let mut acc: Option<(f64, f64)> = None;
    match rescale {
        Rescale::Uniform(a) => {
            if let Some(r) = stored_minmax(s, 0..s.len()) {
                acc = Some(a.apply_range(r));
            }
        }
        Rescale::PerSlice(_) => {
            for z in 0..s.len() / slice_len.max(1) {
                let range = z * slice_len..(z + 1) * slice_len;
                if let Some(r) = stored_minmax(s, range) {
                    let (lo, hi) = rescale.for_slice(z).apply_range(r);
                    acc = Some(acc.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))));
                }
            }
        }
    }
    acc.unwrap_or((0.0, 0.0))
}

/// The window for integer data (rule 2, first case).
pub(crate) fn integer_window(
    type_range: (f64, f64),
    data: (f64, f64),
    rescale: &Rescale,
    slices: u32,
) -> (f64, f64) {
    let t = match rescale {
        Rescale::Uniform(a) => a.apply_range(type_range),
        Rescale::PerSlice(_) => (0..slices as usize)
            .map(|z| rescale.for_slice(z).apply_range(type_range))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (lo, hi)| {
                (a.min(lo), b.max(hi))
            }),
    };
    let (lo, hi) = data;
    if hi > lo && (hi - lo) < (t.1 - t.0) / 4.0 {
        data
    } else {
        t
    }
}

/// The window for float data (rule 2, second case).
pub(crate) fn float_window((lo, hi): (f64, f64)) -> (f64, f64) {
    if lo >= 0.0 && hi <= 1.0 {
        (0.0, 1.0)
    } else if hi > lo {
        (lo, hi)
    } else {
        (lo.min(0.0), hi.max(1.0))
    }
}

/// Voxels sampled (evenly) to estimate the percentiles of [`outlier_window`].
const PERCENTILE_SAMPLES: usize = 1 << 20;
/// Share of the values below and above the percentile range of [`outlier_window`].
const TAIL: f64 = 0.001;
/// The percentile range may span this share of the min–max window before the window
/// counts as set by outliers (the bulk would then use less than 1/1000 of `[0, 1]`).
const DOMINATED: f64 = 1e-3;
/// Values within this many percentile ranges of it are kept inside the window.
const KEEP_SPANS: f64 = 10.0;

/// A float volume's window when outliers set its min–max window (see the module's
/// rule 2), with the number of voxels clamped; `None` when they do not.
fn outlier_window(
    v: &[f32],
    slice_len: usize,
    rescale: &Rescale,
    (lo, hi): (f64, f64),
) -> Option<((f64, f64), usize)> {
    let physical = |i: usize| {
        rescale
            .for_slice(i / slice_len.max(1))
            .apply(f64::from(v[i]))
    };
    let step = v.len().div_ceil(PERCENTILE_SAMPLES).max(1);
    let mut sample: Vec<f64> = (0..v.len()).step_by(step).map(physical).collect();
    if sample.len() < 2 || hi <= lo {
        return None;
    }
    let at = |q: f64| ((sample.len() - 1) as f64 * q).round() as usize;
    let (i_lo, i_hi) = (at(TAIL), at(1.0 - TAIL));
    let q_lo = *sample.select_nth_unstable_by(i_lo, f64::total_cmp).1;
    let q_hi = *sample.select_nth_unstable_by(i_hi, f64::total_cmp).1;
    let span = q_hi - q_lo;
    if span >= DOMINATED * (hi - lo) {
        return None;
    }
    let (keep_lo, keep_hi) = (q_lo - KEEP_SPANS * span, q_hi + KEEP_SPANS * span);
    let mut window = (f64::INFINITY, f64::NEG_INFINITY);
    let mut clamped = 0;
    for i in 0..v.len() {
        let p = physical(i);
        if p < keep_lo || p > keep_hi {
            clamped += 1;
        } else {
            window = (window.0.min(p), window.1.max(p));
        }
    }
    (clamped > 0).then(|| (float_window(window), clamped))
}

/// Maps a physical value through the window to `[0, 1]`.
fn unit(p: f64, (lo, hi): (f64, f64)) -> f64 {
    if hi > lo {
        ((p - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

fn apply_window(stored: Stored, slice_len: usize, window: (f64, f64)) -> VolumeData {
    let Stored {
        samples,
        type_range,
        rescale,
        ..
    } = stored;
    let identity = rescale == Rescale::Uniform(Affine::IDENTITY);
    let untouched = identity && type_range == samples.kind().full_range();
    match samples {
        Samples::U8(v) if untouched && window == (0.0, 255.0) => VolumeData::U8(v),
        Samples::U16(v) if untouched && window == (0.0, 65535.0) => VolumeData::U16(v),
        Samples::U8(v) => VolumeData::U8(map_slices(&v, slice_len, &rescale, |a| {
            lut(a, window, 255.0, (0..=255u8).map(f64::from))
        })),
        Samples::U16(v) => VolumeData::U16(map_slices(&v, slice_len, &rescale, |a| {
            lut(a, window, 65535.0, (0..=65535u16).map(f64::from))
        })),
        Samples::I16(v) => {
            // Index the table by the raw bits so one 64 Ki table serves i16 too.
            let bits: Vec<u16> = v.iter().map(|&x| x as u16).collect();
            VolumeData::U16(map_slices(&bits, slice_len, &rescale, |a| {
                lut(
                    a,
                    window,
                    65535.0,
                    (0..=65535u16).map(|b| f64::from(b as i16)),
                )
            }))
        }
        Samples::F32(mut v) => {
            for (z, slice) in v.chunks_mut(slice_len.max(1)).enumerate() {
                let a = rescale.for_slice(z);
                for x in slice {
                    *x = unit(a.apply(f64::from(*x)), window) as f32;
                }
            }
            VolumeData::F32(v)
        }
    }
}

/// A lookup table from every stored value (in index order) to the output unorm value.
fn lut<O: TryFrom<u32> + Default>(
    a: Affine,
    window: (f64, f64),
    scale: f64,
    values: impl Iterator<Item = f64>,
) -> Vec<O> {
    values
        .map(|v| {
            let q = (unit(a.apply(v), window) * scale).round() as u32;
            O::try_from(q).unwrap_or_default()
        })
        .collect()
}

/// Maps each slice through a table built for its rescale (rebuilt only when it changes).
fn map_slices<I, O>(
    v: &[I],
    slice_len: usize,
    rescale: &Rescale,
    make_lut: impl Fn(Affine) -> Vec<O>,
) -> Vec<O>
where
    I: Copy + Into<usize>,
    O: Copy + Default,
{
    let mut out = Vec::with_capacity(v.len());
    let mut current: Option<(Affine, Vec<O>)> = None;
    for (z, slice) in v.chunks(slice_len.max(1)).enumerate() {
        let a = rescale.for_slice(z);
        if current.as_ref().is_none_or(|(ca, _)| *ca != a) {
            current = Some((a, make_lut(a)));
        }
        let Some((_, table)) = &current else {
            continue;
        };
        out.extend(
            slice
                .iter()
                .map(|&x| table.get(x.into()).copied().unwrap_or_default()),
        );
    }
    out
}

#[cfg(test)]
mod tests;
