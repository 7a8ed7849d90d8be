//! The scene on the device: geometry, draw records and materials uploaded once,
//! textures, and the per-frame camera and light buffers; descriptor set 1 (scene
//! data) and set 2 (a material's textures) that every scene shader binds.

mod acceleration;
pub use acceleration::structure_scratch_bytes;
mod environment;
mod ltc;
mod placement;
mod trace;

use crate::bindings::{self, *};
use crate::error::RenderError;
use crate::geometry::SceneGeometry;
use crate::gpu_types::{bytes_of, GpuFrame, GpuLight, GpuMaterial};
use crate::lights::{pack_lights, LightSet, LIGHT_BYTES};
use crate::materials::pack_material;
use crate::shadows::{self, ShadowSettings, ShadowView, ViewVolume};
use crate::texture;
use ash::vk;
use environment::EnvironmentBuffers;
use glam::{UVec4, Vec4};
use ltc::ltc_table_words;
use placement::{changed_records, moved_panels};
use std::collections::HashMap;
use std::path::PathBuf;
use trace::TraceBuffers;
use weft_gpu::buffer::{Buffer, TexelBuffer, TexelFormat};
use weft_gpu::descriptors::{DescriptorPool, DescriptorWriter};
use weft_gpu::samplers::Sampler;
use weft_gpu::scene::{SceneBinding, SceneLayouts, SceneSet};
use weft_gpu::texture::{Rgba8Image, Texture};
use weft_gpu::{Gpu, GpuError};
use weft_scene::material::TextureRef;
use weft_scene::{Camera, Scene, SceneAt};

/// Bytes of the `Frame` uniform block.
pub const FRAME_BYTES: usize = std::mem::size_of::<GpuFrame>();
/// A pool for the two scene sets (raster, traced) and one set per material;
/// the traced set's top level only on a device with ray queries.
fn descriptor_pool(gpu: &Gpu, materials: u32) -> Result<DescriptorPool<'_>, GpuError> {
    let scene_sets = 2;
    let top_level = (vk::DescriptorType::ACCELERATION_STRUCTURE_KHR, 1);
    let ray_query = gpu.info().shaders.ray_query;
    DescriptorPool::new(
        gpu,
        scene_sets + materials,
        &[
            (vk::DescriptorType::UNIFORM_BUFFER, scene_sets),
            (
                vk::DescriptorType::STORAGE_BUFFER,
                (SCENE_SET_BINDINGS.len() + TRACE_SET_BINDINGS.len()) as u32 * scene_sets,
            ),
            (
                vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
                SCENE_TEXEL_BUFFERS * scene_sets + TRACE_TEXEL_BUFFERS,
            ),
            (
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                MATERIAL_SET_BINDINGS.len() as u32 * materials.max(1) + TRACE_TEXTURE_ARRAYS,
            ),
        ]
        .into_iter()
        .chain(ray_query.then_some(top_level))
        .collect::<Vec<_>>(),
    )
}

