//! Creating the context: the instance (with the validation layer and its
//! messenger), the physical device chosen and the logical device with every
//! optional feature the device offers.

use super::*;

/// Owns the instance and messenger until the device exists, destroying them
/// if creation fails part way.
pub(super) struct InstanceGuard {
    pub(super) instance: Option<ash::Instance>,
    pub(super) debug: DebugParts,
}

impl InstanceGuard {
    pub(super) fn instance(&self) -> Result<&ash::Instance, GpuError> {
        self.instance.as_ref().ok_or(GpuError::Vulkan {
            call: "vkCreateInstance",
            result: vk::Result::ERROR_INITIALIZATION_FAILED,
        })
    }

    /// Hands ownership on; the guard then destroys nothing.
    pub(super) fn release(mut self) -> Result<(ash::Instance, DebugParts), GpuError> {
        let instance = self.instance.take().ok_or(GpuError::Vulkan {
            call: "vkCreateInstance",
            result: vk::Result::ERROR_INITIALIZATION_FAILED,
        })?;
        Ok((instance, self.debug.take()))
    }
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        unsafe {
            if let Some((loader, messenger)) = &self.debug {
                loader.destroy_debug_utils_messenger(*messenger, None);
            }
            if let Some(instance) = &self.instance {
                instance.destroy_instance(None);
            }
        }
    }
}

pub(super) fn destroy_base(instance: &ash::Instance, debug: &DebugParts, device: &ash::Device) {
    unsafe {
        device.destroy_device(None);
        if let Some((loader, messenger)) = debug {
            loader.destroy_debug_utils_messenger(*messenger, None);
        }
        instance.destroy_instance(None);
    }
}

pub(super) fn messenger_info(
    log: &Arc<ValidationLog>,
) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(validation::callback))
        .user_data(Arc::as_ptr(log) as *mut c_void)
}

pub(super) fn create_instance(
    entry: &ash::Entry,
    validate: bool,
    log: &Arc<ValidationLog>,
    surface_extensions: &[*const c_char],
) -> Result<ash::Instance, GpuError> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"weft")
        .engine_name(c"weft")
        .api_version(vk::API_VERSION_1_3);
    let mut layers = Vec::new();
    let mut extensions = surface_extensions.to_vec();
    if validate {
        let available = unsafe { entry.enumerate_instance_layer_properties() }
            .call("vkEnumerateInstanceLayerProperties")?;
        let found = available
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER));
        if !found {
            return Err(GpuError::NoValidationLayer);
        }
        layers.push(VALIDATION_LAYER.as_ptr());
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    let enabled = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled);
    let mut messenger = messenger_info(log);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if validate {
        info = info.push_next(&mut features).push_next(&mut messenger);
    }
    unsafe { entry.create_instance(&info, None) }.call("vkCreateInstance")
}

pub(super) fn choose_device(
    instance: &ash::Instance,
    wanted: Option<&str>,
    presenting: bool,
) -> Result<(vk::PhysicalDevice, DeviceInfo, u32), GpuError> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.call("vkEnumeratePhysicalDevices")?;
    let mut candidates = Vec::new();
    let mut names = Vec::new();
    for physical in devices {
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let name = props
            .device_name_as_c_str()
            .map(|c| c.to_string_lossy().into_owned())
            .unwrap_or_default();
        names.push(name.clone());
        if props.api_version < vk::API_VERSION_1_3 {
            continue;
        }
        if let Some(w) = wanted {
            if !name.to_lowercase().contains(&w.to_lowercase()) {
                continue;
            }
        }
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let needed = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
        let Some((family, props_family)) = families
            .iter()
            .enumerate()
            .find(|(_, f)| f.queue_flags.contains(needed))
        else {
            continue;
        };
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
        unsafe { instance.get_physical_device_features2(physical, &mut f2) };
        let f2 = f2.features;
        if f13.synchronization2 == vk::FALSE || f13.maintenance4 == vk::FALSE {
            continue;
        }
        if presenting && !has_swapchain(instance, physical) {
            continue;
        }
        let shaders = ShaderSupport::query(instance, physical);
        let info = DeviceInfo {
            name,
            kind: DeviceKind::from_vk(props.device_type),
            timestamp_period: props.limits.timestamp_period,
            timestamps: props_family.timestamp_valid_bits > 0,
            pipeline_statistics: f2.pipeline_statistics_query == vk::TRUE,
            depth_clamp: f2.depth_clamp == vk::TRUE,
            fragment_stores: f2.fragment_stores_and_atomics == vk::TRUE,
            acceleration_scratch_alignment: crate::ray_query::scratch_offset_alignment(
                instance,
                physical,
                shaders.ray_query,
            ),
            shaders,
            max_image_dimension: props.limits.max_image_dimension2_d,
            max_texel_buffer_elements: props.limits.max_texel_buffer_elements,
            buffer_image_granularity: props.limits.buffer_image_granularity,
            attachment_sample_counts: (props.limits.framebuffer_color_sample_counts
                & props.limits.framebuffer_depth_sample_counts)
                .as_raw(),
        };
        candidates.push((physical, info, family as u32));
    }
    candidates.sort_by_key(|(_, info, _)| info.kind);
    candidates
        .into_iter()
        .next()
        .ok_or_else(|| GpuError::NoDevice {
            wanted: wanted.map(str::to_string),
            available: if names.is_empty() {
                "none".into()
            } else {
                names.join(", ")
            },
        })
}

pub(super) fn create_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    family: u32,
    info: &DeviceInfo,
    presenting: bool,
) -> Result<ash::Device, GpuError> {
    let priorities = [1.0];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .maintenance4(true);
    let shaders = &info.shaders;
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
        .shader_float16(shaders.float16)
        .shader_int8(shaders.int8);
    let core = vk::PhysicalDeviceFeatures::default()
        .pipeline_statistics_query(info.pipeline_statistics)
        .depth_clamp(info.depth_clamp)
        .fragment_stores_and_atomics(info.fragment_stores)
        .geometry_shader(shaders.geometry)
        .shader_float64(shaders.float64)
        .shader_int64(shaders.int64)
        .shader_int16(shaders.int16);
    let ray_query = shaders.ray_query;
    f12 = f12.buffer_device_address(ray_query);
    let mut structures =
        vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut queries = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    let mut features = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut f12)
        .push_next(&mut f13);
    if ray_query {
        features = features.push_next(&mut structures).push_next(&mut queries);
    }
    let mut extensions = if presenting {
        vec![ash::khr::swapchain::NAME.as_ptr()]
    } else {
        Vec::new()
    };
    if ray_query {
        extensions.extend(crate::ray_query::DEVICE_EXTENSIONS.map(|name| name.as_ptr()));
    }
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&extensions)
        .push_next(&mut features);
    unsafe { instance.create_device(physical, &info, None) }.call("vkCreateDevice")
}

/// Whether the device offers `VK_KHR_swapchain`.
pub(super) fn has_swapchain(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    unsafe { instance.enumerate_device_extension_properties(physical) }
        .map(|all| {
            all.iter()
                .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::swapchain::NAME))
        })
        .unwrap_or(false)
}
