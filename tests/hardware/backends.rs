//! The ray tracer's two backends against each other on one device: the
//! software BVH walk and ray queries against hardware acceleration
//! structures (`TRACE_HARDWARE` in `shaders/include/trace.glsl`), on the
//! device [`crate::gpu`] selects.
//!
//! - Hit equality: a hostile ray set (random, aimed at corners, at points on
//!   edges, grazing; `tests/shaders/ray_set.comp`) gives the same hit on
//!   both: the same triangle, the two hit points within 1e-5 of its plane
//!   (a grazing ray's distance is ill-conditioned: 1e-7 off the plane is
//!   1e-4 along a ray 1e-3 from it). The exceptions are ties, stated and
//!   counted: a hit within rounding of its triangle's edge (1e-5 of the
//!   point's magnitude over the sine of the ray's angle to the plane), where
//!   the walk's edge tolerance (1e-5) and the hardware's watertight rule
//!   may each keep or pass the ray (a shared edge or corner, or the
//!   outline), or two triangles met at the same distance (1e-5 relative)
//!   or each hit on the other's plane (coplanar surfaces a grazing ray
//!   crosses).
//! - A script moving a placement refits the top level, and the next frame's
//!   rays, aimed at the moved triangles, agree with the rebuilt BVH.
//! - Every shipped tracing graph (path tracer, megakernel and wavefront,
//!   denoised; forward and tiled with `rt_shadows`; deferred with `gi`,
//!   `rt_ao`, `rt_specular`; hybrid with ReSTIR, the radiance cache and the
//!   denoiser) gives the same image mean on both (0.5%).

use glam::Vec3;
use std::path::Path;
use weft_graph::plan::Extent;
use weft_graph::schema::PassKind;
use weft_graph::vk::{Access, Stage};
use weft_render::{render, RenderSettings, TraceBackend};
use weft_tests::render::{root, square_settings};

/// One ray of the fixture and what it hit (distance or -1, triangle).
#[derive(Debug, Clone, Copy)]
struct Cast {
    origin: Vec3,
    direction: Vec3,
    kind: u32,
    t: f32,
    triangle: usize,
}

/// Each ray of the fixture on `scene` through `backend`, the last of
/// `frames` frames from `time`, half a second apart.
fn ray_hits(scene: &Path, backend: TraceBackend, (time, frames): (f64, u32)) -> Vec<Cast> {
    let gpu = crate::gpu();
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: weft_tests::graph("ray_set.ron"),
        extent: Extent {
            width: 128,
            height: 64,
        },
        time,
        frames,
        frame_time: 0.5,
        trace_backend: backend,
        extra_readback: vec!["ray".into(), "direction".into()],
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{backend:?}");
    assert_builds_structures(&rendered.plan, backend == TraceBackend::Hardware);
    let floats = |pixels: &weft_gpu::Pixels| match pixels {
        weft_gpu::Pixels::RgbaF32(texels) => texels.clone(),
        _ => panic!("the fixture's images are float images"),
    };
    let hits = floats(&rendered.report.output.as_ref().expect("read back").pixels);
    let read = |name: &str| {
        let image = rendered
            .report
            .first_read_back(&[name.to_string()])
            .unwrap_or_else(|| panic!("{name} read back"));
        floats(&image.pixels)
    };
    let (origins, directions) = (read("ray"), read("direction"));
    (0..hits.len() / 4)
        .map(|i| {
            let at = |v: &[f32]| Vec3::new(v[4 * i], v[4 * i + 1], v[4 * i + 2]);
            Cast {
                origin: at(&origins),
                direction: at(&directions),
                kind: hits[4 * i + 2] as u32,
                t: hits[4 * i],
                triangle: hits[4 * i + 1] as usize,
            }
        })
        .collect()
}