/// Everything the scene shaders read, on the device.
pub struct GpuScene<'g> {
    gpu: &'g Gpu,
    /// The flattened scene the buffers were filled from.
    pub geometry: SceneGeometry,
    /// Every vertex ([`crate::geometry::VERTEX_BYTES`] each).
    pub vertices: Buffer<'g>,
    /// Every index, `u32`.
    pub indices: Buffer<'g>,
    draws: Buffer<'g>,
    materials: TexelBuffer<'g>,
    frame: Buffer<'g>,
    lights: Buffer<'g>,
    shadows: Buffer<'g>,
    ltc_tables: Buffer<'g>,
    pub(crate) environment: EnvironmentBuffers<'g>,
    textures: Vec<Texture<'g>>,
    sampler: Sampler<'g>,
    pool: DescriptorPool<'g>,
    /// The layouts of the scene sets, defined as the executor's pipelines
    /// define them ([`bindings::scene_interface`]).
    layouts: SceneLayouts<'g>,
    /// Set 1 with the raster bindings.
    scene_set: vk::DescriptorSet,
    /// Set 1 with the ray tracer's bindings too, made when a pass first traces.
    traced_set: Option<vk::DescriptorSet>,
    /// Set 2 per material.
    pub material_sets: Vec<vk::DescriptorSet>,
    /// Built on first use by a ray-tracing pass.
    trace: Option<TraceBuffers<'g>>,
    /// Whether tracing passes use ray queries, and then the acceleration
    /// structures, built with the ray tracer's buffers.
    hardware: bool,
    structures: Option<acceleration::SceneStructures<'g>>,
    /// Where the BVH is cached (`crate::bvh_cache`); `None` builds it every time.
    bvh_cache: Option<PathBuf>,
    /// Each scene instance's transform as the draw records hold it.
    transforms: Vec<glam::Mat4>,
    /// Each scene instance's material overrides as the material records hold them.
    overrides: Vec<weft_scene::material::MaterialOverride>,
    /// Per material, whether it has a normal map (how its record is packed).
    normal_mapped: Vec<bool>,
    /// The scene's `boundingbox`, which moving placements do not change.
    declared_bounds: Option<weft_scene::Aabb>,
    /// Whether the script has moved a placement since the scene loaded.
    moved: bool,
    /// The world boxes, before and after, of the draws moved by the last
    /// update: the shadow views they meet are redrawn.
    moved_boxes: Vec<weft_scene::Aabb>,
    bounds: weft_scene::Aabb,
    /// The camera's view volume at the last update, what sun cascades are fitted to.
    pub view_volume: ViewVolume,
    /// Camera position at the last update, for sorting transparent meshes.
    pub camera_position: glam::Vec3,
    /// The camera's world-to-clip matrix at the last update, for culling draws.
    pub view_proj: glam::Mat4,
    /// Whether an update ran (so `view_proj` is the previous frame's).
    uploaded: bool,
    /// Light counts by kind (stable over time; animation moves lights only).
    pub light_set: LightSet,
    /// Emissive geometry as polygon lights for raster passes, as placed now.
    pub emitter_lights: crate::emitter_lights::EmitterLights,
    /// Textures that could not be loaded (their materials use white), and skipped meshes.
    pub warnings: Vec<String>,
}

