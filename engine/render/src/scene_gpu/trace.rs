//! The ray tracer's scene data on the device, built when a pass first traces:
//! world-space triangles, the BVH over them (in its 4-wide form), per-corner normals, tangents and
//! UVs, per-triangle materials and draws, the emitters' alias table, the lights' choice
//! table, the texture arrays and the per-pass ray counters (set 1's
//! tracing-only bindings, [`crate::bindings::TRACE_SET_BINDINGS`]); and the
//! scene's methods that build them and read the counters.

use super::{scene_radius, GpuScene};
use crate::bindings::*;
use crate::geometry::SceneGeometry;
use crate::gpu_types::bytes_of;
use crate::light_choice::LightChoices;
use crate::lights::LightSet;
use ash::vk;
use std::path::{Path, PathBuf};
use weft_gpu::buffer::TexelFormat::{Words2, Words4};
use weft_gpu::buffer::{Buffer, TexelBuffer};
use weft_gpu::texture::{Rgba8Image, Texture};
use weft_gpu::{Gpu, GpuError};

/// The ray tracer's scene data on the device.
pub(super) struct TraceBuffers<'g> {
    pub(super) triangles: TexelBuffer<'g>,
    pub(super) nodes: TexelBuffer<'g>,
    pub(super) leaf_triangles: TexelBuffer<'g>,
    pub(super) normals: TexelBuffer<'g>,
    pub(super) tangents: TexelBuffer<'g>,
    pub(super) uvs: TexelBuffer<'g>,
    pub(super) materials: TexelBuffer<'g>,
    pub(super) emitters: TexelBuffer<'g>,
    /// Which light NEE samples ([`LightChoices`]), rewritten when lights change.
    pub(super) light_choices: TexelBuffer<'g>,
    /// The emissive triangles' power as one light choice, `None` without any.
    emitter_power: Option<f32>,
    /// Colour arrays by class, then data arrays by class.
    pub(super) textures: Vec<Texture<'g>>,
    pub(super) material_textures: Buffer<'g>,
    /// Rays per tracing pass this frame ([`crate::providers::ray_counts`]), host-visible:
    /// zeroed before a frame, read after it.
    ray_counts: Buffer<'g>,
    /// Whether the BVH was built (tracing through ray queries needs none).
    bvh: bool,
}