/// On the hardware backend the plan's first pass builds the scene's
/// acceleration structures and every pass that traces reads them, after it
/// (the compiler's barrier from the build stage); on the software backend
/// the build is culled and nothing reads them.
fn assert_builds_structures(plan: &weft_graph::plan::Plan, hardware: bool) {
    let builds: Vec<_> = plan
        .passes
        .iter()
        .filter(|p| p.kind == PassKind::BuildAccelerationStructures)
        .collect();
    let tracing: Vec<_> = plan
        .passes
        .iter()
        .filter(|p| p.derive.iter().any(|d| d.name == "RayTracing"))
        .collect();
    if !hardware {
        assert!(builds.is_empty(), "{}: software builds nothing", plan.name);
        assert!(tracing.iter().all(|p| p.structure.is_none()));
        return;
    }
    assert_eq!(builds.len(), 1, "{}: one build pass", plan.name);
    let structure = builds[0].structure.expect("the build names its structure");
    let readers: Vec<_> = tracing.iter().filter(|p| p.structure.is_some()).collect();
    assert!(
        !readers.is_empty(),
        "{}: a tracing pass reads it",
        plan.name
    );
    for pass in readers {
        assert_eq!(pass.structure, Some(structure), "{} reads it", pass.name);
    }
    let first_reader = plan
        .passes
        .iter()
        .find(|p| p.kind != PassKind::BuildAccelerationStructures && p.structure.is_some())
        .expect("a reader");
    let barrier = first_reader
        .barriers
        .iter()
        .find(|b| b.resource == structure)
        .expect("the first reader waits for the build");
    assert_eq!(barrier.src_stage, Stage::ACCELERATION_STRUCTURE_BUILD);
    assert_eq!(barrier.src_access, Access::ACCELERATION_STRUCTURE_WRITE);
    assert_eq!(barrier.dst_access, Access::ACCELERATION_STRUCTURE_READ);
}

/// How the backends' answers for one ray set compare.
#[derive(Debug, Default, PartialEq)]
struct Agreement {
    rays: usize,
    hits: usize,
    same: usize,
    /// A hit within rounding of its triangle's edge on either backend.
    edges: usize,
    /// Different triangles at the same distance, or each hit on the other's
    /// plane (coplanar surfaces where a grazing ray crosses them).
    ties: usize,
    /// Anything else.
    disagree: Vec<String>,
}

/// Where `p` lies on `triangle`: its distance from the nearest edge (below
/// zero outside), from the triangle's plane, and the triangle's unit normal.
fn on_triangle(p: Vec3, triangle: &[Vec3; 3]) -> (f32, f32, Vec3) {
    let [a, b, c] = *triangle;
    let (e1, e2, d) = (b - a, c - a, p - a);
    let cross = e1.cross(e2);
    let normal = cross.normalize_or_zero();
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (d.dot(e1), d.dot(e2));
    let denom = d00 * d11 - d01 * d01;
    let u = (d11 * d20 - d01 * d21) / denom;
    let v = (d00 * d21 - d01 * d20) / denom;
    // A barycentric coordinate times the height over its edge is the
    // distance from that edge: the height is twice the area over the edge.
    let twice_area = cross.length();
    let edge = [(1.0 - u - v, c - b), (u, a - c), (v, b - a)]
        .iter()
        .map(|&(w, e)| w * twice_area / e.length())
        .fold(f32::INFINITY, f32::min);
    (edge, d.dot(normal).abs(), normal)
}

/// Whether a hit lies within rounding of its triangle's edge: 1e-5 of the
/// hit point's magnitude, divided by the sine of the angle between ray and
/// plane (at a grazing angle a tiny offset of the plane moves the hit far
/// along it).
fn near_edge(cast: &Cast, triangles: &[[Vec3; 3]]) -> bool {
    if cast.t < 0.0 {
        return false;
    }
    let p = cast.origin + cast.t * cast.direction;
    let (edge, _, normal) = on_triangle(p, &triangles[cast.triangle]);
    let sine = cast.direction.dot(normal).abs().max(1e-4);
    edge < 1e-5 * p.abs().max_element().max(1.0) / sine
}