impl<'g> GpuScene<'g> {
    /// Uploads `scene`; `animates` says whether its placements and colours
    /// may change per frame ([`weft_scene::SceneUpdater::animates`]).
    pub fn new(gpu: &'g Gpu, scene: &Scene, animates: bool) -> Result<Self, RenderError> {
        // A scene whose script animates may move and recolour placements:
        // each then draws its own material copies, and the draw records and
        // materials are rewritten in place each frame.
        let geometry = if animates {
            SceneGeometry::with_own_materials(scene)
        } else {
            SceneGeometry::new(scene)
        };
        let mut warnings: Vec<String> = geometry
            .skipped
            .iter()
            .map(|m| format!("mesh skipped (inconsistent arrays): {m}"))
            .chain(
                geometry
                    .non_finite
                    .iter()
                    .map(|m| format!("triangles with a non-finite vertex left out: {m}")),
            )
            .collect();
        if geometry.draws.len() > u32::MAX as usize / 2 {
            return Err(RenderError::TooLarge(format!(
                "{} draws",
                geometry.draws.len()
            )));
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        // Bottom-level acceleration structures read the geometry in place.
        let geometry_usage = if gpu.info().shaders.ray_query {
            storage | weft_gpu::acceleration::INPUT_USAGE
        } else {
            storage
        };
        let vertices = Buffer::device_local(
            gpu,
            "scene vertices",
            bytes_of(&geometry.vertices),
            vk::BufferUsageFlags::VERTEX_BUFFER | geometry_usage,
        )?;
        let index_bytes: Vec<u8> = geometry
            .indices
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let indices = Buffer::device_local(
            gpu,
            "scene indices",
            &index_bytes,
            vk::BufferUsageFlags::INDEX_BUFFER | geometry_usage,
        )?;
        let draws = rewritable(
            gpu,
            "scene draws",
            bytes_of(&geometry.draw_records),
            animates,
        )?;
        let mut textures = vec![Texture::upload(gpu, "white", &Rgba8Image::white(), true)?];
        let mut by_source: HashMap<(String, bool), usize> = HashMap::new();
        let mut material_texture = Vec::with_capacity(geometry.materials.len());
        let mut material_records: Vec<GpuMaterial> = Vec::with_capacity(geometry.materials.len());
        let mut slot = |t: Option<&TextureRef>, srgb: bool| -> Result<usize, GpuError> {
            let Some(t) = t else { return Ok(0) };
            let key = (texture::source_key(&t.source), srgb);
            if let Some(&i) = by_source.get(&key) {
                return Ok(i);
            }
            let i = match texture::decode(&t.source, gpu.info().max_image_dimension) {
                Ok(decoded) => {
                    warnings.extend(decoded.warning);
                    textures.push(Texture::upload(gpu, &key.0, &decoded.image, srgb)?);
                    textures.len() - 1
                }
                Err(e) => {
                    warnings.push(format!("texture left white: {e}"));
                    0
                }
            };
            by_source.insert(key, i);
            Ok(i)
        };
        for m in &geometry.materials {
            let base = slot(m.textures.base_color.as_ref(), true)?;
            let metal_rough = slot(m.textures.metallic_roughness.as_ref(), false)?;
            let normal = slot(m.textures.normal.as_ref(), false)?;
            let emissive = slot(m.textures.emissive.as_ref(), true)?;
            let occlusion = slot(m.textures.occlusion.as_ref(), false)?;
            material_records.push(pack_material(m, normal != 0));
            material_texture.push([base, metal_rough, normal, emissive, occlusion]);
        }
        // A texel buffer: the path tracer reads a record at every vertex, and
        // lavapipe reads a storage buffer a component and a lane at a time.
        let materials = {
            let (name, bytes) = ("the materials", bytes_of(&material_records));
            if animates {
                TexelBuffer::host(gpu, name, bytes, TexelFormat::Words4)?
            } else {
                TexelBuffer::device_local(gpu, name, bytes, TexelFormat::Words4)?
            }
        };
        let normal_mapped = material_texture.iter().map(|slots| slots[2] != 0).collect();
        let frame = Buffer::host(
            gpu,
            "frame",
            FRAME_BYTES as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let bounds = scene.effective_bounds();
        let emitter_lights = crate::emitter_lights::emitter_lights(&geometry);
        if emitter_lights.clusters > 0 || emitter_lights.dropped > 0 {
            warnings.extend(emitter_lights.summary());
        }
        let mut light_set = pack_lights(
            &weft_scene::animation::lights_at(&scene.lights, 0.0, 0),
            &bounds,
        );
        light_set.add_emitter_polygons(&emitter_lights.records());
        let mut lights = Buffer::host(
            gpu,
            "lights",
            (light_set.records.len() * LIGHT_BYTES) as u64,
            storage,
        )?;
        // `update` writes only the records that change from these.
        if !light_set.records.is_empty() {
            lights.write(bytes_of(&light_set.records))?;
        }
        let mut shadows = Buffer::host(gpu, "shadows", shadows::SHADOWS_BYTES as u64, storage)?;
        shadows.write(&vec![0u8; shadows::SHADOWS_BYTES])?;
        let tables = weft_ltc::tables::committed()
            .map_err(|e| GpuError::Plan(format!("the built-in LTC tables: {e}")))?;
        let albedo = weft_ltc::energy::AlbedoTable::committed()
            .map_err(|e| GpuError::Plan(format!("the built-in GGX albedo table: {e}")))?;
        let words = ltc_table_words(tables, albedo);
        let mut ltc_tables = Buffer::host(gpu, "ltc_tables", (words.len() * 4) as u64, storage)?;
        ltc_tables.write(bytes_of(&words))?;
        let environment = EnvironmentBuffers::new(gpu, scene.environment.as_ref())?;
        let sampler = Sampler::linear_repeat(gpu)?;
        let layouts = SceneLayouts::new(gpu, &bindings::scene_interface())?;
        let pool = descriptor_pool(gpu, material_texture.len() as u32)?;
        let mut this = Self {
            gpu,
            geometry,
            vertices,
            indices,
            draws,
            materials,
            frame,
            lights,
            shadows,
            ltc_tables,
            environment,
            textures,
            sampler,
            pool,
            layouts,
            scene_set: vk::DescriptorSet::null(),
            traced_set: None,
            material_sets: Vec::new(),
            transforms: scene.instances.iter().map(|i| i.transform).collect(),
            overrides: scene.instances.iter().map(|i| i.material).collect(),
            normal_mapped,
            declared_bounds: scene.declared_bounds,
            moved: false,
            moved_boxes: Vec::new(),
            trace: None,
            hardware: false,
            structures: None,
            bvh_cache: None,
            bounds,
            view_volume: ViewVolume::new(
                glam::Vec3::ZERO,
                glam::Quat::IDENTITY,
                1.0,
                1.0,
                0.1,
                100.0,
            ),
            camera_position: glam::Vec3::ZERO,
            view_proj: glam::Mat4::IDENTITY,
            uploaded: false,
            light_set,
            emitter_lights,
            warnings,
        };
        this.create_sets(&material_texture)?;
        Ok(this)
    }

    fn create_sets(&mut self, material_texture: &[[usize; 5]]) -> Result<(), GpuError> {
        self.scene_set = self.pool.allocate(self.layouts.scene(SceneSet::Raster))?;
        self.write_scene_set(self.scene_set, false);
        for slots in material_texture {
            let set = self.pool.allocate(self.layouts.material.handle())?;
            let mut writer = DescriptorWriter::default();
            for (binding, slot) in MATERIAL_SET_BINDINGS.iter().zip(slots) {
                writer.image(
                    binding.binding,
                    vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                    self.sampler.handle(),
                    self.textures[*slot].view,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                );
            }
            writer.write(self.gpu, set);
            self.material_sets.push(set);
        }
        Ok(())
    }

    /// Writes the scene buffers into set 1 `set`: the raster bindings, and
    /// the ray tracer's too when `traced`.
    fn write_scene_set(&self, set: vk::DescriptorSet, traced: bool) {
        let mut writer = DescriptorWriter::default();
        let trace = TRACE_SET_BINDINGS.iter().filter(|_| traced);
        for &SceneBinding {
            binding: b, kind, ..
        } in SCENE_SET_BINDINGS.iter().chain(trace)
        {
            if let Some(buffer) = self.scene_buffer(b) {
                writer.buffer(b, kind.vk(), buffer.buffer);
            }
            if let Some(view) = self.scene_texel_view(b) {
                writer.texel_buffer(b, view);
            }
            if let Some(structures) = self.structures.as_ref().filter(|_| b == TOP_LEVEL_BINDING) {
                writer.acceleration_structure(b, structures.top.structure.handle);
            }
            let texture = self
                .trace
                .as_ref()
                .filter(|_| is_trace_texture(b))
                .and_then(|t| t.textures.get((b - TRACE_TEXTURES_BINDING) as usize));
            if let Some(texture) = texture {
                writer.image(
                    b,
                    kind.vk(),
                    self.sampler.handle(),
                    texture.view,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                );
            }
        }
        writer.write(self.gpu, set);
    }

    /// The texel buffer view behind a set 1 binding.
    fn scene_texel_view(&self, binding: u32) -> Option<vk::BufferView> {
        match binding {
            MATERIALS_BINDING => Some(self.materials.view),
            ENVIRONMENT_BINDING => Some(self.environment.texels.view),
            ENVIRONMENT_TABLE_BINDING => Some(self.environment.table.view),
            _ => self.trace.as_ref().and_then(|t| t.texel_view(binding)),
        }
    }

    /// The buffer behind a set 1 binding.
    fn scene_buffer(&self, binding: u32) -> Option<&Buffer<'_>> {
        match binding {
            FRAME_BINDING => Some(&self.frame),
            LIGHTS_BINDING => Some(&self.lights),
            DRAWS_BINDING => Some(&self.draws),
            SHADOWS_BINDING => Some(&self.shadows),
            LTC_TABLES_BINDING => Some(&self.ltc_tables),
            VERTICES_BINDING => Some(&self.vertices),
            INDICES_BINDING => Some(&self.indices),
            _ => self.trace.as_ref().and_then(|t| t.buffer(binding)),
        }
    }

    /// Set 1 of the layout `kind`: the raster bindings, or with the ray
    /// tracer's too (its BVH built and its buffers uploaded on first use).
    pub fn scene_set(&mut self, kind: SceneSet) -> Result<vk::DescriptorSet, GpuError> {
        match (kind, self.traced_set) {
            (SceneSet::Raster, _) => Ok(self.scene_set),
            (SceneSet::Traced, Some(set)) => Ok(set),
            (SceneSet::Traced, None) => {
                self.ensure_trace_buffers()?;
                let set = self.pool.allocate(self.layouts.scene(SceneSet::Traced))?;
                self.write_scene_set(set, true);
                self.traced_set = Some(set);
                Ok(set)
            }
        }
    }

    /// Uploads the scene as it is at `time` (`at`, from a [`weft_scene::SceneUpdater`]):
    /// lights, moved and recoloured placements, and `camera` (or the script's camera of
    /// its name) for a target of `extent`, its projection moved by `jitter` pixels (zero
    /// unless the plan jitters the camera); call it before each frame (the previous
    /// frame must have finished). Returns a hash of what it uploaded (camera, lights,
    /// placements and their colours), so callers can tell whether two frames see the same inputs.
    pub fn update(
        &mut self,
        at: &SceneAt<'_>,
        camera: &Camera,
        time: f64,
        (extent, jitter): ([u32; 2], glam::Vec2),
    ) -> Result<u64, GpuError> {
        if let Some(transforms) = at.transforms {
            self.place_instances(transforms)?;
        } else {
            self.moved_boxes.clear();
        }
        if let Some(colors) = at.colors {
            self.recolour_instances(colors)?;
        }
        let camera = at.camera(camera);
        let [w, h] = [extent[0].max(1) as f32, extent[1].max(1) as f32];
        let view_proj = camera.view_projection(time, w / h);
        let prev_view_proj = if self.uploaded {
            self.view_proj
        } else {
            view_proj
        };
        self.uploaded = true;
        let eye = camera.pose_at(time).0;
        self.camera_position = eye;
        self.view_proj = view_proj;
        let (_, rotation) = camera.pose_at(time);
        self.view_volume =
            ViewVolume::new(eye, rotation, camera.fov_y, w / h, camera.near, camera.far);
        let bounds = self.bounds;
        let mut lights = pack_lights(at.lights, &bounds);
        lights.add_emitter_polygons(&self.emitter_lights.records());
        let shown_view_proj = crate::jitter::jittered(view_proj, jitter, glam::Vec2::new(w, h));
        let changed = changed_records(&self.light_set.records, &lights.records);
        if let Some(changed) = changed.clone() {
            let panels = moved_panels(&self.light_set.records, &lights.records, changed);
            self.moved_boxes.extend(panels);
        }
        let (moved, moved_lo, moved_hi) = crate::gpu_types::moved_boxes(&self.moved_boxes);
        let frame = GpuFrame {
            view_proj: shown_view_proj,
            inv_view_proj: shown_view_proj.inverse(),
            camera_position: eye.extend(1.0),
            ambient: lights.ambient.extend(0.0),
            counts: UVec4::new(
                lights.suns,
                lights.points,
                lights.spot_cones + lights.spot_spheres,
                lights.len(),
            ),
            viewport: Vec4::new(w, h, 1.0 / w, 1.0 / h),
            emitter_lights: UVec4::new(lights.emitter_polygons, 0, 0, 0),
            prev_view_proj,
            unjittered_view_proj: view_proj,
            jitter: jitter.extend(0.0).extend(0.0),
            moved,
            moved_lo,
            moved_hi,
            environment: self.environment.frame.params,
            environment_size: self.environment.frame.size,
            environment_sh: self.environment.frame.sh,
        };
        self.frame.write(bytes_of(&[frame]))?;
        if let Some(changed) = changed {
            let offset = changed.start * std::mem::size_of::<GpuLight>();
            self.lights
                .write_at(offset, bytes_of(&lights.records[changed]))?;
            if let Some(trace) = self.trace.as_mut() {
                trace.update_light_choices(&lights, scene_radius(&bounds))?;
            }
        }
        let mut inputs = std::collections::hash_map::DefaultHasher::new();
        // What this frame shows, not how the last one differed or where its jitter
        // fell: a still camera's frames hash alike even right after it moved, and
        // jittered frames of one view alike (the inverse follows from `view_proj`).
        let shown = GpuFrame {
            view_proj,
            inv_view_proj: glam::Mat4::ZERO,
            prev_view_proj: view_proj,
            jitter: glam::Vec4::ZERO,
            moved: glam::UVec4::ZERO,
            moved_lo: Default::default(),
            moved_hi: Default::default(),
            ..frame
        };
        std::hash::Hash::hash(bytes_of(&[shown]), &mut inputs);
        std::hash::Hash::hash(bytes_of(&lights.records), &mut inputs);
        std::hash::Hash::hash(bytes_of(&self.transforms), &mut inputs);
        for overrides in &self.overrides {
            std::hash::Hash::hash(&overrides.key(), &mut inputs);
        }
        self.light_set = lights;
        Ok(std::hash::Hasher::finish(&inputs))
    }
}

impl GpuScene<'_> {
    /// Where the draws and area-light panels the last [`GpuScene::update`]
    /// moved were and are now (world boxes): a kept shadow tile whose view
    /// meets one is stale.
    pub fn moved_boxes(&self) -> &[weft_scene::Aabb] {
        &self.moved_boxes
    }

