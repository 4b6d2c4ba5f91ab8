//! Patient space: where each voxel lies, in millimetres, in one stated frame.
//!
//! **The frame is RAS+**: +x points to the patient's Right, +y Anterior, +z Superior
//! (NIfTI's and nibabel's convention). DICOM and NRRD files stated in LPS are converted
//! by negating x and y.
//!
//! Every loader states its file's [`PatientTransform`] (index to patient mm). The volume
//! then holds its voxels **in RAS order**: index axis 0 runs along +R, 1 along +A, 2
//! along +S, so the renderer, which places the volume as an axis-aligned box, shows the
//! anatomy the right way round. A transform that only permutes or flips axes is applied
//! exactly (the voxels are reordered); an oblique one is resampled (trilinear, outside
//! the data is empty) onto the RAS-aligned grid that `nibabel.processing.
//! resample_to_output(img, voxel_sizes)` builds: the box of the input's voxel centres,
//! with the input's voxel sizes along the RAS axes they lie closest to.

use std::path::Path;

use crate::{Volume, VolumeData, VolumeError};

/// Index space to patient space (RAS+, mm): `p = origin + Σ_a index[a] · axes[a]`, where
/// `axes[a]` is index axis a's step (its direction times its spacing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatientTransform {
    pub axes: [[f64; 3]; 3],
    pub origin: [f64; 3],
}

/// Off-axis share of an axis's direction past which the grid is oblique and resampled
/// (about 0.06°: rounding in a header is far below it, a tilted gantry far above).
const OBLIQUE_SINE: f64 = 1e-3;

impl PatientTransform {
    /// Axes along R, A, S with these spacings, the first voxel at the origin: what a
    /// file that states no orientation gets.
    pub fn aligned(spacing: [f32; 3]) -> PatientTransform {
        let s = spacing.map(f64::from);
        PatientTransform {
            axes: [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
            origin: [0.0; 3],
        }
    }

    /// From a 4×4 (or 3×4) row-major affine in RAS mm (NIfTI's sform).
    pub fn from_rows(rows: [[f64; 4]; 3]) -> PatientTransform {
        PatientTransform {
            axes: [0, 1, 2].map(|a| [rows[0][a], rows[1][a], rows[2][a]]),
            origin: [rows[0][3], rows[1][3], rows[2][3]],
        }
    }

    /// The same transform stated in LPS (DICOM, NRRD `left-posterior-superior`), as RAS.
    pub fn from_lps(axes: [[f64; 3]; 3], origin: [f64; 3]) -> PatientTransform {
        let flip = |v: [f64; 3]| [-v[0], -v[1], v[2]];
        PatientTransform {
            axes: axes.map(flip),
            origin: flip(origin),
        }
    }

    /// The patient position of index (i, j, k).
    pub fn apply(&self, index: [f64; 3]) -> [f64; 3] {
        let mut p = self.origin;
        for (a, axis) in self.axes.iter().enumerate() {
            for (r, pr) in p.iter_mut().enumerate() {
                *pr += index[a] * axis[r];
            }
        }
        p
    }

    /// The length of each axis's step: the voxel spacing in mm.
    pub fn spacing(&self) -> [f64; 3] {
        self.axes.map(norm)
    }

    /// Checks that the axes are finite, non-zero and span space.
    pub fn check(&self) -> Result<(), String> {
        let finite = self
            .axes
            .iter()
            .flatten()
            .chain(self.origin.iter())
            .all(|x| x.is_finite());
        if !finite {
            return Err(format!("{self:?} is not finite"));
        }
        let det = det3(self.axes);
        let scale: f64 = self.spacing().iter().product();
        if scale <= 0.0 || (det / scale).abs() < 1e-3 {
            return Err(format!(
                "the axes {:?} do not span three dimensions",
                self.axes
            ));
        }
        Ok(())
    }

    /// Which RAS axis each index axis lies closest to, and whether it points along it
    /// (`true`) or against it. A permutation: no two index axes get one RAS axis.
    fn nearest_ras(&self) -> [(usize, bool); 3] {
        // Greedy on the largest |cosine| left, as nibabel's io_orientation does.
        let cos = self.axes.map(|v| {
            let n = norm(v);
            v.map(|c| c / n)
        });
        let mut out = [(usize::MAX, true); 3];
        let mut used_axis = [false; 3];
        let mut used_ras = [false; 3];
        for _ in 0..3 {
            let mut best = (0, 0, -1.0);
            for (a, c) in cos.iter().enumerate() {
                for (r, &x) in c.iter().enumerate() {
                    if !used_axis[a] && !used_ras[r] && x.abs() > best.2 {
                        best = (a, r, x.abs());
                    }
                }
            }
            let (a, r, _) = best;
            used_axis[a] = true;
            used_ras[r] = true;
            out[a] = (r, cos[a][r] >= 0.0);
        }
        out
    }

    /// Whether any axis is further than `OBLIQUE_SINE` from the RAS axis it is
    /// nearest to.
    pub fn is_oblique(&self) -> bool {
        let near = self.nearest_ras();
        self.axes.iter().zip(near).any(|(v, (r, _))| {
            let c = v[r].abs() / norm(*v);
            (1.0 - c * c).max(0.0).sqrt() > OBLIQUE_SINE
        })
    }
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|c| c * c).sum::<f64>().sqrt()
}

fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Puts `v`'s voxels (in the file's index order, `t` their transform) into RAS order:
/// reordered exactly when `t` only permutes and flips axes, resampled when it is
/// oblique. Sets `dims`, `spacing` and `to_patient` to the result's.
pub(crate) fn to_ras(
    path: &Path,
    mut v: Volume,
    t: PatientTransform,
) -> Result<Volume, VolumeError> {
    t.check().map_err(|problem| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: "orientation".into(),
        problem,
    })?;
    if t.is_oblique() {
        return resample(path, v, t);
    }
    let near = t.nearest_ras();
    let identity = near.iter().enumerate().all(|(a, &(r, pos))| a == r && pos);
    let spacing = t.spacing();
    let mut dims = [0u32; 3];
    let mut new_spacing = [0f32; 3];
    for (a, &(r, _)) in near.iter().enumerate() {
        dims[r] = v.dims[a];
        new_spacing[r] = spacing[a] as f32;
    }
    // The new first voxel is the old voxel at the far end of every flipped axis.
    let corner = [0, 1, 2].map(|a| {
        if near[a].1 {
            0.0
        } else {
            f64::from(v.dims[a]) - 1.0
        }
    });
    let origin = t.apply(corner);
    if !identity {
        v.data = permute(&v.data, v.dims, near);
    }
    v.dims = dims;
    v.spacing = new_spacing;
    let mut aligned = PatientTransform::aligned(new_spacing);
    aligned.origin = origin;
    v.to_patient = aligned;
    Ok(v)
}

/// The voxels reordered so that old index axis a becomes axis `near[a].0`, reversed
/// where `near[a].1` is false.
fn permute(data: &VolumeData, dims: [u32; 3], near: [(usize, bool); 3]) -> VolumeData {
    fn go<T: Copy>(src: &[T], dims: [u32; 3], near: [(usize, bool); 3]) -> Vec<T> {
        let d = dims.map(|x| x as usize);
        let mut nd = [0usize; 3];
        for a in 0..3 {
            nd[near[a].0] = d[a];
        }
        let stride = [1, nd[0], nd[0] * nd[1]];
        let mut out = Vec::with_capacity(src.len());
        // Every destination index is written exactly once below.
        out.resize(src.len(), src[0]);
        let mut i = 0;
        for z in 0..d[2] {
            for y in 0..d[1] {
                for x in 0..d[0] {
                    let old = [x, y, z];
                    let mut j = 0;
                    for a in 0..3 {
                        let (r, pos) = near[a];
                        let c = if pos { old[a] } else { d[a] - 1 - old[a] };
                        j += c * stride[r];
                    }
                    out[j] = src[i];
                    i += 1;
                }
            }
        }
        out
    }
    match data {
        VolumeData::U8(s) => VolumeData::U8(go(s, dims, near)),
        VolumeData::U16(s) => VolumeData::U16(go(s, dims, near)),
        VolumeData::F32(s) => VolumeData::F32(go(s, dims, near)),
    }
}

