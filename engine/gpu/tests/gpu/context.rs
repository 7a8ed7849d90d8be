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

#[test]
fn optional_shader_features_are_enabled_when_the_device_offers_them() {
    use weft_gpu::pipeline::{PipelineCache, PipelineKey, ShaderKey};
    use weft_gpu::ShaderStage;
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("a Vulkan 1.3 device");
    let key = ShaderKey {
        path: std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/shaders/optional_features.comp"),
        stage: ShaderStage::Compute,
        defines: Vec::new(),
    };
    let mut cache = PipelineCache::new().expect("shaderc");
    let shader = cache.shader(&key).expect("the fixture compiles");
    let unmet = gpu.info().shaders.unmet(&shader.compiled);
    if gpu.info().kind == DeviceKind::Cpu {
        // lavapipe offers all of them (docs/architecture.md, "Optional device features").
        assert_eq!(unmet, Vec::<String>::new());
    }
    if unmet.is_empty() {
        cache
            .pipeline(
                gpu.device(),
                &PipelineKey::Compute {
                    shader: key,
                    scene: None,
                },
                None,
            )
            .expect("a pipeline from the offered features");
    }
    cache.destroy(gpu.device());
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}
