//! The value providers weft-render registers: what a graph may name in a
//! pass's `derive: [...]`, with each argument's range, and the code that
//! computes the values. A technique needs at most one of these; everything
//! else it needs is graph data and shaders.
//!
//! - `Gaussian(sigma, radius, linear_taps)`: a separable blur's taps, added to
//!   the pass's parameters as `gauss_taps`, `gauss_weights` and `gauss_offsets`
//!   once, when the plan is compiled (see `gaussian.rs`).
//! - `ShadowAtlas(cascades, split_lambda, normal_bias, pcf_radius)`: the shadow
//!   views of a depth-only scene pass, fitted every frame; the pass is drawn
//!   once per view with the push-constant member `shadow_view` set to the
//!   view's index (see `shadows/`).
//! - `RayTracing()`: the scene's world-space triangles, their corners'
//!   normals and UVs, their materials, and a BVH over them (`bvh.rs`), built
//!   on first use and bound in set 1 of the pass (compute, fullscreen or
//!   scene-drawing: raster lighting traces its shadow rays in place); each
//!   such pass also gets its slot in the ray counters (`ray_counts.rs`), and
//!   traces through the software BVH or hardware ray queries
//!   (`trace_backend.rs`; `hardware: true` insists on ray queries).

pub mod ray_counts;
pub mod trace_backend;

use crate::gaussian::{self, GaussianTaps};
use crate::shadows::{
    ShadowSettings, MAX_AREA_SHADOWS, MAX_CASCADES, MAX_PCF_RADIUS, MAX_POINT_SHADOWS,
};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::provider::{find, ArgDefault, ArgKind, ArgSpec, ProviderSpec};
use weft_graph::schema::{ParamValue, PassKind, ProviderDecl};
use weft_graph::Diagnostic;

/// The Gaussian blur provider.
pub const GAUSSIAN: ProviderSpec = ProviderSpec {
    name: "Gaussian",
    summary: "a separable Gaussian's taps, neighbours paired into linear-filtered fetches",
    kinds: &[PassKind::Fullscreen, PassKind::Compute],
    args: &[
        ArgSpec {
            name: "sigma",
            kind: ArgKind::Number {
                min: 1e-3,
                max: 1e4,
            },
            default: None,
        },
        ArgSpec {
            name: "radius",
            kind: ArgKind::Integer {
                min: 1,
                max: gaussian::MAX_RADIUS as i64,
            },
            default: None,
        },
        ArgSpec {
            name: "linear_taps",
            kind: ArgKind::Bool,
            default: Some(ArgDefault::Bool(true)),
        },
    ],
    supplies: &["gauss_taps", "gauss_weights", "gauss_offsets"],
};

/// The shadow-atlas provider.
pub const SHADOW_ATLAS: ProviderSpec = ProviderSpec {
    name: "ShadowAtlas",
    summary:
        "sun cascades, spot views, area-light views and point-light cubes in one depth atlas, drawn once per view",
    kinds: &[PassKind::Raster],
    args: &[
        ArgSpec {
            name: "cascades",
            kind: ArgKind::Integer {
                min: 1,
                max: MAX_CASCADES as i64,
            },
            default: Some(ArgDefault::Number(1.0)),
        },
        ArgSpec {
            name: "split_lambda",
            kind: ArgKind::Number { min: 0.0, max: 1.0 },
            default: Some(ArgDefault::Number(0.75)),
        },
        ArgSpec {
            name: "normal_bias",
            kind: ArgKind::Number {
                min: 0.0,
                max: 64.0,
            },
            default: Some(ArgDefault::Number(1.0)),
        },
        ArgSpec {
            name: "pcf_radius",
            kind: ArgKind::Integer {
                min: 0,
                max: MAX_PCF_RADIUS as i64,
            },
            default: Some(ArgDefault::Number(1.0)),
        },
        ArgSpec {
            name: "area_lights",
            kind: ArgKind::Integer {
                min: 0,
                max: MAX_AREA_SHADOWS as i64,
            },
            default: Some(ArgDefault::Number(MAX_AREA_SHADOWS as f64)),
        },
        ArgSpec {
            name: "point_lights",
            kind: ArgKind::Integer {
                min: 0,
                max: MAX_POINT_SHADOWS as i64,
            },
            default: Some(ArgDefault::Number(MAX_POINT_SHADOWS as f64)),
        },
    ],
    supplies: &[SHADOW_VIEW],
};

/// The push-constant member through which a shadow pass's vertex shader
/// learns which view it draws.
pub const SHADOW_VIEW: &str = "shadow_view";

/// The ray-tracing provider: the scene's world-space triangles and a BVH over
/// them, bound in set 1 (`shaders/include/trace.glsl`) of a compute,
/// fullscreen or scene-drawing pass. A variant whose shaders read none of it
/// (a feature turned off) builds no BVH.
pub const RAY_TRACING: ProviderSpec = ProviderSpec {
    name: "RayTracing",
    summary: "the scene's triangles and their BVH for shaders that trace rays",
    kinds: &[PassKind::Compute, PassKind::Fullscreen, PassKind::Raster],
    args: &[ArgSpec {
        name: "hardware",
        kind: ArgKind::Bool,
        default: Some(ArgDefault::Bool(false)),
    }],
    supplies: &[
        "Triangles",
        "BvhNodes",
        "BvhLeafTriangles",
        "TriangleNormals",
        "TriangleUvs",
        "TriangleMaterials",
    ],
};

