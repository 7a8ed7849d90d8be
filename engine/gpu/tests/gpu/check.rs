//! Shader/graph cross-checks and hot reload.

use crate::common;

use weft_gpu::{FrameOptions, NoDraws, Renderer};
use weft_testkit::render_frames;

#[test]
fn reports_every_disagreement_between_shaders_and_graph() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mismatch.ron"), 4, 4);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let problems: Vec<(String, String)> = renderer
        .check_shaders(&plan)
        .into_iter()
        .map(|p| (p.pass, p.message))
        .collect();
    let without_device: Vec<(String, String)> = weft_gpu::check_shaders(&plan, None)
        .expect("shaderc")
        .into_iter()
        .map(|p| (p.pass, p.message))
        .collect();
    assert_eq!(without_device, problems);
    // Problems with a shader variable name the line that declares it.
    let consume = common::graph("shaders/consume_wrong.frag");
    let expected: Vec<(String, String)> = [
        (
            "produce",
            "the fragment shader writes outputs at locations [0] but the pass has 2 colour attachment(s)",
        ),
        (
            "consume",
            &format!("shader binding 1 `b` is a StorageImage but graph resource `b` is bound as Sampled (CombinedImageSampler) (declared at {}:5)", consume.display()),
        ),
        (
            "consume",
            &format!("shader binding 3 `extra` is fed by no graph resource (the pass binds `a`, `b`) (declared at {}:6)", consume.display()),
        ),
        (
            "consume",
            "graph resource `b` is bound to nothing in the pass's shaders",
        ),
        (
            "label",
            "graph resource `out` is bound to nothing in the pass's shaders",
        ),
        (
            "label",
            "fragment output 0 is Float but colour attachment `ids` (R32_UINT) takes Uint",
        ),
    ]
    .iter()
    .map(|(p, m)| (p.to_string(), m.to_string()))
    .collect();
    assert_eq!(problems, expected);
    let mut resources = renderer.create_resources(&plan).expect("resources");
    let err = renderer
        .execute(
            &plan,
            &mut resources,
            &mut NoDraws,
            &FrameOptions::default(),
        )
        .expect_err("the executor refuses the mismatched pass");
    assert_eq!(
        err.to_string(),
        "pass `produce`: the fragment shader writes outputs at locations [0] but the pass has 2 colour attachment(s)"
    );
    drop(resources);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn reload_drops_pipelines_built_from_a_changed_file() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mixed.ron"), 8, 8);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let options = FrameOptions {
        readback: true,
        ..FrameOptions::default()
    };
    render_frames(&mut renderer, &plan, &mut NoDraws, 1, 0.0, &options).expect("first frame");
    assert_eq!(renderer.pipelines().pipeline_count(), 3);
    let fill = common::graph("shaders/fill.frag");
    assert_eq!(renderer.reload(&fill).expect("reload"), 1);
    assert_eq!(renderer.pipelines().pipeline_count(), 2);
    let unrelated = common::graph("shaders/show.frag");
    assert_eq!(renderer.reload(&unrelated).expect("reload"), 0);
    let report =
        render_frames(&mut renderer, &plan, &mut NoDraws, 2, 0.5, &options).expect("after reload");
    assert_eq!(renderer.pipelines().pipeline_count(), 3);
    assert_eq!(
        report.output.expect("readback").rgba8_at(1, 2),
        [32, 191, 51, 255]
    );
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

/// A pass whose shader needs a feature the device lacks is refused by name
/// before any shader module is created: no validation message, no crash.
/// lavapipe offers no clustered subgroup operations; a device that does
/// renders the pass.
#[test]
fn a_shader_needing_a_feature_the_device_lacks_is_refused_naming_it() {
    use ash::vk::SubgroupFeatureFlags;
    use weft_gpu::ShaderStage;
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("clustered.ron"), 4, 4);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let mut resources = renderer.create_resources(&plan).expect("resources");
    let result = renderer.execute(
        &plan,
        &mut resources,
        &mut NoDraws,
        &FrameOptions::default(),
    );
    let device = gpu.info();
    let offered = device
        .shaders
        .offers_subgroup(ShaderStage::Fragment, SubgroupFeatureFlags::CLUSTERED);
    if offered {
        result.expect("the device offers clustered subgroup operations");
    } else {
        let err = result.expect_err("refused");
        assert_eq!(
            err.to_string(),
            format!(
                "pass `clustered`: {} needs subgroup clustered operations (`supportedOperations` lacks CLUSTERED), which the device `{}` does not offer",
                common::graph("shaders/clustered.frag").display(),
                device.name
            )
        );
    }
    drop(resources);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}
