//! The Vulkan context: instance (with optional validation and synchronization
//! validation), the chosen physical device, a device with synchronization2 and
//! maintenance4, one queue, a command pool and the memory allocator.

mod setup;

use setup::*;

use crate::capabilities::ShaderSupport;
use crate::error::{GpuError, VkCall};
use crate::validation::{self, ValidationCounts, ValidationLog};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use gpu_allocator::{AllocationSizes, AllocatorDebugSettings};
use std::ffi::{c_char, c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex, MutexGuard};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How to create the context.
#[derive(Debug, Clone, Default)]
pub struct GpuOptions {
    /// Enable the Khronos validation layer with synchronization validation.
    pub validation: bool,
    /// Pick the first device whose name contains this (case-insensitive).
    pub device: Option<String>,
}

/// What was chosen, for printing and reports.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceInfo {
    /// The driver's device name, as `--device` matches it.
    pub name: String,
    /// Discrete, integrated, CPU (lavapipe), ...
    pub kind: DeviceKind,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period: f32,
    /// Whether the graphics queue writes timestamps.
    pub timestamps: bool,
    /// Whether pipeline-statistics queries are available (and enabled).
    pub pipeline_statistics: bool,
    /// Whether pipelines may clamp depth instead of clipping (`depthClamp`, enabled when offered).
    pub depth_clamp: bool,
    /// Whether fragment shaders may write storage images and buffers and use
    /// atomics (`fragmentStoresAndAtomics`, enabled when offered): debug views
    /// count invocations this way.
    pub fragment_stores: bool,
    /// The optional shader capabilities offered, each enabled when offered
    /// (`geometryShader` for `gl_PrimitiveID` in the mesh-density view, wider
    /// and narrower number types, subgroup operations): pipelines whose
    /// shaders need more are refused with the missing feature named.
    pub shaders: ShaderSupport,
    /// The largest width or height of a 2D image (`maxImageDimension2D`):
    /// plans with a larger image are refused before any is created.
    pub max_image_dimension: u32,
    /// The most texels a texel buffer's view may cover
    /// (`maxTexelBufferElements`): larger scene tables are refused.
    pub max_texel_buffer_elements: u32,
    /// Bytes a buffer and an optimally tiled image in one allocation keep
    /// apart (`bufferImageGranularity`): transient buffers are placed on
    /// multiples of it, so none shares a page with an image.
    pub buffer_image_granularity: u64,
    /// Where acceleration-structure builds may start their scratch
    /// (`minAccelerationStructureScratchOffsetAlignment`; 1 without ray
    /// queries), read once rather than at each frame's build.
    pub acceleration_scratch_alignment: u64,
    /// Sample counts colour and depth attachments may have, as a mask of
    /// counts (bit n: 2^n samples; `framebufferColorSampleCounts` and
    /// `framebufferDepthSampleCounts` together): plans with another count
    /// are refused before any image is created.
    pub attachment_sample_counts: u32,
}

/// The physical device type, in preference order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum DeviceKind {
    /// A separate GPU: preferred.
    Discrete,
    /// A GPU sharing memory with the CPU.
    Integrated,
    /// A GPU exposed by a hypervisor.
    Virtual,
    /// A software rasteriser such as lavapipe: the fallback.
    Cpu,
    /// Anything else the driver reports.
    Other,
}

impl DeviceKind {
    fn from_vk(t: vk::PhysicalDeviceType) -> Self {
        match t {
            vk::PhysicalDeviceType::DISCRETE_GPU => Self::Discrete,
            vk::PhysicalDeviceType::INTEGRATED_GPU => Self::Integrated,
            vk::PhysicalDeviceType::VIRTUAL_GPU => Self::Virtual,
            vk::PhysicalDeviceType::CPU => Self::Cpu,
            _ => Self::Other,
        }
    }
}

/// The Vulkan context every other part of the crate works through.
pub struct Gpu {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: DebugParts,
    debug_device: Option<ash::ext::debug_utils::Device>,
    /// The acceleration-structure entry points, with hardware ray queries.
    acceleration: Option<ash::khr::acceleration_structure::Device>,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    command_pool: vk::CommandPool,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    info: DeviceInfo,
    log: Arc<ValidationLog>,
    presenting: bool,
}