/// Every provider a graph may name.
pub const PROVIDERS: &[ProviderSpec] = &[GAUSSIAN, SHADOW_ATLAS, RAY_TRACING];

/// Whether a pass declares `RayTracing`, so its shaders may read the ray
/// tracer's scene data.
pub fn traces(pass: &PlanPass) -> bool {
    pass.derive.iter().any(|c| c.name == RAY_TRACING.name)
}

/// The graph held to what the renderer registers: its provider uses
/// against [`PROVIDERS`], its scene names against the scene vocabulary
/// ([`crate::vocabulary::VOCABULARY`]).
pub fn check(graph: &weft_graph::LoadedGraph) -> Vec<Diagnostic> {
    check_resolved(graph, &weft_graph::resolve::resolve(graph).0)
}

/// [`check`] of a graph already resolved (a `Prepared`'s IR).
fn check_resolved(
    graph: &weft_graph::LoadedGraph,
    ir: &weft_graph::resolve::Ir,
) -> Vec<Diagnostic> {
    let mut diags = weft_graph::provider::check_providers(graph, PROVIDERS);
    diags.extend(weft_graph::vocabulary::check_vocabulary_resolved(
        graph,
        ir,
        &crate::vocabulary::VOCABULARY,
    ));
    diags
}

/// Compiles a graph for one size and feature set as the renderer runs it:
/// the graph's own checks, its provider uses and scene names ([`check`]), the plan,
/// then the values computed once per plan added to it.
pub fn compile(
    prepared: &weft_graph::Prepared,
    options: &weft_graph::CompileOptions,
) -> Result<Plan, Vec<Diagnostic>> {
    let errors: Vec<Diagnostic> = check_resolved(prepared.graph(), prepared.ir())
        .into_iter()
        .filter(Diagnostic::is_error)
        .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let mut plan = prepared.compile(options)?;
    derive_values(&mut plan)?;
    Ok(plan)
}

/// A pass's use of `spec`, with defaults filled in.
fn call(
    pass: &PlanPass,
    spec: &ProviderSpec,
) -> Option<std::collections::BTreeMap<String, ParamValue>> {
    pass.derive
        .iter()
        .find(|c| c.name == spec.name)
        .map(|c| spec.arguments(c))
}

fn number(args: &std::collections::BTreeMap<String, ParamValue>, name: &str) -> f64 {
    match args.get(name) {
        Some(ParamValue::Number(n)) => *n,
        // `check` guarantees every argument has its declared type.
        _ => unreachable!("provider argument `{name}` was checked to be a number"),
    }
}

/// Adds the values computed once per plan to its passes: the Gaussian taps
/// as parameters, each tracing pass's ray-counter slot as a define
/// ([`crate::providers::ray_counts`]). The plan must come from a graph that passed
/// [`check`].
pub fn derive_values(plan: &mut Plan) -> Result<(), Vec<Diagnostic>> {
    let mut errors = Vec::new();
    for pass in plan.passes.iter_mut() {
        let Some(args) = call(pass, &GAUSSIAN) else {
            continue;
        };
        let (sigma, radius) = (number(&args, "sigma"), number(&args, "radius") as u32);
        let taps = match args.get("linear_taps") {
            Some(ParamValue::Bool(false)) => GaussianTaps::discrete(sigma, radius),
            _ => GaussianTaps::linear(sigma, radius),
        };
        match taps {
            Ok(taps) => {
                let len = taps.len() as f64;
                pass.params
                    .insert("gauss_taps".into(), ParamValue::Number(len));
                pass.params
                    .insert("gauss_weights".into(), ParamValue::Vector(taps.weights));
                pass.params
                    .insert("gauss_offsets".into(), ParamValue::Vector(taps.offsets));
            }
            Err(problem) => errors.push(Diagnostic::error(
                pass.declared_at.file.clone(),
                pass.declared_at.pos,
                format!("pass \"{}\": `Gaussian`: {problem}", pass.name),
            )),
        }
    }
    if errors.is_empty() {
        ray_counts::assign_slots(plan.passes.iter_mut())
    } else {
        Err(errors)
    }
}

/// The shadow settings of a pass that uses `ShadowAtlas`.
pub fn shadow_atlas(pass: &PlanPass) -> Option<ShadowSettings> {
    let args = call(pass, &SHADOW_ATLAS)?;
    Some(ShadowSettings {
        cascades: number(&args, "cascades") as u32,
        pcf_radius: number(&args, "pcf_radius") as u32,
        normal_bias: number(&args, "normal_bias") as f32,
        split_lambda: number(&args, "split_lambda") as f32,
        area_lights: number(&args, "area_lights") as u32,
        point_lights: number(&args, "point_lights") as u32,
    })
}

