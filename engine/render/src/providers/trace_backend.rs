//! Which traversal the passes that trace rays compile against: the software
//! BVH walk every Vulkan device runs, or ray queries against hardware
//! acceleration structures (`VK_KHR_ray_query`). The choice is one define,
//! [`HARDWARE_DEFINE`], that `shaders/include/trace.glsl` tests, added to
//! every pass that declares `RayTracing`: every fragment that traces runs on
//! either backend unchanged. A pass may insist on hardware
//! (`RayTracing(hardware: true)`); on a device without ray queries its graph
//! is then refused at that pass, naming the missing extension.

use super::{call, traces, RAY_TRACING};
use weft_graph::plan::Plan;
use weft_graph::schema::{ParamValue, PassKind};
use weft_graph::Diagnostic;

/// The define that selects the ray-query implementation of `trace.glsl`.
pub const HARDWARE_DEFINE: &str = "TRACE_HARDWARE";

/// The backend asked for (`--backend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TraceBackend {
    /// Hardware on a GPU that offers ray queries, software elsewhere (on a
    /// CPU device such as lavapipe the software walk is the faster:
    /// docs/hardware_rt.md).
    #[default]
    Auto,
    /// The software BVH walk, on every device.
    Software,
    /// Ray queries; refused on a device without them.
    Hardware,
}

impl TraceBackend {
    /// The backend's name, as `--backend` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Software => "software",
            Self::Hardware => "hardware",
        }
    }
}

impl std::str::FromStr for TraceBackend {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        [Self::Auto, Self::Software, Self::Hardware]
            .into_iter()
            .find(|b| b.name() == text)
            .ok_or_else(|| format!("expected auto, software or hardware, found `{text}`"))
    }
}

/// What the device offers, as the choice needs it.
#[derive(Debug, Clone)]
pub struct DeviceTracing {
    /// The device's name, for errors.
    pub name: String,
    /// Whether it offers hardware ray queries.
    pub ray_query: bool,
    /// Whether it is a CPU device (lavapipe), where `auto` stays in software.
    pub cpu: bool,
}

/// What the missing extensions are called in errors.
const NEEDS: &str = "VK_KHR_acceleration_structure and VK_KHR_ray_query";

/// The feature the renderer turns on when a plan is compiled for ray
/// queries (and off otherwise, whatever a user asks): graphs read the
/// scene's acceleration structure under it (`storage_read: [(name:
/// "scene_structures", enabled_if: ["ray_queries"])]`), so its build pass
/// runs only for the hardware backend.
pub const RAY_QUERY_FEATURE: &str = "ray_queries";

/// Whether to compile for ray queries before the plan says whether a pass
/// insists on them: what `asked` means on `device` ([`choose`] may still ask
/// for another compile).
pub fn compile_for_hardware(asked: TraceBackend, device: &DeviceTracing) -> bool {
    device.ray_query
        && match asked {
            TraceBackend::Hardware => true,
            TraceBackend::Software => false,
            TraceBackend::Auto => !device.cpu,
        }
}

/// Whether `plan` was compiled with [`RAY_QUERY_FEATURE`] on.
pub fn compiled_for_ray_queries(plan: &Plan) -> bool {
    plan.features.iter().any(|f| f == RAY_QUERY_FEATURE)
}

/// What [`choose`] decided for a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The backend is chosen and the plan's tracing passes are compiled for
    /// it ([`in_hardware`] says which).
    Chosen,
    /// The plan must be compiled again with [`RAY_QUERY_FEATURE`] on
    /// (`hardware`) or off, and chosen for again.
    Recompile { hardware: bool },
}

