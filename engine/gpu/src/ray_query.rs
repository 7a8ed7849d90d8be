//! Whether a device offers hardware ray queries, and the device extensions
//! they need: what the context enables and the capability check reports
//! (the acceleration structures themselves are `acceleration/`).

use ash::vk;

/// The device extensions ray queries need, all enabled when offered.
pub const DEVICE_EXTENSIONS: [&std::ffi::CStr; 3] = [
    ash::khr::acceleration_structure::NAME,
    ash::khr::ray_query::NAME,
    ash::khr::deferred_host_operations::NAME,
];

/// `minAccelerationStructureScratchOffsetAlignment` of `physical`, a device
/// that [`offered`] ray queries; 1 for one that did not.
pub(crate) fn scratch_offset_alignment(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    offered: bool,
) -> u64 {
    if !offered {
        return 1;
    }
    let mut structures = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut structures);
    unsafe { instance.get_physical_device_properties2(physical, &mut properties) };
    u64::from(
        structures
            .min_acceleration_structure_scratch_offset_alignment
            .max(1),
    )
}

/// Whether `physical` offers hardware ray queries: the extensions of
/// [`DEVICE_EXTENSIONS`] and the `accelerationStructure`, `rayQuery` and
/// `bufferDeviceAddress` features.
pub(crate) fn offered(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    let Ok(extensions) = (unsafe { instance.enumerate_device_extension_properties(physical) })
    else {
        return false;
    };
    let has = |name: &std::ffi::CStr| {
        extensions
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(name))
    };
    if !DEVICE_EXTENSIONS.iter().all(|name| has(name)) {
        return false;
    }
    let mut structures = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut queries = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut features = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut structures)
        .push_next(&mut queries)
        .push_next(&mut f12);
    unsafe { instance.get_physical_device_features2(physical, &mut features) };
    structures.acceleration_structure == vk::TRUE
        && queries.ray_query == vk::TRUE
        && f12.buffer_device_address == vk::TRUE
}

/// The ICD file of the lavapipe with ray queries that `tools/setup` unpacks
/// beside an older system driver (`$XDG_CACHE_HOME/weft/mesa/lvp_icd.json`,
/// `~/.cache` by default), or `WEFT_RAY_QUERY_ICD` where set: what the
/// hardware ray tracing tests, and a user on such a system, point
/// `VK_ICD_FILENAMES` at. `None` when neither names an existing file.
pub fn unpacked_icd() -> Option<std::path::PathBuf> {
    let path = match std::env::var_os("WEFT_RAY_QUERY_ICD") {
        Some(path) => std::path::PathBuf::from(path),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(std::path::PathBuf::from)
            .or_else(|| std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".cache")))?
            .join("weft/mesa/lvp_icd.json"),
    };
    path.is_file().then_some(path)
}
