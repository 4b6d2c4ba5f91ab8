//! GPU images and buffers backed by gpu-allocator. These are plain resources: who may
//! access them when, and in which layout, is the render graph's business.

use super::context::{set_name, GpuContext};
use crate::error::{EngineError, Result, VkContext};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

/// Shape and format of an image; the graph compares these to decide reuse.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageDesc {
    pub kind: vk::ImageType,
    pub format: vk::Format,
    pub extent: [u32; 3],
}

impl ImageDesc {
    pub fn d1(width: u32, format: vk::Format) -> Self {
        Self {
            kind: vk::ImageType::TYPE_1D,
            format,
            extent: [width, 1, 1],
        }
    }
    pub fn d2(width: u32, height: u32, format: vk::Format) -> Self {
        Self {
            kind: vk::ImageType::TYPE_2D,
            format,
            extent: [width, height, 1],
        }
    }
    pub fn d3(extent: [u32; 3], format: vk::Format) -> Self {
        Self {
            kind: vk::ImageType::TYPE_3D,
            format,
            extent,
        }
    }
    pub fn texel_count(&self) -> u64 {
        self.extent.iter().map(|&e| e as u64).product()
    }
    pub fn view_type(&self) -> vk::ImageViewType {
        match self.kind {
            vk::ImageType::TYPE_1D => vk::ImageViewType::TYPE_1D,
            vk::ImageType::TYPE_3D => vk::ImageViewType::TYPE_3D,
            _ => vk::ImageViewType::TYPE_2D,
        }
    }
}

/// Bytes per texel of the formats the engine uses.
pub fn format_size(format: vk::Format) -> u64 {
    match format {
        vk::Format::R8_UNORM => 1,
        vk::Format::R16_UNORM | vk::Format::R16_SFLOAT => 2,
        vk::Format::R32_SFLOAT | vk::Format::R32_UINT | vk::Format::R8G8B8A8_UNORM => 4,
        vk::Format::B8G8R8A8_UNORM | vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB => 4,
        vk::Format::R16G16_SFLOAT | vk::Format::R16G16B16A16_UNORM => 8,
        vk::Format::R16G16B16A16_SFLOAT | vk::Format::R32G32_SFLOAT => 8,
        vk::Format::R32G32B32A32_SFLOAT => 16,
        _ => 16,
    }
}

pub struct GpuImage {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub desc: ImageDesc,
    /// What it was created for (none for an image not allocated yet).
    pub usage: vk::ImageUsageFlags,
    allocation: Option<Allocation>,
    /// Owned elsewhere (a swapchain image): `destroy` leaves it alone.
    external: bool,
}

impl GpuImage {
    /// Allocates a device-local image for `usage`.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        desc: ImageDesc,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        let bytes = desc.texel_count() * format_size(desc.format);
        if bytes > ctx.info.max_memory_allocation_size {
            return Err(EngineError::TooLarge {
                what: format!("image {name:?} ({:?} {:?})", desc.extent, desc.format),
                needed: bytes,
                limit: ctx.info.max_memory_allocation_size,
                device: ctx.info.name.clone(),
            });
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(desc.kind)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent[0],
                height: desc.extent[1],
                depth: desc.extent[2],
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let d = &ctx.device;
        let image = unsafe { d.create_image(&info, None) }.vk("vkCreateImage")?;
        let requirements = unsafe { d.get_image_memory_requirements(image) };
        let allocation = allocate(ctx, name, requirements, MemoryLocation::GpuOnly, false)
            .inspect_err(|_| unsafe { d.destroy_image(image, None) })?;
        unsafe { d.bind_image_memory(image, allocation.memory(), allocation.offset()) }
            .vk("vkBindImageMemory")?;
        // Shaders and attachments see an image through a view; transfers do not, and an
        // image made for transfers only may not have one.
        let viewed = vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        let view = if usage.intersects(viewed) {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(desc.view_type())
                .format(desc.format)
                .subresource_range(color_range());
            unsafe { d.create_image_view(&view_info, None) }.vk("vkCreateImageView")?
        } else {
            vk::ImageView::null()
        };
        set_name(ctx, image, name);
        Ok(Self {
            image,
            view,
            desc,
            usage,
            allocation: Some(allocation),
            external: false,
        })
    }

