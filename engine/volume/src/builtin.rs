//! The built-in datasets by name.

use std::path::Path;

use super::blocks::VoxelBlocks;
use super::error::VolumeError;
use super::samples::{Samples, Stored};
use super::{cloud, phantom, validate_dims, Volume};

/// Names accepted by [`Volume::builtin`].
pub const BUILTIN_NAMES: [&str; 4] = ["phantom", "cloud", "mri", "sparse"];

pub(crate) fn build(name: &str, size: u32) -> Result<Volume, VolumeError> {
    let procedural = |size: u32| validate_dims(Path::new(name), [i64::from(size); 3]);
    match name {
        "phantom" => {
            let dims = procedural(size)?;
            let stored = Stored::plain(Samples::U16(phantom::generate(size)));
            Volume::from_stored(Path::new(name), name.into(), dims, [1.0; 3], stored)
        }
        "cloud" => {
            let dims = procedural(size)?;
            let stored = Stored::plain(Samples::U8(cloud::generate(size)));
            Volume::from_stored(Path::new(name), name.into(), dims, [1.0; 3], stored)
        }
        "sparse" => {
            let v = super::sparse::Sparse::new(size);
            let dims = validate_dims(Path::new(name), v.dims().map(i64::from))?;
            let stored = Stored::plain(Samples::U16(v.dense()));
            Volume::from_stored(Path::new(name), name.into(), dims, [1.0; 3], stored)
        }
        "mri" => {
            let mut v = Volume::load(&crate::assets::mri_volume(), None)?;
            v.name = name.into();
            Ok(v)
        }
        _ => Err(VolumeError::UnknownBuiltin {
            name: name.into(),
            valid: BUILTIN_NAMES.join(", "),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::VolumeData;

    #[test]
    fn mri_loads_with_the_documented_geometry() {
        let v = Volume::builtin("mri", 0).expect("mri asset");
        assert_eq!(v.name, "mri");
        assert_eq!(v.dims, [197, 233, 189]);
        assert_eq!(v.spacing, [1.0; 3]);
        let VolumeData::U8(d) = &v.data else {
            panic!("uint8 NIfTI must load as U8")
        };
        assert_eq!(d.len(), 197 * 233 * 189);
        // Brain-masked: empty corner, bright tissue inside.
        assert_eq!(v.value(0, 0, 0), Some(0.0));
        assert!(d.iter().any(|&x| x > 200));
    }

    #[test]
    fn unknown_builtin_lists_the_valid_names() {
        let err = Volume::builtin("teapot", 64).unwrap_err();
        assert!(matches!(err, VolumeError::UnknownBuiltin { .. }));
        let msg = err.to_string();
        assert!(
            msg.contains("teapot") && msg.contains("phantom, cloud, mri"),
            "{msg}"
        );
    }

    #[test]
    fn procedural_sizes_are_validated() {
        let err = Volume::builtin("cloud", 0).unwrap_err();
        assert!(matches!(err, VolumeError::BadDims { .. }));
        assert!(err.to_string().contains("cloud"));
        let err = Volume::builtin("phantom", 5000).unwrap_err();
        assert!(matches!(err, VolumeError::BadDims { .. }));
    }

    /// `cargo test --release -p dvr-engine --lib volume -- --ignored --nocapture`
    #[test]
    #[ignore = "timing; run in release"]
    fn time_procedural_256() {
        for name in ["phantom", "cloud"] {
            let t = std::time::Instant::now();
            let v = Volume::builtin(name, 256).expect("builtin");
            let ms = t.elapsed().as_secs_f64() * 1e3;
            println!("{name} 256^3: {ms:.1} ms ({} MiB)", v.byte_size() >> 20);
        }
        let v = Volume::builtin("phantom", 256).expect("builtin");
        let t = std::time::Instant::now();
        let g = crate::MajorantGrid::build(&v, 8);
        println!(
            "majorant grid 256^3 / 8: {:.1} ms ({:?} bricks)",
            t.elapsed().as_secs_f64() * 1e3,
            g.dims
        );
    }
}
