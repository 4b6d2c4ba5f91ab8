//! A scene's medium from its `[volume]` section: one field (a built-in dataset or a
//! file's first channel, loaded as ever), or the channels of a series (a file's C axis,
//! or `files`, one channel per file on the first file's grid), with each channel's view
//! from its `[[channel]]` section and the file's metadata.

use crate::scene::{ChannelView, Scene, VolumeSource};
use crate::volume::{Series, Volume, VolumeError};
use std::sync::Arc;

/// The loaded channels of a multi-channel medium, with what the file says of each.
pub struct Channels {
    pub volumes: Vec<Volume>,
    pub series: Arc<Series>,
}

impl Channels {
    /// A series' channels at time point 0.
    pub fn of(series: Arc<Series>) -> Result<Self, VolumeError> {
        let volumes = series.read(0)?;
        Ok(Self { volumes, series })
    }
}

/// The scene's channels at time point 0 when its volume has several channels or time
/// points (or the scene picks channels, or gives `[[channel]]` sections): `None` for one
/// field at one time, which loads as a single volume.
pub fn load_channels(scene: &Scene) -> Result<Option<Channels>, VolumeError> {
    let picked = scene.volume.channels.as_deref();
    let series = match &scene.volume.source {
        VolumeSource::Builtin { .. } | VolumeSource::File { raw: Some(_), .. } => return Ok(None),
        VolumeSource::Files { paths } => Series::open_channels(paths, picked)?,
        VolumeSource::File { path, raw: None } => {
            let series = Series::open(path, picked)?;
            let info = series.info();
            // `[[channel]]` sections (a colour, a window) apply to one channel too.
            if picked.is_none()
                && scene.channels.is_empty()
                && info.channels.len() == 1
                && info.times == 1
            {
                return Ok(None);
            }
            series
        }
    };
    Channels::of(Arc::new(series)).map(Some)
}

/// Each channel's view as the scene starts: its `[[channel]]` TF (else `[transfer] a`)
/// over its window (the section's, else the file's display window, else the channel's
/// data range), its colour (the section's, the file's, or white) and visibility.
pub fn channel_views(scene: &Scene, channels: &Channels) -> Vec<ChannelView> {
    let info = channels.series.info();
    channels
        .volumes
        .iter()
        .zip(&info.channels)
        .enumerate()
        .map(|(i, (v, meta))| {
            let spec = scene.channels.get(i);
            let f32s = |[lo, hi]: [f64; 2]| [lo as f32, hi as f32];
            ChannelView {
                name: meta.name.clone(),
                tf: spec
                    .and_then(|s| s.tf.clone())
                    .unwrap_or_else(|| scene.tf_a.clone()),
                window: spec
                    .and_then(|s| s.file.window)
                    .or(meta.display_window)
                    .map_or(v.window, f32s),
                data_window: v.window,
                colour: spec
                    .and_then(|s| s.file.colour)
                    .map(|c| c.map(|x| x as f32))
                    .or(meta.colour.map(|c| c.map(|x| f32::from(x) / 255.0)))
                    .unwrap_or([1.0; 3]),
                visible: spec.and_then(|s| s.file.visible).unwrap_or(true),
            }
        })
        .collect()
}
