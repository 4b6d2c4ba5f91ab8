//! OME-Zarr label images: an image's `labels/` group lists them (`"labels": [names]`);
//! each is a multiscales image of integers whose `image-label` block gives per label
//! value a colour (`colors`: `label-value`, `rgba` 0–255) and properties
//! (`properties`: `label-value` and any fields; a `name` or `label` names it). 0.4
//! keeps the blocks in `.zattrs`, 0.5 in `zarr.json`'s `attributes.ome`.

use std::path::{Path, PathBuf};

use serde_json::{Map, Value};

use super::{Label, LabelTable, PALETTE};
use crate::VolumeError;

/// A group's attributes (the OME block's for 0.5), or `None` where it has no metadata.
fn attributes(group: &Path) -> Result<Option<Map<String, Value>>, VolumeError> {
    let read = |file: &str| -> Result<Option<Value>, VolumeError> {
        let path = group.join(file);
        if !path.is_file() {
            return Ok(None);
        }
        let text = crate::files::read_text(&path, crate::files::MAX_TEXT_FILE_BYTES)
            .map_err(|e| bad(&path, "metadata", e.to_string()))?;
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| bad(&path, "metadata", format!("not JSON: {e}")))
    };
    if let Some(v) = read(".zattrs")? {
        return Ok(v.as_object().cloned());
    }
    Ok(read("zarr.json")?.and_then(|v| {
        let attrs = v.get("attributes")?;
        attrs.get("ome").or(Some(attrs))?.as_object().cloned()
    }))
}

fn bad(path: &Path, field: &str, problem: impl Into<String>) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.into(),
        problem: problem.into(),
    }
}

/// The first label image an OME-Zarr image's `labels/` group lists, if it has one.
pub fn first_label_image(image: &Path) -> Result<Option<PathBuf>, VolumeError> {
    let group = image.join("labels");
    let Some(attrs) = attributes(&group)? else {
        return Ok(None);
    };
    let Some(list) = attrs.get("labels") else {
        return Ok(None);
    };
    let name = list
        .as_array()
        .and_then(|l| l.first())
        .and_then(Value::as_str)
        .filter(|n| !n.is_empty() && !n.contains(['/', '\\']) && *n != "..")
        .ok_or_else(|| {
            bad(
                &group,
                "labels",
                format!("{list} is not a list of image names"),
            )
        })?;
    Ok(Some(group.join(name)))
}

/// The label table of an OME-Zarr label image's `image-label` block (`None` where the
/// group has none). A colour out of 0–255 or a value that is not a label is an error
/// naming the entry.
pub fn image_label_table(group: &Path) -> Result<Option<LabelTable>, VolumeError> {
    let Some(attrs) = attributes(group)? else {
        return Ok(None);
    };
    let Some(block) = attrs.get("image-label") else {
        return Ok(None);
    };
    let value_of = |field: &str, e: &Value| -> Result<u16, VolumeError> {
        e.get("label-value")
            .and_then(Value::as_u64)
            .and_then(|v| u16::try_from(v).ok())
            .ok_or_else(|| bad(group, field, "label-value must be an integer 0 to 65535"))
    };
    let list = |key: &str| -> Result<Vec<Value>, VolumeError> {
        match block.get(key) {
            None | Some(Value::Null) => Ok(Vec::new()),
            Some(Value::Array(a)) => Ok(a.clone()),
            Some(v) => Err(bad(
                group,
                &format!("image-label.{key}"),
                format!("{v} is not a list"),
            )),
        }
    };
    let mut labels: Vec<Label> = Vec::new();
    for (i, e) in list("colors")?.iter().enumerate() {
        let field = format!("image-label.colors[{i}]");
        let value = value_of(&field, e)?;
        let rgba = e
            .get("rgba")
            .and_then(Value::as_array)
            .filter(|c| c.len() == 4)
            .and_then(|c| {
                c.iter()
                    .map(|x| x.as_u64().filter(|&x| x <= 255))
                    .collect::<Option<Vec<_>>>()
            })
            .ok_or_else(|| {
                bad(
                    group,
                    &format!("{field}.rgba"),
                    "must be four integers 0 to 255",
                )
            })?;
        let unit = |x: u64| x as f32 / 255.0;
        labels.retain(|l| l.value != value);
        labels.push(Label {
            value,
            name: format!("label {value}"),
            colour: [unit(rgba[0]), unit(rgba[1]), unit(rgba[2])],
            opacity: unit(rgba[3]),
            visible: true,
        });
    }
    for (i, e) in list("properties")?.iter().enumerate() {
        let value = value_of(&format!("image-label.properties[{i}]"), e)?;
        let name = ["name", "label", "class"]
            .iter()
            .find_map(|k| e.get(*k).and_then(Value::as_str))
            .filter(|n| !n.is_empty());
        let Some(name) = name else { continue };
        match labels.iter_mut().find(|l| l.value == value) {
            Some(l) => l.name = name.to_string(),
            None => labels.push(Label {
                value,
                name: name.to_string(),
                colour: PALETTE[usize::from(value) % PALETTE.len()],
                opacity: 1.0,
                visible: true,
            }),
        }
    }
    labels.sort_by_key(|l| l.value);
    Ok(Some(LabelTable { labels }))
}
