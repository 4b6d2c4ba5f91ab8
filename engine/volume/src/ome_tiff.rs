//! OME-TIFF z-stacks (and plain multi-page TIFF stacks), read through the `tiff` crate.
//!
//! An OME-TIFF's first page holds OME-XML in its ImageDescription: the `Pixels` element
//! gives the sizes (SizeX/Y/Z/C/T), the order the pages run in (DimensionOrder, e.g.
//! XYZCT: z fastest) and the voxel size (PhysicalSizeX/Y/Z, in µm unless a unit is
//! given). The volume is channel 0 at time 0, with a warning when there are more. A TIFF
//! without OME-XML is a stack of its pages, one z slice each, with 1 mm voxels (the log
//! says so). Pages are one grey sample each (uint8, uint16, int16, float32), all the
//! same size; the full-resolution series is read (sub-resolution pages are not).
//!
//! Reads are bounded by the volume the file describes: the OME-XML's sizes and each
//! page's size and sample type are checked against the volume limits before any pixel
//! is decoded, and the `tiff` crate decodes at most one page of [`MAX_PAGE_BYTES`] at a
//! time (tag values and compressed strips bounded likewise).

use super::error::VolumeError;
use super::samples::{Samples, Stored};
use super::series::{channel_list, Source, SourceChannel, SourceInfo, Window, Windowed};
use super::{io, name_of, validate_dims, validate_spacing, Volume, MAX_DIM};
use std::path::Path;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

/// Largest page decoded: `MAX_DIM`² samples of 4 bytes (float32), 64 MiB. Also the
/// largest tag value (the OME-XML) read.
pub const MAX_PAGE_BYTES: usize = (MAX_DIM as usize) * (MAX_DIM as usize) * 4;

/// Largest compressed strip or tile read: a page's worth, and as much again for codecs
/// that grow incompressible data.
pub const MAX_CHUNK_BYTES: usize = 2 * MAX_PAGE_BYTES;

/// What the OME-XML says about the pixels.
struct Pixels {
    size: [u64; 3],
    channels: u64,
    times: u64,
    /// Pages between consecutive z slices (the sizes of the dimensions that run faster).
    z_stride: u64,
    /// Pages between consecutive channels, and time points.
    c_stride: u64,
    t_stride: u64,
    spacing_mm: [f64; 3],
    /// The `Channel` elements' `Name` and `Color`, in order.
    channel_meta: Vec<SourceChannel>,
}

impl Pixels {
    /// The page of z slice 0 of channel `c` at time point `t`.
    fn first_page(&self, c: u64, t: u64) -> u64 {
        c.saturating_mul(self.c_stride)
            .saturating_add(t.saturating_mul(self.t_stride))
    }
}

fn malformed(path: &Path, field: &str, problem: impl Into<String>) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.into(),
        problem: problem.into(),
    }
}

/// The value of attribute `name` in the XML start tag `tag` (`<Pixels a="1" …>`).
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let mut rest = tag;
    while let Some(i) = rest.find(name) {
        let before = rest[..i].chars().last();
        let after = &rest[i + name.len()..];
        let value = after.trim_start().strip_prefix('=').map(str::trim_start);
        if before.is_some_and(char::is_whitespace) {
            if let Some(v) = value.and_then(|v| v.strip_prefix('"')) {
                return v.split('"').next();
            }
        }
        rest = after;
    }
    None
}

fn millimetres_per(unit: &str) -> Option<f64> {
    Some(match unit {
        "µm" | "\u{3bc}m" | "um" | "micrometer" => 1e-3,
        "nm" | "nanometer" => 1e-6,
        "Å" | "angstrom" => 1e-7,
        "mm" | "millimeter" => 1.0,
        "cm" | "centimeter" => 10.0,
        "m" | "meter" => 1e3,
        _ => return None,
    })
}

