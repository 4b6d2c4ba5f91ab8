//! `<name>.gradient` (wrls_gradient.comp): ours' temporal gradients. When the scene (a
//! light or the TF) changed since last frame, one pixel per S×S stratum of last frame's
//! image is traced again with last frame's camera and random numbers in this frame's
//! scene; the update pass compares the two per stratum.

use super::Wrls;
use crate::denoise::DenoiseInputs;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::{Bind, Frame, ImageHandle, RenderGraph};
use crate::renderer::uniforms::WrlsGradientPush;
use ash::vk;

/// Ours' temporal gradients of a frame, at stratum resolution in last frame's image.
#[derive(Clone, Copy, Debug)]
pub(super) struct Gradients {
    /// Re-traced radiance (this frame's scene) and last frame's, per stratum.
    pub new: ImageHandle,
    pub old: ImageHandle,
    /// Measured this frame (false: the scene did not change, or nothing to compare).
    pub valid: bool,
}

impl Wrls {
    /// Adds the temporal-gradient pass when the scene changed since last frame; the
    /// images exist either way (the update pass binds them, and reads them only when
    /// `valid`).
    pub(super) fn add_gradients<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
    ) -> Result<Gradients> {
        let size = input.size;
        let s = self.params.stratum.max(1);
        let desc = ImageDesc::d2(
            size.width.div_ceil(s),
            size.height.div_ceil(s),
            vk::Format::R32G32B32A32_SFLOAT,
        );
        let n = &self.name;
        let g = Gradients {
            new: graph.image(ctx, &format!("{n}.gradient_new"), desc)?,
            old: graph.image(ctx, &format!("{n}.gradient_old"), desc)?,
            valid: false,
        };
        let (Some(pipeline), Some(retrace)) = (&self.gradients, input.retrace) else {
            return Ok(g);
        };
        let push = WrlsGradientPush {
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
        frame.add_pass(
            format!("{n}.gradient"),
            |b| {
                scene.declare_volume(b);
                b.sampled(scene.environment)
                    .read(retrace.radiance_prev)
                    .write(g.new)
                    .write(g.old);
            },
            move |pc| {
                let mut binds = scene.volume_binds();
                binds.extend([
                    ("environment_map", Bind::Image(scene.environment)),
                    ("noisy_prev", Bind::Image(retrace.radiance_prev)),
                    ("gradient_new", Bind::Image(g.new)),
                    ("gradient_old", Bind::Image(g.old)),
                ]);
                let groups = pipeline.groups_2d(desc.extent[0], desc.extent[1]);
                pc.dispatch(pipeline, &binds, &push, groups)
            },
        );
        Ok(Gradients { valid: true, ..g })
    }
}
