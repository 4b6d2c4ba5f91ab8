//! Instance and device creation. Prefers a discrete GPU, falls back to whatever exists
//! (lavapipe on CI); `DVR_DEVICE=<substring>` forces one by name. The device is always
//! headless here: the explorer adds a surface on top of the same context.

use super::validation;
use crate::error::{EngineError, Result, VkContext};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::sync::Mutex;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Held while a context is created or destroyed. Loading and unloading the layers and
/// the driver (lavapipe's LLVM set-up among them) from several threads at once is not
/// safe on every stack: a test binary whose tests each make a context crashed in it.
/// Rendering itself runs in parallel; only these few milliseconds are serial.
static LIFECYCLE: Mutex<()> = Mutex::new(());

fn lifecycle() -> std::sync::MutexGuard<'static, ()> {
    LIFECYCLE
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// What the rest of the engine needs to know about the chosen device.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    /// `VkPhysicalDeviceDriverProperties::driverID`: which driver this is, as the
    /// driver itself says (e.g. `MESA_LLVMPIPE` for lavapipe), not guessed from the name.
    pub driver_id: vk::DriverId,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period: f64,
    pub max_image_dimension_3d: u32,
    /// `maxImageDimension2D`: the widest and tallest 2D image.
    pub max_image_dimension_2d: u32,
    pub max_memory_allocation_size: u64,
    pub max_storage_buffer_range: u32,
    pub max_push_constants_size: u32,
    /// Size of the largest device-local memory heap.
    pub device_local_heap: u64,
    /// `shaderStorageImageWriteWithoutFormat` (enabled when present): the present pass
    /// writes swapchain images of whatever format the surface offers.
    pub storage_write_without_format: bool,
}

/// Device memory in use (see [`GpuContext::memory_in_use`]), bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuMemory {
    /// Used by live allocations.
    pub allocated: u64,
    /// Held in memory blocks (allocated and free).
    pub reserved: u64,
}

/// Instance, device, queue and allocator: everything that lives as long as the program.
pub struct GpuContext {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub info: DeviceInfo,
    pub push_descriptor: ash::khr::push_descriptor::Device,
    /// Present when the debug-utils extension is on: names passes in captures/validation.
    pub debug_utils: Option<ash::ext::debug_utils::Device>,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    pub validation_enabled: bool,
    /// À-trous levels read their window through shared memory ([`ContextOptions::shared_tiles`]).
    pub shared_tiles: bool,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    one_shot_pool: vk::CommandPool,
    /// Every pipeline built through [`GpuContext::pipeline`], destroyed with the device.
    pub(crate) pipelines: super::pipeline::PipelineCache,
}

/// Options for [`GpuContext::new`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable the validation layer (defaults to the `DVR_VALIDATION` environment variable).
    pub validation: Option<bool>,
    /// Substring of the device name to force (defaults to `DVR_DEVICE`).
    pub device: Option<String>,
    /// Instance extensions a surface needs (the explorer passes ash-window's list).
    pub instance_extensions: Vec<*const c_char>,
    /// Device extensions beyond the engine's own (the explorer adds the swapchain).
    pub device_extensions: Vec<*const c_char>,
    /// Whether à-trous levels read their window through workgroup shared memory
    /// (include/atrous_tile.glsl). Defaults to `DVR_SHARED_TILES=0|1`, else to on for
    /// every device but a CPU implementation (lavapipe, where tiles are slower).
    pub shared_tiles: Option<bool>,
}

/// `DVR_SHARED_TILES`: `1`/`0` forces shared-memory tiles on or off; unset leaves the
/// choice to the device type.
fn shared_tiles_requested() -> Result<Option<bool>> {
    match std::env::var("DVR_SHARED_TILES").as_deref() {
        Err(_) | Ok("") => Ok(None),
        Ok("1") => Ok(Some(true)),
        Ok("0") => Ok(Some(false)),
        Ok(other) => Err(EngineError::InvalidSetting {
            name: "DVR_SHARED_TILES",
            value: other.to_string(),
            allowed: "1 (shared-memory tiles on), 0 (off) or unset (on for GPUs)".into(),
        }),
    }
}

fn device_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

