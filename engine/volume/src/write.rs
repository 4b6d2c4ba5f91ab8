//! Minimal writers for the formats the loaders read, used by the loader tests to make
//! small files in a temp dir. They write exactly the fields the tests need, in the
//! layouts the specifications give, so a test failure points at the loader.

use std::io::Write;
use std::path::Path;

use flate2::write::GzEncoder;
use flate2::Compression;

pub(crate) fn bytes(path: &Path, b: &[u8]) {
    std::fs::write(path, b).expect("write test file");
}

pub(crate) fn text(path: &Path, s: &str) {
    bytes(path, s.as_bytes());
}

pub(crate) fn raw_u16(path: &Path, v: &[u16]) {
    bytes(
        path,
        &v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>(),
    );
}

pub(crate) fn raw_f32(path: &Path, v: &[f32]) {
    bytes(
        path,
        &v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>(),
    );
}

fn gzip(b: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::fast());
    e.write_all(b).expect("gzip");
    e.finish().expect("gzip")
}

pub(crate) enum NrrdData {
    U8(Vec<u8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

impl NrrdData {
    fn type_name(&self) -> &'static str {
        match self {
            NrrdData::U8(_) => "uint8",
            NrrdData::U16(_) => "uint16",
            NrrdData::I16(_) => "int16",
            NrrdData::F32(_) => "float",
        }
    }

    fn encode(&self, big: bool) -> Vec<u8> {
        macro_rules! enc {
            ($v:expr) => {
                $v.iter()
                    .flat_map(|x| {
                        if big {
                            x.to_be_bytes()
                        } else {
                            x.to_le_bytes()
                        }
                    })
                    .collect()
            };
        }
        match self {
            NrrdData::U8(v) => v.clone(),
            NrrdData::U16(v) => enc!(v),
            NrrdData::I16(v) => enc!(v),
            NrrdData::F32(v) => v
                .iter()
                .flat_map(|x| {
                    if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    }
                })
                .collect(),
        }
    }
}

/// Writes an NRRD: attached (`.nrrd`, `spacings`) or detached (`.nhdr` + `<stem>.raw[.gz]`,
/// `space directions`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn nrrd(
    path: &Path,
    dims: [u32; 3],
    spacing: [f32; 3],
    data: &NrrdData,
    gz: bool,
    big: bool,
    detached: bool,
) {
    let mut h = format!(
        "NRRD0004\n# written by the dvr tests\ntype: {}\ndimension: 3\nsizes: {} {} {}\nencoding: {}\nendian: {}\n",
        data.type_name(),
        dims[0],
        dims[1],
        dims[2],
        if gz { "gzip" } else { "raw" },
        if big { "big" } else { "little" },
    );
    let payload = data.encode(big);
    let payload = if gz { gzip(&payload) } else { payload };
    if detached {
        h += &format!(
            "space: left-posterior-superior\nspace directions: ({},0,0) (0,{},0) (0,0,{})\n",
            spacing[0], spacing[1], spacing[2]
        );
        let stem = path.file_stem().expect("stem").to_string_lossy();
        let name = format!("{stem}.raw{}", if gz { ".gz" } else { "" });
        h += &format!("data file: {name}\n");
        bytes(path, h.as_bytes());
        bytes(&path.with_file_name(name), &payload);
    } else {
        h += &format!("spacings: {} {} {}\n\n", spacing[0], spacing[1], spacing[2]);
        let mut f = h.into_bytes();
        f.extend_from_slice(&payload);
        bytes(path, &f);
    }
}

