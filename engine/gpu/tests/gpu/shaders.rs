//! Run-time GLSL compilation and SPIR-V reflection on real shaders.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use weft_gpu::reflect::{
    DescriptorKind, PipelineInterface, PushMember, ScalarKind, ShaderInterface,
};
use weft_gpu::{ShaderCompiler, ShaderError, ShaderStage};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/shaders")
}

fn compiler() -> ShaderCompiler {
    ShaderCompiler::new(Vec::new()).expect("shaderc initialises")
}

#[test]
fn records_every_included_file() {
    let path = dir().join("tint.frag");
    let shader = compiler()
        .compile_file(&path, ShaderStage::Fragment, &[])
        .expect("tint.frag compiles");
    let expected: BTreeSet<PathBuf> = [
        path.clone(),
        dir().join("lib/color.glsl"),
        dir().join("lib/math.glsl"),
    ]
    .into_iter()
    .collect();
    assert_eq!(shader.dependencies, expected);
    assert_eq!(shader.spirv[0], 0x0723_0203);
}

#[test]
fn errors_name_the_included_file_and_line() {
    let path = dir().join("uses_broken.frag");
    let err = compiler()
        .compile_file(&path, ShaderStage::Fragment, &[])
        .expect_err("broken include fails");
    let ShaderError::Compile(diagnostics) = err else {
        panic!("expected a compile error, got {err:?}");
    };
    assert_eq!(diagnostics[0].file, dir().join("lib/broken.glsl"));
    assert_eq!(diagnostics[0].line, Some(2));
    assert!(
        diagnostics[0].message.contains("undeclared_thing"),
        "{}",
        diagnostics[0].message
    );
}

#[test]
fn missing_include_is_located_in_the_includer() {
    let err = compiler()
        .compile_source(
            "#version 450\n\n#include \"nope.glsl\"\nvoid main() {}\n",
            &dir().join("inline.frag"),
            ShaderStage::Fragment,
            &[],
        )
        .expect_err("missing include fails");
    let ShaderError::Compile(diagnostics) = err else {
        panic!("expected a compile error, got {err:?}");
    };
    assert_eq!(diagnostics[0].file, dir().join("inline.frag"));
    assert_eq!(diagnostics[0].line, Some(3));
    assert!(diagnostics[0].message.contains("nope.glsl"));
}

#[test]
fn defines_select_variants() {
    let path = dir().join("tint.frag");
    let plain = compiler()
        .compile_file(&path, ShaderStage::Fragment, &[])
        .expect("plain variant");
    let inverted = compiler()
        .compile_file(&path, ShaderStage::Fragment, &["INVERT".to_string()])
        .expect("inverted variant");
    assert_ne!(plain.spirv, inverted.spirv);
    let err = compiler()
        .compile_file(&path, ShaderStage::Fragment, &["BAD NAME".to_string()])
        .expect_err("invalid define");
    assert_eq!(err.to_string(), "invalid shader define `BAD NAME`");
}

#[test]
fn reflects_samplers_and_push_constants() {
    let shader = compiler()
        .compile_file(&dir().join("tint.frag"), ShaderStage::Fragment, &[])
        .expect("compiles");
    let iface = ShaderInterface::reflect(&shader).expect("reflects");
    let names: Vec<(u32, &str, DescriptorKind)> = iface
        .bindings
        .iter()
        .map(|b| (b.binding, b.name.as_str(), b.kind))
        .collect();
    assert_eq!(
        names,
        vec![
            (0, "source", DescriptorKind::CombinedImageSampler),
            (1, "mask", DescriptorKind::CombinedImageSampler),
        ]
    );
    let push = iface.push.expect("push block");
    assert_eq!(push.size, 24);
    assert_eq!(
        push.members,
        vec![
            PushMember {
                name: "color".into(),
                offset: 0,
                scalar: ScalarKind::Float,
                components: 4,
                count: 1,
                stride: 0,
            },
            PushMember {
                name: "strength".into(),
                offset: 16,
                scalar: ScalarKind::Float,
                components: 1,
                count: 1,
                stride: 0,
            },
            PushMember {
                name: "mode".into(),
                offset: 20,
                scalar: ScalarKind::Int,
                components: 1,
                count: 1,
                stride: 0,
            },
        ]
    );
    assert_eq!(iface.outputs.len(), 1);
    assert_eq!(iface.outputs[0].location, 0);
    assert_eq!(iface.outputs[0].components, 4);
}