/// The plan `compile` makes with [`RAY_QUERY_FEATURE`] on (`true`) or off,
/// its tracing passes compiled for the backend `asked` means on `device`
/// ([`choose`]): compiled first as [`compile_for_hardware`] says (in
/// software where the graph never names the feature, `names_feature`, as
/// it then compiles the same either way), and once more where the plan
/// asks for the feature the other way.
pub fn compile_traced(
    asked: TraceBackend,
    device: &DeviceTracing,
    names_feature: bool,
    mut compile: impl FnMut(bool) -> Result<Plan, Vec<Diagnostic>>,
) -> Result<Plan, Vec<Diagnostic>> {
    let mut hardware = names_feature && compile_for_hardware(asked, device);
    let mut plan = compile(hardware)?;
    if let Choice::Recompile { hardware: again } = choose(&mut plan, asked, device)? {
        hardware = again;
        plan = compile(hardware)?;
        // The second compile has the feature as chosen: asking again would
        // flip it back.
        if choose(&mut plan, asked, device)? != Choice::Chosen {
            return Err(vec![Diagnostic::error(
                plan.file.clone(),
                Default::default(),
                "the trace backend changed with every compile of the graph",
            )]);
        }
    }
    Ok(plan)
}

/// Chooses the backend for `plan`'s tracing passes as `asked` on `device`,
/// and adds [`HARDWARE_DEFINE`] to each when it is hardware. Hardware means
/// a plan compiled with [`RAY_QUERY_FEATURE`] on, so its tracing passes read
/// the acceleration structure its build pass writes: where the plan was
/// compiled the other way, the answer is to compile it again. Where no pass
/// reads a structure (a graph without one, or whose tracing is off) `auto`
/// takes the software walk; a pass whose shaders then trace in hardware
/// without reading one is refused when its pipeline is checked
/// (`weft_gpu::scene_set_problems`). A pass that insists on hardware, or
/// `--backend hardware`, on a device without ray queries is an error at
/// that pass.
pub fn choose(
    plan: &mut Plan,
    asked: TraceBackend,
    device: &DeviceTracing,
) -> Result<Choice, Vec<Diagnostic>> {
    let insisting: Vec<_> = plan
        .passes
        .iter()
        .filter(|p| insists(p))
        .map(|p| (p.name.clone(), p.declared_at.clone()))
        .collect();
    let mut errors = Vec::new();
    if !device.ray_query {
        for (name, at) in &insisting {
            errors.push(
                Diagnostic::error(
                    at.file.clone(),
                    at.pos,
                    format!(
                        "pass \"{name}\" traces with `RayTracing(hardware: true)`, which needs {NEEDS}: \
                         the device `{}` offers neither",
                        device.name
                    ),
                )
                .with_hint("drop `hardware: true` to let the software BVH trace on this device"),
            );
        }
    }
    if asked == TraceBackend::Hardware && !device.ray_query {
        if let Some(pass) = plan.passes.iter().find(|p| traces(p)) {
            errors.push(
                Diagnostic::error(
                    pass.declared_at.file.clone(),
                    pass.declared_at.pos,
                    format!(
                        "--backend hardware: pass \"{}\" would trace with ray queries, which need \
                         {NEEDS}: the device `{}` offers neither",
                        pass.name, device.name
                    ),
                )
                .with_hint("use --backend software (or auto)"),
            );
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let required = asked == TraceBackend::Hardware || !insisting.is_empty();
    let compiled_for = compiled_for_ray_queries(plan);
    if required && !compiled_for {
        return Ok(Choice::Recompile { hardware: true });
    }
    if !required && !compile_for_hardware(asked, device) && compiled_for {
        return Ok(Choice::Recompile { hardware: false });
    }
    // Where no pass reads a structure the plan builds (a graph without one,
    // or whose tracing is off), what is not required takes the software walk.
    let reads_structures = plan
        .passes
        .iter()
        .any(|p| traces(p) && p.structure.is_some());
    let hardware = compiled_for && (required || reads_structures);
    if compiled_for && !hardware {
        return Ok(Choice::Recompile { hardware: false });
    }
    if let Some(error) = built_in_software(plan).filter(|_| !hardware) {
        return Err(vec![error]);
    }
    if hardware {
        for pass in plan.passes.iter_mut().filter(|p| traces(p)) {
            pass.defines.push(HARDWARE_DEFINE.to_string());
        }
    }
    Ok(Choice::Chosen)
}

/// The error at a plan's acceleration-structure build when the plan was
/// compiled without [`RAY_QUERY_FEATURE`]: a pass reads the structure where
/// nothing traces in hardware, so the build would run for the software walk,
/// which has no structures to build.
pub fn built_in_software(plan: &Plan) -> Option<Diagnostic> {
    if compiled_for_ray_queries(plan) {
        return None;
    }
    let build = plan
        .passes
        .iter()
        .find(|p| p.kind == PassKind::BuildAccelerationStructures)?;
    Some(
        Diagnostic::error(
            build.declared_at.file.clone(),
            build.declared_at.pos,
            format!(
                "pass \"{}\" builds acceleration structures without `{RAY_QUERY_FEATURE}`: a pass \
                 reads them where the software BVH traces, which has none to build",
                build.name
            ),
        )
        .with_hint(format!(
            "read the structure only under ray queries: `(name: \"...\", enabled_if: \
             [\"{RAY_QUERY_FEATURE}\"])`"
        )),
    )
}

/// Whether a plan's tracing passes were compiled for ray queries.
pub fn in_hardware(plan: &Plan) -> bool {
    plan.passes
        .iter()
        .any(|p| p.defines.iter().any(|d| d == HARDWARE_DEFINE))
}

/// Whether a pass declares `RayTracing(hardware: true)`.
fn insists(pass: &weft_graph::plan::PlanPass) -> bool {
    call(pass, &RAY_TRACING)
        .is_some_and(|args| args.get("hardware") == Some(&ParamValue::Bool(true)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::providers::tests::pass_with;
    use weft_graph::schema::ProviderDecl;

    /// A plan with a tracing pass (insisting on hardware as `hardware`
    /// says) and one that does not trace, compiled with the ray-query
    /// feature as `feature` says; the tracing pass reads a structure under
    /// it where the graph `reads` one.
    fn plan_tracing(hardware: Option<bool>, reads: bool, feature: bool) -> Plan {
        let args = hardware
            .map(|h| ("hardware".to_string(), ParamValue::Bool(h)))
            .into_iter()
            .collect();
        let mut pass = pass_with(vec![ProviderDecl {
            name: "RayTracing".into(),
            args,
        }]);
        pass.declared_at.file = "graphs/t.ron".into();
        pass.declared_at.pos = weft_graph::spans::Pos { line: 7, col: 9 };
        if reads && feature {
            pass.structure = Some(weft_graph::id::ResourceId::new(0));
        }
        let mut plan = crate::providers::tests::plan_of_one(pass);
        plan.passes.push(pass_with(Vec::new()));
        if feature {
            plan.features.push(RAY_QUERY_FEATURE.into());
        }
        plan
    }

    /// What the renderer's compile settles on ([`compile_traced`]): whether
    /// the plan traces in hardware, and the plan.
    fn settle(
        hardware: Option<bool>,
        reads: bool,
        asked: TraceBackend,
        device: &DeviceTracing,
    ) -> Result<(bool, Plan), Vec<Diagnostic>> {
        let plan = compile_traced(asked, device, true, |feature| {
            Ok(plan_tracing(hardware, reads, feature))
        })?;
        Ok((in_hardware(&plan), plan))
    }

    fn device(ray_query: bool, cpu: bool) -> DeviceTracing {
        DeviceTracing {
            name: "llvmpipe".into(),
            ray_query,
            cpu,
        }
    }

    fn defined(plan: &Plan) -> Vec<bool> {
        plan.passes
            .iter()
            .map(|p| p.defines.iter().any(|d| d == HARDWARE_DEFINE))
            .collect()
    }

    #[test]
    fn auto_takes_hardware_on_a_gpu_with_ray_queries_and_software_elsewhere() {
        let cases = [
            (device(true, false), true),
            (device(true, true), false),
            (device(false, false), false),
        ];
        for (device, expected) in cases {
            let (chosen, plan) = settle(None, true, TraceBackend::Auto, &device).expect("chosen");
            assert_eq!(chosen, expected, "{device:?}");
            // Only the tracing pass gets the define.
            assert_eq!(defined(&plan), vec![expected, false]);
            assert_eq!(in_hardware(&plan), expected);
            let feature = compiled_for_ray_queries(&plan);
            assert_eq!(
                feature, expected,
                "compiled with the feature only for hardware"
            );
        }
    }

    #[test]
    fn asking_for_a_backend_takes_it_where_the_device_allows() {
        let (hw, _) = settle(None, true, TraceBackend::Hardware, &device(true, true)).expect("hw");
        assert!(hw);
        let (hw, plan) =
            settle(None, true, TraceBackend::Software, &device(true, false)).expect("sw");
        assert!(!hw);
        assert_eq!(defined(&plan), vec![false, false]);
    }

    #[test]
    fn a_plan_compiled_the_other_way_is_compiled_again() {
        let mut plan = plan_tracing(None, true, false);
        let choice = choose(&mut plan, TraceBackend::Hardware, &device(true, false));
        assert_eq!(
            choice.expect("no error"),
            Choice::Recompile { hardware: true }
        );
        assert_eq!(defined(&plan), vec![false, false], "nothing defined yet");
        let mut plan = plan_tracing(None, true, true);
        let choice = choose(&mut plan, TraceBackend::Software, &device(true, false));
        assert_eq!(
            choice.expect("no error"),
            Choice::Recompile { hardware: false }
        );
    }

    #[test]
    fn a_graph_without_a_structure_traces_in_software_unless_hardware_is_required() {
        let (hw, plan) = settle(None, false, TraceBackend::Auto, &device(true, false)).expect("sw");
        assert!(!hw, "auto falls back to the software walk");
        assert_eq!(defined(&plan), vec![false, false]);
        // Required: hardware, and the pipeline check refuses a pass whose
        // shaders then trace against nothing built.
        for (insisting, asked) in [
            (Some(true), TraceBackend::Auto),
            (None, TraceBackend::Hardware),
        ] {
            let (hw, plan) = settle(insisting, false, asked, &device(true, false)).expect("hw");
            assert!(hw, "{asked:?}");
            assert_eq!(defined(&plan), vec![true, false]);
        }
    }

    #[test]
    fn hardware_on_a_device_without_ray_queries_is_refused_at_the_pass() {
        let errors = settle(Some(true), true, TraceBackend::Auto, &device(false, false))
            .expect_err("refused");
        assert_eq!(errors.len(), 1);
        let text = errors[0].to_string();
        assert!(text.contains("graphs/t.ron:7:9"), "{text}");
        assert!(
            text.contains(
                "pass \"blur\" traces with `RayTracing(hardware: true)`, which needs \
                 VK_KHR_acceleration_structure and VK_KHR_ray_query: the device `llvmpipe` offers neither"
            ),
            "{text}"
        );
        let errors =
            settle(None, true, TraceBackend::Hardware, &device(false, false)).expect_err("refused");
        assert!(errors[0].to_string().contains("--backend hardware"));
        // A pass that insists takes hardware even where auto would not.
        let (hw, _) = settle(
            Some(true),
            true,
            TraceBackend::Software,
            &device(true, true),
        )
        .expect("hw");
        assert!(hw);
    }

    #[test]
    fn backend_names_round_trip() {
        for backend in [
            TraceBackend::Auto,
            TraceBackend::Software,
            TraceBackend::Hardware,
        ] {
            assert_eq!(backend.name().parse::<TraceBackend>(), Ok(backend));
        }
        assert!("rtx".parse::<TraceBackend>().is_err());
    }
}
