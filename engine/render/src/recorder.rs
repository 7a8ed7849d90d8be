//! The draw recorder the executor calls for scene passes: it picks the
//! pipeline variant each run of draws needs (by shading model, opaque or
//! blended), binds the scene (set 1) and each material's textures (set 2),
//! then draws the meshes the pass's material filter selects or one instanced
//! light volume per light. Pipelines, set 0 and push constants are the
//! executor's ([`RasterContext::bind_variant`]).

use crate::frustum::Frustum;
use crate::geometry::DrawItem;
use crate::providers::{self, SHADOW_VIEW};
use crate::scene_gpu::GpuScene;
use crate::shadows::ShadowSettings;
use ash::vk;
use glam::{Mat4, Vec3};
use weft_gpu::commands::Commands;
use weft_gpu::pipeline::Pipeline;

use crate::vocabulary::{LightVolume, MeshFilter, SceneDraw, ShadingModelName};
use weft_gpu::draw::SceneVariant;
use weft_gpu::state::{front_face, pass_state, BlendCode, DepthTest, PassState};
use weft_gpu::{DrawRecorder, Gpu, GpuError, RasterContext, MATERIAL_SET, SCENE_SET};
use weft_graph::plan::{LoadOp, PlanPass};
use weft_graph::schema::CompareOp;

/// The most light volumes (point spheres, spot cones and spheres) one pass
/// draws: 65,536 volumes of 320 triangles already take seconds a frame on a
/// software rasteriser, and a million took minutes and gigabytes, so more are
/// refused with a pointer to tiled shading (see docs/lights.md).
pub const MAX_LIGHT_VOLUMES: u32 = 65_536;

/// The first instance index `shaders/shadow.vert` reads as an area light's
/// panel (light record index + this): a `ShadowCasters` pass draws the
/// panels after the meshes in every shadow view, so they block light as the
/// path tracer's do.
pub const PANEL_INSTANCES: u32 = 1 << 30;

/// Whether a pass drawing every mesh must blend its transparent ones itself: it
/// shades colour (a fragment stage writing attachments) that the graph does not blend.
fn blends_transparency(state: &PassState) -> bool {
    !state.blends.is_empty() && state.blends.iter().all(|b| *b == BlendCode::Off)
}

/// Whether a pass draws its meshes in runs of one shading model, each with
/// that model's variant: it groups by model and is not a shadow-atlas pass
/// (whose views draw every mesh with the pass's own).
fn draws_by_model(pass: &PlanPass) -> bool {
    pass.groups_by_model() && providers::shadow_atlas(pass).is_none()
}

/// The state for transparent meshes in such a pass: alpha blending, depth tested
/// but not written, so they do not hide each other or what lies behind them.
fn transparent_state(state: &PassState) -> PassState {
    PassState {
        blends: vec![BlendCode::Alpha; state.blends.len()],
        // Tested, not written; a pass that tests for equality with a depth
        // pre-pass tests transparent meshes (which the pre-pass left out) with
        // the reverse-Z test instead.
        depth: match state.depth {
            DepthTest::Off => DepthTest::Off,
            DepthTest::On { compare, .. } => DepthTest::On {
                compare: match compare {
                    CompareOp::Less | CompareOp::LessOrEqual => compare,
                    _ => CompareOp::GreaterOrEqual,
                },
                write: false,
            },
        },
        ..state.clone()
    }
}

/// Draws a [`GpuScene`] into the scene passes of any plan.
pub struct SceneRecorder<'g> {
    gpu: &'g Gpu,
    /// The uploaded scene; update it before each frame.
    pub scene: GpuScene<'g>,
    /// Draw calls recorded in the current frame.
    pub draw_calls: u64,
    /// Meshes drawn and culled per view in the current frame.
    pub culling: Vec<ViewCulling>,
    /// Per shadow view, what its atlas tile holds from an earlier frame.
    shadow_tiles: Vec<Option<ShadowTile>>,
}

/// What a shadow view drew into its atlas tile: the tile is kept while a
/// later frame's view is bit-identical (same world-to-clip matrix, same
/// rectangle) and no placement moved into or out of it (a moved light changes
/// its views' matrices); [`SceneRecorder::forget_shadow_tiles`] drops every
/// kept tile (a new plan, scene or shader).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct ShadowTile {
    clip: [u32; 16],
    viewport: [u32; 3],
}

