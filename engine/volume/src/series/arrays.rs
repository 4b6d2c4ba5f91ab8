//! A series handed over in memory: time points × channels of stored samples on one grid
//! (a numpy `(T, C, Z, Y, X)` array), read and normalised as a file's would be, each
//! channel through the window of its first time point.

use super::{Arrangement, Series, Source, SourceChannel, SourceInfo, Window, Windowed};
use crate::samples::{Samples, Stored};
use crate::{validate_dims, validate_spacing, Volume, VolumeError, Voxels};
use std::path::{Path, PathBuf};

struct Arrays {
    info: SourceInfo,
    spacing: [f32; 3],
    /// `blocks[t][c]`.
    blocks: Vec<Vec<Voxels>>,
}

impl Source for Arrays {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed {
        let samples = match &self.blocks[time][channel] {
            Voxels::U8(v) => Samples::U8(v.clone()),
            Voxels::U16(v) => Samples::U16(v.clone()),
            Voxels::I16(v) => Samples::I16(v.clone()),
            Voxels::F32(v) => Samples::F32(v.clone()),
        };
        Volume::from_stored_in(
            &self.info.path,
            self.info.name.clone(),
            self.info.dims,
            self.spacing,
            Stored::plain(samples),
            window,
        )
    }
}

impl Series {
    /// A series of `blocks[t][c]` (x fastest, `dims` voxels each, all of one type per
    /// channel) with voxels of `spacing` mm, named `name`; `channels` picks some, as
    /// [`Series::open`]'s does. Errors name the block whose length or type is wrong, an
    /// empty time or channel axis, and more than 4 channels (saying how to pick some).
    pub fn from_arrays(
        name: &str,
        dims: [u32; 3],
        spacing: [f32; 3],
        blocks: Vec<Vec<Voxels>>,
        channels: Option<&[usize]>,
    ) -> Result<Series, VolumeError> {
        let path = PathBuf::from(name);
        let dims = validate_dims(&path, dims.map(i64::from))?;
        let spacing = validate_spacing(&path, "spacing", spacing.map(f64::from))?;
        let bad = |problem: String| VolumeError::MalformedHeader {
            path: path.clone(),
            field: "shape".into(),
            problem,
        };
        let count = blocks.first().map_or(0, Vec::len);
        if blocks.is_empty() || count == 0 {
            return Err(bad(format!(
                "{} time point(s) of {count} channel(s): a series needs at least one of each",
                blocks.len()
            )));
        }
        let voxels = crate::voxel_count(dims) as usize;
        for (t, row) in blocks.iter().enumerate() {
            for (c, b) in row.iter().enumerate() {
                if len(b) != voxels
                    || std::mem::discriminant(b) != std::mem::discriminant(&blocks[0][c])
                {
                    return Err(bad(format!(
                        "time point {t}, channel {c}: {} samples, {voxels} expected, of channel {c}'s type",
                        len(b)
                    )));
                }
            }
            if row.len() != count {
                return Err(bad(format!(
                    "time point {t} has {} channels, time point 0 {count}",
                    row.len()
                )));
            }
        }
        let info = SourceInfo {
            path: Path::new(name).to_path_buf(),
            name: name.to_string(),
            dims,
            orientation: None,
            channels: vec![SourceChannel::default(); count],
            times: blocks.len(),
        };
        let source = Arrays {
            info,
            spacing,
            blocks,
        };
        Series::build(Arrangement::OneFile, vec![Box::new(source)], channels)
    }
}

fn len(v: &Voxels) -> usize {
    match v {
        Voxels::U8(x) => x.len(),
        Voxels::U16(x) => x.len(),
        Voxels::I16(x) => x.len(),
        Voxels::F32(x) => x.len(),
    }
}
