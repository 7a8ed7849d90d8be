//! Scene passes: meshes or light volumes drawn by the draw recorder inside
//! the pass's render pass. Every pipeline variant the recorder names for the
//! pass ([`crate::DrawRecorder::variants`]) is checked against the graph and
//! the scene interface and built here, before the first frame; its set 0 is
//! written with the plan's other sets.

use super::{PassAt, PassKindOps, Preparing, Recording};
use crate::bind::resolve_bindings;
use crate::draw::{SceneVariant, Variant};
use crate::error::GpuError;
use crate::executor::{Prepared, Renderer};
use crate::scene_check::scene_pass_problems;

/// The scene-drawing kind (a `Raster` pass drawing meshes or light volumes).
pub(super) struct SceneRaster;

impl PassKindOps for SceneRaster {
    fn prepare<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        prep: &mut Preparing<'_, 'g>,
    ) -> Result<(), GpuError> {
        super::prepare_render_pass(renderer, prep)?;
        for wanted in prep.draws.variants(prep.at.pass) {
            let variant = prepare_variant(renderer, prep.at, prep.prepared, &wanted)?;
            if !prep.prepared.variants.iter().any(|v| v.key == variant.key) {
                prep.prepared.variants.push(variant);
            }
        }
        Ok(())
    }

    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        let device = renderer.gpu.device();
        super::begin_render_pass(device, rec.cmd, rec.prep);
        let mut ctx = super::raster_context(
            renderer,
            (rec.at, &*rec.prep, rec.resources),
            (rec.cmd, rec.frame),
            rec.prep.render_pass,
        );
        let drawn = rec.draws.record(&mut ctx);
        super::end_render_pass(device, rec.cmd);
        drawn
    }
}

/// Checks a variant's shaders against the graph and the scene interface,
/// builds its pipeline and resolves the graph resources its set 0 reads.
fn prepare_variant(
    renderer: &mut Renderer<'_>,
    at: PassAt<'_>,
    prepared: &Prepared,
    wanted: &SceneVariant,
) -> Result<Variant, GpuError> {
    let (gpu, pass) = (renderer.gpu, at.pass);
    let fail = |message: String| GpuError::Pass {
        pass: pass.name.clone(),
        message,
    };
    let Some(scene) = renderer.scene.as_ref() else {
        return Err(fail(
            "draws scene content but no scene interface is registered".into(),
        ));
    };
    let (key, keys) = wanted
        .key(pass, prepared.render_pass)
        .ok_or_else(|| fail("needs a vertex shader".into()))?;
    if wanted.state.depth_clamp && !gpu.info().depth_clamp {
        return Err(fail(
            "`raster.depth_clamp` needs the device feature depthClamp, which this device lacks"
                .into(),
        ));
    }
    let modules = keys
        .iter()
        .map(|k| renderer.pipelines.shader(k))
        .collect::<Result<Vec<_>, _>>()?;
    let compiled: Vec<_> = modules.iter().map(|m| &m.compiled).collect();
    let info = gpu.info();
    info.shaders.check(&info.name, &pass.name, &compiled)?;
    let problems = scene_pass_problems(
        &scene.interface,
        at.plan,
        pass,
        &modules[0].interface,
        modules.get(1).map(|m| &m.interface),
    );
    if !problems.is_empty() {
        return Err(fail(problems.join("; ")));
    }
    let pipeline = renderer
        .pipelines
        .pipeline(gpu.device(), &key, Some(scene))?;
    let mut graph_only = pipeline.interface.clone();
    graph_only.bindings.retain(|(set, _), _| *set == 0);
    let bindings = if graph_only.bindings.is_empty() {
        Vec::new()
    } else {
        resolve_bindings(at.plan, pass, &graph_only).map_err(|problems| GpuError::Mismatch {
            pass: pass.name.clone(),
            problems,
        })?
    };
    Ok(Variant {
        key,
        pipeline,
        bindings,
        graph_set: ash::vk::DescriptorSet::null(),
    })
}
