//! The frame's uniforms: the block every pass reads (camera, lights, the medium's
//! scale and majorant, the sampling settings, the cut) and the scene bindings that point
//! the passes at this slot's copy of it and at the scene's images.

use super::{FrameInputs, Renderer};
use crate::error::{EngineError, Result};
use crate::passes::SceneBindings;
use crate::shaders::frame::{FrameBlock, FrameParams, SampleStream, MAX_LIGHTS};
use glam::{Vec3, Vec4};

impl Renderer {
    /// This frame's uniform block, drawing random numbers from `stream`.
    pub(super) fn frame_block(
        &self,
        inputs: &FrameInputs,
        majorant_max: f32,
        stream: SampleStream,
    ) -> FrameBlock {
        let s = &self.settings;
        let view_proj = inputs.camera.proj * inputs.camera.view;
        let prev_view_proj = self
            .last_inputs
            .as_ref()
            .map(|p| p.camera.proj * p.camera.view)
            .unwrap_or(view_proj);
        let world = Vec3::from(self.world_size);
        let voxel = (world / Vec3::from(self.volume_dims.map(|d| d as f32))).min_element();
        let (crop, clip) = cut_uniforms(&inputs.cut, world, self.volume_dims);
        FrameBlock::new(&FrameParams {
            view_proj,
            prev_view_proj,
            camera: inputs.camera.position,
            half_size: world * 0.5,
            density_scale: self.config.density_scale,
            majorant_max,
            volume_dims: self.volume_dims,
            brick: self.bricks.brick,
            lights: &inputs.lights,
            stream,
            max_bounces: s.max_bounces(),
            rr_depth: s.russian_roulette_depth(),
            step: voxel * s.step_size() as f32,
            hg_g: s.hg_g() as f32,
            feature_threshold: s.feature_threshold() as f32,
            filter_sigma: s.filter_sigma() as f32,
            seed: s.seed(),
            crop,
            clip: &clip,
            channel_opacity: &self.channel_opacity,
            label_opacity: inputs.labels.as_ref().map_or(0.0, |l| l.0.shown_opacity),
        })
    }

    /// Writes `uniforms` into slot `slot`'s uniform buffer; returns the scene bindings.
    pub(super) fn write_uniforms(
        &mut self,
        slot: usize,
        uniforms: &FrameBlock,
    ) -> Result<SceneBindings> {
        let ubo = self.slots[slot].uniforms;
        self.graph
            .buffer_mut(ubo)
            .write(bytemuck::bytes_of(uniforms))?;
        Ok(SceneBindings {
            uniforms: ubo,
            volume: self.scene.volume,
            tf_diffuse_opacity: self.scene.tf[0],
            tf_specular_roughness: self.scene.tf[1],
            tf_emissive: self.scene.tf[2],
            majorant: self.scene.majorant,
            environment: self.scene.environment,
            brick_pool: self.scene.pool,
            brick_table: self.scene.brick_table,
            labels: self.scene.labels,
            label_shape: self.scene.label_shape,
        })
    }
}

/// The frame block's cut: the crop box in world space, clamped to the volume's box
/// (which it is when nothing is cropped), and the enabled clip planes as (unit normal,
/// offset). A crop box equal to the volume's bounds gives the box's own numbers.
fn cut_uniforms(cut: &crate::scene::Cut, world: Vec3, dims: [u32; 3]) -> ((Vec3, Vec3), Vec<Vec4>) {
    let half = world * 0.5;
    let (mut lo, mut hi) = (-half, half);
    if let Some(c) = cut.crop.filter(|c| c.enabled) {
        let (min, max) = c.in_box_frame(dims);
        let w = world.as_dvec3();
        lo = lo.max((min * w).as_vec3());
        hi = hi.min((max * w).as_vec3());
    }
    let planes = cut
        .planes
        .iter()
        .filter(|p| p.enabled)
        .map(|p| {
            let (n, w) = p.equation();
            n.as_vec3().extend(w as f32)
        })
        .collect();
    ((lo, hi), planes)
}

/// The frame block's light array holds [`MAX_LIGHTS`]: more is an error, never a
/// silent drop (scenes are checked against the same limit when loaded).
pub(super) fn check_light_count(inputs: &FrameInputs) -> Result<()> {
    if inputs.lights.len() > MAX_LIGHTS {
        return Err(EngineError::InvalidSetting {
            name: "lights",
            value: inputs.lights.len().to_string(),
            allowed: format!("the path tracer takes at most {MAX_LIGHTS}"),
        });
    }
    Ok(())
}
