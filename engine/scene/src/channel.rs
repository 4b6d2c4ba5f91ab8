//! `[[channel]]`: how each field of a multi-channel medium looks. The channels come from
//! `[volume]` (a file's C axis, picked with `channels = [..]`, or `files = [..]`, one
//! channel per file on the first file's grid); the sections give, in order, each
//! channel's TF, the data values that TF's 0–1 spans, a colour that tints it and
//! whether it is shown. A channel with no section takes `[transfer] a`, its window from
//! the file's metadata, the file's colour or white, and is shown.

use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};
use super::transfer_ref;
use crate::transfer::{ControlPoint, TfLut, TfUnits, TransferFunction};

/// Most channels one medium holds (the texel's four components).
pub const MAX_CHANNELS: usize = 4;

/// One `[[channel]]` section as written.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<[f64; 2]>,
    #[serde(default, alias = "color", skip_serializing_if = "Option::is_none")]
    pub colour: Option<[f64; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible: Option<bool>,
}

/// A `[[channel]]` section, its TF loaded (paths joined to the scene file's folder).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSpec {
    pub file: ChannelFile,
    /// The TF `transfer` names, if it names one.
    pub tf: Option<TransferFunction>,
}

impl ChannelSpec {
    pub(crate) fn resolve(files: Vec<ChannelFile>, ctx: &Ctx) -> Result<Vec<Self>, SceneError> {
        if files.len() > MAX_CHANNELS {
            return Err(ctx.invalid(
                "channel",
                format!(
                    "{} [[channel]] sections; a medium holds at most {MAX_CHANNELS} channels",
                    files.len()
                ),
            ));
        }
        files
            .into_iter()
            .enumerate()
            .map(|(i, mut file)| {
                let field = format!("channel[{i}].transfer");
                let tf = match &file.transfer {
                    Some(spec) => {
                        let (resolved, tf) = transfer_ref::resolve_one(ctx, &field, spec)?;
                        file.transfer = Some(resolved);
                        Some(tf)
                    }
                    None => None,
                };
                let spec = Self { file, tf };
                spec.check(ctx, i)?;
                Ok(spec)
            })
            .collect()
    }

    fn check(&self, ctx: &Ctx, i: usize) -> Result<(), SceneError> {
        if let Some([lo, hi]) = self.file.window {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(ctx.invalid(
                    format!("channel[{i}].window"),
                    format!("[{lo}, {hi}] must be two finite data values, low < high"),
                ));
            }
        }
        if let Some(c) = self.file.colour {
            let c = glam::DVec3::from(c);
            if !(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0) {
                return Err(ctx.invalid(
                    format!("channel[{i}].colour"),
                    format!("{c} must be in [0, 1] in every component"),
                ));
            }
        }
        Ok(())
    }
}

/// One channel of a view: its TF as written (over `window`, or in data units), the
/// colour that tints it and whether it is shown. Channel 0's TF in effect is the view's
/// own ([`super::View::tf`], which animations blend and shift, set from this one).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelView {
    pub name: String,
    pub tf: TransferFunction,
    /// The data values the TF's 0–1 spans.
    pub window: [f32; 2],
    /// The data values at the channel's density 0 and 1 (fixed by its data).
    pub data_window: [f32; 2],
    pub colour: [f32; 3],
    pub visible: bool,
}

impl ChannelView {
    /// The TF over this channel's normalised density.
    pub fn density_tf(&self) -> TransferFunction {
        over_window(&self.tf, self.window, self.data_window)
    }

    /// This channel's LUT segment from its TF's LUT: diffuse and emissive tinted by the
    /// colour, and no opacity (empty medium) when hidden.
    pub fn apply(&self, mut lut: TfLut) -> TfLut {
        let [r, g, b] = self.colour;
        for (d, e) in lut.diffuse_opacity.iter_mut().zip(&mut lut.emissive) {
            d[0] *= r;
            d[1] *= g;
            d[2] *= b;
            e[0] *= r;
            e[1] *= g;
            e[2] *= b;
            if !self.visible {
                d[3] = 0.0;
                *e = [0.0; 4];
            }
        }
        lut
    }
}

/// The LUTs of a medium: one channel's as they are, several one after another (channel
/// c's TF is the c-th segment, include/volume.glsl). `view` is the view's TF's LUT:
/// channel 0's.
pub fn medium_lut(view: TfLut, channels: &[ChannelView]) -> TfLut {
    let Some(c0) = channels.first() else {
        return view;
    };
    let mut out = c0.apply(view);
    for c in &channels[1..] {
        let seg = c.apply(c.density_tf().lut());
        out.diffuse_opacity.extend(seg.diffuse_opacity);
        out.specular_roughness.extend(seg.specular_roughness);
        out.emissive.extend(seg.emissive);
    }
    out
}

/// The TF over a channel's normalised density when its 0–1 is to span the data values
/// `window` and the channel's density 0–1 is the data values `data_window`: the TF's
/// points are placed in data units and brought back through the data window. A TF
/// already in data units ignores `window`.
pub fn over_window(
    tf: &TransferFunction,
    window: [f32; 2],
    data_window: [f32; 2],
) -> TransferFunction {
    if tf.units == TfUnits::Data {
        return tf.in_density(data_window);
    }
    let [lo, hi] = window;
    let in_data = TransferFunction {
        name: tf.name.clone(),
        points: tf
            .points
            .iter()
            .map(|p| ControlPoint {
                density: lo + p.density * (hi - lo),
                ..*p
            })
            .collect(),
        units: TfUnits::Data,
    };
    in_data.in_density(data_window)
}
