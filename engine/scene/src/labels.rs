//! `[labels]` and `[[label]]`: a label map (a segmentation) beside the volume, and how
//! each label looks. `[labels]` names the map (an integer NIfTI, NRRD or OME-Zarr
//! `labels/` image; put on the volume's grid by nearest neighbour through the patient
//! transforms), optionally a label table (ITK-SNAP's label description file or 3D
//! Slicer's `.ctbl`) and the mode: `tint` (the intensity TF, coloured by each label,
//! hidden labels empty) or `solid` (only the labels, as solid tissue of their colour).
//! A `[[label]]` section sets one label's colour, opacity or visibility over the table;
//! labels neither names take a palette colour. Label 0 is "no label": in `tint` mode it
//! is the intensity TF untinted unless a section sets it; in `solid` mode it is empty.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};
use dvr_volume::labels::Look;

/// How labelled medium is shown.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LabelMode {
    /// The intensity TF inside every label, tinted by its colour; hidden labels empty.
    #[default]
    Tint,
    /// Only the labels, as solid tissue of their colour and opacity (no intensity TF).
    Solid,
}

/// `[labels]` as written: a file, or a built-in dataset's segmentation (`phantom`,
/// `mri`; its volume must be that dataset).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelsSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub builtin: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<PathBuf>,
    #[serde(default)]
    pub mode: LabelMode,
}

/// One `[[label]]` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelFile {
    pub value: u16,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, alias = "color", skip_serializing_if = "Option::is_none")]
    pub colour: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opacity: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible: Option<bool>,
}

/// One label of a view: what it is called and how it looks.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelView {
    pub value: u16,
    pub name: String,
    /// RGB in [0, 1]: tints the TF's colour inside the label (`solid`: the colour).
    pub colour: [f32; 3],
    /// In [0, 1]: scales the medium's extinction inside the label.
    pub opacity: f32,
    pub visible: bool,
}

impl LabelView {
    /// What the renderer's label look holds for this label.
    pub fn look(&self) -> Look {
        Look {
            colour: self.colour,
            opacity: self.opacity,
            visible: self.visible,
        }
    }

    /// This label with a section's fields over it.
    pub fn with(mut self, s: &LabelFile) -> Self {
        if let Some(n) = &s.name {
            self.name = n.clone();
        }
        if let Some(c) = s.colour {
            self.colour = c.map(|x| x as f32);
        }
        if let Some(o) = s.opacity {
            self.opacity = o as f32;
        }
        if let Some(v) = s.visible {
            self.visible = v;
        }
        self
    }
}

/// What "no label" (value 0) looks like in `mode` when no section sets it.
pub fn unlabelled(mode: LabelMode) -> LabelView {
    LabelView {
        value: 0,
        name: "no label".into(),
        colour: [1.0; 3],
        opacity: 1.0,
        visible: mode == LabelMode::Tint,
    }
}

/// The look of value `value` among `views` (sorted by value; label 0 as
/// [`unlabelled`] unless a view sets it).
pub fn look_of(views: &[LabelView], mode: LabelMode, value: u16) -> Look {
    match views.binary_search_by_key(&value, |v| v.value) {
        Ok(i) => views[i].look(),
        Err(_) if value == 0 => unlabelled(mode).look(),
        // A value no view names (none: the views are the map's labels).
        Err(_) => Look {
            colour: [1.0; 3],
            opacity: 1.0,
            visible: false,
        },
    }
}

impl LabelsSpec {
    /// Paths joined to the scene file's folder.
    pub(crate) fn resolve(mut self, ctx: &Ctx) -> Self {
        self.file = self.file.map(|f| ctx.resolve(&f));
        self.table = self.table.map(|t| ctx.resolve(&t));
        self
    }
}

pub(crate) fn check_sections(
    ctx: &Ctx,
    labels: Option<&LabelsSpec>,
    sections: &[LabelFile],
) -> Result<(), SceneError> {
    if let Some(l) = labels {
        if l.file.is_some() == l.builtin.is_some() {
            return Err(ctx.invalid(
                "labels",
                "give one of file = \"...\" (a label map) or builtin = \"phantom\" | \"mri\"",
            ));
        }
        if let Some(b) = &l.builtin {
            if !matches!(b.as_str(), "phantom" | "mri") {
                return Err(ctx.invalid(
                    "labels.builtin",
                    format!("{b:?} has no built-in labels (phantom, mri)"),
                ));
            }
        }
    }
    if labels.is_none() && !sections.is_empty() {
        return Err(ctx.invalid(
            "label",
            "[[label]] sections without a [labels] file = \"...\" to apply to",
        ));
    }
    for (i, s) in sections.iter().enumerate() {
        if let Some(j) = sections[..i].iter().position(|t| t.value == s.value) {
            return Err(ctx.invalid(
                format!("label[{i}].value"),
                format!("{} is set again (label[{j}] sets it)", s.value),
            ));
        }
        if let Some(c) = s.colour {
            if !c.iter().all(|x| (0.0..=1.0).contains(x)) {
                return Err(ctx.invalid(
                    format!("label[{i}].colour"),
                    format!("{c:?} must be in [0, 1] in every component"),
                ));
            }
        }
        if let Some(o) = s.opacity {
            if !(0.0..=1.0).contains(&o) {
                return Err(ctx.invalid(
                    format!("label[{i}].opacity"),
                    format!("{o} must be in [0, 1]"),
                ));
            }
        }
    }
    Ok(())
}
