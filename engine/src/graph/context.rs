//! What a pass sees while it records: its declared resources and nothing else.

use super::access::Access;
use super::resources::{Bound, BufferHandle, ImageHandle, Res};
use super::RenderGraph;
use crate::error::{EngineError, Result};
use crate::gpu::{ComputePipeline, GpuContext, Pipeline};
use crate::shaders::GpuBlock;
use ash::vk;

pub struct PassContext<'a> {
    pub ctx: &'a GpuContext,
    pub cmd: vk::CommandBuffer,
    graph: &'a RenderGraph,
    pass: &'a str,
    declared: &'a [(Res, Access)],
    bound: &'a [Bound],
    samplers: [vk::Sampler; 2],
}

impl<'a> PassContext<'a> {
    pub(crate) fn new(
        ctx: &'a GpuContext,
        cmd: vk::CommandBuffer,
        graph: &'a RenderGraph,
        pass: &'a str,
        declared: &'a [(Res, Access)],
        bound: &'a [Bound],
        samplers: [vk::Sampler; 2],
    ) -> Self {
        Self {
            ctx,
            cmd,
            graph,
            pass,
            declared,
            bound,
            samplers,
        }
    }

    fn err(&self, problem: String) -> EngineError {
        EngineError::Pass {
            pass: self.pass.to_string(),
            problem,
        }
    }

    fn access_of(&self, r: Res) -> Result<Access> {
        self.declared
            .iter()
            .find(|(d, _)| *d == r)
            .map(|(_, a)| *a)
            .ok_or_else(|| {
                let name = match r {
                    Res::Image(h) => self.graph.image_name(h).to_string(),
                    Res::Buffer(h) => self.graph.buffers[h.0 as usize].name.clone(),
                };
                self.err(format!("uses {name:?}, which it did not declare"))
            })
    }

    /// The Vulkan image of a declared image (for transfer commands).
    pub fn image(&self, h: ImageHandle) -> Result<vk::Image> {
        self.access_of(Res::Image(h))?;
        Ok(self.graph.images[h.0 as usize].image.image)
    }

    /// The view of a declared image (for a pass that begins its own rendering).
    pub fn image_view(&self, h: ImageHandle) -> Result<vk::ImageView> {
        self.access_of(Res::Image(h))?;
        Ok(self.graph.images[h.0 as usize].image.view)
    }

    /// Shape and format of a declared image.
    pub fn image_desc(&self, h: ImageHandle) -> Result<crate::gpu::ImageDesc> {
        self.access_of(Res::Image(h))?;
        Ok(self.graph.image_desc(h))
    }

    /// The Vulkan buffer of a declared buffer.
    pub fn buffer(&self, h: BufferHandle) -> Result<vk::Buffer> {
        self.access_of(Res::Buffer(h))?;
        Ok(self.graph.buffers[h.0 as usize].buffer.buffer)
    }

    /// Binds what the pass declared with [`super::Bindings`] to the shader variables it
    /// named, pushes `push` and dispatches `groups` workgroups.
    pub(crate) fn dispatch_bound<P: GpuBlock>(
        &mut self,
        pipeline: &Pipeline<P>,
        push: &P,
        groups: [u32; 3],
    ) -> Result<()> {
        let bound: Vec<_> = self
            .bound
            .iter()
            .map(|b| (b.var, b.res, b.nearest))
            .collect();
        self.bind_and_dispatch(pipeline, &bound, bytemuck::bytes_of(push), groups)
    }

