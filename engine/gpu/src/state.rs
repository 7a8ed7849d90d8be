//! Fixed-function state of a scene pass, as its graph declares it: the depth
//! comparison and bias and the culled faces (`raster`), depth writes (the depth
//! attachment's `read_only`), blending per colour attachment; and the Vulkan
//! state it becomes.

use ash::vk;
use weft_graph::plan::PlanPass;
use weft_graph::schema::{Blend, CompareOp, CullMode};

/// A colour attachment's blend mode as a hashable key part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BlendCode {
    /// No blending: the output replaces the attachment.
    Off,
    /// dst + src.
    Additive,
    /// Source-over with source alpha.
    Alpha,
}

impl From<Option<Blend>> for BlendCode {
    fn from(b: Option<Blend>) -> Self {
        match b {
            None => Self::Off,
            Some(Blend::Additive) => Self::Additive,
            Some(Blend::Alpha) => Self::Alpha,
        }
    }
}

/// Depth testing and writing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepthState {
    /// Whether fragments are tested against the depth attachment.
    pub test: bool,
    /// Whether passing fragments write their depth.
    pub write: bool,
    /// How a fragment's depth is compared with the stored one.
    pub compare: vk::CompareOp,
}

impl DepthState {
    /// No depth test and no writes.
    pub const OFF: DepthState = DepthState {
        test: false,
        write: false,
        compare: vk::CompareOp::ALWAYS,
    };
}

/// The colour-blend state of a blend mode.
pub fn blend_state(blend: BlendCode) -> vk::PipelineColorBlendAttachmentState {
    let state = vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA);
    match blend {
        BlendCode::Off => state,
        BlendCode::Additive => state
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD),
        BlendCode::Alpha => state
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD),
    }
}

/// How the depth attachment is tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DepthTest {
    /// No depth attachment.
    Off,
    /// Compared with `compare`, written unless the attachment is read-only.
    On {
        /// The comparison (default `GreaterOrEqual`: reverse-Z).
        compare: CompareOp,
        /// Whether depth is written.
        write: bool,
    },
}

/// Everything about a scene pass's pipeline that is not its shaders.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct PassState {
    /// Depth test and write.
    pub depth: DepthTest,
    /// Face culling.
    pub cull: CullMode,
    /// Whether fragment depth is clamped instead of clipped at near and far.
    pub depth_clamp: bool,
    /// Blend per colour attachment.
    pub blends: Vec<BlendCode>,
    /// Constant and slope-scaled depth bias, as `f32` bits.
    pub depth_bias: Option<(u32, u32)>,
    /// Samples per pixel of the attachments.
    pub samples: u32,
}

/// The state of a raster pass that draws scene meshes or light volumes.
pub fn pass_state(pass: &PlanPass) -> PassState {
    let raster = &pass.raster;
    let Some(rp) = &pass.render_pass else {
        return PassState {
            depth: DepthTest::Off,
            cull: raster.cull,
            depth_clamp: raster.depth_clamp,
            blends: Vec::new(),
            depth_bias: None,
            samples: 1,
        };
    };
    let depth = match rp.depth.and_then(|i| rp.attachments.get(i)) {
        None => DepthTest::Off,
        Some(a) => DepthTest::On {
            compare: raster.depth_compare.unwrap_or(CompareOp::GreaterOrEqual),
            write: !a.read_only,
        },
    };
    PassState {
        depth,
        cull: raster.cull,
        depth_clamp: raster.depth_clamp,
        blends: rp
            .color
            .iter()
            .map(|&i| rp.attachments.get(i).and_then(|a| a.blend).into())
            .collect(),
        depth_bias: raster
            .depth_bias
            .map(|(c, s)| ((c as f32).to_bits(), (s as f32).to_bits())),
        samples: rp.attachments.first().map_or(1, |a| a.samples),
    }
}

impl DepthTest {
    /// The Vulkan depth state.
    pub fn vk(self) -> DepthState {
        match self {
            Self::Off => DepthState::OFF,
            Self::On { compare, write } => DepthState {
                test: true,
                write,
                compare: compare_op(compare),
            },
        }
    }
}

