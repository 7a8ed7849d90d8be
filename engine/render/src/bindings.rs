//! The scene data shaders bind, as one table: set 1 (scene buffers, and the
//! ray tracer's, fed only to passes that trace), set 2 (a material's
//! textures) and the vertex layout, registered with the executor as a
//! [`SceneInterface`]. The GLSL side is `shaders/include/scene.glsl`,
//! `mesh_data.glsl` and `trace.glsl`.

use crate::geometry::VERTEX_ATTRIBUTES;
use crate::geometry::VERTEX_BYTES;
use weft_gpu::reflect::DescriptorKind;
use weft_gpu::scene::{SceneBinding, SceneInterface};
use weft_graph::plan::PlanPass;

/// A set binding every scene pass may read.
const fn raster(
    glsl: &'static str,
    binding: u32,
    kind: DescriptorKind,
    what: &'static str,
) -> SceneBinding {
    SceneBinding {
        glsl,
        binding,
        kind,
        what,
        arrayed: false,
        tracing: false,
    }
}

/// A set-1 binding only passes that trace rays read (a texture array among them).
const fn tracing(
    glsl: &'static str,
    binding: u32,
    kind: DescriptorKind,
    what: &'static str,
) -> SceneBinding {
    SceneBinding {
        arrayed: is_trace_texture(binding),
        tracing: true,
        ..raster(glsl, binding, kind, what)
    }
}

/// Binding of the per-frame uniform block (`Frame` in `scene.glsl`).
pub const FRAME_BINDING: u32 = 0;
/// Binding of the light records.
pub const LIGHTS_BINDING: u32 = 1;
/// Binding of the draw records.
pub const DRAWS_BINDING: u32 = 2;
/// Binding of the material records.
pub const MATERIALS_BINDING: u32 = 3;
/// Binding of the shadow views (`Shadows` in `shaders/include/shadows.glsl`).
pub const SHADOWS_BINDING: u32 = 4;
/// Binding of the ray tracer's triangles: three world-space corners per
/// triangle, a texel each (`trace_corners` in `shaders/include/trace.glsl`).
pub const TRIANGLES_BINDING: u32 = 5;
/// Binding of the ray tracer's 4-wide BVH nodes (`bvh_nodes`, 8 texels each).
pub const BVH_NODES_BINDING: u32 = 6;
/// Binding of the BVH's leaf triangles, in leaf order with their edges
/// (`bvh_leaf_triangles`, 3 texels each): leaves point into it.
pub const BVH_LEAF_TRIANGLES_BINDING: u32 = 7;
/// Binding of the corners' world normals (`trace_normals`, a texel each).
pub const TRIANGLE_NORMALS_BINDING: u32 = 8;
/// Binding of the corners' UVs (`trace_uvs`, a two-word texel each).
pub const TRIANGLE_UVS_BINDING: u32 = 9;
/// Binding of each triangle's material index and draw record (`trace_materials`).
pub const TRIANGLE_MATERIALS_BINDING: u32 = 10;
/// Binding of the emissive triangles' alias table (`emitter_table`, a texel
/// buffer; [`crate::emitters::EmitterTable`]).
pub const EMITTERS_BINDING: u32 = 11;
/// First of the path tracer's texture arrays (`trace.glsl`): sRGB colour
/// layers of each size class of [`crate::trace_textures::CLASSES`] at 12, 13,
/// 14, UNORM data layers at 15, 16, 17.
pub const TRACE_TEXTURES_BINDING: u32 = 12;
/// How many texture arrays the path tracer binds from [`TRACE_TEXTURES_BINDING`] on.
pub const TRACE_TEXTURE_ARRAYS: u32 = 2 * crate::trace_textures::CLASSES.len() as u32;
/// Whether set 1 `binding` is one of the path tracer's texture arrays.
pub const fn is_trace_texture(binding: u32) -> bool {
    binding >= TRACE_TEXTURES_BINDING && binding < TRACE_TEXTURES_BINDING + TRACE_TEXTURE_ARRAYS
}

