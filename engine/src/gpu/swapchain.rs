//! A window's swapchain: surface format and present-mode choice, creation and
//! recreation (resize, out-of-date, suboptimal), acquire and present with semaphores.
//!
//! The engine knows nothing of windows: the application creates the `vk::SurfaceKHR`
//! (ash-window does it from a window handle) and hands it over; the swapchain owns and
//! destroys it. Swapchain images are written by a compute pass (the tone map) and drawn
//! over by the UI, so they are created with `STORAGE | COLOR_ATTACHMENT` usage (and
//! `TRANSFER_SRC` where allowed, for screenshots), in a UNORM format: sRGB formats do
//! not support storage, so the present pass writes sRGB-encoded values itself.
//!
//! Synchronisation: [`Swapchain::acquire`] returns the image with the semaphore the
//! frame's submission must wait on (at [`ACQUIRE_WAIT_STAGE`]) and the one it must
//! signal; [`Swapchain::present`] waits on the latter. Layout transitions are the render
//! graph's: the renderer imports the acquired image into its graph.

use super::context::GpuContext;
use crate::error::{EngineError, Result, VkContext};
use ash::vk;

/// The stage at which a frame's submission waits for its acquired image. The render
/// graph starts the image's first barrier at this stage (see
/// [`crate::graph::ResourceState::external`]); the first access is the present compute
/// pass.
pub const ACQUIRE_WAIT_STAGE: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::COMPUTE_SHADER;

/// Acquire semaphores in rotation. One is reused only after the frame that waited on it
/// has finished; the renderer keeps two frames in flight and waits for frame N−2 before
/// recording frame N, so three would do; four leaves margin.
const ACQUIRE_SEMAPHORES: usize = 4;

/// Formats the present pass can write as storage images, in order of preference.
const PREFERRED_FORMATS: [vk::Format; 3] = [
    vk::Format::B8G8R8A8_UNORM,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::A2B10G10R10_UNORM_PACK32,
];