impl Gpu {
    /// Creates the instance, picks a device and creates everything on it.
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
        Self::create(options, None)
    }

    /// Like [`Gpu::new`], with the surface extensions of `display` and the
    /// swapchain extension enabled, so windows on that display can be presented
    /// to; headless contexts leave them off.
    pub fn for_display(
        options: &GpuOptions,
        display: raw_window_handle::RawDisplayHandle,
    ) -> Result<Self, GpuError> {
        let extensions = ash_window::enumerate_required_extensions(display)
            .call("vkEnumerateInstanceExtensionProperties")?;
        Self::create(options, Some(extensions))
    }

    fn create(
        options: &GpuOptions,
        surface_extensions: Option<&[*const c_char]>,
    ) -> Result<Self, GpuError> {
        let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::Loader(e.to_string()))?;
        let log = ValidationLog::new();
        let presenting = surface_extensions.is_some();
        let mut guard = InstanceGuard {
            instance: Some(create_instance(
                &entry,
                options.validation,
                &log,
                surface_extensions.unwrap_or_default(),
            )?),
            debug: None,
        };
        if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, guard.instance()?);
            let info = messenger_info(&log);
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .call("vkCreateDebugUtilsMessengerEXT")?;
            guard.debug = Some((loader, messenger));
        }
        let (physical, info, queue_family) =
            choose_device(guard.instance()?, options.device.as_deref(), presenting)?;
        let device = create_device(guard.instance()?, physical, queue_family, &info, presenting)?;
        let (instance, debug) = guard.release()?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let command_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
            Ok(pool) => pool,
            Err(result) => {
                destroy_base(&instance, &debug, &device);
                return Err(GpuError::Vulkan {
                    call: "vkCreateCommandPool",
                    result,
                });
            }
        };
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: AllocatorDebugSettings::default(),
            buffer_device_address: info.shaders.ray_query,
            allocation_sizes: AllocationSizes::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                unsafe { device.destroy_command_pool(command_pool, None) };
                destroy_base(&instance, &debug, &device);
                return Err(GpuError::Allocation {
                    what: "the allocator".into(),
                    message: e.to_string(),
                });
            }
        };
        let debug_device = debug
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));
        let acceleration = info
            .shaders
            .ray_query
            .then(|| ash::khr::acceleration_structure::Device::new(&instance, &device));
        Ok(Self {
            entry,
            instance,
            debug,
            debug_device,
            acceleration,
            physical,
            device,
            queue,
            queue_family,
            command_pool,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            info,
            log,
            presenting,
        })
    }

    /// Whether the swapchain extension is on (made by [`Gpu::for_display`]).
    pub fn can_present(&self) -> bool {
        self.presenting
    }

    /// The logical device, for recording commands.
    pub fn device(&self) -> &ash::Device {
        &self.device
    }

    /// The instance.
    pub fn instance(&self) -> &ash::Instance {
        &self.instance
    }

    /// The loader entry points.
    pub fn entry(&self) -> &ash::Entry {
        &self.entry
    }

    /// The chosen physical device.
    pub fn physical_device(&self) -> vk::PhysicalDevice {
        self.physical
    }

    /// The one graphics+compute queue.
    pub fn queue(&self) -> vk::Queue {
        self.queue
    }

    /// Family index of `queue`.
    pub fn queue_family(&self) -> u32 {
        self.queue_family
    }

    /// The command pool (resettable buffers) on `queue_family`.
    pub fn command_pool(&self) -> vk::CommandPool {
        self.command_pool
    }

    /// Name, type and timestamp support of the chosen device.
    pub fn info(&self) -> &DeviceInfo {
        &self.info
    }

    /// The acceleration-structure entry points, on a device with hardware
    /// ray queries ([`ShaderSupport::ray_query`]).
    pub fn acceleration(&self) -> Option<&ash::khr::acceleration_structure::Device> {
        self.acceleration.as_ref()
    }

    /// The memory allocator.
    pub fn allocator(&self) -> MutexGuard<'_, Allocator> {
        self.allocator
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Debug-utils device functions when validation is on (object names, labels).
    pub fn debug_utils(&self) -> Option<&ash::ext::debug_utils::Device> {
        self.debug_device.as_ref()
    }

    /// The validation messages; keep a clone to read leak reports after drop.
    pub fn validation(&self) -> Arc<ValidationLog> {
        Arc::clone(&self.log)
    }

    /// Message counts so far.
    pub fn validation_counts(&self) -> ValidationCounts {
        self.log.counts()
    }

    /// Device memory in use by live allocations, and reserved in blocks.
    pub fn memory_report(&self) -> MemoryReport {
        let report = self.allocator().generate_report();
        MemoryReport {
            allocated_bytes: report.total_allocated_bytes,
            reserved_bytes: report.total_capacity_bytes,
        }
    }

    /// Whether optimally tiled images of a format can be sampled (and blitted)
    /// with linear filtering.
    pub fn linear_filter(&self, format_raw: i32) -> bool {
        let props = unsafe {
            self.instance.get_physical_device_format_properties(
                self.physical,
                vk::Format::from_raw(format_raw),
            )
        };
        props
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
    }

    /// Waits until the device is idle.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        unsafe { self.device.device_wait_idle() }.call("vkDeviceWaitIdle")
    }

    /// Records commands into a fresh command buffer, submits them and waits.
    pub fn one_shot(
        &self,
        record: impl FnOnce(vk::CommandBuffer) -> Result<(), GpuError>,
    ) -> Result<(), GpuError> {
        let cmd = self.allocate_command_buffer()?;
        let result = (|| {
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            unsafe { self.device.begin_command_buffer(cmd, &begin) }
                .call("vkBeginCommandBuffer")?;
            record(cmd)?;
            unsafe { self.device.end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
            self.submit_and_wait(cmd)
        })();
        unsafe { self.device.free_command_buffers(self.command_pool, &[cmd]) };
        result
    }

    /// Allocates one primary command buffer from the pool.
    pub fn allocate_command_buffer(&self) -> Result<vk::CommandBuffer, GpuError> {
        let info = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let buffers = unsafe { self.device.allocate_command_buffers(&info) }
            .call("vkAllocateCommandBuffers")?;
        buffers.into_iter().next().ok_or(GpuError::Vulkan {
            call: "vkAllocateCommandBuffers",
            result: vk::Result::ERROR_UNKNOWN,
        })
    }

    /// Submits one recorded command buffer and blocks until it has executed.
    pub fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .call("vkCreateFence")?;
        let result = self.submit_and_wait_on(cmd, fence);
        unsafe { self.device.destroy_fence(fence, None) };
        result
    }

    /// [`Gpu::submit_and_wait`] on a fence the caller keeps (unsignalled on
    /// entry, and again on return), for work submitted every frame.
    pub fn submit_and_wait_on(
        &self,
        cmd: vk::CommandBuffer,
        fence: vk::Fence,
    ) -> Result<(), GpuError> {
        let buffers = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&buffers);
        unsafe {
            self.device
                .queue_submit2(self.queue, &[submit], fence)
                .call("vkQueueSubmit2")?;
            self.device
                .wait_for_fences(&[fence], true, u64::MAX)
                .call("vkWaitForFences")?;
            self.device.reset_fences(&[fence]).call("vkResetFences")
        }
    }

    /// Gives a Vulkan object a name that validation messages will show.
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // Naming is a debugging aid; a failure changes nothing the user sees.
        let _ = unsafe { debug.set_debug_utils_object_name(&info) };
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_command_pool(self.command_pool, None);
        }
        destroy_base(&self.instance, &self.debug, &self.device);
    }
}

/// Device memory figures from the allocator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct MemoryReport {
    /// Bytes in live allocations (aliased transient blocks count once).
    pub allocated_bytes: u64,
    /// Bytes of device memory the allocator holds.
    pub reserved_bytes: u64,
}

type DebugParts = Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>;