impl<'g> TraceBuffers<'g> {
    /// Builds the BVH over `geometry`'s triangles (read from and stored in
    /// `cache` when given; with `bvh` false, for ray queries, an empty one)
    /// and uploads it with them and the choice table over `lights` (a scene
    /// of radius `scene_radius`); what went wrong on the way is added to
    /// `warnings`.
    pub(super) fn build(
        gpu: &'g Gpu,
        (geometry, bvh): (&SceneGeometry, bool),
        cache: Option<&Path>,
        (lights, scene_radius): (&LightSet, f32),
        warnings: &mut Vec<String>,
    ) -> Result<Self, GpuError> {
        let mesh = geometry.trace_mesh();
        let wide = if bvh {
            let (tree, cache_warning) = crate::bvh_cache::load_or_build(&mesh.corners, cache);
            warnings.extend(cache_warning);
            crate::bvh_wide::WideBvh::collapse(&tree, &mesh.corners)
        } else {
            crate::bvh_wide::WideBvh::collapse(&crate::bvh::Bvh::build(&[]), &[])
        };
        // The walk names nodes and leaf slots in 24 bits.
        let tables = [
            (
                "the BVH nodes",
                wide.nodes.len(),
                crate::bvh_wide::MAX_NODES,
                "nodes",
            ),
            (
                "the BVH's leaf triangles",
                wide.triangles.len(),
                crate::bvh_wide::MAX_LEAF_TRIANGLES,
                "triangles",
            ),
        ];
        for (what, len, limit, unit) in tables {
            within_index(what, len, limit, unit)?;
        }
        let stack_need = wide.stack_need();
        if stack_need > crate::bvh_wide::GPU_STACK {
            warnings.push(format!(
                "the ray tracer's BVH is {} levels deep and its walk may hold {stack_need} groups \
                 of nodes, more than the {} its stack has: rays may miss geometry",
                wide.depth(),
                crate::bvh_wide::GPU_STACK
            ));
        }
        let corners: Vec<[f32; 4]> = mesh
            .corners
            .iter()
            .flat_map(|t| t.map(|p| p.extend(1.0).to_array()))
            .collect();
        let normals: Vec<[f32; 4]> = mesh
            .normals
            .iter()
            .flat_map(|t| t.map(|n| n.extend(0.0).to_array()))
            .collect();
        let uvs: Vec<[f32; 2]> = mesh
            .uvs
            .iter()
            .flat_map(|t| t.map(|uv| uv.to_array()))
            .collect();
        let emitters = crate::emitters::EmitterTable::build(&mesh.corners, |t| {
            crate::sanitize::radiance(geometry.materials[mesh.materials[t] as usize].emissive)
        });
        // Luminance times area, summed; π times that is their power.
        let emitter_power =
            (!emitters.records.is_empty()).then_some(std::f32::consts::PI * emitters.total);
        let choices = light_choices(lights, emitter_power, scene_radius);
        let trace_textures = crate::trace_textures::gather(&geometry.materials);
        warnings.extend(trace_textures.warnings.iter().cloned());
        // Each triangle's material and the draw record that placed it.
        let material_draws: Vec<[u32; 2]> = mesh
            .materials
            .iter()
            .zip(&mesh.draws)
            .map(|(&m, &d)| [m, d])
            .collect();
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        Ok(Self {
            triangles: TexelBuffer::device_local(
                gpu,
                "the ray tracer's triangles",
                bytes_of(&corners),
                Words4,
            )?,
            nodes: TexelBuffer::device_local(gpu, "the BVH nodes", bytes_of(&wide.nodes), Words4)?,
            leaf_triangles: TexelBuffer::device_local(
                gpu,
                "the BVH's leaf triangles",
                bytes_of(&wide.triangles),
                Words4,
            )?,
            normals: TexelBuffer::device_local(
                gpu,
                "the corners' normals",
                bytes_of(&normals),
                Words4,
            )?,
            tangents: TexelBuffer::device_local(
                gpu,
                "the corners' tangents",
                bytes_of(&mesh.tangents),
                Words4,
            )?,
            uvs: TexelBuffer::device_local(gpu, "the corners' UVs", bytes_of(&uvs), Words2)?,
            materials: TexelBuffer::device_local(
                gpu,
                "the triangles' materials and draws",
                bytes_of(&material_draws),
                Words2,
            )?,
            emitters: TexelBuffer::device_local(
                gpu,
                "the emissive triangles' alias table",
                &emitters.bytes(),
                Words4,
            )?,
            light_choices: TexelBuffer::host(
                gpu,
                "the light choice table",
                &choices.bytes(),
                Words4,
            )?,
            emitter_power,
            textures: trace_textures
                .colour
                .iter()
                .map(|layers| (layers, true))
                .chain(trace_textures.data.iter().map(|layers| (layers, false)))
                .map(|(layers, srgb)| {
                    let white = [Rgba8Image::white()];
                    let layers = if layers.is_empty() {
                        &white[..]
                    } else {
                        layers
                    };
                    Texture::upload_layers(gpu, "trace textures", layers, srgb)
                })
                .collect::<Result<_, _>>()?,
            material_textures: Buffer::device_local(
                gpu,
                "material texture slots",
                bytes_of(&trace_textures.slots),
                storage,
            )?,
            ray_counts: zeroed_counters(gpu)?,
            bvh,
        })
    }

    /// Whether the BVH was built, so the software walk can trace.
    pub(super) fn has_bvh(&self) -> bool {
        self.bvh
    }

    /// Zeroes the ray counters; the previous frame must have finished.
    pub(super) fn reset_ray_counts(&mut self) -> Result<(), GpuError> {
        self.ray_counts
            .write(&[0u8; crate::providers::ray_counts::BYTES as usize])
    }

    /// The ray counters' words, slot order; the frame must have finished.
    pub(super) fn ray_counts(&self) -> Result<Vec<u32>, GpuError> {
        Ok(self
            .ray_counts
            .mapped()?
            .chunks_exact(4)
            .map(|w| u32::from_ne_bytes([w[0], w[1], w[2], w[3]]))
            .collect())
    }

    /// Rewrites the light choice table for `lights` as they are now (the
    /// count of lights never changes: animation moves and recolours them).
    pub(super) fn update_light_choices(
        &mut self,
        lights: &LightSet,
        scene_radius: f32,
    ) -> Result<(), GpuError> {
        let choices = light_choices(lights, self.emitter_power, scene_radius);
        self.light_choices.write(&choices.bytes())
    }