/// Binding of each material's texture slots (`MaterialTextures`).
pub const MATERIAL_TEXTURES_BINDING: u32 = 18;
/// Binding of the corners' world tangents (`trace_tangents`, a texel each,
/// w the bitangent's sign).
pub const TRIANGLE_TANGENTS_BINDING: u32 = 19;
/// Binding of the LTC tables analytic area lights read (`LtcTables` in
/// `shaders/include/ltc.glsl`, [`ltc_table_words`]).
pub const LTC_TABLES_BINDING: u32 = 20;
/// Binding of the vertex buffer as 32-bit words (`Vertices` in
/// `shaders/include/mesh_data.glsl`), for shaders that fetch whole triangles.
pub const VERTICES_BINDING: u32 = 21;
/// Binding of the index buffer (`Indices` in `shaders/include/mesh_data.glsl`).
pub const INDICES_BINDING: u32 = 22;
/// Binding of the table next-event estimation picks a light from
/// (`light_choice_table`, a texel buffer; [`crate::light_choice::LightChoices`]).
pub const LIGHT_CHOICES_BINDING: u32 = 23;
/// Binding of the per-pass ray counters (`ray_counts` in `trace.glsl`): every
/// traced ray adds one to its pass's slot ([`crate::providers::ray_counts`]), so
/// `weft compare` can show rays per pixel per pass.
pub const RAY_COUNTS_BINDING: u32 = 24;
/// Binding of the environment map's texels (`environment_texels` in
/// `shaders/include/environment.glsl`: RGB f32 bits, a texel each).
pub const ENVIRONMENT_BINDING: u32 = 25;
/// Binding of the table the path tracer samples the environment from
/// (`environment_table`, [`crate::environment::EnvironmentTable`]).
pub const ENVIRONMENT_TABLE_BINDING: u32 = 26;
/// Binding of the top-level acceleration structure that ray queries trace
/// (`trace_top_level` in `trace.glsl`, compiled with
/// [`crate::providers::trace_backend::HARDWARE_DEFINE`]): only on a device
/// with hardware ray queries, whose traced layout alone has it.
pub const TOP_LEVEL_BINDING: u32 = 27;
/// Set 2 binding of a material's base-colour texture (sRGB).
pub const BASE_COLOR_BINDING: u32 = 0;
/// Set 2 binding of a material's metallicRoughness texture (UNORM; B metal, G rough).
pub const METALLIC_ROUGHNESS_BINDING: u32 = 1;
/// Set 2 binding of a material's tangent-space normal map (UNORM).
pub const NORMAL_BINDING: u32 = 2;
/// Set 2 binding of the emissive texture (sRGB; white when the material has none).
pub const EMISSIVE_BINDING: u32 = 3;
/// Set 2 binding of the occlusion texture (its red channel; white when none).
pub const OCCLUSION_BINDING: u32 = 4;
/// Set 1 as the engine creates and writes it for every scene pass.
pub const SCENE_SET_BINDINGS: [SceneBinding; 9] = [
    raster(
        "FRAME",
        FRAME_BINDING,
        DescriptorKind::UniformBuffer,
        "the Frame block",
    ),
    raster(
        "LIGHTS",
        LIGHTS_BINDING,
        DescriptorKind::StorageBuffer,
        "the lights",
    ),
    raster(
        "DRAWS",
        DRAWS_BINDING,
        DescriptorKind::StorageBuffer,
        "the draw records",
    ),
    raster(
        "MATERIALS",
        MATERIALS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the materials",
    ),
    raster(
        "SHADOWS",
        SHADOWS_BINDING,
        DescriptorKind::StorageBuffer,
        "the shadow views",
    ),
    raster(
        "LTC_TABLES",
        LTC_TABLES_BINDING,
        DescriptorKind::StorageBuffer,
        "the area-light LTC tables",
    ),
    raster(
        "VERTICES",
        VERTICES_BINDING,
        DescriptorKind::StorageBuffer,
        "the vertices",
    ),
    raster(
        "INDICES",
        INDICES_BINDING,
        DescriptorKind::StorageBuffer,
        "the indices",
    ),
    raster(
        "ENVIRONMENT",
        ENVIRONMENT_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the environment map",
    ),
];

/// Set 1 bindings for ray tracing: built only when a compute pass that
/// declares `derive: [RayTracing()]` first asks for them, since the BVH costs
/// a build (docs/pathtrace.md) that raster graphs should not pay.
pub const TRACE_SET_BINDINGS: [SceneBinding; 19] = [
    tracing(
        "TRIANGLES",
        TRIANGLES_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the ray tracer's triangles",
    ),
    tracing(
        "BVH_NODES",
        BVH_NODES_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the BVH nodes",
    ),
    tracing(
        "BVH_LEAF_TRIANGLES",
        BVH_LEAF_TRIANGLES_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the BVH's leaf triangles",
    ),
    tracing(
        "TRIANGLE_NORMALS",
        TRIANGLE_NORMALS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the corners' normals",
    ),
    tracing(
        "TRIANGLE_UVS",
        TRIANGLE_UVS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the corners' UVs",
    ),
    tracing(
        "TRIANGLE_MATERIALS",
        TRIANGLE_MATERIALS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the triangles' materials and draws",
    ),
    tracing(
        "EMITTERS",
        EMITTERS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the emissive triangles",
    ),
    tracing(
        "TRACE_COLOUR_256",
        TRACE_TEXTURES_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the 256-texel colour texture array",
    ),
    tracing(
        "TRACE_COLOUR_512",
        TRACE_TEXTURES_BINDING + 1,
        DescriptorKind::CombinedImageSampler,
        "the 512-texel colour texture array",
    ),
    tracing(
        "TRACE_COLOUR_1024",
        TRACE_TEXTURES_BINDING + 2,
        DescriptorKind::CombinedImageSampler,
        "the 1024-texel colour texture array",
    ),
    tracing(
        "TRACE_DATA_256",
        TRACE_TEXTURES_BINDING + 3,
        DescriptorKind::CombinedImageSampler,
        "the 256-texel data texture array",
    ),
    tracing(
        "TRACE_DATA_512",
        TRACE_TEXTURES_BINDING + 4,
        DescriptorKind::CombinedImageSampler,
        "the 512-texel data texture array",
    ),
    tracing(
        "TRACE_DATA_1024",
        TRACE_TEXTURES_BINDING + 5,
        DescriptorKind::CombinedImageSampler,
        "the 1024-texel data texture array",
    ),
    tracing(
        "MATERIAL_TEXTURES",
        MATERIAL_TEXTURES_BINDING,
        DescriptorKind::StorageBuffer,
        "the materials' texture slots",
    ),
    tracing(
        "TRIANGLE_TANGENTS",
        TRIANGLE_TANGENTS_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the corners' tangents",
    ),
    tracing(
        "LIGHT_CHOICES",
        LIGHT_CHOICES_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the light choice table",
    ),
    tracing(
        "RAY_COUNTS",
        RAY_COUNTS_BINDING,
        DescriptorKind::StorageBuffer,
        "the per-pass ray counters",
    ),
    tracing(
        "ENVIRONMENT_TABLE",
        ENVIRONMENT_TABLE_BINDING,
        DescriptorKind::UniformTexelBuffer,
        "the environment's sampling table",
    ),
    tracing(
        "TOP_LEVEL",
        TOP_LEVEL_BINDING,
        DescriptorKind::AccelerationStructure,
        "the top-level acceleration structure (hardware ray queries)",
    ),
];