impl PassState {
    /// The Vulkan faces culled.
    pub fn cull_flags(&self) -> vk::CullModeFlags {
        match self.cull {
            CullMode::None => vk::CullModeFlags::NONE,
            CullMode::Front => vk::CullModeFlags::FRONT,
            CullMode::Back => vk::CullModeFlags::BACK,
        }
    }

    /// The constant and slope-scaled depth bias as floats.
    pub fn depth_bias(&self) -> Option<(f32, f32)> {
        self.depth_bias
            .map(|(c, s)| (f32::from_bits(c), f32::from_bits(s)))
    }
}

fn compare_op(compare: CompareOp) -> vk::CompareOp {
    match compare {
        CompareOp::Never => vk::CompareOp::NEVER,
        CompareOp::Less => vk::CompareOp::LESS,
        CompareOp::Equal => vk::CompareOp::EQUAL,
        CompareOp::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
        CompareOp::Greater => vk::CompareOp::GREATER,
        CompareOp::NotEqual => vk::CompareOp::NOT_EQUAL,
        CompareOp::GreaterOrEqual => vk::CompareOp::GREATER_OR_EQUAL,
        CompareOp::Always => vk::CompareOp::ALWAYS,
    }
}

/// The front face of a draw: counter-clockwise model triangles, turned around
/// by a mirroring (negative-determinant) model matrix.
pub fn front_face(mirrored: bool) -> vk::FrontFace {
    if mirrored {
        vk::FrontFace::CLOCKWISE
    } else {
        vk::FrontFace::COUNTER_CLOCKWISE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use weft_graph::plan::{Extent, Plan};
    use weft_graph::CompileOptions;

    fn plan(graph: &str, features: &[&str]) -> Plan {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../graphs")
            .join(graph);
        let loaded = weft_graph::load(&path);
        let options = CompileOptions {
            extent: Extent {
                width: 64,
                height: 32,
            },
            features: loaded.features(features),
            ..CompileOptions::default()
        };
        weft_graph::compile(&loaded, &options).expect("compiles")
    }

    fn state(plan: &Plan, name: &str) -> PassState {
        pass_state(plan.passes.iter().find(|p| p.name == name).expect("pass"))
    }

    #[test]
    fn forward_passes_use_reverse_z_shadow_maps_forward_z() {
        let p = plan("forward.ron", &["shadow_casters"]);
        let reverse_z = DepthTest::On {
            compare: CompareOp::GreaterOrEqual,
            write: true,
        };
        assert_eq!(state(&p, "forward").depth, reverse_z);
        let shadow = state(&p, "shadow_sun");
        assert_eq!(
            shadow.depth,
            DepthTest::On {
                compare: CompareOp::LessOrEqual,
                write: true
            }
        );
        assert_eq!(
            shadow.depth_bias,
            Some((1.25f32.to_bits(), 1.75f32.to_bits()))
        );
        assert!(shadow.blends.is_empty());
        let pre = plan("forward.ron", &["depth_prepass"]);
        assert_eq!(
            state(&pre, "forward_after_prepass").depth,
            DepthTest::On {
                compare: CompareOp::Equal,
                write: false
            }
        );
        assert_eq!(state(&pre, "depth_prepass").depth, reverse_z);
    }

    #[test]
    fn light_volumes_draw_back_faces_behind_surfaces_additively() {
        let p = plan("deferred.ron", &["point_lights", "spot_lights"]);
        for name in ["point_lights", "spot_lights"] {
            let s = state(&p, name);
            assert_eq!(
                s.depth,
                DepthTest::On {
                    compare: CompareOp::LessOrEqual,
                    write: false
                }
            );
            assert_eq!(s.cull, CullMode::Front);
            assert_eq!(s.blends, vec![BlendCode::Additive]);
        }
        assert_eq!(state(&p, "gbuffer").blends, vec![BlendCode::Off; 3]);
    }
}
