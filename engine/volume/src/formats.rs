//! The table of volume formats: how each is recognised (a folder probe, name endings,
//! magic bytes) and which function reads it. [`crate::Volume::load`] walks this table
//! and nothing else, so a new format is its module and one row here. A [`Table`] is the
//! walk over a table: [`FORMATS`], or (in a test) it with a toy row added.
//!
//! Order matters where two rows could claim one input: folder probes run in table order
//! (an OME-Zarr folder before "any other folder is a DICOM series"), then name endings,
//! then magic bytes (a file named for no format, whose first bytes say what it is).

use std::io::Read;
use std::path::Path;

use crate::series::{Source, WholeFile};
use crate::{dicom, nifti, nrrd, ome_tiff, raw, zarr, Volume, VolumeError};

/// What a load asks beyond the path.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Request {
    /// Bytes a renderer has for its volume: multiscale formats read the finest level
    /// that fits.
    pub budget: Option<u64>,
}

/// Bytes at a fixed offset that identify a format.
#[derive(Clone, Copy)]
pub(crate) struct Magic {
    pub offset: usize,
    pub bytes: &'static [u8],
}

/// One format: its name in messages, how it is recognised, how it is read.
#[derive(Clone, Copy)]
pub(crate) struct Format {
    pub name: &'static str,
    /// Lower-case name endings that select it (`.nii.gz` before `.gz` would matter).
    pub extensions: &'static [&'static str],
    /// Leading bytes that select it when no ending does.
    pub magic: &'static [Magic],
    /// For a format stored as a folder: whether this folder holds one.
    pub folder: Option<fn(&Path) -> bool>,
    pub load: fn(&Path, Request) -> Result<Volume, VolumeError>,
    /// Opens it as a series of channels and time points (`series.rs`).
    pub series: fn(&Path) -> Result<Box<dyn Source>, VolumeError>,
}

/// Every format `Volume::load` reads, in the order it tries them.
pub(crate) const FORMATS: &[Format] = &[
    Format {
        name: "OME-Zarr",
        extensions: &[".zarr"],
        magic: &[],
        folder: Some(zarr::is_zarr),
        load: |p, r| zarr::load(p, r.budget),
        series: zarr::open_series,
    },
    Format {
        name: "DICOM series",
        extensions: &[".dcm"],
        magic: &[Magic {
            offset: 128,
            bytes: b"DICM",
        }],
        folder: Some(|p| p.is_dir()),
        load: |p, _| {
            if p.is_dir() {
                dicom::load_series(p)
            } else {
                dicom::load_files(p, vec![p.to_path_buf()])
            }
        },
        // A DICOM series is one 3D volume with an orientation.
        series: |p| WholeFile::open(p, load(p, Request::default())?, true),
    },
    Format {
        name: "NRRD",
        extensions: &[".nrrd", ".nhdr"],
        magic: &[Magic {
            offset: 0,
            bytes: b"NRRD000",
        }],
        folder: None,
        load: |p, _| nrrd::load(p),
        series: nrrd::open_series,
    },
    Format {
        name: "NIfTI-1",
        extensions: &[".nii", ".nii.gz"],
        magic: &[
            Magic {
                offset: 344,
                bytes: b"n+1\0",
            },
            Magic {
                offset: 344,
                bytes: b"ni1\0",
            },
        ],
        folder: None,
        load: |p, _| nifti::load(p),
        series: nifti::open_series,
    },
    Format {
        name: "OME-TIFF / TIFF stack",
        extensions: &[".ome.tif", ".ome.tiff", ".tif", ".tiff"],
        magic: &[
            Magic {
                offset: 0,
                bytes: b"II*\0",
            },
            Magic {
                offset: 0,
                bytes: b"MM\0*",
            },
        ],
        folder: None,
        load: |p, _| ome_tiff::load(p),
        series: ome_tiff::open_series,
    },
];

/// Name endings of raw data, which need a sidecar or explicit parameters.
pub(crate) const RAW_EXTENSIONS: &[&str] = &[".raw", ".bin", ".dat", ".vol"];

/// A table of formats, walked in its order.
#[derive(Clone, Copy)]
pub(crate) struct Table<'t>(pub &'t [Format]);

