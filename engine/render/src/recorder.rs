//! The draw recorder the executor calls for scene passes: binds the pass's
//! pipeline, the graph resources it samples (set 0), the scene (set 1) and each
//! material's texture (set 2), then draws the meshes the pass's material filter
//! selects or one instanced light volume per light.

use crate::frustum::Frustum;
use crate::geometry::DrawItem;
use crate::pipelines::{front_face, ScenePipeline, ScenePipelineKey, ScenePipelines, MATERIAL_SET};
use crate::providers::{self, SHADOW_VIEW};
use crate::scene_gpu::GpuScene;
use crate::scene_interface::scene_set_problems;
use crate::shadows::ShadowSettings;
use crate::state::{pass_state, DepthTest, PassState};
use ash::vk;
use glam::{Mat4, Vec3};
use std::collections::BTreeMap;
use std::sync::Arc;
use weft_gpu::bind::{pack_push, resolve_bindings, FrameValues};
use weft_gpu::commands::Commands;
use weft_gpu::descriptors::{write_graph_set, DescriptorPool};
use weft_gpu::pipeline::{BlendCode, Pipeline, ShaderKey, ShaderModule};
use weft_gpu::reflect::PipelineInterface;
use weft_gpu::{DrawRecorder, Gpu, GpuError, RasterContext, ShaderStage, SCENE_SET};
use weft_graph::plan::LoadOp;
use weft_graph::schema::{CompareOp, Draw, LightKind, MaterialFilter, ParamValue, ShadingModel};

/// The most light volumes (point spheres, spot cones and spheres) one pass
/// draws: 65,536 volumes of 320 triangles already take seconds a frame on a
/// software rasteriser, and a million took minutes and gigabytes, so more are
/// refused with a pointer to tiled shading (see docs/lights.md).
pub const MAX_LIGHT_VOLUMES: u32 = 65_536;

/// Descriptor sets for graph resources one frame may need.
const FRAME_SETS: u32 = 64;

/// What a scene pass binds besides its pipeline.
struct PassBindings {
    graph_set: Option<vk::DescriptorSet>,
    push: Option<(vk::ShaderStageFlags, Vec<u8>)>,
}