impl ShadowTile {
    fn of(view: &crate::shadows::ShadowView) -> Self {
        Self {
            clip: view.clip.to_cols_array().map(f32::to_bits),
            viewport: view.viewport,
        }
    }
}

/// How many meshes one view drew and how many it left out because their
/// bounds lie outside its frustum.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ViewCulling {
    /// The pass, with the shadow view's index for shadow passes (`shadow_sun[2]`).
    pub view: String,
    /// Meshes drawn.
    pub drawn: u64,
    /// Meshes outside the view.
    pub culled: u64,
    /// Whether the view drew nothing because its shadow-map tile from the
    /// previous frame still holds (same view, nothing changed).
    pub kept: bool,
}

impl<'g> SceneRecorder<'g> {
    /// A recorder for an uploaded scene.
    pub fn new(gpu: &'g Gpu, scene: GpuScene<'g>) -> Self {
        Self {
            gpu,
            scene,
            draw_calls: 0,
            culling: Vec::new(),
            shadow_tiles: Vec::new(),
        }
    }

    /// Forgets every shadow tile kept from earlier frames, so the next frame
    /// draws every shadow view (its plan, scene or shaders changed).
    pub fn forget_shadow_tiles(&mut self) {
        self.shadow_tiles.clear();
    }

    /// Binds the scene set of the pipeline's layout (with the ray tracer's
    /// bindings for shaders that trace), the shared vertex and index buffers
    /// and the unmirrored front face for a scene pipeline the context bound.
    fn bind(&mut self, ctx: &RasterContext<'_>, p: &Pipeline) -> Result<(), GpuError> {
        self.bind_scene(ctx, p)?;
        let commands = Commands::new(self.gpu.device(), ctx.cmd);
        commands.bind_geometry(self.scene.vertices.buffer, self.scene.indices.buffer);
        commands.set_front_face(front_face(false));
        Ok(())
    }