/// The formats `Volume::load` reads.
pub(crate) const BUILTIN: Table<'static> = Table(FORMATS);

/// Reads `path` with the built-in table (see [`Table::load`]).
pub(crate) fn load(path: &Path, request: Request) -> Result<Volume, VolumeError> {
    BUILTIN.load(path, request)
}

/// Opens `path` as a series with the built-in table (see [`Table::open_series`]).
pub(crate) fn open_series(path: &Path) -> Result<Box<dyn Source>, VolumeError> {
    BUILTIN.open_series(path)
}

impl<'t> Table<'t> {
    /// The format that reads `path`, by folder probe, name ending, then magic bytes.
    pub(crate) fn format_of(self, path: &Path) -> Option<&'t Format> {
        if path.is_dir() {
            return self
                .0
                .iter()
                .find(|f| f.folder.is_some_and(|probe| probe(path)));
        }
        let lower = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if let Some(f) = self
            .0
            .iter()
            .find(|f| f.extensions.iter().any(|e| lower.ends_with(e)))
        {
            return Some(f);
        }
        // Only regular files are sniffed: a FIFO or device must not be opened here (the
        // loaders refuse those with their own error).
        if !path.is_file() {
            return None;
        }
        let head = self.leading_bytes(path)?;
        self.0.iter().find(|f| {
            f.magic.iter().any(|m| {
                head.get(m.offset..m.offset + m.bytes.len())
                    .is_some_and(|b| b == m.bytes)
            })
        })
    }

    /// The first bytes of a file, enough for every magic in the table.
    fn leading_bytes(self, path: &Path) -> Option<Vec<u8>> {
        let need = self
            .0
            .iter()
            .flat_map(|f| f.magic.iter().map(|m| m.offset + m.bytes.len()))
            .max()
            .unwrap_or(0);
        let mut head = Vec::with_capacity(need);
        std::fs::File::open(path)
            .ok()?
            .take(need as u64)
            .read_to_end(&mut head)
            .ok()?;
        Some(head)
    }

    /// Reads `path` with the format the table picks (see [`Table::format_of`]), or raw
    /// data described by a sidecar `<file>.json` / `<file>.toml`.
    pub(crate) fn load(self, path: &Path, request: Request) -> Result<Volume, VolumeError> {
        if let Some(format) = self.format_of(path) {
            log::debug!("{}: read as {}", path.display(), format.name);
            return (format.load)(path, request);
        }
        if let Some(params) = raw::read_sidecar(path)? {
            return raw::load(path, &params);
        }
        let lower = path.to_string_lossy().to_ascii_lowercase();
        if RAW_EXTENSIONS.iter().any(|e| lower.ends_with(e)) {
            return Err(VolumeError::MissingRawParams {
                path: path.to_path_buf(),
            });
        }
        Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "unknown volume format; expected {}, a DICOM or OME-Zarr folder, or raw data \
                 with a <file>.json/.toml sidecar",
                self.known_endings()
            ),
        })
    }

    /// Opens `path` as a series with the format the table picks; raw data (a sidecar) is
    /// one channel at one time point without an orientation.
    pub(crate) fn open_series(self, path: &Path) -> Result<Box<dyn Source>, VolumeError> {
        if let Some(format) = self.format_of(path) {
            return (format.series)(path);
        }
        // Raw, or the error `load` gives for what it cannot read.
        WholeFile::open(path, self.load(path, Request::default())?, false)
    }

    /// Every name ending of the table, for messages: ".zarr, .dcm, .nrrd, …".
    pub(crate) fn known_endings(self) -> String {
        self.0
            .iter()
            .flat_map(|f| f.extensions.iter().copied())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_is_reachable_and_endings_are_unique() {
        let mut seen = std::collections::HashSet::new();
        for f in FORMATS {
            assert!(
                !f.extensions.is_empty() || f.folder.is_some() || !f.magic.is_empty(),
                "{} cannot be selected",
                f.name
            );
            for e in f.extensions {
                assert!(e.starts_with('.') && *e == e.to_ascii_lowercase(), "{e}");
                assert!(seen.insert(*e), "{e} names two formats");
            }
        }
        for e in RAW_EXTENSIONS {
            assert!(!seen.contains(e), "{e} is both raw and a format");
        }
    }

    #[test]
    fn files_named_for_no_format_are_read_by_their_magic() {
        let dir = tempfile::tempdir().expect("tempdir");
        let cases: [(&str, Vec<u8>, &str); 3] = [
            ("a", b"NRRD0004\ntype: uint8\n".to_vec(), "NRRD"),
            (
                "b",
                [b"II*\0".as_slice(), &[0u8; 60]].concat(),
                "OME-TIFF / TIFF stack",
            ),
            (
                "c",
                [vec![0u8; 128], b"DICM".to_vec(), vec![0u8; 400]].concat(),
                "DICOM series",
            ),
        ];
        for (name, bytes, want) in cases {
            let p = dir.path().join(name);
            std::fs::write(&p, bytes).expect("write");
            assert_eq!(BUILTIN.format_of(&p).map(|f| f.name), Some(want), "{name}");
        }
        let mut nifti = vec![0u8; 352];
        nifti[344..348].copy_from_slice(b"n+1\0");
        let p = dir.path().join("d.img");
        std::fs::write(&p, nifti).expect("write");
        assert_eq!(BUILTIN.format_of(&p).map(|f| f.name), Some("NIfTI-1"));
        let p = dir.path().join("e.bin");
        std::fs::write(&p, [1u8, 2, 3]).expect("write");
        assert!(BUILTIN.format_of(&p).is_none());
    }

    #[test]
    fn the_unknown_format_error_lists_the_tables_endings() {
        let err = load(Path::new("/nonexistent/picture.png"), Request::default()).unwrap_err();
        let msg = err.to_string();
        for f in FORMATS {
            for e in f.extensions {
                assert!(msg.contains(e), "{msg} lacks {e}");
            }
        }
    }

    /// The toy format of the plugin test: `TOY3`, three little-endian u32 dims, then
    /// the u8 voxels, x fastest.
    fn load_toy(path: &Path) -> Result<Volume, VolumeError> {
        let bytes = std::fs::read(path).expect("a toy file");
        let dim = |i: usize| u32::from_le_bytes(bytes[4 + 4 * i..8 + 4 * i].try_into().unwrap());
        let voxels = bytes[16..].to_vec();
        Volume::new(
            "toy",
            [dim(0), dim(1), dim(2)],
            [1.0; 3],
            crate::VolumeData::U8(voxels),
        )
    }

    /// The row a new format adds to [`FORMATS`].
    const TOY: Format = Format {
        name: "toy",
        extensions: &[".toy"],
        magic: &[Magic {
            offset: 0,
            bytes: b"TOY3",
        }],
        folder: None,
        load: |p, _| load_toy(p),
        series: |p| WholeFile::open(p, load_toy(p)?, false),
    };

    #[test]
    fn a_new_format_is_one_row() {
        let rows: Vec<Format> = FORMATS.iter().copied().chain([TOY]).collect();
        let table = Table(&rows);
        let dir = tempfile::tempdir().expect("tempdir");
        let file = [
            b"TOY3".as_slice(),
            &[2, 0, 0, 0, 1, 0, 0, 0, 3, 0, 0, 0],
            &[0, 51, 102, 153, 204, 255],
        ]
        .concat();
        // By its ending, and by its magic under a name that says nothing.
        for name in ["a.toy", "b"] {
            let p = dir.path().join(name);
            std::fs::write(&p, &file).expect("write");
            assert_eq!(table.format_of(&p).map(|f| f.name), Some("toy"), "{name}");
            let v = table.load(&p, Request::default()).expect("a toy volume");
            assert_eq!(v.dims, [2, 1, 3]);
            assert_eq!(v.value(1, 0, 2), Some(1.0));
            let series = table.open_series(&p).expect("a toy series");
            assert_eq!(series.info().dims, [2, 1, 3]);
            assert!(
                BUILTIN.load(&p, Request::default()).is_err(),
                "{name}: not built in"
            );
        }
        let err = table
            .load(Path::new("/nonexistent/picture.png"), Request::default())
            .unwrap_err();
        assert!(err.to_string().contains(".toy"), "{err}");
    }
}