impl GpuContext {
    pub fn new(options: ContextOptions) -> Result<Self> {
        let _serial = lifecycle();
        // SAFETY: loading the Vulkan loader library; failure is reported, not unwrapped.
        let entry =
            unsafe { ash::Entry::load() }.map_err(|e| EngineError::NoLoader(e.to_string()))?;
        let want_validation = options.validation.unwrap_or_else(validation::requested);
        let layers_available = unsafe { entry.enumerate_instance_layer_properties() }
            .vk("vkEnumerateInstanceLayerProperties")?;
        let has_layer = layers_available
            .iter()
            .any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
        if want_validation && !has_layer {
            return Err(EngineError::NoDevice(
                "DVR_VALIDATION=1 but VK_LAYER_KHRONOS_validation is not installed \
                 (apt-get install vulkan-validationlayers)"
                    .into(),
            ));
        }
        let validation_enabled = want_validation && has_layer;

        let app_info = vk::ApplicationInfo::default()
            .application_name(c"dvr")
            .engine_name(c"dvr")
            .api_version(vk::API_VERSION_1_3);
        let mut extensions = options.instance_extensions.clone();
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        let mut layers = Vec::new();
        if validation_enabled {
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
            layers.push(VALIDATION_LAYER.as_ptr());
        }
        let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
        let mut messenger_info = validation::messenger_info();
        let mut instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_extension_names(&extensions)
            .enabled_layer_names(&layers);
        if validation_enabled {
            instance_info = instance_info
                .push_next(&mut validation_features)
                .push_next(&mut messenger_info);
        }
        let instance = unsafe { entry.create_instance(&instance_info, None) }
            .map_err(|e| EngineError::NoDevice(format!("vkCreateInstance failed: {e}")))?;

        let messenger = if validation_enabled {
            let du = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let m = unsafe { du.create_debug_utils_messenger(&validation::messenger_info(), None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            Some((du, m))
        } else {
            None
        };

        let (physical, info, queue_family) = pick_device(&instance, options.device.clone())?;

        let mut ext_names = vec![ash::khr::push_descriptor::NAME.as_ptr()];
        ext_names.extend(options.device_extensions.iter().copied());
        let supported = unsafe { instance.get_physical_device_features(physical) };
        let features = vk::PhysicalDeviceFeatures::default()
            .shader_storage_image_extended_formats(
                supported.shader_storage_image_extended_formats == vk::TRUE,
            )
            .shader_storage_image_write_without_format(
                supported.shader_storage_image_write_without_format == vk::TRUE,
            );
        // dynamicRendering (core in 1.3, always supported) lets the explorer's UI draw
        // into a swapchain image without a render pass, so the render graph keeps
        // every layout transition.
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .synchronization2(true)
            .maintenance4(true)
            .dynamic_rendering(true);
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&ext_names)
            .enabled_features(&features)
            .push_next(&mut f13);
        let device =
            unsafe { instance.create_device(physical, &device_info, None) }.map_err(|e| {
                EngineError::NoDevice(format!("{}: vkCreateDevice failed: {e}", info.name))
            })?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let push_descriptor = ash::khr::push_descriptor::Device::new(&instance, &device);
        let debug_utils = Some(ash::ext::debug_utils::Device::new(&instance, &device));

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|source| EngineError::Alloc {
            what: "allocator".into(),
            source,
        })?;

        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let one_shot_pool =
            unsafe { device.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")?;

        let shared_tiles = match options.shared_tiles {
            Some(on) => on,
            None => {
                shared_tiles_requested()?.unwrap_or(info.device_type != vk::PhysicalDeviceType::CPU)
            }
        };
        log::info!("dvr: using {} ({:?})", info.name, info.device_type);
        Ok(Self {
            entry,
            instance,
            physical,
            device,
            queue,
            queue_family,
            info,
            push_descriptor,
            debug_utils,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            validation_enabled,
            shared_tiles,
            messenger,
            one_shot_pool,
            pipelines: Default::default(),
        })
    }

    /// Device memory this context's allocator holds: what its live allocations use, and
    /// what its memory blocks reserve (the allocations plus free room in the blocks).
    /// A long session whose figures keep growing leaks device memory.
    pub fn memory_in_use(&self) -> GpuMemory {
        let report = self
            .allocator
            .lock()
            .map(|a| a.generate_report())
            .unwrap_or_else(|p| p.into_inner().generate_report());
        GpuMemory {
            allocated: report.total_allocated_bytes,
            reserved: report.total_capacity_bytes,
        }
    }

    /// Headless context with options from the environment (`DVR_DEVICE`, `DVR_VALIDATION`).
    pub fn headless() -> Result<Self> {
        Self::new(ContextOptions::default())
    }

    /// Records `f` into a fresh command buffer, submits it and waits. For set-up work only
    /// (the per-frame path goes through [`crate::graph`] and the frame loop).
    pub fn submit_and_wait(&self, f: impl FnOnce(vk::CommandBuffer) -> Result<()>) -> Result<()> {
        let d = &self.device;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.one_shot_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { d.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?[0];
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { d.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
            f(cmd)?;
            unsafe { d.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
            let fence = unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) }
                .vk("vkCreateFence")?;
            let cmds = [cmd];
            let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
            let r = unsafe { d.queue_submit(self.queue, &submit, fence) }
                .vk("vkQueueSubmit")
                .and_then(|_| {
                    unsafe { d.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")
                });
            unsafe { d.destroy_fence(fence, None) };
            r
        })();
        unsafe { d.free_command_buffers(self.one_shot_pool, &[cmd]) };
        result
    }

    pub fn wait_idle(&self) -> Result<()> {
        unsafe { self.device.device_wait_idle() }.vk("vkDeviceWaitIdle")
    }
}

/// Names an object for validation messages and GPU captures.
pub fn set_name<H: vk::Handle>(ctx: &GpuContext, handle: H, name: &str) {
    if let (Some(du), Ok(cname)) = (&ctx.debug_utils, std::ffi::CString::new(name)) {
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&cname);
        unsafe {
            let _ = du.set_debug_utils_object_name(&info);
        }
    }
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            let _serial = lifecycle();
            let pipelines = std::mem::take(&mut self.pipelines);
            pipelines.destroy(self);
            self.device.destroy_command_pool(self.one_shot_pool, None);
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some((du, m)) = self.messenger.take() {
                du.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

fn pick_device(
    instance: &ash::Instance,
    forced: Option<String>,
) -> Result<(vk::PhysicalDevice, DeviceInfo, u32)> {
    let forced = forced.or_else(|| std::env::var("DVR_DEVICE").ok().filter(|s| !s.is_empty()));
    let physicals = unsafe { instance.enumerate_physical_devices() }
        .map_err(|e| EngineError::NoDevice(format!("vkEnumeratePhysicalDevices failed: {e}")))?;
    if physicals.is_empty() {
        return Err(EngineError::NoDevice(
            "the loader reports no devices".into(),
        ));
    }
    let mut candidates = Vec::new();
    let mut names = Vec::new();
    for &p in &physicals {
        let props = unsafe { instance.get_physical_device_properties(p) };
        let name = props
            .device_name_as_c_str()
            .map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_else(|_| "unnamed device".into());
        names.push(name.clone());
        if props.api_version < vk::API_VERSION_1_3 {
            continue;
        }
        let families = unsafe { instance.get_physical_device_queue_family_properties(p) };
        let Some(family) = families.iter().position(|f| {
            f.queue_flags.contains(vk::QueueFlags::COMPUTE) && f.timestamp_valid_bits > 0
        }) else {
            continue;
        };
        let exts = unsafe { instance.enumerate_device_extension_properties(p) }.unwrap_or_default();
        if !exts
            .iter()
            .any(|e| e.extension_name_as_c_str().ok() == Some(ash::khr::push_descriptor::NAME))
        {
            continue;
        }
        let info = DeviceInfo {
            name,
            device_type: props.device_type,
            driver_id: driver_id(instance, p),
            timestamp_period: props.limits.timestamp_period as f64,
            max_image_dimension_3d: props.limits.max_image_dimension3_d,
            max_image_dimension_2d: props.limits.max_image_dimension2_d,
            max_memory_allocation_size: max_allocation(instance, p),
            max_storage_buffer_range: props.limits.max_storage_buffer_range,
            max_push_constants_size: props.limits.max_push_constants_size,
            device_local_heap: largest_device_heap(instance, p),
            storage_write_without_format: unsafe { instance.get_physical_device_features(p) }
                .shader_storage_image_write_without_format
                == vk::TRUE,
        };
        candidates.push((p, info, family as u32));
    }
    if let Some(want) = forced {
        let w = want.to_lowercase();
        return candidates
            .into_iter()
            .find(|(_, i, _)| i.name.to_lowercase().contains(&w))
            .ok_or(EngineError::DeviceNotFound {
                wanted: want,
                available: names.join(", "),
            });
    }
    candidates.sort_by_key(|(_, i, _)| device_rank(i.device_type));
    candidates.into_iter().next().ok_or_else(|| {
        EngineError::NoDevice(format!(
            "none of [{}] offers Vulkan 1.3 compute with timestamps and VK_KHR_push_descriptor",
            names.join(", ")
        ))
    })
}

fn largest_device_heap(instance: &ash::Instance, p: vk::PhysicalDevice) -> u64 {
    let mem = unsafe { instance.get_physical_device_memory_properties(p) };
    mem.memory_heaps_as_slice()
        .iter()
        .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .map(|h| h.size)
        .max()
        .unwrap_or(0)
}

fn driver_id(instance: &ash::Instance, p: vk::PhysicalDevice) -> vk::DriverId {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    unsafe { instance.get_physical_device_properties2(p, &mut props2) };
    driver.driver_id
}

impl DeviceInfo {
    /// lavapipe (Mesa's llvmpipe driver), whose shader loops run under an iteration
    /// limiter (see `renderer::MAX_SAMPLES_PER_DISPATCH`).
    pub fn is_llvmpipe(&self) -> bool {
        self.driver_id == vk::DriverId::MESA_LLVMPIPE
    }
}

fn max_allocation(instance: &ash::Instance, p: vk::PhysicalDevice) -> u64 {
    let mut m3 = vk::PhysicalDeviceMaintenance3Properties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut m3);
    unsafe { instance.get_physical_device_properties2(p, &mut props2) };
    m3.max_memory_allocation_size
}
