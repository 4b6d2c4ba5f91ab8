//! Stored samples as the loaders decode them, before normalisation.
//!
//! Every file format ends in the same place: a flat array of one of four sample types
//! (x fastest), the range the type can hold, and an affine rescale to physical units
//! (NIfTI `scl_slope/scl_inter`, DICOM `RescaleSlope/Intercept`, possibly per slice).
//! Keeping that step separate lets [`super::normalise`] apply one windowing rule to all
//! formats.

/// The sample types the loaders read. float64 is held as float32 once decoded (a
/// renderer's density needs no more), so it never names a volume's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleKind {
    U8,
    U16,
    I16,
    F32,
    F64,
}

impl SampleKind {
    /// Bytes per sample.
    pub(crate) fn bytes(self) -> usize {
        match self {
            SampleKind::U8 => 1,
            SampleKind::U16 | SampleKind::I16 => 2,
            SampleKind::F32 => 4,
            SampleKind::F64 => 8,
        }
    }

    /// Its numpy name (also what messages say).
    pub fn name(self) -> &'static str {
        match self {
            SampleKind::U8 => "uint8",
            SampleKind::U16 => "uint16",
            SampleKind::I16 => "int16",
            SampleKind::F32 => "float32",
            SampleKind::F64 => "float64",
        }
    }

    /// The full range of the type, `None` for float.
    pub(crate) fn full_range(self) -> Option<(f64, f64)> {
        match self {
            SampleKind::U8 => Some((0.0, 255.0)),
            SampleKind::U16 => Some((0.0, 65535.0)),
            SampleKind::I16 => Some((-32768.0, 32767.0)),
            SampleKind::F32 | SampleKind::F64 => None,
        }
    }
}

/// Decoded stored values, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Samples {
    U8(Vec<u8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

impl Samples {
    pub(crate) fn len(&self) -> usize {
        match self {
            Samples::U8(v) => v.len(),
            Samples::U16(v) => v.len(),
            Samples::I16(v) => v.len(),
            Samples::F32(v) => v.len(),
        }
    }

    pub(crate) fn kind(&self) -> SampleKind {
        match self {
            Samples::U8(_) => SampleKind::U8,
            Samples::U16(_) => SampleKind::U16,
            Samples::I16(_) => SampleKind::I16,
            Samples::F32(_) => SampleKind::F32,
        }
    }

    /// Decodes `bytes` (exactly `n * kind.bytes()` long; a trailing partial sample is
    /// ignored, callers check the length first) in the given byte order.
    pub(crate) fn decode(kind: SampleKind, bytes: Vec<u8>, big_endian: bool) -> Samples {
        fn pairs(b: &[u8]) -> impl Iterator<Item = [u8; 2]> + '_ {
            b.chunks_exact(2).map(|c| [c[0], c[1]])
        }
        match kind {
            SampleKind::U8 => Samples::U8(bytes),
            SampleKind::U16 => Samples::U16(if big_endian {
                pairs(&bytes).map(u16::from_be_bytes).collect()
            } else {
                pairs(&bytes).map(u16::from_le_bytes).collect()
            }),
            SampleKind::I16 => Samples::I16(if big_endian {
                pairs(&bytes).map(i16::from_be_bytes).collect()
            } else {
                pairs(&bytes).map(i16::from_le_bytes).collect()
            }),
            SampleKind::F64 => {
                let eights = bytes.chunks_exact(8).map(|c| {
                    let mut b = [0u8; 8];
                    b.copy_from_slice(c);
                    b
                });
                // Out of f32's range becomes ±inf, which normalisation refuses by name.
                Samples::F32(if big_endian {
                    eights.map(|b| f64::from_be_bytes(b) as f32).collect()
                } else {
                    eights.map(|b| f64::from_le_bytes(b) as f32).collect()
                })
            }
            SampleKind::F32 => {
                let quads = bytes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]);
                Samples::F32(if big_endian {
                    quads.map(f32::from_be_bytes).collect()
                } else {
                    quads.map(f32::from_le_bytes).collect()
                })
            }
        }
    }
}

/// `physical = slope * stored + intercept`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Affine {
    pub slope: f64,
    pub intercept: f64,
}

impl Affine {
    pub(crate) const IDENTITY: Affine = Affine {
        slope: 1.0,
        intercept: 0.0,
    };

    pub(crate) fn apply(self, v: f64) -> f64 {
        self.slope * v + self.intercept
    }

    /// Maps a stored interval to physical units, keeping lo <= hi for negative slopes.
    pub(crate) fn apply_range(self, (lo, hi): (f64, f64)) -> (f64, f64) {
        let (a, b) = (self.apply(lo), self.apply(hi));
        (a.min(b), a.max(b))
    }
}

/// The rescale from stored to physical values.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Rescale {
    /// One affine map for the whole volume.
    Uniform(Affine),
    /// One affine map per z slice (DICOM series may differ slice to slice).
    PerSlice(Vec<Affine>),
}

impl Rescale {
    pub(crate) fn for_slice(&self, z: usize) -> Affine {
        match self {
            Rescale::Uniform(a) => *a,
            Rescale::PerSlice(v) => v.get(z).copied().unwrap_or(Affine::IDENTITY),
        }
    }
}

/// What a loader hands to [`super::normalise::normalise`].
#[derive(Clone, Debug)]
pub(crate) struct Stored {
    pub samples: Samples,
    /// The range the stored type can hold (narrower than the type when, e.g., DICOM
    /// `BitsStored` is 12); `None` for float data.
    pub type_range: Option<(f64, f64)>,
    pub rescale: Rescale,
    /// Index to patient space as the file states it; `None` for formats with no
    /// orientation (the index axes are taken as R, A, S).
    pub orientation: Option<crate::PatientTransform>,
}

impl Stored {
    /// Samples with the type's full range and no rescale.
    pub(crate) fn plain(samples: Samples) -> Stored {
        Stored {
            type_range: samples.kind().full_range(),
            samples,
            rescale: Rescale::Uniform(Affine::IDENTITY),
            orientation: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_respects_byte_order() {
        let bytes = vec![0x01, 0x02, 0xff, 0xfe];
        assert_eq!(
            Samples::decode(SampleKind::U16, bytes.clone(), false),
            Samples::U16(vec![0x0201, 0xfeff])
        );
        assert_eq!(
            Samples::decode(SampleKind::U16, bytes.clone(), true),
            Samples::U16(vec![0x0102, 0xfffe])
        );
        assert_eq!(
            Samples::decode(SampleKind::I16, bytes, true),
            Samples::I16(vec![0x0102, -2])
        );
        let f = 1.5f32.to_be_bytes().to_vec();
        assert_eq!(
            Samples::decode(SampleKind::F32, f, true),
            Samples::F32(vec![1.5])
        );
    }

    #[test]
    fn negative_slope_keeps_range_ordered() {
        let a = Affine {
            slope: -2.0,
            intercept: 1.0,
        };
        assert_eq!(a.apply_range((0.0, 10.0)), (-19.0, 1.0));
    }
}