#[test]
fn reflects_texel_buffers() {
    let shader = compiler()
        .compile_source(
            "#version 450
layout(local_size_x = 8) in;
layout(set = 1, binding = 6) uniform usamplerBuffer nodes;
layout(set = 0, binding = 0) buffer Out { uvec4 out_texels[]; };
void main() {
    out_texels[gl_GlobalInvocationID.x] = texelFetch(nodes, int(gl_GlobalInvocationID.x));
}
",
            &dir().join("texels.comp"),
            ShaderStage::Compute,
            &[],
        )
        .expect("compiles");
    let iface = ShaderInterface::reflect(&shader).expect("reflects");
    let kinds: Vec<(u32, u32, &str, DescriptorKind)> = iface
        .bindings
        .iter()
        .map(|b| (b.set, b.binding, b.name.as_str(), b.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (0, 0, "Out", DescriptorKind::StorageBuffer),
            (1, 6, "nodes", DescriptorKind::UniformTexelBuffer),
        ]
    );
}

#[test]
fn reflects_vulkan_1_3_compute_storage() {
    let shader = compiler()
        .compile_file(&dir().join("blur.comp"), ShaderStage::Compute, &[])
        .expect("compiles");
    let iface = ShaderInterface::reflect(&shader).expect("reflects");
    let names: Vec<(u32, &str, DescriptorKind)> = iface
        .bindings
        .iter()
        .map(|b| (b.binding, b.name.as_str(), b.kind))
        .collect();
    assert_eq!(
        names,
        vec![
            (0, "src_image", DescriptorKind::StorageImage),
            (1, "dst_image", DescriptorKind::StorageImage),
            (2, "histogram", DescriptorKind::StorageBuffer),
        ]
    );
    let merged = PipelineInterface::merge(&[&iface]).expect("merges");
    assert_eq!(merged.set_count(), 1);
    let push = merged.push.expect("push").0;
    assert_eq!(push.size, 8);
    assert_eq!(push.members[0].scalar, ScalarKind::Uint);
    assert_eq!(push.members[0].components, 2);
}

#[test]
fn merged_stages_give_set_layout_bindings_and_push_ranges() {
    use ash::vk;
    let vs = compiler()
        .compile_file(&dir().join("shared.vert"), ShaderStage::Vertex, &[])
        .expect("vertex compiles");
    let fs = compiler()
        .compile_file(&dir().join("tint.frag"), ShaderStage::Fragment, &[])
        .expect("fragment compiles");
    let vi = ShaderInterface::reflect(&vs).expect("reflects");
    let fi = ShaderInterface::reflect(&fs).expect("reflects");
    let merged = PipelineInterface::merge(&[&vi, &fi]).expect("merges");
    let bindings: Vec<(u32, vk::DescriptorType, u32, vk::ShaderStageFlags)> = merged
        .set_layout_bindings(0)
        .iter()
        .map(|b| {
            (
                b.binding,
                b.descriptor_type,
                b.descriptor_count,
                b.stage_flags,
            )
        })
        .collect();
    assert_eq!(
        bindings,
        vec![
            (
                0,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                1,
                vk::ShaderStageFlags::FRAGMENT
            ),
            (
                1,
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                1,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT
            ),
        ]
    );
    let ranges: Vec<(vk::ShaderStageFlags, u32, u32)> = merged
        .push_constant_ranges()
        .iter()
        .map(|r| (r.stage_flags, r.offset, r.size))
        .collect();
    assert_eq!(
        ranges,
        vec![(
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            0,
            24
        )]
    );
    assert_eq!(merged.set_count(), 1);
    assert!(merged.set_layout_bindings(1).is_empty());
}

/// Optional capabilities a module declares, and the features they need
/// (`weft_gpu::capabilities`). Here rather than beside the code: the unit
/// tests share one process-wide SPIR-V cache folder with its own test.
mod capabilities {
    use super::*;
    use ash::vk;
    use spirv::Capability;
    use weft_gpu::capabilities::declared;
    use weft_gpu::{CompiledShader, ShaderSupport};

    fn compiled(source: &str, name: &str, stage: ShaderStage) -> CompiledShader {
        compiler()
            .compile_source(source, Path::new(name), stage, &[])
            .unwrap()
    }