/// Picks a UNORM surface format with storage support from `available` (the surface's
/// formats, filtered by the caller to those the device can use as storage images).
pub fn choose_format(available: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    PREFERRED_FORMATS.iter().find_map(|&f| {
        available
            .iter()
            .find(|s| s.format == f && s.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
            .copied()
    })
}

/// FIFO with vsync (always available); without, MAILBOX if offered, else IMMEDIATE,
/// else FIFO.
pub fn choose_present_mode(available: &[vk::PresentModeKHR], vsync: bool) -> vk::PresentModeKHR {
    if vsync {
        return vk::PresentModeKHR::FIFO;
    }
    [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE]
        .into_iter()
        .find(|m| available.contains(m))
        .unwrap_or(vk::PresentModeKHR::FIFO)
}

/// The swapchain extent: the surface's current extent, or `wanted` clamped to its
/// limits when the surface lets the swapchain decide (`u32::MAX`).
pub fn choose_extent(caps: &vk::SurfaceCapabilitiesKHR, wanted: vk::Extent2D) -> vk::Extent2D {
    if caps.current_extent.width != u32::MAX {
        return caps.current_extent;
    }
    vk::Extent2D {
        width: wanted.width.clamp(
            caps.min_image_extent.width,
            caps.max_image_extent.width.max(1),
        ),
        height: wanted.height.clamp(
            caps.min_image_extent.height,
            caps.max_image_extent.height.max(1),
        ),
    }
}

/// An image acquired for one frame.
#[derive(Clone, Copy, Debug)]
pub struct AcquiredImage {
    pub index: u32,
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    /// The frame's submission waits on this at [`ACQUIRE_WAIT_STAGE`].
    pub wait: vk::Semaphore,
    /// The frame's submission signals this; [`Swapchain::present`] waits on it.
    pub signal: vk::Semaphore,
}

pub struct Swapchain {
    surface_loader: ash::khr::surface::Instance,
    loader: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    swapchain: vk::SwapchainKHR,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub present_mode: vk::PresentModeKHR,
    /// Whether screenshots can copy from the images (`TRANSFER_SRC` usage).
    pub readable: bool,
    vsync: bool,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    /// One per image: signalled by the frame that drew it, waited on by its present.
    rendered: Vec<vk::Semaphore>,
    acquire: Vec<vk::Semaphore>,
    next_acquire: usize,
}

fn err(problem: impl Into<String>) -> EngineError {
    EngineError::Resource {
        resource: "swapchain".into(),
        problem: problem.into(),
    }
}

impl Swapchain {
    /// Takes ownership of `surface` (destroyed with the swapchain, also on error).
    /// `wanted` is the window's size in pixels.
    pub fn new(
        ctx: &GpuContext,
        surface: vk::SurfaceKHR,
        wanted: vk::Extent2D,
        vsync: bool,
    ) -> Result<Self> {
        let surface_loader = ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance);
        let loader = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let mut me = Self {
            surface_loader,
            loader,
            surface,
            swapchain: vk::SwapchainKHR::null(),
            format: vk::Format::UNDEFINED,
            extent: wanted,
            present_mode: vk::PresentModeKHR::FIFO,
            readable: false,
            vsync,
            images: Vec::new(),
            views: Vec::new(),
            rendered: Vec::new(),
            acquire: Vec::new(),
            next_acquire: 0,
        };
        match me.init(ctx, wanted) {
            Ok(()) => Ok(me),
            Err(e) => {
                me.destroy(ctx);
                Err(e)
            }
        }
    }

    fn init(&mut self, ctx: &GpuContext, wanted: vk::Extent2D) -> Result<()> {
        let families = unsafe {
            ctx.instance
                .get_physical_device_queue_family_properties(ctx.physical)
        };
        let graphics = families
            .get(ctx.queue_family as usize)
            .is_some_and(|f| f.queue_flags.contains(vk::QueueFlags::GRAPHICS));
        let present = unsafe {
            self.surface_loader.get_physical_device_surface_support(
                ctx.physical,
                ctx.queue_family,
                self.surface,
            )
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !graphics || !present {
            return Err(err(format!(
                "{} cannot draw to this window from its queue (graphics: {graphics}, \
                 present: {present}); pick another device with DVR_DEVICE",
                ctx.info.name
            )));
        }
        if !ctx.info.storage_write_without_format {
            return Err(err(format!(
                "{} lacks shaderStorageImageWriteWithoutFormat, which the present pass needs \
                 to write swapchain images",
                ctx.info.name
            )));
        }
        for _ in 0..ACQUIRE_SEMAPHORES {
            self.acquire.push(semaphore(ctx)?);
        }
        self.create(ctx, wanted)
    }

    /// (Re)creates the swapchain for a window of `wanted` pixels. Waits for the device
    /// to go idle first (the old images may still be in flight).
    fn create(&mut self, ctx: &GpuContext, wanted: vk::Extent2D) -> Result<()> {
        let sl = &self.surface_loader;
        let (caps, formats, modes) = unsafe {
            (
                sl.get_physical_device_surface_capabilities(ctx.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?,
                sl.get_physical_device_surface_formats(ctx.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?,
                sl.get_physical_device_surface_present_modes(ctx.physical, self.surface)
                    .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?,
            )
        };
        let usable: Vec<_> = formats
            .iter()
            .copied()
            .filter(|f| {
                let props = unsafe {
                    ctx.instance
                        .get_physical_device_format_properties(ctx.physical, f.format)
                };
                props.optimal_tiling_features.contains(
                    vk::FormatFeatureFlags::STORAGE_IMAGE
                        | vk::FormatFeatureFlags::COLOR_ATTACHMENT
                        | vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND,
                )
            })
            .collect();
        let format = choose_format(&usable).ok_or_else(|| {
            err(format!(
                "no UNORM surface format usable as a storage image and colour attachment \
                 (surface offers {:?})",
                formats.iter().map(|f| f.format).collect::<Vec<_>>()
            ))
        })?;
        let required = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        if !caps.supported_usage_flags.contains(required) {
            return Err(err(format!(
                "surface images support {:?}; the present pass needs STORAGE and \
                 COLOR_ATTACHMENT",
                caps.supported_usage_flags
            )));
        }
        self.readable = caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_SRC);
        let usage = if self.readable {
            required | vk::ImageUsageFlags::TRANSFER_SRC
        } else {
            required
        };
        let extent = choose_extent(&caps, wanted);
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let alpha = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|a| caps.supported_composite_alpha.contains(*a))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let present_mode = choose_present_mode(&modes, self.vsync);

        ctx.wait_idle()?;
        let old = self.swapchain;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(alpha)
            .present_mode(present_mode)
            .clipped(true)
            .old_swapchain(old);
        let swapchain =
            unsafe { self.loader.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR")?;
        self.destroy_images(ctx);
        if old != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(old, None) };
        }
        self.swapchain = swapchain;
        self.format = format.format;
        self.extent = extent;
        self.present_mode = present_mode;
        self.images =
            unsafe { self.loader.get_swapchain_images(swapchain) }.vk("vkGetSwapchainImagesKHR")?;
        for (i, &image) in self.images.iter().enumerate() {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format.format)
                .subresource_range(super::resources::color_range());
            let view = unsafe { ctx.device.create_image_view(&view_info, None) }
                .vk("vkCreateImageView")?;
            super::context::set_name(ctx, image, &format!("swapchain.{i}"));
            self.views.push(view);
            self.rendered.push(semaphore(ctx)?);
        }
        log::info!(
            "swapchain: {} images {}x{} {:?} {:?}",
            self.images.len(),
            extent.width,
            extent.height,
            format.format,
            present_mode
        );
        Ok(())
    }

    /// Recreates the swapchain for a window of `wanted` pixels (after a resize, or when
    /// acquire/present reported it out of date or suboptimal).
    pub fn recreate(&mut self, ctx: &GpuContext, wanted: vk::Extent2D) -> Result<()> {
        self.create(ctx, wanted)
    }

    /// Switches between FIFO (vsync) and MAILBOX/IMMEDIATE; recreates the swapchain.
    pub fn set_vsync(&mut self, ctx: &GpuContext, vsync: bool) -> Result<()> {
        self.vsync = vsync;
        self.create(ctx, self.extent)
    }

    /// Acquires the next image. `None` means the swapchain is out of date: recreate it
    /// and try again. A suboptimal swapchain is used for this frame; the following
    /// [`Swapchain::present`] reports it.
    pub fn acquire(&mut self) -> Result<Option<AcquiredImage>> {
        let wait = self.acquire[self.next_acquire];
        let result = unsafe {
            self.loader
                .acquire_next_image(self.swapchain, u64::MAX, wait, vk::Fence::null())
        };
        let index = match result {
            Ok((index, _suboptimal)) => index,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(None),
            Err(result) => {
                return Err(EngineError::Vk {
                    call: "vkAcquireNextImageKHR",
                    result,
                })
            }
        };
        self.next_acquire = (self.next_acquire + 1) % self.acquire.len();
        let i = index as usize;
        Ok(Some(AcquiredImage {
            index,
            image: self.images[i],
            view: self.views[i],
            format: self.format,
            extent: self.extent,
            wait,
            signal: self.rendered[i],
        }))
    }

    /// Presents an image whose frame has been submitted. Returns false when the
    /// swapchain is out of date or suboptimal and should be recreated.
    pub fn present(&mut self, ctx: &GpuContext, image: &AcquiredImage) -> Result<bool> {
        let swapchains = [self.swapchain];
        let indices = [image.index];
        let waits = [image.signal];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        match unsafe { self.loader.queue_present(ctx.queue, &info) } {
            Ok(suboptimal) => Ok(!suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(result) => Err(EngineError::Vk {
                call: "vkQueuePresentKHR",
                result,
            }),
        }
    }

    fn destroy_images(&mut self, ctx: &GpuContext) {
        unsafe {
            for v in self.views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            for s in self.rendered.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
        }
        self.images.clear();
    }

    /// Destroys the swapchain, its views and semaphores, and the surface. Waits for
    /// the device to go idle first.
    pub fn destroy(&mut self, ctx: &GpuContext) {
        let _ = ctx.wait_idle();
        self.destroy_images(ctx);
        unsafe {
            for s in self.acquire.drain(..) {
                ctx.device.destroy_semaphore(s, None);
            }
            if self.swapchain != vk::SwapchainKHR::null() {
                self.loader.destroy_swapchain(self.swapchain, None);
                self.swapchain = vk::SwapchainKHR::null();
            }
            if self.surface != vk::SurfaceKHR::null() {
                self.surface_loader.destroy_surface(self.surface, None);
                self.surface = vk::SurfaceKHR::null();
            }
        }
    }
}