    /// Draws meshes one indexed draw each (the draw record as `firstInstance`),
    /// binding a material's texture set when the material changes; returns the draw count.
    fn draw_meshes<'a>(
        &self,
        cmd: vk::CommandBuffer,
        p: &Pipeline,
        draws: impl Iterator<Item = &'a DrawItem>,
    ) -> u64 {
        let commands = Commands::new(self.gpu.device(), cmd);
        let textured = p
            .interface
            .bindings
            .keys()
            .any(|(set, _)| *set == MATERIAL_SET);
        let mut bound = None;
        let mut face = None;
        let mut calls = 0;
        for d in draws {
            if face != Some(d.mirrored) {
                commands.set_front_face(front_face(d.mirrored));
                face = Some(d.mirrored);
            }
            if textured && bound != Some(d.material) {
                let set = self.scene.material_sets[d.material as usize];
                commands.bind_sets(
                    vk::PipelineBindPoint::GRAPHICS,
                    p.layout,
                    MATERIAL_SET,
                    &[set],
                );
                bound = Some(d.material);
            }
            commands.draw_indexed(
                d.range.index_count,
                d.range.first_index,
                d.range.vertex_offset,
                d.draw_id,
            );
            calls += 1;
        }
        calls
    }

    /// The draws of `filter` inside the frustum of `clip`, counted under `view`.
    fn visible(&mut self, view: String, clip: Mat4, filter: MeshFilter) -> Vec<DrawItem> {
        let frustum = Frustum::from_clip(clip);
        let (inside, outside): (Vec<DrawItem>, Vec<DrawItem>) = self
            .scene
            .geometry
            .filtered(filter)
            .partition(|d| frustum.may_contain(&d.bounds));
        let (drawn, culled) = (inside.len() as u64, outside.len() as u64);
        match self.culling.iter_mut().find(|c| c.view == view) {
            Some(c) => {
                c.drawn += drawn;
                c.culled += culled;
            }
            None => self.culling.push(ViewCulling {
                view,
                drawn,
                culled,
                kept: false,
            }),
        }
        inside
    }

    /// Draws `draws` with the pass's variant; with `by_model`, in runs of one
    /// shading model, each run with the variant the pass declares for that
    /// model (`PlanPass::defines_for`), opaque-safe order kept: callers pass
    /// blended draws already sorted, and the runs follow that order.
    fn draw_variants(
        &mut self,
        ctx: &mut RasterContext<'_>,
        state: &PassState,
        mut draws: Vec<DrawItem>,
        by_model: bool,
    ) -> Result<u64, GpuError> {
        if !by_model {
            let defines = ctx.pass().defines.clone();
            let p = ctx.bind_variant(&defines, state)?;
            self.bind(ctx, &p)?;
            return Ok(self.draw_meshes(ctx.cmd, &p, draws.iter()));
        }
        if !blends_transparency(&ctx.pass_state()) {
            // Depth-tested opaque draws may go in any order: one run per model.
            draws.sort_by_key(|d| self.model_of(d));
        }
        let models: Vec<ShadingModelName> = draws.iter().map(|d| self.model_of(d)).collect();
        let mut calls = 0;
        let mut start = 0;
        while start < draws.len() {
            let model = models[start];
            let end = start + models[start..].iter().take_while(|m| **m == model).count();
            let defines = ctx.pass().defines_for(model.name());
            let p = ctx.bind_variant(&defines, state)?;
            self.bind(ctx, &p)?;
            calls += self.draw_meshes(ctx.cmd, &p, draws[start..end].iter());
            start = end;
        }
        Ok(calls)
    }

    /// The variants `draw_variants` binds for the draws of `filter` with
    /// `state`: the pass's own, or with `by_model` one per shading model
    /// among those draws.
    fn model_variants(
        &self,
        pass: &PlanPass,
        state: &PassState,
        filter: MeshFilter,
        by_model: bool,
    ) -> Vec<SceneVariant> {
        if !by_model {
            return vec![SceneVariant {
                defines: pass.defines.clone(),
                state: state.clone(),
            }];
        }
        let mut models: Vec<ShadingModelName> = self
            .scene
            .geometry
            .filtered(filter)
            .map(|d| self.model_of(d))
            .collect();
        models.sort();
        models.dedup();
        models
            .into_iter()
            .map(|model| SceneVariant {
                defines: pass.defines_for(model.name()),
                state: state.clone(),
            })
            .collect()
    }

    /// The shading model of a draw's material, as passes group draws by it.
    fn model_of(&self, d: &DrawItem) -> ShadingModelName {
        let material = self.scene.geometry.materials.get(d.material as usize);
        material.map_or(ShadingModelName::BlinnPhong, |m| {
            ShadingModelName::of(m.shading)
        })
    }

    /// `draws` sorted farthest from the camera first (by the placed model's
    /// origin), the order alpha blending needs.
    fn back_to_front(&self, draws: Vec<DrawItem>) -> Vec<DrawItem> {
        let g = &self.scene.geometry;
        let eye = self.scene.camera_position;
        let mut draws: Vec<(f32, DrawItem)> = draws
            .into_iter()
            .map(|d| {
                let origin = g
                    .model_matrix(d.draw_id)
                    .map_or(Vec3::ZERO, |m| m.w_axis.truncate());
                (origin.distance_squared(eye), d)
            })
            .collect();
        draws.sort_by(|a, b| b.0.total_cmp(&a.0));
        draws.into_iter().map(|(_, d)| d).collect()
    }
}