    /// Binds (shader variable, resource, nearest sampler) triples and dispatches. Every
    /// reflected binding must be bound, and each resource's declared access must suit
    /// the descriptor type.
    fn bind_and_dispatch(
        &mut self,
        pipeline: &ComputePipeline,
        bindings: &[(&str, Res, bool)],
        bytes: &[u8],
        groups: [u32; 3],
    ) -> Result<()> {
        // Names the shader does not reflect are skipped: the optimiser drops bindings a
        // specialised variant never reads (e.g. the emissive LUT without emission). Every
        // binding the shader does use must be bound, which catches misspelt names.
        let mut image_infos = Vec::with_capacity(bindings.len());
        let mut buffer_infos = Vec::with_capacity(bindings.len());
        let mut plan = Vec::with_capacity(pipeline.reflection.bindings.len());
        for b in &pipeline.reflection.bindings {
            let Some(&(_, res, nearest)) = bindings.iter().find(|(n, ..)| *n == b.name) else {
                return Err(self.err(format!(
                    "shader {} binding {:?} (binding {}) is not bound",
                    pipeline.name, b.name, b.binding
                )));
            };
            let sampler = match (res, nearest) {
                (Res::Buffer(_), _) => vk::Sampler::null(),
                (_, false) => self.samplers[0],
                (_, true) => self.samplers[1],
            };
            let access = self.access_of(res)?;
            let ok = match b.ty {
                vk::DescriptorType::STORAGE_IMAGE => {
                    matches!(res, Res::Image(_)) && access.is_storage()
                }
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER | vk::DescriptorType::SAMPLED_IMAGE => {
                    matches!(res, Res::Image(_)) && access == Access::Sampled
                }
                vk::DescriptorType::UNIFORM_BUFFER => {
                    matches!(res, Res::Buffer(_)) && access == Access::Uniform
                }
                vk::DescriptorType::STORAGE_BUFFER => {
                    matches!(res, Res::Buffer(_)) && access.is_storage()
                }
                _ => false,
            };
            if !ok {
                return Err(self.err(format!(
                    "binding {:?} is a {:?} but the pass declared {access:?} on it",
                    b.name, b.ty
                )));
            }
            match res {
                Res::Image(h) => {
                    let layout = access.info().layout;
                    image_infos.push(
                        vk::DescriptorImageInfo::default()
                            .image_view(self.graph.images[h.0 as usize].image.view)
                            .image_layout(layout)
                            .sampler(sampler),
                    );
                    plan.push((b.binding, b.ty, true, image_infos.len() - 1));
                }
                Res::Buffer(h) => {
                    buffer_infos.push(
                        vk::DescriptorBufferInfo::default()
                            .buffer(self.graph.buffers[h.0 as usize].buffer.buffer)
                            .offset(0)
                            .range(vk::WHOLE_SIZE),
                    );
                    plan.push((b.binding, b.ty, false, buffer_infos.len() - 1));
                }
            }
        }
        let writes: Vec<_> = plan
            .iter()
            .map(|&(binding, ty, is_image, i)| {
                let w = vk::WriteDescriptorSet::default()
                    .dst_binding(binding)
                    .descriptor_type(ty);
                if is_image {
                    w.image_info(std::slice::from_ref(&image_infos[i]))
                } else {
                    w.buffer_info(std::slice::from_ref(&buffer_infos[i]))
                }
            })
            .collect();
        if bytes.len() as u32 != pipeline.reflection.push_constant_size
            && pipeline.reflection.push_constant_size != 0
        {
            return Err(self.err(format!(
                "push constants are {} bytes but shader {} declares {}",
                bytes.len(),
                pipeline.name,
                pipeline.reflection.push_constant_size
            )));
        }
        let d = &self.ctx.device;
        unsafe {
            d.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, pipeline.pipeline);
            if !writes.is_empty() {
                self.ctx.push_descriptor.cmd_push_descriptor_set(
                    self.cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    pipeline.layout,
                    0,
                    &writes,
                );
            }
            if pipeline.reflection.push_constant_size > 0 {
                d.cmd_push_constants(
                    self.cmd,
                    pipeline.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    bytes,
                );
            }
            d.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
        Ok(())
    }

    /// Copies a declared buffer (TransferSrc) into a declared image (TransferDst).
    pub fn copy_buffer_to_image(&mut self, src: BufferHandle, dst: ImageHandle) -> Result<()> {
        let desc = self.graph.image_desc(dst);
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers())
            .image_extent(extent(desc.extent));
        self.copy_buffer_to_image_regions(src, dst, &[region])
    }

    /// Copies regions of a declared buffer (TransferSrc) into regions of a declared
    /// image (TransferDst): the brick pool's uploads.
    pub fn copy_buffer_to_image_regions(
        &mut self,
        src: BufferHandle,
        dst: ImageHandle,
        regions: &[vk::BufferImageCopy],
    ) -> Result<()> {
        let buffer = self.buffer(src)?;
        let image = self.image(dst)?;
        unsafe {
            self.ctx.device.cmd_copy_buffer_to_image(
                self.cmd,
                buffer,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                regions,
            )
        };
        Ok(())
    }

    /// Copies the whole of a declared buffer (TransferSrc) into another (TransferDst) of
    /// at least its size.
    pub fn copy_buffer(&mut self, src: BufferHandle, dst: BufferHandle) -> Result<()> {
        let (from, to) = (self.buffer(src)?, self.buffer(dst)?);
        let size = self.graph.buffer_ref(src).size;
        let region = vk::BufferCopy::default().size(size);
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer(self.cmd, from, to, &[region])
        };
        Ok(())
    }

    /// Fills a declared buffer (TransferDst) with a repeated 32-bit value.
    pub fn fill_buffer(&mut self, dst: BufferHandle, value: u32) -> Result<()> {
        let buffer = self.buffer(dst)?;
        unsafe {
            self.ctx
                .device
                .cmd_fill_buffer(self.cmd, buffer, 0, vk::WHOLE_SIZE, value)
        };
        Ok(())
    }

    /// Copies all of a declared image (TransferSrc) into a declared image of the same
    /// shape (TransferDst).
    pub fn copy_image(&mut self, src: ImageHandle, dst: ImageHandle) -> Result<()> {
        let (from, to) = (self.image(src)?, self.image(dst)?);
        let desc = self.graph.image_desc(src);
        let region = vk::ImageCopy::default()
            .src_subresource(color_layers())
            .dst_subresource(color_layers())
            .extent(extent(desc.extent));
        unsafe {
            self.ctx.device.cmd_copy_image(
                self.cmd,
                from,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                to,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
        Ok(())
    }

    /// Copies a declared image (TransferSrc) into a declared buffer (TransferDst).
    pub fn copy_image_to_buffer(&mut self, src: ImageHandle, dst: BufferHandle) -> Result<()> {
        let image = self.image(src)?;
        let buffer = self.buffer(dst)?;
        let desc = self.graph.image_desc(src);
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers())
            .image_extent(extent(desc.extent));
        unsafe {
            self.ctx.device.cmd_copy_image_to_buffer(
                self.cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer,
                &[region],
            )
        };
        Ok(())
    }
}

fn color_layers() -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    }
}

fn extent(e: [u32; 3]) -> vk::Extent3D {
    vk::Extent3D {
        width: e[0],
        height: e[1],
        depth: e[2],
    }
}