    /// The texel buffer view behind a tracing-only set 1 binding.
    pub(super) fn texel_view(&self, binding: u32) -> Option<vk::BufferView> {
        match binding {
            TRIANGLES_BINDING => Some(self.triangles.view),
            BVH_NODES_BINDING => Some(self.nodes.view),
            BVH_LEAF_TRIANGLES_BINDING => Some(self.leaf_triangles.view),
            TRIANGLE_NORMALS_BINDING => Some(self.normals.view),
            TRIANGLE_TANGENTS_BINDING => Some(self.tangents.view),
            TRIANGLE_UVS_BINDING => Some(self.uvs.view),
            TRIANGLE_MATERIALS_BINDING => Some(self.materials.view),
            EMITTERS_BINDING => Some(self.emitters.view),
            LIGHT_CHOICES_BINDING => Some(self.light_choices.view),
            _ => None,
        }
    }

    /// The buffer behind a tracing-only set 1 binding.
    pub(super) fn buffer(&self, binding: u32) -> Option<&Buffer<'g>> {
        match binding {
            MATERIAL_TEXTURES_BINDING => Some(&self.material_textures),
            RAY_COUNTS_BINDING => Some(&self.ray_counts),
            _ => None,
        }
    }
}

impl GpuScene<'_> {
    /// Builds the ray tracer's buffers, once, with the BVH unless rays
    /// trace through ray queries, and then the acceleration structures;
    /// placements a script has moved give new geometry each frame, so their
    /// BVH is not cached.
    pub(super) fn ensure_trace_buffers(&mut self) -> Result<(), GpuError> {
        if self.trace.is_none() {
            let cache = self.bvh_cache.as_deref().filter(|_| !self.moved);
            let built = TraceBuffers::build(
                self.gpu,
                (&self.geometry, !self.hardware),
                cache,
                (&self.light_set, scene_radius(&self.bounds)),
                &mut self.warnings,
            )?;
            self.trace = Some(built);
        }
        self.ensure_structures()
    }

    /// Caches the ray tracer's BVH in `dir` (the user's cache folder), so
    /// the next run over the same geometry reads it instead of building it.
    pub fn cache_bvh_in(&mut self, dir: Option<PathBuf>) {
        self.bvh_cache = dir;
    }

    /// Zeroes the per-pass ray counters before a frame (the previous one
    /// must have finished); nothing to do before the ray tracer's data exists.
    pub fn reset_ray_counts(&mut self) -> Result<(), GpuError> {
        match &mut self.trace {
            Some(trace) => trace.reset_ray_counts(),
            None => Ok(()),
        }
    }

    /// The rays each pass of `plan` traced in the frame that just finished
    /// ([`crate::providers::ray_counts`]); empty when nothing traces.
    pub fn pass_rays(
        &self,
        plan: &weft_graph::plan::Plan,
    ) -> Result<Vec<crate::providers::ray_counts::PassRays>, GpuError> {
        match &self.trace {
            Some(trace) => Ok(crate::providers::ray_counts::per_pass(
                plan.passes.iter(),
                &trace.ray_counts()?,
            )),
            None => Ok(Vec::new()),
        }
    }
}

/// The ray counters, zeroed: built during a frame's recording, they count
/// that frame's rays from the first.
fn zeroed_counters(gpu: &Gpu) -> Result<Buffer<'_>, GpuError> {
    let mut counters = Buffer::host(
        gpu,
        "the per-pass ray counters",
        crate::providers::ray_counts::BYTES,
        vk::BufferUsageFlags::STORAGE_BUFFER,
    )?;
    counters.write(&[0u8; crate::providers::ray_counts::BYTES as usize])?;
    Ok(counters)
}

/// The choice table over `lights`' analytic records (the emissive polygons
/// after them are the raster path's; the tracer samples the triangles).
fn light_choices(lights: &LightSet, emitter_power: Option<f32>, scene_radius: f32) -> LightChoices {
    LightChoices::build(
        &lights.records[..lights.len() as usize],
        emitter_power,
        scene_radius,
    )
}

/// Refuses a BVH table of `len` `unit` when more than `limit`, the most the
/// walk's 24-bit indices can name.
fn within_index(what: &str, len: usize, limit: usize, unit: &str) -> Result<(), GpuError> {
    if len <= limit {
        return Ok(());
    }
    Err(GpuError::Allocation {
        what: what.into(),
        message: format!("{len} {unit}, more than the {limit} the walk's 24-bit indices can name"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_beyond_the_walks_indices_is_refused_with_its_size_and_limit() {
        assert!(within_index("the BVH nodes", 16, 16, "nodes").is_ok());
        let refused = within_index("the BVH's leaf triangles", 17, 16, "triangles");
        let Err(GpuError::Allocation { what, message }) = refused else {
            panic!("17 triangles under a limit of 16 were accepted: {refused:?}");
        };
        assert_eq!(what, "the BVH's leaf triangles");
        assert_eq!(
            message,
            "17 triangles, more than the 16 the walk's 24-bit indices can name"
        );
    }
}
