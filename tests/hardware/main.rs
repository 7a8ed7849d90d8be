//! The ray tracer's hardware backend (ray queries, docs/hardware_rt.md)
//! against its software one, in a process of its own: where the system's
//! lavapipe has no ray queries (Mesa before 24.1), this binary runs on the
//! one `tools/setup` unpacks beside it
//! ([`weft_gpu::ray_query::unpacked_icd`]), selected before any Vulkan call.
//! A device without ray queries fails these tests rather than skipping them.

mod backends;

/// A validating context on a device with ray queries.
pub fn gpu() -> weft_gpu::Gpu {
    static SELECT: std::sync::Once = std::sync::Once::new();
    SELECT.call_once(|| {
        if let Some(icd) = weft_gpu::ray_query::unpacked_icd() {
            // Every test comes here before its first Vulkan call, and the
            // Once holds the others back until the driver is chosen.
            std::env::set_var("VK_ICD_FILENAMES", icd);
        }
    });
    let gpu = weft_tests::gpu();
    assert!(
        gpu.info().shaders.ray_query,
        "the device `{}` offers no ray queries: run tools/setup (it unpacks Mesa 25's lavapipe)",
        gpu.info().name
    );
    gpu
}
