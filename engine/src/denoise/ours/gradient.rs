//! `<name>.gradient` (ours_gradient.comp): ours' temporal gradients. When the scene (a
//! light or the TF) changed since last frame, one pixel per S×S stratum of last frame's
//! image is traced again with last frame's camera and random numbers in this frame's
//! scene; the pooling pass compares the two per stratum.

use super::Ours;
use crate::denoise::DenoiseFrame;
use crate::error::Result;
use crate::gpu::ImageDesc;
use crate::gpu_block;
use crate::graph::ImageHandle;
use ash::vk;
use glam::{Mat4, Vec4};

gpu_block! {
    /// `OursGradientPush` in ours_gradient.comp.
    pub struct OursGradientPush {
        pub prev_inv_view_proj: Mat4,
        pub prev_camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub spp: u32,
        pub prev_frame: u32,
        pub stratum: u32,
        pub pad0: u32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

/// Ours' temporal gradients of a frame, at stratum resolution in last frame's image.
#[derive(Clone, Copy, Debug)]
pub(super) struct Gradients {
    /// Strata across and down.
    pub strata: [u32; 2],
    /// Re-traced radiance (this frame's scene) and last frame's, per stratum.
    pub new: ImageHandle,
    pub old: ImageHandle,
    /// Pooled and shrunk over 3×3, 5×5 and 9×9 strata ([`super::gradient_pool`]): rgb
    /// the colour of the change, a the log luminance ratio (0 and 1 where nothing was
    /// measured).
    pub ratio: ImageHandle,
    /// Measured this frame (false: the scene did not change, or nothing to compare).
    pub valid: bool,
}

impl Ours {
    /// Adds the temporal-gradient pass and its pooling when the scene changed since last
    /// frame; the images exist either way (the update pass binds them, and reads them
    /// only when `valid`).
    pub(super) fn add_gradients<'f>(&'f self, f: &mut DenoiseFrame<'_, 'f>) -> Result<Gradients> {
        let (ctx, graph, frame, input) = f.parts();
        let size = input.size;
        let s = self.params.stratum.max(1);
        let desc = ImageDesc::d2(
            size.width.div_ceil(s),
            size.height.div_ceil(s),
            vk::Format::R32G32B32A32_SFLOAT,
        );
        let n = &self.name;
        let g = Gradients {
            strata: [desc.extent[0], desc.extent[1]],
            new: graph.image(ctx, &format!("{n}.gradient_new"), desc)?,
            old: graph.image(ctx, &format!("{n}.gradient_old"), desc)?,
            ratio: graph.image(ctx, &format!("{n}.gradient_ratio"), desc)?,
            valid: false,
        };
        let (Some(pipeline), Some(retrace)) = (&self.gradients, input.retrace) else {
            return Ok(g);
        };
        let push = OursGradientPush {
            prev_inv_view_proj: retrace.inv_view_proj_prev,
            prev_camera: retrace.camera_prev.extend(1.0),
            width: size.width,
            height: size.height,
            spp: input.spp,
            prev_frame: retrace.frame_prev,
            stratum: s,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        };
        let scene = retrace.scene;
        // One invocation per stratum.
        let grid = [desc.extent[0], desc.extent[1], 1];
        frame.add_compute(format!("{n}.gradient"), pipeline, push, grid, |b| {
            scene.bind_volume(b);
            b.sampled("environment_map", scene.environment)
                .read("noisy_prev", retrace.radiance_prev)
                .write("gradient_new", g.new)
                .write("gradient_old", g.old);
        });
        let g = Gradients { valid: true, ..g };
        self.add_gradient_pool(frame, &g);
        Ok(g)
    }
}
