//! The scene interface: what a renderer hands the shaders of scene passes —
//! set 1 (scene data), set 2 (one material's textures), the vertex layout —
//! registered once with the executor ([`crate::Renderer::register_scene`]).
//! The executor builds every pipeline against it and checks every shader with
//! it; the renderer's draw recorder only binds the sets and draws.

use crate::context::Gpu;
use crate::descriptors::SetLayout;
use crate::error::GpuError;
use crate::reflect::DescriptorKind;
use crate::sets::{MATERIAL_SET, SCENE_SET};
use ash::vk;
use weft_graph::plan::PlanPass;

/// One binding of a scene set as the renderer creates and writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneBinding {
    /// Its name in GLSL: set 1's binding `NAME` is `BINDING_NAME`, set 2's
    /// is `MATERIAL_NAME` ([`SceneInterface::glsl_header`]).
    pub glsl: &'static str,
    /// The binding number.
    pub binding: u32,
    /// Its descriptor kind.
    pub kind: DescriptorKind,
    /// What it holds, for the shader check's messages.
    pub what: &'static str,
    /// Whether an image here is a 2D array (the path tracer's texture arrays).
    pub arrayed: bool,
    /// Whether it is fed only to passes that trace rays (the BVH and the
    /// triangles cost a build raster graphs should not pay).
    pub tracing: bool,
}

/// How one vertex attribute is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexFormat {
    /// Three 32-bit floats (a `vec3` input).
    Float3,
    /// One 32-bit unsigned integer (a `uint` input).
    Uint,
    /// Two 16-bit unsigned normalized values (a `vec2` input).
    Unorm16x2,
}

impl VertexFormat {
    /// The Vulkan format.
    pub fn vk(self) -> vk::Format {
        match self {
            Self::Float3 => vk::Format::R32G32B32_SFLOAT,
            Self::Uint => vk::Format::R32_UINT,
            Self::Unorm16x2 => vk::Format::R16G16_UNORM,
        }
    }
}

/// One attribute of the shared vertex buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VertexAttribute {
    /// `layout(location = ...)` in the vertex shader.
    pub location: u32,
    /// Bytes from the vertex's start.
    pub offset: u32,
    /// How it is stored.
    pub format: VertexFormat,
    /// What it holds, for messages.
    pub what: &'static str,
}

/// Everything the executor needs to know about a renderer's scene data.
#[derive(Debug, Clone)]
pub struct SceneInterface {
    /// Set 1, the raster bindings first and the tracing-only ones after.
    pub scene_set: Vec<SceneBinding>,
    /// Set 2: one material's textures.
    pub material_set: Vec<SceneBinding>,
    /// Bytes per vertex of the shared vertex buffer.
    pub vertex_stride: u32,
    /// The vertex attributes; the first is the position, all that passes
    /// reading positions only ([`position_only`]) get.
    pub vertex_attributes: Vec<VertexAttribute>,
    /// Whether a pass traces rays (and so may read the tracing-only bindings).
    pub traces: fn(&PlanPass) -> bool,
    /// Push-constant parameters the draw recorder sets per draw (a shadow
    /// view's index), checked as present with the value 0.
    pub per_draw_params: fn(&PlanPass) -> Vec<&'static str>,
}

/// Which layout of set 1 a pipeline is built with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SceneSet {
    /// The raster bindings.
    Raster,
    /// The raster and the tracing-only bindings.
    Traced,
}

/// Descriptor set layouts of the scene sets, one definition shared by the
/// executor's pipelines and the renderer's sets: identically defined layouts
/// are compatible, so a set allocated from one binds to a pipeline built
/// with another.
pub struct SceneLayouts<'g> {
    /// Set 1 with the raster bindings.
    pub raster: SetLayout<'g>,
    /// Set 1 with the tracing-only bindings too.
    pub traced: SetLayout<'g>,
    /// Set 2.
    pub material: SetLayout<'g>,
}

/// A scene interface registered with the executor, with the set layouts its
/// pipelines are built against.
pub struct RegisteredScene<'g> {
    /// What the renderer supplies.
    pub interface: SceneInterface,
    /// Its sets' layouts.
    pub layouts: SceneLayouts<'g>,
}