/// Whether a pass drawing every mesh must blend its transparent ones itself: it
/// shades colour (a fragment stage writing attachments) that the graph does not blend.
fn blends_transparency(state: &PassState) -> bool {
    !state.blends.is_empty() && state.blends.iter().all(|b| *b == BlendCode::Off)
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
    pipelines: ScenePipelines,
    pool: DescriptorPool<'g>,
    frame: FrameValues,
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
    pub fn new(gpu: &'g Gpu, scene: GpuScene<'g>) -> Result<Self, GpuError> {
        let pool = DescriptorPool::new(
            gpu,
            FRAME_SETS,
            &[
                (vk::DescriptorType::COMBINED_IMAGE_SAMPLER, FRAME_SETS * 8),
                (vk::DescriptorType::UNIFORM_BUFFER, FRAME_SETS),
                (vk::DescriptorType::STORAGE_BUFFER, FRAME_SETS * 4),
                (vk::DescriptorType::STORAGE_IMAGE, FRAME_SETS),
            ],
        )?;
        Ok(Self {
            gpu,
            scene,
            pipelines: ScenePipelines::new()?,
            pool,
            frame: FrameValues::default(),
            draw_calls: 0,
            culling: Vec::new(),
            shadow_tiles: Vec::new(),
        })
    }

    /// Forgets every shadow tile kept from earlier frames, so the next frame
    /// draws every shadow view (its plan, scene or shaders changed).
    pub fn forget_shadow_tiles(&mut self) {
        self.shadow_tiles.clear();
    }

    /// Sets the `time`, `frame` and `history_frames` values push constants receive.
    pub fn set_frame(&mut self, time: f32, frame: u32, history_frames: u32) {
        self.frame.time = time;
        self.frame.frame = frame;
        self.frame.history_frames = history_frames;
    }

    /// Drops every scene pipeline built from `changed` so the next frame rebuilds
    /// it (hot reload, see `reload::LiveRender`); waits for the device first.
    /// Returns how many were dropped.
    pub fn reload(&mut self, changed: &std::path::Path) -> Result<usize, GpuError> {
        self.gpu.wait_idle()?;
        self.forget_shadow_tiles();
        Ok(self.pipelines.invalidate(self.gpu.device(), changed))
    }

    /// Takes a shader variant a hot reload already compiled and checked, so the
    /// next frame only builds its pipeline.
    pub fn adopt(&mut self, key: ShaderKey, module: Arc<ShaderModule>) {
        self.forget_shadow_tiles();
        self.pipelines.adopt(key, module);
    }

    /// Binds a scene pipeline with the pass's graph set, the scene set, push
    /// constants and the shared vertex and index buffers.
    fn bind(&self, cmd: vk::CommandBuffer, p: &ScenePipeline, b: &PassBindings) {
        let commands = Commands::new(self.gpu.device(), cmd);
        let point = vk::PipelineBindPoint::GRAPHICS;
        commands.bind_pipeline(point, p.pipeline);
        if let Some(set) = b.graph_set {
            commands.bind_sets(point, p.layout, 0, &[set]);
        }
        commands.bind_sets(point, p.layout, SCENE_SET, &[self.scene.scene_set]);
        if let Some((stages, bytes)) = &b.push {
            commands.push_constants(p.layout, *stages, bytes);
        }
        commands.bind_geometry(self.scene.vertices.buffer, self.scene.indices.buffer);
        commands.set_front_face(front_face(false));
    }

    /// Draws meshes one indexed draw each (the draw record as `firstInstance`),
    /// binding a material's texture set when the material changes; returns the draw count.
    fn draw_meshes<'a>(
        &self,
        cmd: vk::CommandBuffer,
        p: &ScenePipeline,
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
    fn visible(&mut self, view: String, clip: Mat4, filter: MaterialFilter) -> Vec<DrawItem> {
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

    /// The pipeline for `key` with the pass's graph set and push constants
    /// (`params` packed into the pipeline's push block).
    fn ready(
        &mut self,
        ctx: &RasterContext<'_>,
        key: &ScenePipelineKey,
        layouts: [vk::DescriptorSetLayout; 2],
        params: &BTreeMap<String, ParamValue>,
    ) -> Result<(Arc<ScenePipeline>, PassBindings), GpuError> {
        let pass = ctx.pass();
        let p = self
            .pipelines
            .get(self.gpu, key, layouts, (ctx.plan, pass))?;
        let graph_set = self.graph_set(ctx, p.graph_layout, &p.interface)?;
        let push = match &p.interface.push {
            Some((block, stages)) => {
                let frame = FrameValues {
                    extent: [ctx.extent.width, ctx.extent.height],
                    ..self.frame
                };
                let bytes =
                    pack_push(block, params, &frame).map_err(|problems| GpuError::Pass {
                        pass: pass.name.clone(),
                        message: problems.join("; "),
                    })?;
                Some((*stages, bytes))
            }
            None => None,
        };
        Ok((p, PassBindings { graph_set, push }))
    }

    /// Draws `draws` with the pass's variant; with `by_model`, in runs of one
    /// shading model, each run with the variant the pass declares for that
    /// model (`PlanPass::defines_for`), opaque-safe order kept: callers pass
    /// blended draws already sorted, and the runs follow that order.
    fn draw_variants(
        &mut self,
        ctx: &RasterContext<'_>,
        key: &ScenePipelineKey,
        layouts: [vk::DescriptorSetLayout; 2],
        params: &BTreeMap<String, ParamValue>,
        mut draws: Vec<DrawItem>,
        by_model: bool,
    ) -> Result<u64, GpuError> {
        if !by_model {
            let (p, bindings) = self.ready(ctx, key, layouts, params)?;
            self.bind(ctx.cmd, &p, &bindings);
            return Ok(self.draw_meshes(ctx.cmd, &p, draws.iter()));
        }
        if !blends_transparency(&key.state) {
            // Depth-tested opaque draws may go in any order: one run per model.
            draws.sort_by_key(|d| self.model_of(d));
        }
        let models: Vec<ShadingModel> = draws.iter().map(|d| self.model_of(d)).collect();
        let mut calls = 0;
        let mut start = 0;
        while start < draws.len() {
            let model = models[start];
            let end = start + models[start..].iter().take_while(|m| **m == model).count();
            let defines = ctx.pass().defines_for(model);
            let variant = |shader: &ShaderKey| ShaderKey {
                defines: defines.clone(),
                ..shader.clone()
            };
            let for_model = ScenePipelineKey {
                vertex: variant(&key.vertex),
                fragment: key.fragment.as_ref().map(variant),
                ..key.clone()
            };
            let (p, bindings) = self.ready(ctx, &for_model, layouts, params)?;
            self.bind(ctx.cmd, &p, &bindings);
            calls += self.draw_meshes(ctx.cmd, &p, draws[start..end].iter());
            start = end;
        }
        Ok(calls)
    }

    /// The shading model of a draw's material, as passes group draws by it.
    fn model_of(&self, d: &DrawItem) -> ShadingModel {
        let material = self.scene.geometry.materials.get(d.material as usize);
        match material.map(|m| m.shading) {
            Some(weft_scene::material::ShadingModel::MetallicRoughness) => {
                ShadingModel::MetallicRoughness
            }
            _ => ShadingModel::BlinnPhong,
        }
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

    /// Allocates and writes set 0: the graph resources the pass samples or stores.
    fn graph_set(
        &self,
        ctx: &RasterContext<'_>,
        layout: vk::DescriptorSetLayout,
        interface: &PipelineInterface,
    ) -> Result<Option<vk::DescriptorSet>, GpuError> {
        let mut graph_only = interface.clone();
        graph_only.bindings.retain(|(set, _), _| *set == 0);
        let pass = ctx.pass();
        if graph_only.bindings.is_empty() && pass.bindings.is_empty() {
            return Ok(None);
        }
        let resolved = resolve_bindings(ctx.plan, pass, &graph_only).map_err(|problems| {
            GpuError::Mismatch {
                pass: pass.name.clone(),
                problems,
            }
        })?;
        let set = self.pool.allocate(layout)?;
        write_graph_set(
            self.gpu,
            set,
            &resolved,
            ctx.resources,
            |compare, format| {
                if compare {
                    ctx.compare_sampler
                } else if ctx.gpu.linear_filter(format) {
                    ctx.sampler
                } else {
                    ctx.nearest_sampler
                }
            },
            |resource| ctx.image_layout(resource),
        )?;
        Ok(Some(set))
    }
}

impl SceneRecorder<'_> {
    /// A `ShadowAtlas` pass: fits this frame's views to the attachment's size
    /// with the provider's settings, then draws the casters once per view into
    /// its tile.
    fn draw_shadow_views(
        &mut self,
        ctx: &RasterContext<'_>,
        p: &ScenePipeline,
        filter: MaterialFilter,
        settings: &ShadowSettings,
    ) -> Result<u64, GpuError> {
        let pass = ctx.pass();
        let views = self.scene.prepare_shadows(settings, ctx.extent.width)?;
        let (block, stages) = p.interface.push.as_ref().ok_or_else(|| GpuError::Pass {
            pass: pass.name.clone(),
            message: "shadow pass without push constants".into(),
        })?;
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
            let mut params = pass.params.clone();
            params.insert(SHADOW_VIEW.to_string(), ParamValue::Number(i as f64));
            let bytes =
                pack_push(block, &params, &self.frame).map_err(|problems| GpuError::Pass {
                    pass: pass.name.clone(),
                    message: problems.join("; "),
                })?;
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
            commands.push_constants(p.layout, *stages, &bytes);
            let draws = self.visible(name, view.clip, filter);
            calls += self.draw_meshes(ctx.cmd, p, draws.iter());
            self.shadow_tiles[i] = Some(tile);
        }
        Ok(calls)
    }
}