fn parse_pixels(path: &Path, xml: &str) -> Result<Pixels, VolumeError> {
    let start = xml
        .find("<Pixels")
        .or_else(|| xml.find(":Pixels"))
        .ok_or_else(|| malformed(path, "OME-XML", "no Pixels element"))?;
    let tag = &xml[start..start + xml[start..].find('>').unwrap_or(xml.len() - start)];
    let size = |name: &str| -> Result<u64, VolumeError> {
        match attribute(tag, name) {
            None => Ok(1),
            Some(v) => v
                .parse::<u64>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| malformed(path, name, format!("{v:?} is not a size"))),
        }
    };
    let (x, y, z, c, t) = (
        size("SizeX")?,
        size("SizeY")?,
        size("SizeZ")?,
        size("SizeC")?,
        size("SizeT")?,
    );
    let order = attribute(tag, "DimensionOrder").unwrap_or("XYZCT");
    if order.len() != 5
        || !order.starts_with("XY")
        || !"ZCT".chars().all(|d| order[2..].contains(d))
    {
        return Err(malformed(
            path,
            "DimensionOrder",
            format!("{order:?} is not XY followed by Z, C and T"),
        ));
    }
    // Checked before anything is allocated for the pages they describe.
    validate_dims(
        path,
        [x, y, z].map(|n| i64::try_from(n).unwrap_or(i64::MAX)),
    )?;
    // Each dimension's page stride: the product of the sizes of those that run faster.
    let mut strides = [1u64; 3];
    let mut stride = 1u64;
    for d in order[2..].chars() {
        let i = "ZCT".find(d).unwrap_or(0);
        strides[i] = stride;
        stride = stride.checked_mul([z, c, t][i]).ok_or_else(|| {
            malformed(
                path,
                "SizeC/SizeT",
                format!(
                    "{z} slices × {c} channels × {t} time points: more pages than a TIFF holds"
                ),
            )
        })?;
    }
    let [z_stride, c_stride, t_stride] = strides;
    let mut spacing_mm = [1.0; 3];
    for (i, axis) in ["X", "Y", "Z"].iter().enumerate() {
        let value = attribute(tag, &format!("PhysicalSize{axis}"));
        let unit = attribute(tag, &format!("PhysicalSize{axis}Unit")).unwrap_or("µm");
        if let Some(v) = value {
            let v: f64 = v
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite() && *v > 0.0)
                .ok_or_else(|| {
                    malformed(
                        path,
                        &format!("PhysicalSize{axis}"),
                        format!("{v:?} is not a positive size"),
                    )
                })?;
            let mm = millimetres_per(unit).ok_or_else(|| {
                malformed(
                    path,
                    &format!("PhysicalSize{axis}Unit"),
                    format!("{unit:?} is not a length unit dvr knows"),
                )
            })?;
            spacing_mm[i] = v * mm;
        }
    }
    Ok(Pixels {
        size: [x, y, z],
        channels: c,
        times: t,
        z_stride,
        c_stride,
        t_stride,
        spacing_mm,
        channel_meta: channel_meta(xml),
    })
}

/// `Name` and `Color` of each `Channel` element (OME's `Color` is a signed 32-bit RGBA).
fn channel_meta(xml: &str) -> Vec<SourceChannel> {
    let mut out = Vec::new();
    let mut rest = xml;
    while let Some(i) = rest.find("Channel") {
        let before = rest[..i].chars().last();
        let tail = &rest[i..];
        let end = tail.find('>').unwrap_or(tail.len());
        let is_element = matches!(before, Some('<') | Some(':'))
            && tail[7..].starts_with(|ch: char| ch.is_whitespace() || ch == '/' || ch == '>');
        if is_element {
            let tag = &tail[..end];
            let colour = attribute(tag, "Color")
                .and_then(|c| c.parse::<i64>().ok())
                .map(|c| {
                    let rgba = c as u32;
                    [(rgba >> 24) as u8, (rgba >> 16) as u8, (rgba >> 8) as u8]
                });
            out.push(SourceChannel {
                name: attribute(tag, "Name").map(str::to_string),
                colour,
                display_window: None,
            });
            if out.len() >= 4096 {
                break;
            }
        }
        rest = &tail[end.max(1)..];
    }
    out
}

pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let pixels = read_pixels(path)?;
    if let Some(p) = &pixels {
        if p.channels > 1 || p.times > 1 {
            log::warn!(
                "{}: {} channel(s) × {} time point(s); rendering channel 0 at time 0 (open it \
                 as a series for the others: `dvr info`)",
                path.display(),
                p.channels,
                p.times
            );
        }
    }
    read_stack(path, pixels.as_ref(), 0, 0, None).map(|(v, _)| v)
}

