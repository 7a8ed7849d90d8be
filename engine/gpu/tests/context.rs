//! The Vulkan context comes up with validation and goes down without leaks.

use weft_gpu::{DeviceKind, Gpu, GpuError, GpuOptions};

#[test]
fn creates_and_destroys_cleanly_under_validation() {
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("a Vulkan 1.3 device");
    assert!(!gpu.info().name.is_empty());
    assert!(gpu.debug_utils().is_some());
    gpu.one_shot(|_| Ok(())).expect("an empty submission");
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}

#[test]
fn picks_a_device_by_name_substring() {
    let any = Gpu::new(&GpuOptions::default()).expect("a device");
    let name = any.info().name.clone();
    let kind = any.info().kind;
    drop(any);
    let fragment: String = name.chars().take(4).collect::<String>().to_uppercase();
    let picked = Gpu::new(&GpuOptions {
        validation: false,
        device: Some(fragment),
    })
    .expect("the same device by substring");
    assert_eq!(picked.info().name, name);
    assert_eq!(picked.info().kind, kind);
    assert!(matches!(
        kind,
        DeviceKind::Discrete
            | DeviceKind::Integrated
            | DeviceKind::Cpu
            | DeviceKind::Virtual
            | DeviceKind::Other
    ));
}

#[test]
fn unknown_device_name_lists_what_exists() {
    let err = Gpu::new(&GpuOptions {
        validation: false,
        device: Some("no-such-gpu-xyz".into()),
    })
    .err()
    .expect("no match");
    let GpuError::NoDevice { wanted, available } = &err else {
        panic!("expected NoDevice, got {err}");
    };
    assert_eq!(wanted.as_deref(), Some("no-such-gpu-xyz"));
    assert!(!available.is_empty());
    assert!(err
        .to_string()
        .starts_with("no suitable Vulkan 1.3 device matching \"no-such-gpu-xyz\""));
}

/// A compute shader using optional features: 64-bit and 16-bit integers,
/// 16-bit floats and a subgroup reduction.
const OPTIONAL_FEATURES: &str = "#version 450
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_shader_explicit_arithmetic_types : require
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Values { uint64_t total; float v[]; };
void main() {
    float16_t half_value = float16_t(v[gl_GlobalInvocationID.x]);
    int16_t small = int16_t(gl_LocalInvocationIndex);
    v[gl_GlobalInvocationID.x] = subgroupMax(float(half_value) + float(small));
    total += uint64_t(1);
}
";

#[test]
fn optional_shader_features_are_enabled_when_the_device_offers_them() {
    use weft_gpu::pipeline::{PipelineCache, PipelineKey, ShaderKey};
    use weft_gpu::ShaderStage;
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("a Vulkan 1.3 device");
    let dir = std::env::temp_dir().join(format!("weft-optional-features-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("optional.comp");
    std::fs::write(&path, OPTIONAL_FEATURES).unwrap();
    let key = ShaderKey {
        path,
        stage: ShaderStage::Compute,
        defines: Vec::new(),
    };
    let mut cache = PipelineCache::new().unwrap();
    let shader = cache.shader(&key).unwrap();
    let unmet = gpu.info().shaders.unmet(&shader.compiled);
    if gpu.info().kind == DeviceKind::Cpu {
        // lavapipe offers all of them (docs/architecture.md, "Optional device features").
        assert_eq!(unmet, Vec::<String>::new());
    }
    if unmet.is_empty() {
        cache
            .pipeline(gpu.device(), &PipelineKey::Compute { shader: key })
            .expect("a pipeline from the offered features");
    }
    cache.destroy(gpu.device());
    std::fs::remove_dir_all(&dir).unwrap();
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}