/// How many of set 1's raster bindings are texel buffers (the material
/// records, the environment map).
pub const SCENE_TEXEL_BUFFERS: u32 = texel_buffers(&SCENE_SET_BINDINGS);
/// How many of set 1's tracing-only bindings are texel buffers (the tables
/// every ray or light sample reads: triangles, BVH, per-corner attributes,
/// emitters, light choices).
pub const TRACE_TEXEL_BUFFERS: u32 = texel_buffers(&TRACE_SET_BINDINGS);

/// How many of `bindings` are texel buffers.
const fn texel_buffers(bindings: &[SceneBinding]) -> u32 {
    let mut count = 0;
    let mut i = 0;
    while i < bindings.len() {
        if matches!(bindings[i].kind, DescriptorKind::UniformTexelBuffer) {
            count += 1;
        }
        i += 1;
    }
    count
}
/// Set 2 as the engine creates it: a material's textures, in the order of its
/// texture slots.
pub const MATERIAL_SET_BINDINGS: [SceneBinding; 5] = [
    raster(
        "BASE_COLOR",
        BASE_COLOR_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the base-colour texture",
    ),
    raster(
        "METALLIC_ROUGHNESS",
        METALLIC_ROUGHNESS_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the metallic-roughness texture",
    ),
    raster(
        "NORMAL",
        NORMAL_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the normal map",
    ),
    raster(
        "EMISSIVE",
        EMISSIVE_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the emissive texture",
    ),
    raster(
        "OCCLUSION",
        OCCLUSION_BINDING,
        DescriptorKind::CombinedImageSampler,
        "the occlusion texture",
    ),
];

/// What this renderer hands scene shaders, for the executor to build
/// pipelines against and check shaders with.
pub fn scene_interface() -> SceneInterface {
    SceneInterface {
        scene_set: SCENE_SET_BINDINGS
            .iter()
            .chain(&TRACE_SET_BINDINGS)
            .copied()
            .collect(),
        material_set: MATERIAL_SET_BINDINGS.to_vec(),
        vertex_stride: VERTEX_BYTES,
        vertex_attributes: VERTEX_ATTRIBUTES.to_vec(),
        traces: crate::providers::traces,
        per_draw_params,
    }
}

/// The push-constant parameters the scene recorder sets per draw: a shadow
/// atlas pass's view index.
fn per_draw_params(pass: &PlanPass) -> Vec<&'static str> {
    if crate::providers::supplied(pass, crate::providers::SHADOW_VIEW) {
        vec![crate::providers::SHADOW_VIEW]
    } else {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// `shaders/include/bindings.glsl` is the header this table generates
    /// (`WEFT_UPDATE_GOLDEN=1 cargo test -p weft-render --lib bindings` writes
    /// it), so shaders name bindings instead of repeating their numbers.
    #[test]
    fn the_glsl_binding_header_is_generated_from_this_table() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders/include/bindings.glsl");
        let generated = scene_interface().glsl_header("engine/render/src/bindings.rs");
        if std::env::var_os("WEFT_UPDATE_GOLDEN").is_some() {
            std::fs::write(&path, &generated).expect("write the header");
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == generated,
            "{} is out of date; rewrite it with WEFT_UPDATE_GOLDEN=1 cargo test -p weft-render --lib bindings",
            path.display()
        );
    }

    #[test]
    fn every_binding_has_its_own_number_and_name() {
        let scene = scene_interface();
        for set in [&scene.scene_set, &scene.material_set] {
            let mut numbers: Vec<u32> = set.iter().map(|b| b.binding).collect();
            let mut names: Vec<&str> = set.iter().map(|b| b.glsl).collect();
            numbers.sort_unstable();
            numbers.dedup();
            names.sort_unstable();
            names.dedup();
            assert_eq!((numbers.len(), names.len()), (set.len(), set.len()));
        }
    }
}
