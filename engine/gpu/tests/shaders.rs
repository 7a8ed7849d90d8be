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