    /// Fits this frame's shadow views for a `atlas_size` squared shadow map with
    /// `settings` (after [`GpuScene::update`]) and writes the record the shaders
    /// read; returns the views, to draw one by one. The device must not be
    /// reading the record (the previous frame has finished).
    pub fn prepare_shadows(
        &mut self,
        settings: &ShadowSettings,
        atlas_size: u32,
    ) -> Result<Vec<ShadowView>, GpuError> {
        let frame = shadows::shadow_frame(
            settings,
            atlas_size,
            &self.view_volume,
            &self.light_set,
            &self.bounds,
        );
        self.shadows.write(&frame.pack(settings))?;
        Ok(frame.views)
    }
}

/// A storage buffer holding `bytes`: host-visible when it is `rewritten`
/// per frame (in ranges), else device-local.
fn rewritable<'g>(
    gpu: &'g Gpu,
    name: &str,
    bytes: &[u8],
    rewritten: bool,
) -> Result<Buffer<'g>, GpuError> {
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    if rewritten {
        let mut buffer = Buffer::host(gpu, name, bytes.len().max(1) as u64, storage)?;
        buffer.write(bytes)?;
        Ok(buffer)
    } else {
        Buffer::device_local(gpu, name, bytes, storage)
    }
}

impl Drop for GpuScene<'_> {
    /// The sets, layouts, sampler and buffers are freed when the fields drop;
    /// the device must have finished with them first.
    fn drop(&mut self) {
        let _ = self.gpu.wait_idle();
    }
}

/// The radius a sun's light choice is sized by: half the scene's diagonal,
/// 1 for an empty scene.
fn scene_radius(bounds: &weft_scene::Aabb) -> f32 {
    if bounds.is_empty() {
        1.0
    } else {
        (0.5 * bounds.diagonal()).max(f32::MIN_POSITIVE)
    }
}
