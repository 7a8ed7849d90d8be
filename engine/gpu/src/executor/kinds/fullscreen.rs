//! Fullscreen passes: a checked pipeline drawing one triangle inside the
//! pass's render pass, with scene data bound when its shaders read it.

use super::{PassKindOps, Preparing, Recording};
use crate::check::{stage_key, PassShaders};
use crate::error::GpuError;
use crate::executor::Renderer;
use crate::pipeline::ShaderKey;
use crate::sets::SCENE_SET;
use crate::shader::ShaderStage;
use weft_graph::plan::PlanPass;

/// The fullscreen kind (a `Fullscreen` pass, or a `Raster` pass drawing
/// `FullscreenTriangle`).
pub(super) struct Fullscreen;

impl PassKindOps for Fullscreen {
    /// The pass's vertex shader, or the built-in triangle, and its fragment
    /// shader.
    fn shaders(&self, pass: &PlanPass) -> Result<Option<PassShaders>, GpuError> {
        let fragment = pass.shaders.fragment.as_deref();
        let fragment = fragment.ok_or_else(|| super::missing_shader(pass, "fragment"))?;
        Ok(Some(PassShaders::Fullscreen {
            vertex: match pass.shaders.vertex.as_deref() {
                Some(vertex) => stage_key(vertex, ShaderStage::Vertex, &pass.defines),
                None => ShaderKey::fullscreen_vertex(),
            },
            fragment: stage_key(fragment, ShaderStage::Fragment, &pass.defines),
        }))
    }

    fn prepare<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        prep: &mut Preparing<'_, 'g>,
    ) -> Result<(), GpuError> {
        super::prepare_render_pass(renderer, prep)?;
        renderer.prepare_pipeline(prep.at.plan, prep.at.pass, prep.prepared)
    }

    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        let device = renderer.gpu.device();
        let Some(pipeline) = rec.prep.pipeline.clone() else {
            return Err(GpuError::Pass {
                pass: rec.at.pass.name.clone(),
                message: "has no pipeline prepared".into(),
            });
        };
        super::begin_render_pass(device, rec.cmd, rec.prep);
        renderer.bind(rec.cmd, rec.prep);
        let reads_scene = pipeline
            .interface
            .bindings
            .keys()
            .any(|(s, _)| *s == SCENE_SET);
        let bound = if reads_scene {
            let ctx = super::raster_context(
                renderer,
                (rec.at, &*rec.prep, rec.resources),
                (rec.cmd, rec.frame),
                rec.prep.render_pass,
            );
            rec.draws.bind_scene(&ctx, &pipeline)
        } else {
            Ok(())
        };
        if bound.is_ok() {
            unsafe { device.cmd_draw(rec.cmd, 3, 1, 0, 0) };
        }
        super::end_render_pass(device, rec.cmd);
        bound
    }
}