    /// A compute shader with a subgroup reduction and a 64-bit integer.
    const REDUCE: &str = "#version 450
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Values { uint64_t total; float v[]; };
void main() {
    v[gl_GlobalInvocationID.x] = subgroupMax(v[gl_GlobalInvocationID.x]);
    total += uint64_t(1);
}
";

    /// A fragment shader reading `gl_PrimitiveID`, as the mesh-density view does.
    const PRIMITIVE: &str = "#version 450
layout(location = 0) out vec4 colour;
void main() { colour = vec4(float(gl_PrimitiveID)); }
";

    fn everything() -> ShaderSupport {
        ShaderSupport {
            geometry: true,
            float64: true,
            int64: true,
            int16: true,
            float16: true,
            int8: true,
            subgroup_stages: vk::ShaderStageFlags::ALL,
            subgroup_operations: vk::SubgroupFeatureFlags::from_raw(0xff),
            compute_shared_bytes: 1 << 16,
            compute_invocations: 1024,
            compute_size: [1024, 1024, 64],
            ray_query: true,
        }
    }

    /// A compute shader tracing a ray query, as `trace.glsl` does under
    /// `TRACE_HARDWARE`.
    const RAY_QUERY: &str = "#version 460
#extension GL_EXT_ray_query : require
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform accelerationStructureEXT top;
layout(set = 0, binding = 1) buffer Out { float t; };
void main() {
    rayQueryEXT query;
    rayQueryInitializeEXT(query, top, gl_RayFlagsOpaqueEXT, 0xff, vec3(0.0), 0.0, vec3(0.0, 0.0, 1.0), 10.0);
    while (rayQueryProceedEXT(query)) {
    }
    t = rayQueryGetIntersectionTEXT(query, true);
}
";

    #[test]
    fn ray_queries_are_refused_on_a_device_without_them_naming_the_extensions() {
        let query = compiled(RAY_QUERY, "shaders/query.comp", ShaderStage::Compute);
        assert_eq!(everything().unmet(&query), Vec::<String>::new());
        let without = ShaderSupport {
            ray_query: false,
            ..everything()
        };
        assert_eq!(
            without.unmet(&query),
            [
                "ray queries (the `rayQuery` feature of VK_KHR_ray_query, with VK_KHR_acceleration_structure)",
                "the SPIR-V extension SPV_KHR_ray_query (weft enables no device extension for it)",
            ]
        );
    }

    #[test]
    fn a_module_declares_the_capabilities_its_source_uses() {
        let reduce = compiled(REDUCE, "reduce.comp", ShaderStage::Compute);
        let found = declared(&reduce.spirv);
        for wanted in [
            Capability::Shader,
            Capability::Int64,
            Capability::GroupNonUniform,
            Capability::GroupNonUniformArithmetic,
        ] {
            assert!(found.contains(&wanted), "{wanted:?} in {found:?}");
        }
        let primitive = compiled(PRIMITIVE, "primitive.frag", ShaderStage::Fragment);
        assert_eq!(
            declared(&primitive.spirv),
            [Capability::Shader, Capability::Geometry]
        );
        assert_eq!(declared(&[]), []);
        // The five header words alone declare nothing.
        assert_eq!(declared(&reduce.spirv[..5]), []);
    }

    #[test]
    fn each_missing_feature_is_named() {
        let reduce = compiled(REDUCE, "reduce.comp", ShaderStage::Compute);
        let primitive = compiled(PRIMITIVE, "primitive.frag", ShaderStage::Fragment);
        let all = everything();
        assert_eq!(all.unmet(&reduce), Vec::<String>::new());
        assert_eq!(all.unmet(&primitive), Vec::<String>::new());
        assert_eq!(
            ShaderSupport::core().unmet(&primitive),
            ["gl_PrimitiveID or geometry-stage built-ins (the `geometryShader` feature)"]
        );
        assert_eq!(
            ShaderSupport::core().unmet(&reduce),
            [
                "64-bit integers (the `shaderInt64` feature)",
                "subgroup operations in compute shaders (`supportedStages` lacks COMPUTE)",
            ]
        );
        let fragment_only = ShaderSupport {
            subgroup_stages: vk::ShaderStageFlags::FRAGMENT,
            ..all
        };
        assert_eq!(
            fragment_only.unmet(&reduce),
            ["subgroup operations in compute shaders (`supportedStages` lacks COMPUTE)"]
        );
        assert!(fragment_only
            .offers_subgroup(ShaderStage::Fragment, vk::SubgroupFeatureFlags::ARITHMETIC));
        assert!(
            !fragment_only.offers_subgroup(ShaderStage::Compute, vk::SubgroupFeatureFlags::BASIC)
        );
        let basic_only = ShaderSupport {
            subgroup_operations: vk::SubgroupFeatureFlags::BASIC,
            ..all
        };
        assert_eq!(
            basic_only.unmet(&reduce),
            ["subgroup arithmetic operations (`supportedOperations` lacks ARITHMETIC)"]
        );
    }

