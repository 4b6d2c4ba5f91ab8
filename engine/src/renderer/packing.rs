//! Channels packed into one texture: a medium of 2–4 fields on one grid is one volume
//! upload whose texels hold every channel's density (RG, or RGBA with a zero fourth for
//! three), so one fetch serves all of them. The common sample type is the widest of the
//! channels' (8-bit channels widen exactly: v · 257 / 65535 = v / 255).

use super::uploads::{BrickRanges, ChannelUpload, VolumeFormat, VolumeUpload};
use crate::volume::{Volume, VolumeData};

// The scene's own limit, so a scene refuses what the device cannot hold.
pub use crate::shaders::frame::MAX_CHANNELS;

/// Texel components for `channels` fields: RG for two, RGBA for three or four.
pub fn components(channels: u32) -> u32 {
    match channels {
        0 | 1 => 1,
        2 => 2,
        _ => 4,
    }
}

impl VolumeUpload {
    /// Channels of one grid as one upload: channel 0's name, spacing and window are the
    /// volume's; each later channel keeps its own window and brick ranges. Errors name
    /// the channel whose grid differs, or say how many channels there are past
    /// [`MAX_CHANNELS`].
    pub fn from_channels(channels: &[Volume]) -> Result<Self, String> {
        let Some(first) = channels.first() else {
            return Err("a volume needs at least one channel".into());
        };
        if channels.len() > MAX_CHANNELS {
            return Err(format!(
                "{} channels; a medium holds at most {MAX_CHANNELS} (pick some, e.g. channels = [0, 2])",
                channels.len()
            ));
        }
        for (i, c) in channels.iter().enumerate().skip(1) {
            if c.dims != first.dims {
                return Err(format!(
                    "channel {i} ({}) is {:?} voxels, channel 0 ({}) is {:?}: the channels of one medium share one grid",
                    c.name, c.dims, first.name, first.dims
                ));
            }
        }
        let mut upload = Self::from_volume(first);
        if channels.len() == 1 {
            return Ok(upload);
        }
        let format = channels
            .iter()
            .map(|c| format_of(&c.data))
            .max_by_key(|f| f.bytes())
            .unwrap_or(VolumeFormat::R8);
        upload.format = format;
        upload.bytes = interleave(channels, format);
        upload.extra_channels = channels[1..]
            .iter()
            .map(|c| {
                let u = Self::from_volume(c);
                ChannelUpload {
                    name: c.name.clone(),
                    window: c.window,
                    bricks: u.bricks,
                }
            })
            .collect();
        Ok(upload)
    }
}

fn format_of(d: &VolumeData) -> VolumeFormat {
    match d {
        VolumeData::U8(_) => VolumeFormat::R8,
        VolumeData::U16(_) => VolumeFormat::R16,
        VolumeData::F32(_) => VolumeFormat::R32F,
    }
}

/// The channels' voxels interleaved per texel in `format` (little-endian), padded with
/// zero components to [`components`].
fn interleave(channels: &[Volume], format: VolumeFormat) -> Vec<u8> {
    let n = channels[0].data.len();
    let comps = components(channels.len() as u32) as usize;
    let bpc = format.bytes();
    let mut out = vec![0u8; n * comps * bpc];
    for (c, v) in channels.iter().enumerate() {
        for i in 0..n {
            let at = (i * comps + c) * bpc;
            let dst = &mut out[at..at + bpc];
            match (&v.data, format) {
                (VolumeData::U8(d), VolumeFormat::R8) => dst[0] = d[i],
                (VolumeData::U8(d), VolumeFormat::R16) => {
                    dst.copy_from_slice(&(u16::from(d[i]) * 257).to_le_bytes())
                }
                (VolumeData::U16(d), VolumeFormat::R16) => dst.copy_from_slice(&d[i].to_le_bytes()),
                (data, _) => dst.copy_from_slice(&unit(data, i).to_le_bytes()),
            }
        }
    }
    out
}

/// Voxel `i` as a density in [0, 1].
fn unit(d: &VolumeData, i: usize) -> f32 {
    match d {
        VolumeData::U8(v) => f32::from(v[i]) / 255.0,
        VolumeData::U16(v) => f32::from(v[i]) / 65535.0,
        VolumeData::F32(v) => v[i],
    }
}

