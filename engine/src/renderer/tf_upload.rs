//! A transfer function onto the device: its LUTs and the majorant grid when it changed,
//! and on the pool path the bricks it makes visible and the brick table after them; how
//! the volume is held ([`VolumeResidency`]).

use super::brick_pool::{self, VolumeResidency};
use super::scene_gpu;
use super::uploads::VolumeUpload;
use super::FrameInputs;
use super::Renderer;
use crate::error::{EngineError, Result};
use crate::graph::Frame;
use crate::shaders::frame::ChannelOpacity;
use std::sync::Arc;

impl Renderer {
    /// Adds uploads of the TF LUTs and the majorant grid when the TF or the cut differs
    /// from the one on the device (bricks a cut removes whole get majorant 0), and on
    /// the pool path the bricks they make visible and the brick table; returns the
    /// largest extinction (the global majorant). `stream`: a frame uploads at most
    /// [`brick_pool::STREAM_PER_FRAME`] bricks after the first frame; a reference
    /// (`false`) waits for them all.
    pub(super) fn upload_transfer_function(
        &mut self,
        frame: &mut Frame,
        slot: usize,
        inputs: &FrameInputs,
        stream: bool,
    ) -> Result<f32> {
        if let Some(t) = &inputs.time {
            let volume = t.timeline.at(t.time)?;
            if !Arc::ptr_eq(&volume, &self.volume) {
                self.replace_volume(frame, slot, volume)?;
            }
        }
        let (lut, cut) = (&inputs.lut, &inputs.cut);
        let channels = self.volume.channels() as usize;
        let n = self.lut_size as usize;
        if lut.diffuse_opacity.len() != n * channels {
            return Err(EngineError::Resource {
                resource: "transfer function".into(),
                problem: format!(
                    "LUT has {} entries, renderer expects {} ({channels} channel(s) of {n})",
                    lut.diffuse_opacity.len(),
                    n * channels,
                ),
            });
        }
        let first = self.current_lut.is_none();
        let labels_changed = self.current_labels != inputs.labels;
        if labels_changed {
            if let Some(look) = &inputs.labels {
                if super::packing::mask_in_volume(&self.volume, true) {
                    let bytes = super::packing::with_mask(&self.volume, Some(&look.0.rgba));
                    let (ctx, graph, image) = (&self.ctx, &mut self.graph, self.scene.volume);
                    scene_gpu::add_frame_upload(
                        ctx,
                        graph,
                        frame,
                        "upload_volume",
                        slot,
                        image,
                        &bytes,
                    )?;
                }
                // The shape on the device stays where the edit kept it (see
                // `SceneLabels::look`).
                let same_shape = self
                    .current_labels
                    .as_ref()
                    .is_some_and(|c| std::sync::Arc::ptr_eq(&c.0.shape, &look.0.shape));
                let (ctx, graph) = (&self.ctx, &mut self.graph);
                let rgba = bytemuck::cast_slice(&look.0.rgba);
                let shape = (!same_shape).then_some((
                    "upload_label_shape",
                    self.scene.label_shape,
                    &look.0.shape[..],
                ));
                for (name, image, bytes) in
                    std::iter::once(("upload_labels", self.scene.labels, rgba)).chain(shape)
                {
                    scene_gpu::add_frame_upload(ctx, graph, frame, name, slot, image, bytes)?;
                }
            }
        }
        if self.current_lut.as_ref() != Some(lut)
            || self.current_cut.as_ref() != Some(cut)
            || labels_changed
        {
            let opacity: Vec<f32> = lut.diffuse_opacity.iter().map(|c| c[3]).collect();
            let scale = self.config.density_scale;
            let (dims, world) = (self.volume_dims, self.world_size);
            // The medium's extinction is the channels' sum: so is each brick's majorant.
            let mut majorants = scene_gpu::majorants(&self.bricks, &opacity[..n], scale);
            for (c, extra) in self.volume.extra_channels.iter().enumerate() {
                let segment = &opacity[(c + 1) * n..(c + 2) * n];
                let m = scene_gpu::majorants(&extra.bricks, segment, scale);
                majorants.iter_mut().zip(m).for_each(|(a, b)| *a += b);
            }
            if let Some(look) = &inputs.labels {
                // Tint: the medium times the mask; solid: the mask alone.
                let solid = self.config.labels == Some(crate::scene::LabelMode::Solid);
                for (m, &mask) in majorants.iter_mut().zip(&look.0.brick_max) {
                    *m = if solid { mask * scale } else { *m * mask };
                }
            }
            scene_gpu::mask_cut(&mut majorants, &self.bricks, dims, world, cut);
            self.majorant_max = majorants.iter().copied().fold(0.0f32, f32::max);
            if channels > 1 {
                *self.channel_opacity = ChannelOpacity::from_rows(&opacity);
            }
            let (ctx, graph) = (&self.ctx, &mut self.graph);
            let [a, b, c] = self.scene.tf;
            for (name, image, bytes) in [
                (
                    "upload_tf_diffuse",
                    a,
                    bytemuck::cast_slice(&lut.diffuse_opacity),
                ),
                (
                    "upload_tf_specular",
                    b,
                    bytemuck::cast_slice(&lut.specular_roughness),
                ),
                ("upload_tf_emissive", c, bytemuck::cast_slice(&lut.emissive)),
                (
                    "upload_majorant",
                    self.scene.majorant,
                    bytemuck::cast_slice(&majorants),
                ),
            ] {
                scene_gpu::add_frame_upload(ctx, graph, frame, name, slot, image, bytes)?;
            }
            if let Some(r) = &mut self.residency {
                let mut pool_majorants = scene_gpu::majorants(r.ranges(), &opacity, scale);
                scene_gpu::mask_cut(&mut pool_majorants, r.ranges(), dims, world, cut);
                self.table_dirty |= r.set_transfer_function(&pool_majorants);
                let slots = r.layout.slot_count();
                // Said once each time the TF goes past the pool (not on every edit while
                // it stays there); the HUD and profile header show the count throughout.
                let over = r.visible_count > slots;
                if over && !std::mem::replace(&mut self.over_budget, over) {
                    log::warn!(
                        "{} of the {} bricks this TF makes visible show at the coarse level (1/{} resolution): the budget holds {slots} (raise --gpu-memory)",
                        r.visible_count - slots,
                        r.visible_count,
                        1 << r.layout.level
                    );
                }
                self.over_budget = over;
            }
            self.current_lut = Some(lut.clone());
            self.current_cut = Some(cut.clone());
            self.current_labels = inputs.labels.clone();
        }
        self.upload_bricks(frame, slot, first || !stream)?;
        if first && self.residency.is_some() {
            log::info!("{}", self.volume_residency());
        }
        Ok(self.majorant_max)
    }