/// Whether `name` is a value some provider the pass uses supplies.
pub fn supplied(pass: &PlanPass, name: &str) -> bool {
    pass.derive
        .iter()
        .filter_map(|c: &ProviderDecl| find(PROVIDERS, &c.name))
        .any(|spec| spec.supplies.contains(&name))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::collections::BTreeMap;
    use weft_graph::plan::Location;

    pub(crate) fn pass_with(derive: Vec<ProviderDecl>) -> PlanPass {
        PlanPass {
            name: "blur".into(),
            declared_at: Location::default(),
            kind: PassKind::Fullscreen,
            shaders: Default::default(),
            draw: None,
            dispatch: None,
            indirect: None,
            repeat: 1,
            repeat_barriers: Vec::new(),
            params: BTreeMap::new(),
            defines: Vec::new(),
            model_defines: Vec::new(),
            variants: 1,
            barriers: Vec::new(),
            render_pass: None,
            bindings: Vec::new(),
            transfer: None,
            raster: Default::default(),
            derive,
            structure: None,
            scratch: None,
        }
    }

    fn decl(name: &str, args: &[(&str, ParamValue)]) -> ProviderDecl {
        ProviderDecl {
            name: name.into(),
            args: args
                .iter()
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
        }
    }

    #[test]
    fn gaussian_taps_become_parameters_of_the_pass() {
        let gaussian = decl(
            "Gaussian",
            &[
                ("sigma", ParamValue::Number(9.0)),
                ("radius", ParamValue::Number(21.0)),
            ],
        );
        let mut plan_pass = pass_with(vec![gaussian]);
        let taps = GaussianTaps::linear(9.0, 21).expect("taps");
        let mut passes = weft_graph::id::IdVec::new();
        passes.push(plan_pass.clone());
        let mut plan = plan_of(passes);
        derive_values(&mut plan).expect("derives");
        plan_pass = plan.passes.iter().next().expect("pass").clone();
        assert_eq!(plan_pass.params["gauss_taps"], ParamValue::Number(12.0));
        assert_eq!(
            plan_pass.params["gauss_weights"],
            ParamValue::Vector(taps.weights)
        );
        assert_eq!(
            plan_pass.params["gauss_offsets"],
            ParamValue::Vector(taps.offsets)
        );
        assert!(supplied(&plan_pass, "gauss_weights"));
        assert!(!supplied(&plan_pass, SHADOW_VIEW));
    }

    #[test]
    fn one_tap_per_texel_without_linear_taps() {
        let gaussian = decl(
            "Gaussian",
            &[
                ("sigma", ParamValue::Number(9.0)),
                ("radius", ParamValue::Number(21.0)),
                ("linear_taps", ParamValue::Bool(false)),
            ],
        );
        let mut passes = weft_graph::id::IdVec::new();
        passes.push(pass_with(vec![gaussian]));
        let mut plan = plan_of(passes);
        derive_values(&mut plan).expect("derives");
        let pass = plan.passes.iter().next().expect("pass");
        assert_eq!(pass.params["gauss_taps"], ParamValue::Number(22.0));
    }

    #[test]
    fn shadow_settings_come_from_the_declared_arguments_with_defaults() {
        let atlas = decl(
            "ShadowAtlas",
            &[
                ("cascades", ParamValue::Number(3.0)),
                ("pcf_radius", ParamValue::Number(2.0)),
            ],
        );
        let settings = shadow_atlas(&pass_with(vec![atlas])).expect("a shadow pass");
        assert_eq!(
            settings,
            ShadowSettings {
                cascades: 3,
                pcf_radius: 2,
                ..ShadowSettings::default()
            }
        );
        assert_eq!(shadow_atlas(&pass_with(Vec::new())), None);
        let without_area = decl("ShadowAtlas", &[("area_lights", ParamValue::Number(0.0))]);
        let settings = shadow_atlas(&pass_with(vec![without_area])).expect("a shadow pass");
        assert_eq!(settings.area_lights, 0);
    }

    /// A plan of `pass` alone.
    pub(crate) fn plan_of_one(pass: PlanPass) -> Plan {
        let mut passes = weft_graph::id::IdVec::new();
        passes.push(pass);
        plan_of(passes)
    }

    fn plan_of(passes: weft_graph::id::IdVec<weft_graph::id::PassId, PlanPass>) -> Plan {
        Plan {
            name: "t".into(),
            file: Default::default(),
            files: Vec::new(),
            extent: weft_graph::Extent {
                width: 8,
                height: 8,
            },
            features: Vec::new(),
            scene_values: Default::default(),
            resources: Default::default(),
            passes,
            culled: Vec::new(),
            output: weft_graph::id::ResourceId::new(0),
            readback: Vec::new(),
            samples_per_frame: None,
            views: Vec::new(),
            caveats: Vec::new(),
            camera_jitter: false,
            memory: Default::default(),
            epilogue: Vec::new(),
            warnings: Vec::new(),
        }
    }
}