    #[test]
    fn a_pass_is_refused_naming_its_shader_the_need_and_the_device() {
        let reduce = compiled(REDUCE, "shaders/reduce.comp", ShaderStage::Compute);
        let primitive = compiled(PRIMITIVE, "shaders/primitive.frag", ShaderStage::Fragment);
        let no_int64 = ShaderSupport {
            int64: false,
            ..everything()
        };
        assert!(no_int64.check("gpu", "p", &[&primitive]).is_ok());
        let error = no_int64
            .check("gpu", "reduce", &[&primitive, &reduce])
            .unwrap_err()
            .to_string();
        assert_eq!(
            error,
            "pass `reduce`: shaders/reduce.comp needs 64-bit integers (the `shaderInt64` feature), which the device `gpu` does not offer"
        );
    }

    /// 128 KiB of shared memory, a 64x64 workgroup, and float atomics on
    /// shared memory (an extension weft does not enable).
    const GREEDY: &str = "#version 450
#extension GL_EXT_shader_atomic_float : require
layout(local_size_x = 64, local_size_y = 64) in;
shared float big[32768];
shared float sum;
layout(set = 0, binding = 0) buffer Out { float v[]; };
void main() {
    big[gl_LocalInvocationIndex] = v[gl_GlobalInvocationID.x];
    atomicAdd(sum, 1.0);
    barrier();
    v[gl_GlobalInvocationID.x] = big[gl_LocalInvocationIndex ^ 1u] + sum;
}
";

    #[test]
    fn compute_limits_and_unenabled_capabilities_are_refused() {
        let greedy = compiled(GREEDY, "greedy.comp", ShaderStage::Compute);
        let workgroup = weft_gpu::workgroup::read(&greedy.spirv);
        assert_eq!(workgroup.size, [64, 64, 1]);
        assert_eq!(workgroup.shared_bytes, 32768 * 4 + 4);
        assert_eq!(
            ShaderSupport::core().unmet(&greedy),
            [
                "the SPIR-V capability AtomicFloat32AddEXT (not one weft enables: it needs a device feature or extension)",
                "the SPIR-V extension SPV_EXT_shader_atomic_float_add (weft enables no device extension for it)",
                "131076 bytes of shared memory (`maxComputeSharedMemorySize` is 16384)",
                "4096 invocations per workgroup (64x64x1; `maxComputeWorkGroupInvocations` is 128)",
            ]
        );
        // One axis over its limit, and shared memory exactly at it.
        let wide = compiled(
            "#version 450\nlayout(local_size_x = 512) in;\nshared vec4 s[1024];\nlayout(set = 0, binding = 0) buffer O { vec4 o[]; };\nvoid main() { s[gl_LocalInvocationIndex % 1024] = vec4(1); o[0] = s[0]; }\n",
            "wide.comp",
            ShaderStage::Compute,
        );
        let workgroup = weft_gpu::workgroup::read(&wide.spirv);
        assert_eq!(
            (workgroup.size, workgroup.shared_bytes),
            ([512, 1, 1], 16384)
        );
        assert_eq!(
            ShaderSupport::core().unmet(&wide),
            [
                "a local size x of 512 (`maxComputeWorkGroupSize` x is 128)",
                "512 invocations per workgroup (512x1x1; `maxComputeWorkGroupInvocations` is 128)",
            ]
        );
        // A shader within every limit needs nothing.
        let modest = compiled(
            "#version 450\nlayout(local_size_x = 8, local_size_y = 8) in;\nshared float s[64];\nlayout(set = 0, binding = 0) buffer O { float o[]; };\nvoid main() { s[gl_LocalInvocationIndex] = 1.0; barrier(); o[0] = s[1]; }\n",
            "modest.comp",
            ShaderStage::Compute,
        );
        assert_eq!(ShaderSupport::core().unmet(&modest), Vec::<String>::new());
    }
}
