//! Environment maps (scenes/FORMAT.md, "environment"; docs/environment.md):
//! a wall lit only by a map, against the irradiance integrated on the CPU
//! from the lookup model (engine/render/src/environment.rs, itself checked
//! against Mitsuba 3's `envmap`), in the path tracer and the raster graphs;
//! the tracer's strategies agreeing; what camera rays see behind
//! everything; and maps with extreme texels.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use weft_render::environment::{irradiance_sh, radiance, sh9, uv_direction, world_direction};
use weft_scene::environment::Environment;
use weft_tests::render::{render_hdr_validated, square_settings_without_bloom};

const SIZE: u32 = 16;
/// The wall's diffuse albedo.
const ALBEDO: f32 = 0.5;

/// A map of `width`×`height` texels from `texel(x, y)`, as an EXR in `dir`.
fn write_map(dir: &Path, width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 3]) -> PathBuf {
    let texels: Vec<[f32; 3]> = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| texel(x, y))
        .collect();
    let path = dir.join("map.exr");
    std::fs::write(
        &path,
        weft_io::exr::encode_rgb(width, height, &texels).expect("encodes"),
    )
    .expect("write the map");
    path
}

/// A 40×40 Lambertian wall at z = 0 facing +z, lit only by the map, seen
/// head-on from (0, 0, 3) (or, `away`, from there looking along +z at
/// nothing but the map); returns the scene and its loaded map.
fn wall_scene(
    name: &str,
    map: impl Fn(&Path) -> PathBuf,
    rotation: f32,
    away: bool,
) -> (PathBuf, Environment) {
    let dir = std::env::temp_dir().join(format!("weft-environment-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    map(&dir);
    std::fs::write(
        dir.join("wall.obj"),
        "mtllib wall.mtl\nv -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\nvn 0 0 1\nusemtl wall\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("wall.mtl"),
        format!("newmtl wall\nKd {ALBEDO} {ALBEDO} {ALBEDO}\nKs 0 0 0\nillum 1\n"),
    )
    .expect("mtl");
    let target = if away { "0 0 6" } else { "0 0 0" };
    let scene = dir.join("wall.scene");
    std::fs::write(
        &scene,
        format!("environment\n{{\n\tfile \"map.exr\"\n\trotation_deg {rotation}\n}}\nmodel\n{{\n\tfile \"wall.obj\"\n}}\ncamera\n{{\n\tposition 0 0 3\n\ttarget {target}\n\tfov_deg 30\n}}\n"),
    )
    .expect("scene");
    let environment = weft_scene::load_scene(&scene)
        .expect("loads")
        .environment
        .expect("a map");
    (scene, environment)
}

/// A smooth sky: a gradient from the horizon up and a broad warm lobe.
fn smooth(dir: &Path) -> PathBuf {
    write_map(dir, 64, 32, |x, y| {
        let d = uv_direction(Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0));
        let lobe = (3.0 * (d.dot(Vec3::new(0.3, 0.5, 0.8).normalize()) - 1.0)).exp();
        [
            0.2 + 3.0 * lobe,
            0.3 + 2.0 * lobe + 0.2 * d.y,
            0.5 + 0.6 * lobe + 0.4 * d.y.max(0.0),
        ]
    })
}

/// The irradiance at a surface facing +z, over π, integrated from the lookup
/// model on a 2048×1024 grid.
fn wall_irradiance(env: &Environment) -> Vec3 {
    let (nu, nv) = (2048, 1024);
    let mut sum = glam::DVec3::ZERO;
    for j in 0..nv {
        for i in 0..nu {
            let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let d = world_direction(uv_direction(uv), env.rotation_deg);
            if d.z > 0.0 {
                let d_omega = (2.0 * PI / nu as f32) * (PI / nv as f32) * (uv.y * PI).sin();
                sum += (radiance(env, d) * d.z * d_omega).as_dvec3();
            }
        }
    }
    (sum / std::f64::consts::PI).as_vec3()
}

/// The image's mean RGB.
fn mean(values: &[f32]) -> Vec3 {
    let n = values.len() / 4;
    values
        .chunks(4)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .sum::<Vec3>()
        / n as f32
}

fn trace(scene: &Path, samples: u64, params: &[(&str, f64)]) -> Vec<f32> {
    let settings = square_settings_without_bloom("pathtrace.ron", SIZE, Some(samples), params, &[]);
    render_hdr_validated(scene, settings).1
}

fn assert_close(what: &str, got: Vec3, expected: Vec3, tolerance: f32) {
    let error = ((got - expected) / expected).abs().max_element();
    assert!(
        error <= tolerance,
        "{what}: {got} against {expected} ({error:.4})"
    );
}

#[test]
fn one_bright_texel_lights_a_wall_with_the_integrated_irradiance() {
    let (scene, env) = wall_scene(
        "texel",
        |dir| {
            write_map(dir, 16, 8, |x, y| {
                if (x, y) == (9, 3) {
                    [900.0, 600.0, 300.0]
                } else {
                    [0.0; 3]
                }
            })
        },
        20.0,
        false,
    );
    let expected = ALBEDO * wall_irradiance(&env);
    assert!(expected.x > 1.0, "the texel faces the wall: {expected}");
    let image = trace(&scene, 64, &[("max_depth", 2.0)]);
    assert_close("the path tracer", mean(&image), expected, 0.02);
}

#[test]
fn raster_graphs_light_with_the_maps_sh_irradiance() {
    let (scene, env) = wall_scene("raster", smooth, 70.0, false);
    let sh = irradiance_sh(&env);
    let facing = sh9(weft_render::environment::local_direction(
        Vec3::Z,
        env.rotation_deg,
    ));
    let from_sh: Vec3 = sh.iter().zip(facing).map(|(c, y)| *c * y).sum();
    // SH9 of a smooth sky is its irradiance within 1%.
    assert_close(
        "SH9 against integration",
        from_sh,
        wall_irradiance(&env),
        0.01,
    );
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let settings = square_settings_without_bloom(graph, SIZE, None, &[], &[]);
        let (_, image) = render_hdr_validated(&scene, settings);
        for p in image.chunks(4) {
            assert_close(graph, Vec3::new(p[0], p[1], p[2]), ALBEDO * from_sh, 2e-3);
        }
    }
}