fn compare(software: &[Cast], hardware: &[Cast], triangles: &[[Vec3; 3]]) -> Agreement {
    let mut agreement = Agreement {
        rays: software.len(),
        ..Agreement::default()
    };
    for (i, (s, h)) in software.iter().zip(hardware).enumerate() {
        assert_eq!((s.origin, s.direction), (h.origin, h.direction), "ray {i}");
        let (s_hit, h_hit) = (s.t >= 0.0, h.t >= 0.0);
        agreement.hits += usize::from(s_hit && h_hit);
        let on_plane = |c: &Cast, other: &Cast| {
            on_triangle(
                other.origin + other.t * other.direction,
                &triangles[c.triangle],
            )
            .1 <= 1e-5 * (1.0 + other.t)
        };
        let same = match (s_hit, h_hit) {
            (false, false) => true,
            (true, true) => s.triangle == h.triangle && on_plane(s, h) && on_plane(h, s),
            _ => false,
        };
        if same {
            agreement.same += 1;
        } else if near_edge(s, triangles) || near_edge(h, triangles) {
            agreement.edges += 1;
        } else if s_hit
            && h_hit
            && ((s.t - h.t).abs() <= 1e-5 * s.t.max(h.t).max(1.0)
                || on_plane(s, h) && on_plane(h, s))
        {
            agreement.ties += 1;
        } else {
            agreement.disagree.push(format!(
                "ray {i} (kind {}): software t {} triangle {}, hardware t {} triangle {}",
                s.kind, s.t, s.triangle, h.t, h.triangle
            ));
        }
    }
    agreement
}

fn assert_agree(what: &str, agreement: &Agreement) {
    println!("{what}: {agreement:?}");
    assert!(agreement.disagree.is_empty(), "{what}: {agreement:#?}");
    assert!(
        agreement.hits * 2 > agreement.rays,
        "{what}: most rays hit: {agreement:?}"
    );
}

/// The ray tracer's triangles of `scene` as loaded (the order both
/// backends name them in).
fn triangles(scene: &Path) -> Vec<[Vec3; 3]> {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    weft_render::SceneGeometry::new(&scene).trace_mesh().corners
}

#[test]
fn both_backends_hit_the_same_triangles_on_a_hostile_ray_set() {
    for scene in ["scenes/cornell.scene", "scenes/demo.scene"] {
        let scene = root().join(scene);
        let software = ray_hits(&scene, TraceBackend::Software, (0.0, 1));
        let hardware = ray_hits(&scene, TraceBackend::Hardware, (0.0, 1));
        let agreement = compare(&software, &hardware, &triangles(&scene));
        assert_agree(&scene.display().to_string(), &agreement);
    }
}

