//! OME-TIFF z-stacks (and plain multi-page TIFF stacks), read through the `tiff` crate.
//!
//! An OME-TIFF's first page holds OME-XML in its ImageDescription: the `Pixels` element
//! gives the sizes (SizeX/Y/Z/C/T), the order the pages run in (DimensionOrder, e.g.
//! XYZCT: z fastest) and the voxel size (PhysicalSizeX/Y/Z, in µm unless a unit is
//! given). The volume is channel 0 at time 0, with a warning when there are more. A TIFF
//! without OME-XML is a stack of its pages, one z slice each, with 1 mm voxels (the log
//! says so). Pages are one grey sample each (uint8, uint16, int16, float32), all the
//! same size; the full-resolution series is read (sub-resolution pages are not).

use super::error::VolumeError;
use super::samples::{Samples, Stored};
use super::{io, name_of, validate_dims, Volume};
use std::path::Path;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;

/// What the OME-XML says about the pixels.
struct Pixels {
    size: [u64; 3],
    channels: u64,
    times: u64,
    /// Pages between consecutive z slices (the sizes of the dimensions that run faster).
    z_stride: u64,
    spacing_mm: [f64; 3],
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
    let mut z_stride = 1;
    for d in order[2..].chars().take_while(|&d| d != 'Z') {
        z_stride *= if d == 'C' { c } else { t };
    }
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
        spacing_mm,
    })
}

pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let (file, _) = io::open_regular(path)?;
    let bad = |e: tiff::TiffError| malformed(path, "TIFF", e.to_string());
    let mut decoder = Decoder::new(std::io::BufReader::new(file))
        .map_err(bad)?
        .with_limits(Limits::unlimited());
    let description = decoder.get_tag_ascii_string(Tag::ImageDescription).ok();
    let ome = description
        .as_deref()
        .filter(|d| d.contains("<OME") || d.contains(":OME"));
    let (pixels, pages) = match ome {
        Some(xml) => {
            let p = parse_pixels(path, xml)?;
            if p.channels > 1 || p.times > 1 {
                log::warn!(
                    "{}: {} channel(s) × {} time point(s); rendering channel 0 at time 0",
                    path.display(),
                    p.channels,
                    p.times
                );
            }
            let pages: Vec<u64> = (0..p.size[2]).map(|z| z * p.z_stride).collect();
            (Some(p), pages)
        }
        None => {
            log::info!(
                "{}: no OME-XML; reading its pages as z slices of 1 mm voxels",
                path.display()
            );
            (None, Vec::new())
        }
    };
    let (width, height) = decoder.dimensions().map_err(bad)?;
    if let Some(p) = &pixels {
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
        let wanted = pixels.is_none() || pages.contains(&page);
        if wanted {
            if decoder.dimensions().map_err(bad)? != (width, height) {
                return Err(malformed(
                    path,
                    "pages",
                    format!("page {page} is not {width}x{height} like the first"),
                ));
            }
            let colour = decoder.colortype().map_err(bad)?;
            if !matches!(colour, tiff::ColorType::Gray(_)) {
                return Err(VolumeError::UnsupportedType {
                    path: path.to_path_buf(),
                    datatype: format!("{colour:?} pages"),
                    supported: "one grey sample per pixel: uint8, uint16, int16, float32",
                });
            }
            slices.push(decoder.read_image().map_err(bad)?);
            validate_dims(
                path,
                [i64::from(width), i64::from(height), slices.len() as i64],
            )?;
        }
        let done = pixels.is_some() && slices.len() == pages.len();
        if done || !decoder.more_images() {
            break;
        }
        decoder.next_image().map_err(bad)?;
        page += 1;
    }
    if let Some(p) = &pixels {
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
    let spacing = pixels.map_or([1.0; 3], |p| p.spacing_mm).map(|s| s as f32);
    Volume::from_stored(
        path,
        name_of(path).trim_end_matches(".ome").to_string(),
        dims,
        spacing,
        Stored::plain(samples),
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
}