/// Next-event estimation of the map alone, BSDF sampling alone and their
/// MIS converge to the same image: each strategy is unbiased and the MIS
/// weights of a direction sum to 1.
#[test]
fn the_tracers_environment_strategies_agree() {
    let (scene, env) = wall_scene("strategies", smooth, 40.0, false);
    let expected = ALBEDO * wall_irradiance(&env);
    for sampling in [0.0, 1.0, 2.0] {
        let image = trace(&scene, 128, &[("max_depth", 2.0), ("sampling", sampling)]);
        assert_close(
            &format!("sampling {sampling}"),
            mean(&image),
            expected,
            0.01,
        );
    }
}

/// Where camera rays meet nothing, raster graphs show the map as the path
/// tracer's camera rays see it (pixel centres against box-filtered pixels,
/// so within 1.5% on this smooth map).
#[test]
fn camera_rays_see_the_map_behind_everything() {
    let (scene, _) = wall_scene("background", smooth, 10.0, true);
    let traced = trace(&scene, 32, &[("max_depth", 1.0)]);
    assert!(mean(&traced).min_element() > 0.1, "{}", mean(&traced));
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let settings = square_settings_without_bloom(graph, SIZE, None, &[], &[]);
        let (_, image) = render_hdr_validated(&scene, settings);
        for (p, q) in image.chunks(4).zip(traced.chunks(4)) {
            assert_close(
                graph,
                Vec3::new(p[0], p[1], p[2]),
                Vec3::new(q[0], q[1], q[2]),
                0.015,
            );
        }
    }
}

/// A sun of 3·10³⁸ and negative texels: every graph's image stays finite.
#[test]
fn extreme_texels_give_finite_images() {
    let (scene, env) = wall_scene(
        "extreme",
        |dir| {
            write_map(dir, 16, 8, |x, y| match (x, y) {
                (9, 3) => [3e38, 3e38, 3e38],
                (2, _) => [-5.0, 1.0, -3894.0],
                _ => [0.5, 0.5, 0.5],
            })
        },
        0.0,
        false,
    );
    assert!(env.texels.iter().flatten().all(|c| *c >= 0.0));
    let warnings = weft_scene::load_scene(&scene).expect("loads").warnings;
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .message
            .contains("8 texel(s) have negative channels"),
        "{warnings:?}"
    );
    let traced = trace(&scene, 4, &[]);
    assert!(traced.iter().all(|v| v.is_finite()), "the path tracer");
    for graph in ["forward.ron", "deferred.ron"] {
        let settings = square_settings_without_bloom(graph, SIZE, None, &[], &[]);
        let (_, image) = render_hdr_validated(&scene, settings);
        assert!(image.iter().all(|v| v.is_finite()), "{graph}");
    }
}

/// `rt_ao` under a map counts each ray by the luminance of the sky it points
/// at, so the SH irradiance it scales loses the light the geometry blocks:
/// on scenes/environment.scene (diffuse spheres on a floor under venice.exr)
/// deferred with `rt_ao` comes within 2.5% of the tracer's direct light, where
/// without it the unoccluded map lights the floor under the spheres (+4%).
#[test]
fn ambient_occlusion_weighs_its_rays_by_the_map() {
    let scene = weft_tests::render::root().join("scenes/environment.scene");
    let size = 48;
    let traced = {
        let settings = square_settings_without_bloom(
            "pathtrace.ron",
            size,
            Some(64),
            &[("max_depth", 2.0)],
            &[],
        );
        mean(&render_hdr_validated(&scene, settings).1)
    };
    let raster = |features: &[&str]| {
        let mut settings = square_settings_without_bloom(
            "deferred.ron",
            size,
            None,
            &[("rt_ao.rays", 16.0)],
            features,
        );
        settings.frames = 4;
        mean(&render_hdr_validated(&scene, settings).1)
    };
    let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let occluded = luminance(raster(&["rt_ao"])) / luminance(traced);
    let open = luminance(raster(&[])) / luminance(traced);
    assert!(
        (occluded - 1.0).abs() < 0.025,
        "deferred with rt_ao: {occluded} of the tracer's"
    );
    assert!(open > 1.03, "without rt_ao the map is unoccluded: {open}");
}