    /// Uploads `volume` (another time point of the series on the device: one grid,
    /// format and channel count) into the volume texture in `frame`, and has the
    /// majorants made again from its brick ranges.
    fn replace_volume(
        &mut self,
        frame: &mut Frame,
        slot: usize,
        volume: Arc<VolumeUpload>,
    ) -> Result<()> {
        let old = &self.volume;
        if self.residency.is_some()
            || volume.dims != old.dims
            || volume.format != old.format
            || volume.channels() != old.channels()
        {
            return Err(EngineError::Resource {
                resource: format!("volume {:?}", volume.name),
                problem: format!(
                    "a time point of {:?} voxels, {:?} x {} channel(s) cannot replace {:?} x {:?} x {} held {}",
                    volume.dims,
                    volume.format,
                    volume.channels(),
                    old.dims,
                    old.format,
                    old.channels(),
                    if self.residency.is_some() { "in the brick pool (a series is held dense)" } else { "dense" }
                ),
            });
        }
        let (ctx, graph) = (&self.ctx, &mut self.graph);
        let image = self.scene.volume;
        let bytes = match &self.current_labels {
            Some(look) if super::packing::mask_in_volume(&volume, true) => {
                std::borrow::Cow::Owned(super::packing::with_mask(&volume, Some(&look.0.rgba)))
            }
            _ => std::borrow::Cow::Borrowed(&volume.bytes[..]),
        };
        scene_gpu::add_frame_upload(ctx, graph, frame, "upload_volume", slot, image, &bytes)?;
        self.bricks = volume.bricks.clone();
        self.volume = volume;
        // The majorants follow the new bricks' ranges.
        self.current_lut = None;
        Ok(())
    }

    /// On the pool path: uploads pending bricks into their slots (at most one frame's
    /// worth into `frame`; with `all`, the rest first through set-up submissions) and
    /// the brick table after them, in the same frame, so no frame reads a slot the
    /// table does not describe.
    fn upload_bricks(&mut self, frame: &mut Frame, slot: usize, all: bool) -> Result<()> {
        /// Bricks per set-up submission when a whole TF's bricks load at once.
        const SETUP_CHUNK: usize = 512;
        let Some(r) = &mut self.residency else {
            return Ok(());
        };
        let (ctx, graph, volume) = (&self.ctx, &mut self.graph, &self.volume);
        let size = brick_pool::brick_bytes(volume.format) as u64;
        while all && r.pending() > brick_pool::STREAM_PER_FRAME {
            let uploads = r.take_uploads(SETUP_CHUNK);
            let staging =
                graph.staging(ctx, "brick_pool.staging.setup", SETUP_CHUNK as u64 * size)?;
            let mut setup = Frame::new();
            let pool = self.scene.pool;
            scene_gpu::add_brick_uploads(
                graph, &mut setup, staging, pool, volume, &r.layout, &uploads,
            )?;
            ctx.submit_and_wait(|cmd| graph.execute(ctx, cmd, None, setup))?;
            self.table_dirty = true;
        }
        let uploads = r.take_uploads(brick_pool::STREAM_PER_FRAME);
        if !uploads.is_empty() {
            let staging = graph.staging(
                ctx,
                &format!("brick_pool.staging.{slot}"),
                brick_pool::STREAM_PER_FRAME as u64 * size,
            )?;
            let pool = self.scene.pool;
            scene_gpu::add_brick_uploads(graph, frame, staging, pool, volume, &r.layout, &uploads)?;
            self.table_dirty = true;
        }
        if std::mem::take(&mut self.table_dirty) {
            // Bricks landed: the medium the features march sees changed.
            self.last_march = None;
            let table = r.table();
            let image = self.scene.brick_table;
            let bytes = bytemuck::cast_slice(&table);
            scene_gpu::add_frame_upload(
                ctx,
                graph,
                frame,
                "upload_brick_table",
                slot,
                image,
                bytes,
            )?;
        }
        Ok(())
    }

    /// How the volume reaches the device, and on the pool path how many of the bricks the
    /// current TF makes visible have a slot.
    pub fn volume_residency(&self) -> VolumeResidency {
        match &self.residency {
            None => VolumeResidency::Dense,
            Some(r) => VolumeResidency::Pool {
                layout: r.layout.clone(),
                visible: r.visible_count,
                resident: r.resident_visible(),
                pending: r.pending(),
                uploaded: r.uploaded(),
            },
        }
    }
}
