//! The ray tracer's hardware backend (ray queries, docs/hardware_rt.md)
//! against its software one, in a process of its own: where the default
//! device has no ray queries (lavapipe before Mesa 24.1), this binary runs
//! on the lavapipe `tools/setup` unpacks beside it
//! ([`weft_gpu::ray_query::unpacked_icd`]); a GPU with ray queries is used
//! as it is. A device without ray queries fails these tests rather than
//! skipping them.

mod backends;
mod structures;

/// A validating context on a device with ray queries.
pub fn gpu() -> weft_gpu::Gpu {
    static SELECT: std::sync::Once = std::sync::Once::new();
    SELECT.call_once(|| {
        let offered = weft_tests::gpu().info().shaders.ray_query;
        if let Some(icd) = weft_gpu::ray_query::unpacked_icd().filter(|_| !offered) {
            // Every test comes here first, and the Once holds the others
            // back until the driver is chosen (the loader reads the
            // variable at each instance it creates).
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