pub(crate) enum NiftiData {
    U8(Vec<u8>),
    I16(Vec<i16>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

/// Writes a single-file little-endian NIfTI-1 (`.nii`, or gzipped when the name ends in
/// `.gz`), with `scale = (scl_slope, scl_inter)`.
pub(crate) fn nifti(
    path: &Path,
    dims: [u32; 3],
    spacing: [f32; 3],
    data: &NiftiData,
    scale: Option<(f32, f32)>,
) {
    nifti_series(path, dims, [1, 1], spacing, data, scale, None);
}

/// [`nifti`] of `extra = [dim[4], dim[5]]` time points and channels (the data holds
/// them time fastest, then channel, after x, y, z), with an sform where given.
pub(crate) fn nifti_series(
    path: &Path,
    dims: [u32; 3],
    extra: [u32; 2],
    spacing: [f32; 3],
    data: &NiftiData,
    scale: Option<(f32, f32)>,
    sform: Option<[[f32; 4]; 3]>,
) {
    let (code, bitpix, payload): (i16, i16, Vec<u8>) = match data {
        NiftiData::U8(v) => (2, 8, v.clone()),
        NiftiData::I16(v) => (4, 16, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NiftiData::U16(v) => (512, 16, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NiftiData::F32(v) => (16, 32, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
    };
    let mut h = vec![0u8; 352];
    let put = |h: &mut Vec<u8>, at: usize, b: &[u8]| h[at..at + b.len()].copy_from_slice(b);
    put(&mut h, 0, &348i32.to_le_bytes());
    let ndim = if extra[1] > 1 {
        5
    } else if extra[0] > 1 {
        4
    } else {
        3
    };
    let dim: [i16; 8] = [
        ndim,
        dims[0] as i16,
        dims[1] as i16,
        dims[2] as i16,
        extra[0] as i16,
        extra[1] as i16,
        1,
        1,
    ];
    for (i, d) in dim.iter().enumerate() {
        put(&mut h, 40 + 2 * i, &d.to_le_bytes());
    }
    put(&mut h, 70, &code.to_le_bytes());
    put(&mut h, 72, &bitpix.to_le_bytes());
    let pixdim = [
        1.0f32, spacing[0], spacing[1], spacing[2], 1.0, 1.0, 1.0, 1.0,
    ];
    for (i, p) in pixdim.iter().enumerate() {
        put(&mut h, 76 + 4 * i, &p.to_le_bytes());
    }
    put(&mut h, 108, &352f32.to_le_bytes());
    let (slope, inter) = scale.unwrap_or((0.0, 0.0));
    put(&mut h, 112, &slope.to_le_bytes());
    put(&mut h, 116, &inter.to_le_bytes());
    h[123] = 2; // mm
    if let Some(rows) = sform {
        put(&mut h, 254, &1i16.to_le_bytes());
        for (r, row) in rows.iter().enumerate() {
            for (i, x) in row.iter().enumerate() {
                put(&mut h, 280 + 16 * r + 4 * i, &x.to_le_bytes());
            }
        }
    }
    put(&mut h, 344, b"n+1\0");
    h.extend_from_slice(&payload);
    let gz = path.extension().is_some_and(|e| e == "gz");
    bytes(path, &if gz { gzip(&h) } else { h });
}

/// One slice of a test DICOM series.
pub(crate) struct DicomSlice {
    pub rows: u16,
    pub cols: u16,
    pub pixels16: Option<Vec<i16>>,
    pub pixels8: Option<Vec<u8>>,
    pub signed: bool,
    pub bits_stored: u16,
    pub position: Option<[f64; 3]>,
    pub orientation: Option<[f64; 6]>,
    pub instance: Option<i64>,
    pub pixel_spacing: [f64; 2],
    pub thickness: Option<f64>,
    pub rescale: (f64, f64),
    pub series: String,
    /// Explicit VR little endian, else implicit.
    pub explicit: bool,
}

/// Appends one element. `vr` is written only in explicit VR; values are padded to even
/// length (UI with NUL, text with space, binary with 0).
fn element(out: &mut Vec<u8>, explicit: bool, tag: (u16, u16), vr: &[u8; 2], value: &[u8]) {
    let mut v = value.to_vec();
    if v.len() % 2 == 1 {
        v.push(match vr {
            b"UI" | b"OB" | b"OW" => 0,
            _ => b' ',
        });
    }
    out.extend_from_slice(&tag.0.to_le_bytes());
    out.extend_from_slice(&tag.1.to_le_bytes());
    if explicit {
        out.extend_from_slice(vr);
        if matches!(vr, b"OB" | b"OW" | b"SQ" | b"UN" | b"UT") {
            out.extend_from_slice(&[0, 0]);
            out.extend_from_slice(&(v.len() as u32).to_le_bytes());
        } else {
            out.extend_from_slice(&(v.len() as u16).to_le_bytes());
        }
    } else {
        out.extend_from_slice(&(v.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(&v);
}

fn ds(v: &[f64]) -> Vec<u8> {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join("\\")
        .into_bytes()
}

/// Writes a DICOM Part 10 file: preamble, explicit-VR file meta, then the data set in the
/// slice's VR encoding, including an undefined-length sequence the reader must skip.
pub(crate) fn dicom(path: &Path, s: &DicomSlice) {
    let syntax: &[u8] = if s.explicit {
        b"1.2.840.10008.1.2.1"
    } else {
        b"1.2.840.10008.1.2"
    };
    let mut meta = Vec::new();
    element(&mut meta, true, (0x0002, 0x0001), b"OB", &[0, 1]);
    element(&mut meta, true, (0x0002, 0x0010), b"UI", syntax);
    let mut out = vec![0u8; 128];
    out.extend_from_slice(b"DICM");
    element(
        &mut out,
        true,
        (0x0002, 0x0000),
        b"UL",
        &(meta.len() as u32).to_le_bytes(),
    );
    out.extend_from_slice(&meta);

    let e = s.explicit;
    let mut d = Vec::new();
    element(&mut d, e, (0x0008, 0x0060), b"CS", b"CT");
    // (0008,1140) ReferencedImageSequence, undefined length, one undefined-length item.
    d.extend_from_slice(&[0x08, 0x00, 0x40, 0x11]);
    if e {
        d.extend_from_slice(b"SQ\0\0");
    }
    d.extend_from_slice(&u32::MAX.to_le_bytes());
    d.extend_from_slice(&[0xFE, 0xFF, 0x00, 0xE0]);
    d.extend_from_slice(&u32::MAX.to_le_bytes());
    element(&mut d, e, (0x0008, 0x1155), b"UI", b"1.2.3");
    d.extend_from_slice(&[0xFE, 0xFF, 0x0D, 0xE0, 0, 0, 0, 0]);
    d.extend_from_slice(&[0xFE, 0xFF, 0xDD, 0xE0, 0, 0, 0, 0]);
    if let Some(t) = s.thickness {
        element(&mut d, e, (0x0018, 0x0050), b"DS", &ds(&[t]));
    }
    element(&mut d, e, (0x0020, 0x000E), b"UI", s.series.as_bytes());
    if let Some(i) = s.instance {
        element(&mut d, e, (0x0020, 0x0013), b"IS", i.to_string().as_bytes());
    }
    if let Some(p) = s.position {
        element(&mut d, e, (0x0020, 0x0032), b"DS", &ds(&p));
    }
    if let Some(o) = s.orientation {
        element(&mut d, e, (0x0020, 0x0037), b"DS", &ds(&o));
    }
    element(&mut d, e, (0x0028, 0x0002), b"US", &1u16.to_le_bytes());
    element(&mut d, e, (0x0028, 0x0004), b"CS", b"MONOCHROME2");
    element(&mut d, e, (0x0028, 0x0010), b"US", &s.rows.to_le_bytes());
    element(&mut d, e, (0x0028, 0x0011), b"US", &s.cols.to_le_bytes());
    element(&mut d, e, (0x0028, 0x0030), b"DS", &ds(&s.pixel_spacing));
    let bits: u16 = if s.pixels8.is_some() { 8 } else { 16 };
    element(&mut d, e, (0x0028, 0x0100), b"US", &bits.to_le_bytes());
    element(
        &mut d,
        e,
        (0x0028, 0x0101),
        b"US",
        &s.bits_stored.to_le_bytes(),
    );
    element(
        &mut d,
        e,
        (0x0028, 0x0102),
        b"US",
        &(s.bits_stored - 1).to_le_bytes(),
    );
    element(
        &mut d,
        e,
        (0x0028, 0x0103),
        b"US",
        &u16::from(s.signed).to_le_bytes(),
    );
    element(&mut d, e, (0x0028, 0x1052), b"DS", &ds(&[s.rescale.1]));
    element(&mut d, e, (0x0028, 0x1053), b"DS", &ds(&[s.rescale.0]));
    let pixels: Vec<u8> = match (&s.pixels8, &s.pixels16) {
        (Some(p), _) => p.clone(),
        (None, Some(p)) => p.iter().flat_map(|x| x.to_le_bytes()).collect(),
        (None, None) => Vec::new(),
    };
    element(
        &mut d,
        e,
        (0x7FE0, 0x0010),
        if bits == 8 { b"OB" } else { b"OW" },
        &pixels,
    );
    out.extend_from_slice(&d);
    bytes(path, &out);
}

/// An OME-TIFF of uint8 pages `width`×`height`, `pages` in file order, with `xml` as
/// the first page's ImageDescription.
pub(crate) fn ome_tiff(path: &Path, width: u32, height: u32, pages: &[Vec<u8>], xml: &str) {
    use tiff::encoder::{colortype, TiffEncoder};
    let file = std::fs::File::create(path).expect("create tiff");
    let mut enc = TiffEncoder::new(std::io::BufWriter::new(file)).expect("tiff encoder");
    for (i, page) in pages.iter().enumerate() {
        let mut image = enc
            .new_image::<colortype::Gray8>(width, height)
            .expect("tiff page");
        if i == 0 {
            image
                .encoder()
                .write_tag(tiff::tags::Tag::ImageDescription, xml)
                .expect("description");
        }
        image.write_data(page).expect("tiff data");
    }
}