impl SceneRecorder<'_> {
    /// A `ShadowAtlas` pass: fits this frame's views to the attachment's size
    /// with the provider's settings, then draws the casters once per view into
    /// its tile.
    fn draw_shadow_views(
        &mut self,
        ctx: &RasterContext<'_>,
        p: &Pipeline,
        filter: MeshFilter,
        settings: &ShadowSettings,
    ) -> Result<u64, GpuError> {
        let pass = ctx.pass();
        let views = self.scene.prepare_shadows(settings, ctx.extent.width)?;
        if p.interface.push.is_none() {
            return Err(GpuError::Pass {
                pass: pass.name.clone(),
                message: "shadow pass without push constants".into(),
            });
        }
        let commands = ctx.commands();
        // A shadow map that loads what the last frame left (a `persistent`
        // image) keeps the tiles of views that did not change; one that is
        // cleared draws every view.
        let keeps_tiles = pass
            .render_pass
            .as_ref()
            .and_then(|rp| rp.depth.and_then(|d| rp.attachments.get(d)))
            .is_some_and(|a| a.load == LoadOp::Load);
        if !keeps_tiles || self.shadow_tiles.len() != views.len() {
            self.shadow_tiles = vec![None; views.len()];
            if keeps_tiles {
                // A new atlas layout (or the first frame): nothing kept, and
                // the texels between tiles, which filtering at tile edges
                // reads, are set too, as a cleared map would have them.
                commands.clear_depth(
                    vk::Rect2D {
                        offset: vk::Offset2D::default(),
                        extent: ctx.extent,
                    },
                    1.0,
                );
            }
        }
        let mut calls = 0;
        for (i, view) in views.iter().enumerate() {
            let tile = ShadowTile::of(view);
            let name = format!("{}[{i}]", pass.name);
            // A placement that moved into or out of the view stales its tile.
            let casters_moved = || {
                let frustum = crate::frustum::Frustum::from_clip(view.clip);
                self.scene
                    .moved_boxes()
                    .iter()
                    .any(|b| frustum.may_contain(b))
            };
            if keeps_tiles && self.shadow_tiles[i] == Some(tile) && !casters_moved() {
                self.culling.push(ViewCulling {
                    view: name,
                    drawn: 0,
                    culled: 0,
                    kept: true,
                });
                continue;
            }
            let [x, y, side] = view.viewport;
            let area = vk::Rect2D {
                offset: vk::Offset2D {
                    x: x as i32,
                    y: y as i32,
                },
                extent: vk::Extent2D {
                    width: side,
                    height: side,
                },
            };
            commands.set_viewport_and_scissor(area);
            if keeps_tiles {
                // The tile holds an older view (or nothing yet): start it afresh.
                commands.clear_depth(area, 1.0);
            }
            ctx.push_constants(p, &[(SHADOW_VIEW, i as f64)])?;
            let draws = self.visible(name, view.clip, filter);
            calls += self.draw_meshes(ctx.cmd, p, draws.iter());
            if filter == MeshFilter::ShadowCasters {
                calls += self.draw_panels(ctx.cmd);
            }
            self.shadow_tiles[i] = Some(tile);
        }
        Ok(calls)
    }
}

impl SceneRecorder<'_> {
    /// The area lights' panels as casters: the panel mesh once per area
    /// light, instances from [`PANEL_INSTANCES`] on.
    fn draw_panels(&self, cmd: vk::CommandBuffer) -> u64 {
        let lights = &self.scene.light_set;
        if lights.areas == 0 {
            return 0;
        }
        let panel = self.scene.geometry.panel;
        Commands::new(self.gpu.device(), cmd).draw_indexed_instanced(
            panel.index_count,
            lights.areas,
            panel.first_index,
            panel.vertex_offset,
            PANEL_INSTANCES + lights.first_area(),
        );
        1
    }
}