impl DrawRecorder for SceneRecorder<'_> {
    /// The previous frame's graph descriptor sets are recycled and the draw
    /// count starts again.
    fn begin_frame(&mut self) -> Result<(), GpuError> {
        self.pool.reset()?;
        self.draw_calls = 0;
        self.culling.clear();
        Ok(())
    }

    fn record(&mut self, ctx: &RasterContext<'_>) -> Result<(), GpuError> {
        let pass = ctx.pass();
        let fail = |message: String| GpuError::Pass {
            pass: pass.name.clone(),
            message,
        };
        let draw = pass
            .draw
            .clone()
            .ok_or_else(|| fail("raster pass without a `draw`".into()))?;
        let shader = |path: &std::path::Path, stage| ShaderKey {
            path: path.to_path_buf(),
            stage,
            defines: pass.defines.clone(),
        };
        let vertex = pass
            .shaders
            .vertex
            .as_deref()
            .ok_or_else(|| fail("needs a vertex shader".into()))?;
        let key = ScenePipelineKey {
            vertex: shader(vertex, ShaderStage::Vertex),
            fragment: pass
                .shaders
                .fragment
                .as_deref()
                .map(|f| shader(f, ShaderStage::Fragment)),
            render_pass: ctx.render_pass,
            state: pass_state(pass),
        };
        let layouts = [
            self.scene.scene_layout.handle(),
            self.scene.material_layout.handle(),
        ];
        let shadow_atlas = providers::shadow_atlas(pass);
        let mut params = pass.params.clone();
        if shadow_atlas.is_some() {
            params.insert(SHADOW_VIEW.to_string(), ParamValue::Number(0.0));
        }
        let by_model = pass.groups_by_model() && shadow_atlas.is_none();
        let mut calls = 0u64;
        match draw {
            Draw::Meshes(MaterialFilter::All) if blends_transparency(&key.state) => {
                // Opaque first, then transparent meshes blended over them, farthest first.
                let camera = self.scene.view_proj;
                let opaque = self.visible(pass.name.clone(), camera, MaterialFilter::Opaque);
                calls += self.draw_variants(ctx, &key, layouts, &params, opaque, by_model)?;
                let transparent =
                    self.visible(pass.name.clone(), camera, MaterialFilter::Transparent);
                let transparent = self.back_to_front(transparent);
                if !transparent.is_empty() {
                    let blended = ScenePipelineKey {
                        state: transparent_state(&key.state),
                        ..key.clone()
                    };
                    calls +=
                        self.draw_variants(ctx, &blended, layouts, &params, transparent, by_model)?;
                }
            }
            Draw::Meshes(filter) => match &shadow_atlas {
                Some(settings) => {
                    let (p, bindings) = self.ready(ctx, &key, layouts, &params)?;
                    self.bind(ctx.cmd, &p, &bindings);
                    calls += self.draw_shadow_views(ctx, &p, filter, settings)?;
                }
                None => {
                    let draws = self.visible(pass.name.clone(), self.scene.view_proj, filter);
                    calls += self.draw_variants(ctx, &key, layouts, &params, draws, by_model)?;
                }
            },
            Draw::LightVolumes(kind) => {
                let (p, bindings) = self.ready(ctx, &key, layouts, &params)?;
                self.bind(ctx.cmd, &p, &bindings);
                let g = &self.scene.geometry;
                let lights = &self.scene.light_set;
                let groups = match kind {
                    LightKind::Point => vec![(g.sphere, lights.points, lights.first_point())],
                    LightKind::Spot => vec![
                        (g.cone, lights.spot_cones, lights.first_spot_cone()),
                        (g.sphere, lights.spot_spheres, lights.first_spot_sphere()),
                    ],
                    LightKind::Area => vec![(g.panel, lights.areas, lights.first_area())],
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
            Draw::FullscreenTriangle => {
                return Err(fail(
                    "a fullscreen triangle is drawn by the executor".into(),
                ))
            }
        }
        self.draw_calls += calls;
        Ok(())
    }

    fn bind_scene(&mut self, ctx: &RasterContext<'_>, pipeline: &Pipeline) -> Result<(), GpuError> {
        // Checked and collected once, when the layout's set is first made.
        let bindings = || {
            let tracing = providers::traces(ctx.pass());
            let problems = scene_set_problems(&pipeline.interface, false, tracing);
            if !problems.is_empty() {
                return Err(GpuError::Pass {
                    pass: ctx.pass().name.clone(),
                    message: problems.join("; "),
                });
            }
            Ok(pipeline
                .interface
                .bindings
                .keys()
                .filter(|(set, _)| *set == SCENE_SET)
                .map(|(_, b)| *b)
                .collect())
        };
        let layout = pipeline
            .set_layouts
            .get(SCENE_SET as usize)
            .copied()
            .ok_or_else(|| GpuError::Pass {
                pass: ctx.pass().name.clone(),
                message: "pipeline has no scene set layout".into(),
            })?;
        let set = self.scene.foreign_set(layout, bindings)?;
        ctx.commands()
            .bind_sets(pipeline.bind_point, pipeline.layout, SCENE_SET, &[set]);
        Ok(())
    }
}

impl Drop for SceneRecorder<'_> {
    fn drop(&mut self) {
        let _ = self.gpu.wait_idle();
        self.pipelines.destroy(self.gpu.device());
    }
}