impl<'g> RegisteredScene<'g> {
    /// Creates `interface`'s set layouts.
    pub fn new(gpu: &'g Gpu, interface: SceneInterface) -> Result<Self, GpuError> {
        let layouts = SceneLayouts::new(gpu, &interface)?;
        Ok(Self { interface, layouts })
    }
}

/// Every stage a scene set is visible to.
const SCENE_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::VERTEX.as_raw()
        | vk::ShaderStageFlags::FRAGMENT.as_raw()
        | vk::ShaderStageFlags::COMPUTE.as_raw(),
);

/// The layout bindings of `bindings`, leaving out acceleration structures
/// on a device without ray queries (`ray_query`): shaders for its other
/// backend declare none.
fn layout_bindings<'a>(
    bindings: impl Iterator<Item = &'a SceneBinding>,
    ray_query: bool,
) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    bindings
        .filter(|b| ray_query || b.kind != DescriptorKind::AccelerationStructure)
        .map(|b| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b.binding)
                .descriptor_type(b.kind.vk())
                .descriptor_count(1)
                .stage_flags(SCENE_STAGES)
        })
        .collect()
}

impl<'g> SceneLayouts<'g> {
    /// Creates the layouts of `interface`'s sets.
    pub fn new(gpu: &'g Gpu, interface: &SceneInterface) -> Result<Self, GpuError> {
        let raster = interface.scene_set.iter().filter(|b| !b.tracing);
        let ray_query = gpu.info().shaders.ray_query;
        Ok(Self {
            raster: SetLayout::new(gpu, &layout_bindings(raster, ray_query))?,
            traced: SetLayout::new(gpu, &layout_bindings(interface.scene_set.iter(), ray_query))?,
            material: SetLayout::new(
                gpu,
                &layout_bindings(interface.material_set.iter(), ray_query),
            )?,
        })
    }

    /// The layout of set 1 of kind `set`.
    pub fn scene(&self, set: SceneSet) -> vk::DescriptorSetLayout {
        match set {
            SceneSet::Raster => self.raster.handle(),
            SceneSet::Traced => self.traced.handle(),
        }
    }
}

impl SceneInterface {
    /// The GLSL header that names every set and binding of this interface,
    /// so shaders declare `layout(set = SET_SCENE, binding = BINDING_LIGHTS)`
    /// and the numbers live in one table. `origin` says where the table is.
    pub fn glsl_header(&self, origin: &str) -> String {
        let mut text = format!(
            "// The scene sets' binding numbers, generated from {origin}; do not edit.\n\
             #ifndef WEFT_BINDINGS_GLSL\n#define WEFT_BINDINGS_GLSL\n\n\
             #define SET_SCENE {SCENE_SET}\n#define SET_MATERIAL {MATERIAL_SET}\n\n"
        );
        let line = |prefix: &str, b: &SceneBinding| {
            let name = format!("{prefix}_{}", b.glsl);
            format!("#define {name:<30} {:>2} // {}\n", b.binding, b.what)
        };
        text.extend(self.scene_set.iter().map(|b| line("BINDING", b)));
        text.push('\n');
        text.extend(self.material_set.iter().map(|b| line("MATERIAL", b)));
        text.push_str("\n#endif\n");
        text
    }

    /// The set-1 binding `binding`, if the scene has one there.
    pub fn scene_binding(&self, binding: u32) -> Option<&SceneBinding> {
        self.scene_set.iter().find(|b| b.binding == binding)
    }

    /// The vertex attributes a pass's vertex shader may read: the position
    /// alone for [`position_only`] passes.
    pub fn attributes_for(&self, pass: &PlanPass) -> &[VertexAttribute] {
        if position_only(pass) {
            &self.vertex_attributes[..1.min(self.vertex_attributes.len())]
        } else {
            &self.vertex_attributes
        }
    }
}

/// Whether a scene pass reads only vertex positions (depth-only passes and
/// light volumes); mesh shading reads normals and UVs too.
pub fn position_only(pass: &PlanPass) -> bool {
    matches!(pass.draw, Some(weft_graph::schema::Draw::LightVolumes(_)))
        || pass.shaders.fragment.is_none()
}