#[test]
fn a_moved_placement_refits_the_top_level_and_the_next_frame_sees_it() {
    let dir = weft_tests::TempDir::new("refit");
    std::fs::write(
        dir.0.join("floor.obj"),
        "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 3 2\nf 1 4 3\n",
    )
    .expect("write");
    std::fs::write(
        dir.0.join("cube.obj"),
        "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
         v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
         f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 5 8\nf 1 8 4\n\
         f 2 3 7\nf 2 7 6\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n",
    )
    .expect("write");
    // Where the script leaves the cube, as a file places it.
    let placed = dir.0.join("placed.scene");
    std::fs::write(
        &placed,
        "model\n{\n\tfile \"floor.obj\"\n}\nmodel\n{\n\tfile \"cube.obj\"\n\tposition 1.5 0.75 0.25\n\torientation 0 30 0\n}\n",
    )
    .expect("write");
    let scene = dir.0.join("moving.rhai");
    std::fs::write(
        &scene,
        r#"model("floor.obj", #{});
model("cube.obj", #{ position: [-1, 0.5, 0] });
camera("main", #{ position: [0, 3, 6], target: [0, 0, 0] });
sun_light(#{ direction: [-0.3, -1, -0.4], color: [1, 1, 1] });
fn update(t, dt) {
    if t > 1.2 { set_model_transform(1, #{ position: [1.5, 0.75, 0.25], orientation: [0, 30, 0] }); }
}
"#,
    )
    .expect("write");
    // Frame 0 at 1 s, frame 1 at 1.5 s: the cube has moved.
    let before = ray_hits(&scene, TraceBackend::Hardware, (1.0, 1));
    let software = ray_hits(&scene, TraceBackend::Software, (1.0, 2));
    let hardware = ray_hits(&scene, TraceBackend::Hardware, (1.0, 2));
    let agreement = compare(&software, &hardware, &triangles(&placed));
    assert_agree("the moved cube", &agreement);
    let changed = before
        .iter()
        .zip(&hardware)
        .filter(|(a, b)| a.t != b.t)
        .count();
    assert!(
        changed > before.len() / 4,
        "the rays aim at the moved cube: {changed} of {} changed",
        before.len()
    );
}

/// The mean of `graph`'s `hdr` over the Cornell box at 48² on `backend`.
fn hdr_mean(graph: &str, features: &[&str], samples: Option<u64>, backend: TraceBackend) -> f64 {
    let mut settings = square_settings(graph, 48, samples, &[], features);
    settings.trace_backend = backend;
    settings.frames = 2;
    settings.extra_readback = vec!["hdr".into()];
    settings.readback_asked = true;
    let gpu = crate::gpu();
    let scene = weft_scene::load_scene(&root().join("scenes/cornell.scene")).expect("loads");
    let log = gpu.validation();
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{graph} {backend:?}");
    assert_builds_structures(&rendered.plan, backend == TraceBackend::Hardware);
    let weft_gpu::Pixels::RgbaF32(values) = &rendered.report.readbacks[0].1.pixels else {
        panic!("hdr is a float image");
    };
    let sum: f64 = values
        .chunks(4)
        .map(|p| f64::from(p[0] + p[1] + p[2]))
        .sum();
    sum / (values.len() / 4) as f64
}

/// Renders `graph` with `features` on both backends and asserts the HDR
/// means agree within 0.5%.
fn same_mean_on_both_backends(graph: &str, features: &[&str], samples: Option<u64>) {
    let software = hdr_mean(graph, features, samples, TraceBackend::Software);
    let hardware = hdr_mean(graph, features, samples, TraceBackend::Hardware);
    let ratio = hardware / software;
    println!(
        "{graph} {features:?}: software {software:.6}, hardware {hardware:.6}, ratio {ratio:.6}"
    );
    assert!(
        (ratio - 1.0).abs() < 5e-3,
        "{graph} {features:?}: hardware / software = {ratio}"
    );
}

// Every tracing graph, one test each so the test threads share them out.

#[test]
fn the_path_tracer_gives_the_same_image_on_both_backends() {
    same_mean_on_both_backends("pathtrace.ron", &[], Some(8));
}

#[test]
fn the_wavefront_path_tracer_gives_the_same_image_on_both_backends() {
    same_mean_on_both_backends("pathtrace_wavefront.ron", &[], Some(4));
}

#[test]
fn the_denoised_path_tracer_gives_the_same_image_on_both_backends() {
    same_mean_on_both_backends("pathtrace_denoised.ron", &[], None);
}

#[test]
fn the_hybrid_gives_the_same_image_on_both_backends() {
    same_mean_on_both_backends("hybrid.ron", &[], None);
}

#[test]
fn tiled_shadow_rays_give_the_same_image_on_both_backends() {
    same_mean_on_both_backends("tiled.ron", &["rt_shadows"], None);
}

#[test]
fn forward_shadow_rays_give_the_same_image_on_both_backends() {
    same_mean_on_both_backends("forward.ron", &["rt_shadows"], None);
}

#[test]
fn deferred_gi_gives_the_same_image_on_both_backends() {
    same_mean_on_both_backends("deferred.ron", &["gi"], None);
}

#[test]
fn deferred_ao_and_specular_rays_give_the_same_image_on_both_backends() {
    same_mean_on_both_backends("deferred.ron", &["rt_ao", "rt_specular"], None);
}