/// Opens an OME-TIFF as a series of `SizeC` channels at `SizeT` time points (a plain
/// stack is one of each).
pub(crate) fn open_series(path: &Path) -> Result<Box<dyn Source>, VolumeError> {
    let pixels = read_pixels(path)?;
    let (dims, channels, times) = match &pixels {
        Some(p) => {
            let dims = validate_dims(path, p.size.map(|n| i64::try_from(n).unwrap_or(i64::MAX)))?;
            let meta = channel_list(path, p.channels, p.channel_meta.clone())?;
            (dims, meta, usize::try_from(p.times).unwrap_or(usize::MAX))
        }
        // A plain stack: its page count is known only once read.
        None => {
            let (v, _) = read_stack(path, None, 0, 0, None)?;
            (v.dims, vec![SourceChannel::default()], 1)
        }
    };
    let info = SourceInfo {
        path: path.to_path_buf(),
        name: name_of(path).trim_end_matches(".ome").to_string(),
        dims,
        orientation: None,
        channels,
        times,
    };
    Ok(Box::new(TiffSeries { info, pixels }))
}

struct TiffSeries {
    info: SourceInfo,
    pixels: Option<Pixels>,
}

impl Source for TiffSeries {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed {
        read_stack(
            &self.info.path,
            self.pixels.as_ref(),
            channel as u64,
            time as u64,
            window,
        )
    }
}

fn tiff_error(path: &Path, e: tiff::TiffError) -> VolumeError {
    match e {
        tiff::TiffError::LimitsExceeded => malformed(
            path,
            "TIFF",
            format!(
                "a tag value, strip or page of more than {MAX_PAGE_BYTES} bytes (a {MAX_DIM}x{MAX_DIM} \
                 float32 page), refused before it is read"
            ),
        ),
        e => malformed(path, "TIFF", e.to_string()),
    }
}

fn decoder(path: &Path) -> Result<Decoder<std::io::BufReader<std::fs::File>>, VolumeError> {
    let (file, _) = io::open_regular(path)?;
    let mut limits = Limits::default();
    limits.decoding_buffer_size = MAX_PAGE_BYTES;
    limits.intermediate_buffer_size = MAX_CHUNK_BYTES;
    Ok(Decoder::new(std::io::BufReader::new(file))
        .map_err(|e| tiff_error(path, e))?
        .with_limits(limits))
}

/// The OME-XML's pixels, `None` for a plain TIFF.
fn read_pixels(path: &Path) -> Result<Option<Pixels>, VolumeError> {
    let mut decoder = decoder(path)?;
    let description = decoder.get_tag_ascii_string(Tag::ImageDescription).ok();
    let ome = description
        .as_deref()
        .filter(|d| d.contains("<OME") || d.contains(":OME"));
    match ome {
        Some(xml) => parse_pixels(path, xml).map(Some),
        None => {
            log::info!(
                "{}: no OME-XML; reading its pages as z slices of 1 mm voxels",
                path.display()
            );
            Ok(None)
        }
    }
}

/// The z stack of channel `c` at time point `t` (a plain TIFF: all its pages),
/// normalised through `window` where given.
fn read_stack(
    path: &Path,
    pixels: Option<&Pixels>,
    c: u64,
    t: u64,
    window: Option<(f64, f64)>,
) -> Result<(Volume, (f64, f64)), VolumeError> {
    let bad = |e: tiff::TiffError| tiff_error(path, e);
    let mut decoder = decoder(path)?;
    if let Some(p) = pixels {
        if c >= p.channels || t >= p.times {
            return Err(malformed(
                path,
                "SizeC/SizeT",
                format!(
                    "channel {c} at time point {t} is past the {} channel(s) × {} time point(s)",
                    p.channels, p.times
                ),
            ));
        }
    }
    // Page `page` is a z slice: every page of a plain stack; of an OME-TIFF, the pages
    // `first + z * z_stride` of channel c at time point t.
    let first = pixels.map_or(0, |p| p.first_page(c, t));
    let wanted = |page: u64| match pixels {
        None => true,
        Some(p) => {
            page >= first
                && (page - first).is_multiple_of(p.z_stride)
                && (page - first) / p.z_stride < p.size[2]
        }
    };
    let (width, height) = decoder.dimensions().map_err(bad)?;
    if let Some(p) = pixels {
        if (u64::from(width), u64::from(height)) != (p.size[0], p.size[1]) {
            return Err(malformed(
                path,
                "SizeX/SizeY",
                format!(
                    "the OME-XML says {}x{}, the first page is {width}x{height}",
                    p.size[0], p.size[1]
                ),
            ));
        }
    }
    let mut slices: Vec<DecodingResult> = Vec::new();
    let mut page = 0u64;
    loop {
        if wanted(page) {
            if decoder.dimensions().map_err(bad)? != (width, height) {
                return Err(malformed(
                    path,
                    "pages",
                    format!("page {page} is not {width}x{height} like the first"),
                ));
            }
            let colour = decoder.colortype().map_err(bad)?;
            if !matches!(colour, tiff::ColorType::Gray(8 | 16 | 32)) {
                return Err(VolumeError::UnsupportedType {
                    path: path.to_path_buf(),
                    datatype: format!("{colour:?} pages"),
                    supported: "one grey sample per pixel: uint8, uint16, int16, float32",
                });
            }
            // The volume with this page, checked before the page is decoded.
            validate_dims(
                path,
                [i64::from(width), i64::from(height), slices.len() as i64 + 1],
            )?;
            slices.push(decoder.read_image().map_err(bad)?);
        }
        let done = pixels.is_some_and(|p| slices.len() as u64 == p.size[2]);
        if done || !decoder.more_images() {
            break;
        }
        decoder.next_image().map_err(bad)?;
        page += 1;
    }
    if let Some(p) = pixels {
        if slices.len() as u64 != p.size[2] {
            return Err(VolumeError::Truncated {
                path: path.to_path_buf(),
                expected: p.size[2],
                found: slices.len() as u64,
            });
        }
    }
    let depth = slices.len() as i64;
    let dims = validate_dims(path, [i64::from(width), i64::from(height), depth])?;
    let samples = join(path, slices)?;
    let spacing = validate_spacing(
        path,
        "PhysicalSizeX/Y/Z",
        pixels.map_or([1.0; 3], |p| p.spacing_mm),
    )?;
    Volume::from_stored_in(
        path,
        name_of(path).trim_end_matches(".ome").to_string(),
        dims,
        spacing,
        Stored::plain(samples),
        window,
    )
}

