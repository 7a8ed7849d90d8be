//! Fixed-function state of a scene pass, derived from the plan: depth test and
//! write (reverse-Z for camera passes, forward Z for maps cleared to 1, equal
//! after a depth pre-pass), culling, blending per attachment and depth bias.

use weft_gpu::pipeline::BlendCode;
use weft_graph::plan::{LoadOp, PlanPass};
use weft_graph::schema::{Draw, ParamValue};

/// How the depth attachment is tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DepthTest {
    /// No depth attachment.
    Off,
    /// Nearer is greater (reverse-Z, cleared to 0).
    Greater {
        /// Whether depth is written.
        write: bool,
    },
    /// Nearer is smaller (forward Z, cleared to 1: shadow maps).
    Less {
        /// Whether depth is written.
        write: bool,
    },
    /// Only where depth equals what a pre-pass laid down.
    Equal,
    /// Light volumes: back faces that lie behind the surface (reverse-Z `<=`).
    BehindSurface,
}

/// Which faces are culled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Cull {
    /// Both faces drawn: meshes may be open or one-sided (shading flips back faces).
    None,
    /// Front faces: light volumes draw their back faces so the camera may be inside.
    Front,
}

/// Everything about a scene pass's pipeline that is not its shaders.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct PassState {
    /// Depth test and write.
    pub depth: DepthTest,
    /// Face culling.
    pub cull: Cull,
    /// Blend per colour attachment.
    pub blends: Vec<BlendCode>,
    /// Constant and slope-scaled depth bias, as `f32` bits, from the pass's
    /// `depth_bias` and `slope_bias` parameters.
    pub depth_bias: Option<(u32, u32)>,
    /// Samples per pixel of the attachments.
    pub samples: u32,
}

fn number(pass: &PlanPass, name: &str) -> Option<f64> {
    match pass.params.get(name) {
        Some(ParamValue::Number(n)) => Some(*n),
        _ => None,
    }
}

/// The state of a raster pass that draws scene meshes or light volumes.
pub fn pass_state(pass: &PlanPass) -> PassState {
    let volumes = matches!(pass.draw, Some(Draw::LightVolumes(_)));
    let Some(rp) = &pass.render_pass else {
        return PassState {
            depth: DepthTest::Off,
            cull: Cull::None,
            blends: Vec::new(),
            depth_bias: None,
            samples: 1,
        };
    };
    let depth = match rp.depth.and_then(|i| rp.attachments.get(i)) {
        None => DepthTest::Off,
        Some(_) if volumes => DepthTest::BehindSurface,
        Some(_) if matches!(pass.params.get("depth_equal"), Some(ParamValue::Bool(true))) => {
            DepthTest::Equal
        }
        Some(a) => {
            let write = !a.read_only;
            if a.load == LoadOp::Clear && a.clear.first() == Some(&1.0) {
                DepthTest::Less { write }
            } else {
                DepthTest::Greater { write }
            }
        }
    };
    let depth_bias = match (number(pass, "depth_bias"), number(pass, "slope_bias")) {
        (None, None) => None,
        (c, s) => Some((
            (c.unwrap_or(0.0) as f32).to_bits(),
            (s.unwrap_or(0.0) as f32).to_bits(),
        )),
    };
    PassState {
        depth,
        cull: if volumes { Cull::Front } else { Cull::None },
        blends: rp
            .color
            .iter()
            .map(|&i| rp.attachments.get(i).and_then(|a| a.blend).into())
            .collect(),
        depth_bias,
        samples: rp.attachments.first().map_or(1, |a| a.samples),
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
        assert_eq!(
            state(&p, "forward").depth,
            DepthTest::Greater { write: true }
        );
        let shadow = state(&p, "shadow_sun");
        assert_eq!(shadow.depth, DepthTest::Less { write: true });
        assert_eq!(
            shadow.depth_bias,
            Some((1.25f32.to_bits(), 1.75f32.to_bits()))
        );
        assert!(shadow.blends.is_empty());
        let pre = plan("forward.ron", &["depth_prepass"]);
        assert_eq!(state(&pre, "forward_after_prepass").depth, DepthTest::Equal);
        assert_eq!(
            state(&pre, "depth_prepass").depth,
            DepthTest::Greater { write: true }
        );
    }

    #[test]
    fn light_volumes_draw_back_faces_behind_surfaces_additively() {
        let p = plan("deferred.ron", &["point_lights", "spot_lights"]);
        for name in ["point_lights", "spot_lights"] {
            let s = state(&p, name);
            assert_eq!(s.depth, DepthTest::BehindSurface);
            assert_eq!(s.cull, Cull::Front);
            assert_eq!(s.blends, vec![BlendCode::Additive]);
        }
        assert_eq!(state(&p, "gbuffer").blends, vec![BlendCode::Off; 3]);
    }
}