impl DrawRecorder for SceneRecorder<'_> {
    /// The draw count and the culling figures start again; structure builds
    /// the last frame recorded but never submitted are to be recorded again.
    fn begin_frame(&mut self) -> Result<(), GpuError> {
        self.draw_calls = 0;
        self.culling.clear();
        self.scene.forget_unsubmitted_structures();
        Ok(())
    }

    fn submitted(&mut self) {
        self.scene.structures_submitted();
    }

    /// What `record` binds, with this scene: one variant per shading model
    /// among the pass's draws when it groups by model (opaque, and blended
    /// where it blends the scene's transparent meshes itself), else the
    /// pass's own.
    fn variants(&self, pass: &PlanPass) -> Vec<SceneVariant> {
        let state = pass_state(pass);
        let by_model = draws_by_model(pass);
        match pass.draw.as_ref().map(SceneDraw::of) {
            Some(Ok(SceneDraw::Meshes(MeshFilter::All))) if blends_transparency(&state) => {
                let mut variants = self.model_variants(pass, &state, MeshFilter::Opaque, by_model);
                let mut transparent = self.scene.geometry.filtered(MeshFilter::Transparent);
                if transparent.next().is_some() {
                    let blended = transparent_state(&state);
                    variants.extend(self.model_variants(
                        pass,
                        &blended,
                        MeshFilter::Transparent,
                        by_model,
                    ));
                }
                variants
            }
            Some(Ok(SceneDraw::Meshes(filter))) => {
                self.model_variants(pass, &state, filter, by_model)
            }
            Some(Ok(SceneDraw::LightVolumes(_))) => vec![SceneVariant {
                defines: pass.defines.clone(),
                state,
            }],
            _ => Vec::new(),
        }
    }

    /// The scene's structures: built the first time, refitted after a
    /// placement moved.
    fn build_structures(
        &mut self,
        pass: &PlanPass,
        cmd: vk::CommandBuffer,
        scratch: weft_gpu::acceleration::ScratchSpan,
    ) -> Result<(), GpuError> {
        self.scene.record_structures(&pass.name, cmd, scratch)
    }

    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError> {
        let pass = ctx.pass();
        let name = pass.name.clone();
        let fail = |message: String| GpuError::Pass {
            pass: name.clone(),
            message,
        };
        let draw = pass
            .draw
            .as_ref()
            .ok_or_else(|| fail("raster pass without a `draw`".into()))
            .and_then(|d| SceneDraw::of(d).map_err(fail))?;
        let defines = pass.defines.clone();
        let shadow_atlas = providers::shadow_atlas(pass);
        let by_model = draws_by_model(pass);
        let state = ctx.pass_state();
        let mut calls = 0u64;
        match draw {
            SceneDraw::Meshes(MeshFilter::All) if blends_transparency(&state) => {
                // Opaque first, then transparent meshes blended over them, farthest first.
                let camera = self.scene.view_proj;
                let opaque = self.visible(name.clone(), camera, MeshFilter::Opaque);
                calls += self.draw_variants(ctx, &state, opaque, by_model)?;
                let transparent = self.visible(name.clone(), camera, MeshFilter::Transparent);
                let transparent = self.back_to_front(transparent);
                if !transparent.is_empty() {
                    let blended = transparent_state(&state);
                    calls += self.draw_variants(ctx, &blended, transparent, by_model)?;
                }
            }
            SceneDraw::Meshes(filter) => match &shadow_atlas {
                Some(settings) => {
                    let p = ctx.bind_variant(&defines, &state)?;
                    self.bind(ctx, &p)?;
                    calls += self.draw_shadow_views(ctx, &p, filter, settings)?;
                }
                None => {
                    let draws = self.visible(name.clone(), self.scene.view_proj, filter);
                    calls += self.draw_variants(ctx, &state, draws, by_model)?;
                }
            },
            SceneDraw::LightVolumes(kind) => {
                let p = ctx.bind_variant(&defines, &state)?;
                self.bind(ctx, &p)?;
                let g = &self.scene.geometry;
                let lights = &self.scene.light_set;
                let groups = match kind {
                    LightVolume::Point => vec![(g.sphere, lights.points, lights.first_point())],
                    LightVolume::Spot => vec![
                        (g.cone, lights.spot_cones, lights.first_spot_cone()),
                        (g.sphere, lights.spot_spheres, lights.first_spot_sphere()),
                    ],
                    LightVolume::Area => vec![(g.panel, lights.areas, lights.first_area())],
                };
                let volumes: u64 = groups.iter().map(|g| u64::from(g.1)).sum();
                if volumes > u64::from(MAX_LIGHT_VOLUMES) {
                    return Err(fail(format!(
                        "{volumes} light volumes exceed the {MAX_LIGHT_VOLUMES} a frame draws this way (each is {} triangles through the geometry front end); shade this many lights with a tiled graph such as graphs/tiled.ron",
                        g.sphere.index_count / 3
                    )));
                }
                for (mesh, count, first) in groups.into_iter().filter(|g| g.1 > 0) {
                    ctx.commands().draw_indexed_instanced(
                        mesh.index_count,
                        count,
                        mesh.first_index,
                        mesh.vertex_offset,
                        first,
                    );
                    calls += 1;
                }
            }
            SceneDraw::FullscreenTriangle => {
                return Err(fail(
                    "a fullscreen triangle is drawn by the executor".into(),
                ))
            }
        }
        self.draw_calls += calls;
        Ok(())
    }

    fn bind_scene(&mut self, ctx: &RasterContext<'_>, pipeline: &Pipeline) -> Result<(), GpuError> {
        let kind = pipeline.scene_set.ok_or_else(|| GpuError::Pass {
            pass: ctx.pass().name.clone(),
            message: "its pipeline was built without the scene's set layouts".into(),
        })?;
        let set = self.scene.scene_set(kind)?;
        ctx.commands()
            .bind_sets(pipeline.bind_point, pipeline.layout, SCENE_SET, &[set]);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::PANEL_INSTANCES;

    /// `shaders/shadow.vert` reads instances from [`PANEL_INSTANCES`] on as
    /// panels: its constant is this one.
    #[test]
    fn the_shadow_shader_knows_where_panel_instances_start() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders/shadow.vert");
        let text = std::fs::read_to_string(&path).expect("shadow.vert");
        assert_eq!(PANEL_INSTANCES, 1 << 30);
        assert!(
            text.contains("const uint PANEL_INSTANCES = 1u << 30;"),
            "{} lost its PANEL_INSTANCES",
            path.display()
        );
    }
}