/// The slices, in order, as one array of one sample type.
fn join(path: &Path, slices: Vec<DecodingResult>) -> Result<Samples, VolumeError> {
    let mut out: Option<Samples> = None;
    for s in slices {
        match (&mut out, s) {
            (None, DecodingResult::U8(v)) => out = Some(Samples::U8(v)),
            (None, DecodingResult::U16(v)) => out = Some(Samples::U16(v)),
            (None, DecodingResult::I16(v)) => out = Some(Samples::I16(v)),
            (None, DecodingResult::F32(v)) => out = Some(Samples::F32(v)),
            (Some(Samples::U8(a)), DecodingResult::U8(v)) => a.extend(v),
            (Some(Samples::U16(a)), DecodingResult::U16(v)) => a.extend(v),
            (Some(Samples::I16(a)), DecodingResult::I16(v)) => a.extend(v),
            (Some(Samples::F32(a)), DecodingResult::F32(v)) => a.extend(v),
            (_, other) => {
                return Err(VolumeError::UnsupportedType {
                    path: path.to_path_buf(),
                    datatype: format!("{} pages", sample_name(&other)),
                    supported: "uint8, uint16, int16, float32, the same on every page",
                })
            }
        }
    }
    out.ok_or_else(|| malformed(path, "pages", "the file holds no page"))
}

