//! `omero.channels` of an OME-Zarr image (0.4: the group's `omero`; 0.5: `ome.omero`):
//! each channel's `label`, `color` (hex `RRGGBB`) and `window` (`start`, `end`: a display
//! range in data units). Optional and transitional in the specification, so a missing
//! block is no channel metadata; a present one is checked, and a window that is not
//! finite (NaN written by a tool) is an error naming the channel.

use std::path::Path;

use serde_json::{Map, Value};

use super::malformed;
use crate::series::SourceChannel;
use crate::VolumeError;

/// Most channels read from the metadata: far more than any image has; past it the
/// list is not an image's.
const MAX_OMERO_CHANNELS: usize = 4096;

/// The channels `attributes` lists, in order (empty without an `omero` block).
pub(super) fn channels(
    group: &Path,
    attributes: &Map<String, Value>,
) -> Result<Vec<SourceChannel>, VolumeError> {
    let omero = attributes
        .get("omero")
        .or_else(|| attributes.get("ome").and_then(|o| o.get("omero")));
    let Some(list) = omero.and_then(|o| o.get("channels")) else {
        return Ok(Vec::new());
    };
    let Some(list) = list.as_array() else {
        return Err(malformed(group, "omero.channels", "is not a list"));
    };
    if list.len() > MAX_OMERO_CHANNELS {
        return Err(malformed(
            group,
            "omero.channels",
            format!("{} channels (at most {MAX_OMERO_CHANNELS})", list.len()),
        ));
    }
    list.iter()
        .enumerate()
        .map(|(i, c)| channel(group, i, c))
        .collect()
}

fn channel(group: &Path, i: usize, c: &Value) -> Result<SourceChannel, VolumeError> {
    let field = |name: &str| format!("omero.channels[{i}].{name}");
    let name = c
        .get("label")
        .and_then(Value::as_str)
        .map(str::to_string)
        .filter(|s| !s.is_empty());
    let colour =
        match c.get("color") {
            None | Some(Value::Null) => None,
            Some(v) => Some(v.as_str().and_then(hex_colour).ok_or_else(|| {
                malformed(group, &field("color"), format!("{v} is not RRGGBB hex"))
            })?),
        };
    let display_window = match c.get("window") {
        None | Some(Value::Null) => None,
        Some(w) => {
            let end = |key: &str| -> Result<f64, VolumeError> {
                let v = w.get(key).unwrap_or(&Value::Null);
                v.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                    malformed(
                        group,
                        &field(&format!("window.{key}")),
                        format!("{v} is not a finite number"),
                    )
                })
            };
            let (start, stop) = (end("start")?, end("end")?);
            if start > stop {
                return Err(malformed(
                    group,
                    &field("window"),
                    format!("start {start} is past end {stop}"),
                ));
            }
            Some([start, stop])
        }
    };
    Ok(SourceChannel {
        name,
        colour,
        display_window,
    })
}

/// `RRGGBB` (optionally after `#`) as RGB bytes.
fn hex_colour(s: &str) -> Option<[u8; 3]> {
    let s = s.trim().trim_start_matches('#');
    if s.len() != 6 || !s.is_ascii() {
        return None;
    }
    let byte = |i: usize| u8::from_str_radix(&s[i..i + 2], 16).ok();
    Some([byte(0)?, byte(2)?, byte(4)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_and_windows() {
        assert_eq!(hex_colour("FF8000"), Some([255, 128, 0]));
        assert_eq!(hex_colour("#00ff00"), Some([0, 255, 0]));
        assert_eq!(hex_colour("red"), None);
        let attrs: Map<String, Value> = serde_json::from_str(
            r#"{"omero": {"channels": [{"label": "DAPI", "color": "0000FF",
                "window": {"start": 10, "end": 200, "min": 0, "max": 255}}, {}]}}"#,
        )
        .unwrap();
        let c = channels(Path::new("img.zarr"), &attrs).unwrap();
        assert_eq!(c[0].name.as_deref(), Some("DAPI"));
        assert_eq!(c[0].colour, Some([0, 0, 255]));
        assert_eq!(c[0].display_window, Some([10.0, 200.0]));
        assert_eq!(c[1], SourceChannel::default());
        let bad: Map<String, Value> = serde_json::from_str(
            r#"{"ome": {"omero": {"channels": [{"window": {"start": "NaN", "end": 1}}]}}}"#,
        )
        .unwrap();
        let e = channels(Path::new("img.zarr"), &bad)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("img.zarr") && e.contains("omero.channels[0].window.start"),
            "{e}"
        );
    }
}