    /// An image of shape `desc` not allocated yet (the render graph allocates it when a
    /// frame first declares how it is used).
    pub fn unallocated(desc: ImageDesc) -> Self {
        Self {
            image: vk::Image::null(),
            view: vk::ImageView::null(),
            desc,
            usage: vk::ImageUsageFlags::empty(),
            allocation: None,
            external: false,
        }
    }

    pub fn is_allocated(&self) -> bool {
        self.external || self.image != vk::Image::null()
    }

    /// An image and view owned by someone else (a swapchain), described by `desc`.
    pub fn external(image: vk::Image, view: vk::ImageView, desc: ImageDesc) -> Self {
        Self {
            image,
            view,
            desc,
            usage: vk::ImageUsageFlags::empty(),
            allocation: None,
            external: true,
        }
    }

    pub fn is_external(&self) -> bool {
        self.external
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        if self.external || !self.is_allocated() {
            return;
        }
        unsafe {
            ctx.device.destroy_image_view(self.view, None);
            ctx.device.destroy_image(self.image, None);
        }
        self.image = vk::Image::null();
        self.view = vk::ImageView::null();
        if let (Some(a), Ok(mut alloc)) = (self.allocation.take(), ctx.allocator.lock()) {
            let _ = alloc.free(a);
        }
    }
}

pub fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

pub struct GpuBuffer {
    pub buffer: vk::Buffer,
    pub size: u64,
    allocation: Option<Allocation>,
}

impl GpuBuffer {
    /// `location`: GpuOnly for device data, CpuToGpu for uploads/uniforms, GpuToCpu for
    /// readbacks (those are mapped persistently).
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        let d = &ctx.device;
        let info = vk::BufferCreateInfo::default()
            .size(size.max(4))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { d.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let requirements = unsafe { d.get_buffer_memory_requirements(buffer) };
        let allocation = allocate(ctx, name, requirements, location, true)
            .inspect_err(|_| unsafe { d.destroy_buffer(buffer, None) })?;
        unsafe { d.bind_buffer_memory(buffer, allocation.memory(), allocation.offset()) }
            .vk("vkBindBufferMemory")?;
        set_name(ctx, buffer, name);
        Ok(Self {
            buffer,
            size,
            allocation: Some(allocation),
        })
    }

    /// Host-visible bytes (None for device-only memory).
    pub fn mapped(&self) -> Option<&[u8]> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..self.size as usize])
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size as usize;
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .map(|s| &mut s[..size])
    }

    /// Copies `data` into a host-visible buffer.
    pub fn write(&mut self, data: &[u8]) -> Result<()> {
        let dst = self.mapped_mut().ok_or_else(|| EngineError::Resource {
            resource: "buffer".into(),
            problem: "write to a buffer that is not host visible".into(),
        })?;
        if data.len() > dst.len() {
            return Err(EngineError::Resource {
                resource: "buffer".into(),
                problem: format!("write of {} bytes into {} bytes", data.len(), dst.len()),
            });
        }
        dst[..data.len()].copy_from_slice(data);
        Ok(())
    }

    /// False once destroyed.
    pub fn is_allocated(&self) -> bool {
        self.allocation.is_some()
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        unsafe { ctx.device.destroy_buffer(self.buffer, None) };
        self.buffer = vk::Buffer::null();
        if let (Some(a), Ok(mut alloc)) = (self.allocation.take(), ctx.allocator.lock()) {
            let _ = alloc.free(a);
        }
    }
}

/// Allocates memory for an image (`linear` false) or a buffer, naming the resource in
/// the error.
fn allocate(
    ctx: &GpuContext,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation> {
    let mut allocator = ctx.allocator.lock().map_err(|_| EngineError::Resource {
        resource: name.into(),
        problem: "allocator lock poisoned".into(),
    })?;
    allocator
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|source| EngineError::Alloc {
            what: format!("{name:?} ({} bytes)", requirements.size),
            source,
        })
}