/// Resamples an oblique volume onto the RAS-aligned grid of its voxel centres' box
/// (see the module docs), trilinearly; points outside the data are empty (density 0).
fn resample(path: &Path, v: Volume, t: PatientTransform) -> Result<Volume, VolumeError> {
    let near = t.nearest_ras();
    let spacing = t.spacing();
    let mut vox = [0f64; 3];
    for (a, &(r, _)) in near.iter().enumerate() {
        vox[r] = spacing[a];
    }
    let d = v.dims.map(f64::from);
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for corner in 0..8 {
        let idx = [0, 1, 2].map(|a| {
            if corner >> a & 1 == 1 {
                d[a] - 1.0
            } else {
                0.0
            }
        });
        let p = t.apply(idx);
        for r in 0..3 {
            lo[r] = lo[r].min(p[r]);
            hi[r] = hi[r].max(p[r]);
        }
    }
    // In f64 before the (saturating) cast: a header's extreme axes give a span past
    // i64, which validate_dims then refuses by name.
    let out_dims = [0, 1, 2].map(|r| ((((hi[r] - lo[r]) / vox[r]) - 1e-9).ceil() + 1.0) as i64);
    let out_dims = crate::validate_dims(path, out_dims)?;
    let inverse = invert(t);
    let n = crate::voxel_count(out_dims) as usize;
    let mut out = Vec::with_capacity(n);
    for k in 0..out_dims[2] {
        for j in 0..out_dims[1] {
            for i in 0..out_dims[0] {
                let p = [
                    lo[0] + f64::from(i) * vox[0],
                    lo[1] + f64::from(j) * vox[1],
                    lo[2] + f64::from(k) * vox[2],
                ];
                out.push(trilinear(&v, inverse(p)).unwrap_or(0.0));
            }
        }
    }
    let data = match v.data {
        VolumeData::U8(_) => {
            VolumeData::U8(out.iter().map(|&x| (x * 255.0).round() as u8).collect())
        }
        VolumeData::U16(_) => {
            VolumeData::U16(out.iter().map(|&x| (x * 65535.0).round() as u16).collect())
        }
        VolumeData::F32(_) => VolumeData::F32(out),
    };
    let spacing = vox.map(|s| s as f32);
    let mut aligned = PatientTransform::aligned(spacing);
    aligned.origin = lo;
    log::info!(
        "{}: oblique axes resampled onto a RAS-aligned grid of {out_dims:?} voxels",
        path.display()
    );
    Ok(Volume {
        dims: out_dims,
        spacing,
        to_patient: aligned,
        data,
        ..v
    })
}

/// `v` resampled (trilinear, in patient space) onto the grid of `dims` voxels placed by
/// `onto`: how a channel from another file lands on a series' first file's grid (a 3 mm
/// statistical map on a 1 mm T1). Points outside `v`'s voxel centres hold the data value
/// 0 (nilearn's `resample_to_img` fill: a z map's "no effect", not its most negative
/// value), as far as the window reaches it; the samples keep `v`'s type and window.
pub(crate) fn resample_onto(v: &Volume, dims: [u32; 3], onto: &PatientTransform) -> Volume {
    let inverse = invert(v.to_patient);
    let [lo, hi] = v.window;
    let fill = if hi > lo {
        (-lo / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let n = crate::voxel_count(dims) as usize;
    let mut out = Vec::with_capacity(n);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = onto.apply([f64::from(i), f64::from(j), f64::from(k)]);
                out.push(trilinear(v, inverse(p)).unwrap_or(fill));
            }
        }
    }
    let data = match v.data {
        VolumeData::U8(_) => {
            VolumeData::U8(out.iter().map(|&x| (x * 255.0).round() as u8).collect())
        }
        VolumeData::U16(_) => {
            VolumeData::U16(out.iter().map(|&x| (x * 65535.0).round() as u16).collect())
        }
        VolumeData::F32(_) => VolumeData::F32(out),
    };
    Volume {
        name: v.name.clone(),
        dims,
        spacing: onto.spacing().map(|s| s as f32),
        to_patient: *onto,
        window: v.window,
        sample_kind: v.sample_kind,
        data,
    }
}

/// Patient mm to (fractional) index.
pub(crate) fn invert(t: PatientTransform) -> impl Fn([f64; 3]) -> [f64; 3] {
    let m = t.axes; // columns
    let det = det3(m);
    // Rows of the inverse of the matrix whose columns are m[0], m[1], m[2].
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let rows =
        [cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])].map(|r| r.map(|x| x / det));
    move |p| {
        let q = [0, 1, 2].map(|r| p[r] - t.origin[r]);
        rows.map(|row| row[0] * q[0] + row[1] * q[1] + row[2] * q[2])
    }
}

/// Trilinear density at a fractional index; `None` outside the voxel centres' box.
fn trilinear(v: &Volume, p: [f64; 3]) -> Option<f32> {
    let d = v.dims.map(|x| x as f64);
    let eps = 1e-6;
    if (0..3).any(|a| p[a] < -eps || p[a] > d[a] - 1.0 + eps) {
        return None;
    }
    let base = [0, 1, 2].map(|a| (p[a].max(0.0).floor() as u32).min(v.dims[a] - 1));
    let frac = [0, 1, 2].map(|a| (p[a] - f64::from(base[a])).clamp(0.0, 1.0));
    let mut acc = 0.0;
    for corner in 0..8 {
        let mut w = 1.0;
        let mut idx = [0u32; 3];
        for a in 0..3 {
            let up = corner >> a & 1 == 1;
            w *= if up { frac[a] } else { 1.0 - frac[a] };
            idx[a] = if up {
                (base[a] + 1).min(v.dims[a] - 1)
            } else {
                base[a]
            };
        }
        if w > 0.0 {
            acc += w * f64::from(v.value(idx[0], idx[1], idx[2]).unwrap_or(0.0));
        }
    }
    Some(acc as f32)
}

#[cfg(test)]
mod tests;