/// The brick ranges of every channel of `v`, channel 0's first.
pub fn channel_bricks(v: &VolumeUpload) -> Vec<&BrickRanges> {
    std::iter::once(&v.bricks)
        .chain(v.extra_channels.iter().map(|c| &c.bricks))
        .collect()
}

/// Whether the label mask rides in the volume texture's second component: for a
/// one-channel medium with a label map, so the extinction (evaluated at every step of
/// delta tracking) takes one fetch for density and mask (include/volume.glsl).
pub fn mask_in_volume(volume: &VolumeUpload, labels: bool) -> bool {
    labels && volume.channels() == 1
}

/// The volume's texels with the label mask beside each density (RG in the volume's
/// sample type; `mask` the label look's texels, whose alpha is the mask; `None`: all
/// shown), for [`mask_in_volume`].
pub fn with_mask(volume: &VolumeUpload, mask: Option<&[[u8; 4]]>) -> Vec<u8> {
    let bpp = volume.format.bytes();
    let texels = volume.bytes.len() / bpp;
    let mut out = Vec::with_capacity(texels * 2 * bpp);
    for (i, d) in volume.bytes.chunks_exact(bpp).enumerate() {
        out.extend_from_slice(d);
        let m = mask.and_then(|m| m.get(i)).map_or(255, |t| t[3]);
        match volume.format {
            VolumeFormat::R8 => out.push(m),
            VolumeFormat::R16 => out.extend_from_slice(&(u16::from(m) * 257).to_le_bytes()),
            VolumeFormat::R32F => out.extend_from_slice(&(f32::from(m) / 255.0).to_le_bytes()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Volume;

    fn vol(name: &str, data: VolumeData) -> Volume {
        let mut v = Volume::builtin("cloud", 8).expect("cloud");
        v.name = name.into();
        v.dims = [2, 1, 1];
        v.data = data;
        v
    }

    #[test]
    fn channels_interleave_in_the_widest_format_with_exact_widening() {
        let a = vol("a", VolumeData::U8(vec![255, 1]));
        let b = vol("b", VolumeData::U16(vec![7, 65535]));
        let c = vol("c", VolumeData::U8(vec![0, 128]));
        let u = VolumeUpload::from_channels(&[a, b, c]).expect("packs");
        assert_eq!(u.format, VolumeFormat::R16);
        assert_eq!(u.channels(), 3);
        let texels: Vec<u16> = bytemuck::pod_collect_to_vec(&u.bytes);
        // RGBA: the fourth component of three channels is zero.
        assert_eq!(texels, vec![65535, 7, 0, 0, 257, 65535, 128 * 257, 0]);
        assert_eq!(u.vk_format(), ash::vk::Format::R16G16B16A16_UNORM);
    }

    #[test]
    fn float_channels_make_float_texels() {
        let a = vol("a", VolumeData::U8(vec![51, 0]));
        let b = vol("b", VolumeData::F32(vec![0.25, 1.0]));
        let u = VolumeUpload::from_channels(&[a, b]).expect("packs");
        let texels: Vec<f32> = bytemuck::pod_collect_to_vec(&u.bytes);
        assert_eq!(texels, vec![0.2, 0.25, 0.0, 1.0]);
        assert_eq!(u.vk_format(), ash::vk::Format::R32G32_SFLOAT);
    }

    #[test]
    fn too_many_channels_or_two_grids_are_refused_by_name() {
        let a = vol("a", VolumeData::U8(vec![1, 2]));
        let five = vec![a.clone(); 5];
        let msg = VolumeUpload::from_channels(&five).unwrap_err();
        assert!(
            msg.contains("5 channels") && msg.contains("channels = ["),
            "{msg}"
        );
        let mut b = vol("b", VolumeData::U8(vec![1, 2, 3]));
        b.dims = [3, 1, 1];
        let msg = VolumeUpload::from_channels(&[a, b]).unwrap_err();
        assert!(
            msg.contains("channel 1 (b)") && msg.contains("[3, 1, 1]"),
            "{msg}"
        );
    }
}