fn sample_name(r: &DecodingResult) -> &'static str {
    match r {
        DecodingResult::U8(_) => "uint8",
        DecodingResult::U16(_) => "uint16",
        DecodingResult::I16(_) => "int16",
        DecodingResult::F32(_) => "float32",
        DecodingResult::U32(_) => "uint32",
        DecodingResult::U64(_) => "uint64",
        DecodingResult::I8(_) => "int8",
        DecodingResult::I32(_) => "int32",
        DecodingResult::I64(_) => "int64",
        DecodingResult::F64(_) => "float64",
        _ => "other",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_attributes_and_page_order() {
        let xml = r#"<OME><Image><Pixels ID="Pixels:0" DimensionOrder="XYCZT" Type="uint16"
            SizeX="32" SizeY="24" SizeZ="20" SizeC="3" SizeT="1" PhysicalSizeX="0.25"
            PhysicalSizeY="0.5" PhysicalSizeZ="2" PhysicalSizeZUnit="mm"><Channel/></Pixels></Image></OME>"#;
        let p = parse_pixels(Path::new("x.ome.tif"), xml).unwrap();
        assert_eq!(p.size, [32, 24, 20]);
        assert_eq!(p.z_stride, 3, "channels run faster than z");
        assert_eq!(p.spacing_mm, [0.25e-3, 0.5e-3, 2.0]);
        let bad = xml.replace("XYCZT", "XYZZT");
        let e = parse_pixels(Path::new("x.ome.tif"), &bad)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("DimensionOrder") && e.contains("x.ome.tif"),
            "{e}"
        );
        let unit = xml.replace("\"mm\"", "\"furlong\"");
        let e = parse_pixels(Path::new("x.ome.tif"), &unit)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("furlong"), "{e}");
        assert_eq!(attribute(r#"<P aSizeX="1" SizeX="7">"#, "SizeX"), Some("7"));
    }

    /// A little-endian TIFF of one uint8 page `width`×`height` with `description`, whose
    /// one strip claims `strip_bytes` bytes and holds 16.
    fn tiff(width: u32, height: u32, description: &str, strip_bytes: u32) -> Vec<u8> {
        let desc = [description.as_bytes(), b"\0"].concat();
        let tags: [(u16, u16, u32); 10] = [
            (256, 4, width),
            (257, 4, height),
            (258, 3, 8),
            (259, 3, 1),
            (262, 3, 1),
            (270, 2, 0),
            (273, 4, 0),
            (277, 3, 1),
            (278, 4, height),
            (279, 4, strip_bytes),
        ];
        let desc_at = 8 + 2 + 12 * tags.len() as u32 + 4;
        let strip_at = desc_at + desc.len() as u32;
        let mut out = b"II*\0\x08\0\0\0".to_vec();
        out.extend((tags.len() as u16).to_le_bytes());
        for (tag, kind, value) in tags {
            let count = if tag == 270 { desc.len() as u32 } else { 1 };
            let value = match tag {
                270 => desc_at,
                273 => strip_at,
                _ => value,
            };
            out.extend(tag.to_le_bytes());
            out.extend(kind.to_le_bytes());
            out.extend(count.to_le_bytes());
            out.extend(value.to_le_bytes());
        }
        out.extend(0u32.to_le_bytes());
        out.extend(desc);
        out.extend([0; 16]);
        out
    }

    fn load_error(dir: &Path, bytes: &[u8]) -> String {
        let path = dir.join("x.ome.tif");
        std::fs::write(&path, bytes).unwrap();
        crate::load_within_seconds(&path, 20)
            .unwrap_err()
            .to_string()
    }

    fn ome(sizes: &str) -> String {
        format!(r#"<OME><Image><Pixels DimensionOrder="XYZCT" {sizes}/></Image></OME>"#)
    }

    #[test]
    fn sizes_are_checked_before_pages_are_listed_or_decoded() {
        let dir = tempfile::tempdir().unwrap();
        // SizeZ of 10^12: the list of pages to read took 8 TB.
        let e = load_error(
            dir.path(),
            &tiff(
                2,
                2,
                &ome(r#"SizeX="2" SizeY="2" SizeZ="1000000000000""#),
                4,
            ),
        );
        assert!(
            e.contains("x.ome.tif") && e.contains("1000000000000") && e.contains("4096"),
            "{e}"
        );
        // Channels × time points before z overflowing u64 (this panicked).
        let xml =
            ome(r#"SizeX="2" SizeY="2" SizeZ="4" SizeC="1099511627776" SizeT="1099511627776""#)
                .replace("XYZCT", "XYCTZ");
        let e = load_error(dir.path(), &tiff(2, 2, &xml, 4));
        assert!(e.contains("SizeC/SizeT"), "{e}");
        // A 65535² page claiming 4 GiB: refused before the tiff crate allocates it.
        let e = load_error(dir.path(), &tiff(65535, 65535, "a stack", u32::MAX));
        assert!(e.contains("65535") && e.contains("exceeds 4096"), "{e}");
        // A tag of 2^30 values (StripOffsets), which the tiff crate allocated (32 GiB) with
        // no limits set: found by the fuzzer.
        let mut file = tiff(4, 4, "a stack", 16);
        file[86..90].copy_from_slice(&0x4000_0000u32.to_le_bytes());
        let e = load_error(dir.path(), &file);
        assert!(
            e.contains("x.ome.tif") && e.contains("refused before it is read"),
            "{e}"
        );
        // A voxel size past the spacing limits.
        let xml = ome(r#"SizeX="4" SizeY="4" SizeZ="1" PhysicalSizeX="1e-12""#);
        let e = load_error(dir.path(), &tiff(4, 4, &xml, 16));
        assert!(e.contains("PhysicalSize") && e.contains("spacing"), "{e}");
    }
}