fn semaphore(ctx: &GpuContext) -> Result<vk::Semaphore> {
    unsafe {
        ctx.device
            .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
    }
    .vk("vkCreateSemaphore")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fmt(format: vk::Format) -> vk::SurfaceFormatKHR {
        vk::SurfaceFormatKHR {
            format,
            color_space: vk::ColorSpaceKHR::SRGB_NONLINEAR,
        }
    }

    #[test]
    fn prefers_unorm_and_never_picks_srgb() {
        let offered = [
            fmt(vk::Format::B8G8R8A8_SRGB),
            fmt(vk::Format::R8G8B8A8_UNORM),
            fmt(vk::Format::B8G8R8A8_UNORM),
        ];
        assert_eq!(
            choose_format(&offered).map(|f| f.format),
            Some(vk::Format::B8G8R8A8_UNORM)
        );
        assert_eq!(
            choose_format(&offered[..2]).map(|f| f.format),
            Some(vk::Format::R8G8B8A8_UNORM)
        );
        assert_eq!(choose_format(&offered[..1]), None);
    }

    #[test]
    fn vsync_is_fifo_and_no_vsync_prefers_mailbox() {
        use vk::PresentModeKHR as P;
        let all = [P::FIFO, P::IMMEDIATE, P::MAILBOX];
        assert_eq!(choose_present_mode(&all, true), P::FIFO);
        assert_eq!(choose_present_mode(&all, false), P::MAILBOX);
        assert_eq!(
            choose_present_mode(&[P::FIFO, P::IMMEDIATE], false),
            P::IMMEDIATE
        );
        assert_eq!(choose_present_mode(&[P::FIFO], false), P::FIFO);
    }

    #[test]
    fn extent_follows_the_surface_unless_it_defers() {
        let mut caps = vk::SurfaceCapabilitiesKHR {
            current_extent: vk::Extent2D {
                width: 640,
                height: 480,
            },
            min_image_extent: vk::Extent2D {
                width: 1,
                height: 1,
            },
            max_image_extent: vk::Extent2D {
                width: 4096,
                height: 4096,
            },
            ..Default::default()
        };
        let wanted = vk::Extent2D {
            width: 800,
            height: 9000,
        };
        assert_eq!(choose_extent(&caps, wanted), caps.current_extent);
        caps.current_extent = vk::Extent2D {
            width: u32::MAX,
            height: u32::MAX,
        };
        assert_eq!(
            choose_extent(&caps, wanted),
            vk::Extent2D {
                width: 800,
                height: 4096
            }
        );
    }
}
