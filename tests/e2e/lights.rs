//! Many lights: a generated 1,000-light scene (`weft_testkit::light_scene`,
//! seed 1) rendered at 320x180 through forward, deferred (light volumes) and tiled
//! shading under validation and synchronization validation (zero messages).
//! RGB channel differences in 8-bit units: forward vs deferred and tiled vs
//! deferred each within mean <= 0.25 and 99th percentile <= 1; tiled also
//! against its golden image. The light heat map (`light_heatmap`) is checked
//! exactly: per-tile counts read back against the CPU mirror of the culling tests
//! (`weft_testkit::tiles`: the default surface box and 2.5D depth mask, and the
//! frustum slab) on a scene of known lights, and the legend's pixels.

use weft_tests::render as common;

use common::{agreement, graph, render_validated};
use glam::{Mat4, Vec2, Vec3};
use std::path::{Path, PathBuf};
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};
use weft_testkit::tiles;

/// A fresh folder under the system temp folder for this test's scene files.
fn scratch(name: &str) -> PathBuf {
    weft_testkit::scratch::scratch_path(&format!("weft-lights-{name}-{}", std::process::id()))
}

fn golden(name: &str) -> PathBuf {
    weft_tests::golden(name)
}

#[test]
fn a_thousand_lights_agree_across_forward_deferred_and_tiled() {
    let dir = scratch("agree");
    let scene = weft_testkit::light_scene::write_light_scene(&dir, 1000, 1).unwrap();
    let forward = render_validated(&scene, &graph("forward.ron"), 320, 180, &["!bloom"]);
    let deferred = render_validated(&scene, &graph("deferred.ron"), 320, 180, &["!bloom"]);
    let tiled = render_validated(&scene, &graph("tiled.ron"), 320, 180, &["!bloom"]);
    std::fs::remove_dir_all(&dir).unwrap();
    for out in [&forward, &deferred, &tiled] {
        assert_eq!(out.messages, Vec::new());
    }
    // The four point lights whose reach lies nearest the camera cast cube
    // shadows.
    assert_eq!(
        tiled.passes,
        ["shadow_sun", "gbuffer", "cull_lights", "shade", "tonemap"]
    );
    let fd = agreement(&forward.image, &deferred.image);
    let td = agreement(&tiled.image, &deferred.image);
    eprintln!("forward vs deferred {fd:?}; tiled vs deferred {td:?}");
    assert!(
        fd.mean <= 0.25 && fd.p99 <= 1,
        "forward vs deferred: {fd:?}"
    );
    assert!(td.mean <= 0.25 && td.p99 <= 1, "tiled vs deferred: {td:?}");
    // The lights light the scene: not a comparison of two black images.
    let lit = tiled.image.pixels().filter(|p| p.0[0] > 32).count();
    assert!(lit > 320 * 180 / 4, "{lit} lit pixels");
    if let Err(e) = weft_testkit::check_golden(
        &tiled.image,
        &golden("lights1000_tiled_320x180.png"),
        &weft_testkit::Tolerance {
            per_channel: 12,
            mean: 0.5,
        },
    ) {
        panic!("{e}");
    }
}

/// Eight point lights of known position and cutoff radius over a floor that
/// fills the view of a camera looking steeply down.
const KNOWN_LIGHTS: [([f32; 3], f32); 8] = [
    ([0.0, 0.5, 0.0], 2.0),
    ([0.5, 1.0, 0.5], 1.5),
    ([-3.0, 0.3, -1.0], 1.0),
    ([3.0, 0.2, 1.5], 2.5),
    ([-1.5, 2.5, 2.0], 3.0),
    ([2.0, 0.8, -2.0], 1.2),
    ([-4.0, 0.5, 2.5], 0.8),
    ([0.0, 3.0, -3.0], 2.0),
];

/// Spots of known apex, aim point on the floor, half-angle (degrees) and length,
/// culled by the sphere around their cone (`tiles::spot_bounds`), not their
/// length's ball: 10 and 30 degrees use the sphere through apex and rim, 60
/// the sphere around the rim.
const KNOWN_SPOTS: [([f32; 3], [f32; 3], f32, f32); 3] = [
    ([-2.0, 3.0, -1.0], [-2.5, 0.0, -0.5], 10.0, 4.0),
    ([2.5, 2.0, 2.0], [2.0, 0.0, 2.5], 30.0, 3.0),
    ([1.0, 1.0, -1.5], [1.0, 0.0, -1.0], 60.0, 1.5),
];

/// Every light of the known scene as the culling sees it: (centre, radius).
fn known_bounds() -> Vec<(Vec3, f32)> {
    let points = KNOWN_LIGHTS.iter().map(|(p, r)| (Vec3::from(*p), *r));
    let spots = KNOWN_SPOTS.iter().map(|(apex, aim, angle, length)| {
        let axis = (Vec3::from(*aim) - Vec3::from(*apex)).normalize();
        tiles::spot_bounds(Vec3::from(*apex), axis, angle.to_radians().cos(), *length)
    });
    points.chain(spots).collect()
}

fn known_scene(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("plane.obj"),
        "v -50 0 50\nv 50 0 50\nv 50 0 -50\nv -50 0 -50\nf 1 2 3 4\n",
    )
    .unwrap();
    let mut text = String::from("model\n{\n\tfile \"plane.obj\"\n}\n");
    for ([x, y, z], r) in KNOWN_LIGHTS {
        text.push_str(&format!(
            "pointlight\n{{\n\tposition {x} {y} {z}\n\tcolor 0.5 0.5 0.5\n\tattenuation 1 0 1\n\tradius {r}\n}}\n"
        ));
    }
    for (apex, aim, angle, length) in KNOWN_SPOTS {
        let [x, y, z] = apex;
        let [dx, dy, dz] = (Vec3::from(aim) - Vec3::from(apex)).to_array();
        text.push_str(&format!(
            "spotlight\n{{\n\tposition {x} {y} {z}\n\tdirection {dx} {dy} {dz}\n\tcolor 0.5 0.5 0.5\n\tangle {angle}\n\tattenuation 1 0 1\n\tlength {length}\n}}\n"
        ));
    }
    text.push_str("camera \"top\"\n{\n\tposition 0 9 4\n\ttarget 0 0 0\n\tfov_deg 60\n}\n");
    let path = dir.join("known.scene");
    std::fs::write(&path, text).unwrap();
    path
}

/// The reverse-Z depth of the floor (y = 0) seen through pixel centre `centre`.
fn floor_depth(view_proj: Mat4, inv: Mat4, viewport: Vec2, centre: Vec2) -> f32 {
    let hit = floor_point(inv, viewport, centre);
    let clip = view_proj * hit.extend(1.0);
    clip.z / clip.w
}

/// The floor point (y = 0) seen through pixel centre `centre`.
fn floor_point(inv: Mat4, viewport: Vec2, centre: Vec2) -> Vec3 {
    let near = tiles::unproject(inv, viewport, centre, 1.0);
    let far = tiles::unproject(inv, viewport, centre, 0.5);
    let dir = far - near;
    near + dir * (-near.y / dir.y)
}

/// Which culling test the tiled graph runs, by its features.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Culling {
    /// `!tile_box,!tile_depth_mask`: the frustum slab's six planes.
    Slab,
    /// The default: the box around the tile's surface points and the 2.5D depth mask.
    SurfaceBoxAndDepthMask,
}

/// Slices of slack for rounding differences between the GPU's and the CPU's
/// eye distances.
const SLICE_SLACK: f32 = 0.05;

/// Renders the known scene with the heat map under `culling` and checks every
/// tile's count against the CPU mirror; returns the rendered frame, the
/// largest tile count and the sum over tiles.
fn check_tile_counts(culling: Culling) -> (weft_render::Rendered, u32, u32) {
    let (w, h) = (320u32, 180u32);
    let dir = scratch(&format!("heatmap-{culling:?}"));
    let path = known_scene(&dir);
    let scene = weft_scene::load_scene(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let mut features: Vec<String> = vec!["light_heatmap".into(), "!bloom".into()];
    if culling == Culling::Slab {
        features.extend(["!tile_box".into(), "!tile_depth_mask".into()]);
    }
    let settings = RenderSettings {
        graph: graph("tiled.ron"),
        extent: Extent {
            width: w,
            height: h,
        },
        features,
        extra_readback: vec!["light_counts".into()],
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).unwrap();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let counts = rendered.report.readbacks[0].1.to_rgba8();
    assert_eq!(rendered.report.readbacks[0].0, "light_counts");
    let count_at = |x: u32, y: u32| {
        let [r, g, b, _] = counts.get_pixel(x, y).0;
        u32::from(r) + 256 * u32::from(g) + 65536 * u32::from(b)
    };

    // The CPU mirror of the culling test: the floor's depth at the tile's
    // corner pixel centres bounds the slab (depth on a plane is affine on
    // screen); the floor under each pixel centre gives the surface points.
    let camera = &scene.cameras[0];
    let view_proj = camera.view_projection(0.0, w as f32 / h as f32);
    let inv = view_proj.inverse();
    let eye = camera.pose_at(0.0).0;
    let viewport = Vec2::new(w as f32, h as f32);
    let (tiles_x, tiles_y) = tiles::tile_grid(w, h);
    let (mut ambiguous, mut most, mut zero, mut tighter, mut total) = (0, 0, 0, 0, 0);
    // Each spot's length ball, which culling by the cone improves on.
    let spot_balls: Vec<(Vec3, f32)> = KNOWN_SPOTS
        .iter()
        .map(|(apex, _, _, length)| (Vec3::from(*apex), *length))
        .collect();
    for ty in 0..tiles_y {
        for tx in 0..tiles_x {
            let (x0, y0) = (tx * 16, ty * 16);
            let (x1, y1) = ((x0 + 15).min(w - 1), (y0 + 15).min(h - 1));
            let centre_of = |x: u32, y: u32| Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let depths = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
                .map(|(x, y)| floor_depth(view_proj, inv, viewport, centre_of(x, y)));
            let nearest = depths.iter().copied().fold(f32::MIN, f32::max);
            let farthest = depths.iter().copied().fold(f32::MAX, f32::min);
            let slab = tiles::TileSlab::new(inv, eye, viewport, (tx, ty), nearest, farthest);
            let points: Vec<Vec3> = (y0..=y1)
                .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
                .map(|(x, y)| floor_point(inv, viewport, centre_of(x, y)))
                .collect();
            let surface = tiles::TileSurface::new(&points, eye).unwrap();
            let (sure_mask, maybe_mask) = (
                surface.depth_mask(&points, -SLICE_SLACK),
                surface.depth_mask(&points, SLICE_SLACK),
            );
            // (surely listed, maybe listed) for a sphere.
            let listed = |centre: Vec3, radius: f32| match culling {
                Culling::Slab => {
                    let margin = slab.margin(centre, radius);
                    (margin < -1e-3, margin <= 1e-3)
                }
                Culling::SurfaceBoxAndDepthMask => {
                    let margin = surface.box_margin(centre, radius);
                    let sure = surface.sphere_slices(centre, radius, -SLICE_SLACK) & sure_mask;
                    let maybe = surface.sphere_slices(centre, radius, SLICE_SLACK) & maybe_mask;
                    (margin < -1e-3 && sure != 0, margin <= 1e-3 && maybe != 0)
                }
            };
            let decisions: Vec<(bool, bool)> = known_bounds()
                .iter()
                .map(|(centre, radius)| listed(*centre, *radius))
                .collect();
            let sure = decisions.iter().filter(|d| d.0).count() as u32;
            let maybe = decisions.iter().filter(|d| d.1).count() as u32;
            ambiguous += u32::from(sure != maybe);
            // Every pixel of the tile holds the tile's count.
            let gpu_count = count_at(x0, y0);
            assert_eq!(count_at(x1, y1), gpu_count, "{culling:?} tile ({tx}, {ty})");
            assert!(
                (sure..=maybe).contains(&gpu_count),
                "{culling:?} tile ({tx}, {ty}): GPU {gpu_count}, CPU {sure}..={maybe} ({decisions:?})"
            );
            let by_balls = KNOWN_LIGHTS
                .iter()
                .map(|(p, r)| (Vec3::from(*p), *r))
                .chain(spot_balls.iter().copied())
                .filter(|(centre, radius)| listed(*centre, *radius).0)
                .count() as u32;
            tighter += u32::from(gpu_count < by_balls);
            most = most.max(gpu_count);
            total += gpu_count;
            zero += u32::from(gpu_count == 0);
        }
    }
    eprintln!(
        "{culling:?}: {ambiguous} ambiguous tiles, most lights {most}, {zero} empty tiles, \
         {tighter} tiles list fewer lights than the spots' length balls would"
    );
    assert!(tighter > 0, "{culling:?}: spots are culled by their cones");
    assert!(
        ambiguous * 50 <= tiles_x * tiles_y,
        "{culling:?}: {ambiguous} ambiguous tiles"
    );
    assert!(
        most >= 3,
        "{culling:?}: overlapping lights give tiles with several lights"
    );
    assert!(
        zero > 0,
        "{culling:?}: tiles far from every light list none"
    );
    (rendered, most, total)
}

#[test]
fn the_slab_test_counts_as_its_cpu_mirror_and_lists_more_than_the_surface_tests() {
    let (_, _, slab) = check_tile_counts(Culling::Slab);
    let (_, _, surface) = check_tile_counts(Culling::SurfaceBoxAndDepthMask);
    eprintln!("tile list entries: slab {slab}, surface box and depth mask {surface}");
    assert!(surface * 4 < slab * 3, "slab {slab}, surface {surface}");
}

#[test]
fn the_heat_map_counts_known_lights_per_tile_and_draws_its_legend() {
    let h = 180u32;
    let (rendered, most, _) = check_tile_counts(Culling::SurfaceBoxAndDepthMask);

    // The legend, bottom-left: a black box, the colour bar, labels 0, max / 2, max.
    let image = rendered.report.output.expect("readback");
    let at = |x: i32, y: i32| image.rgba8_at(x as u32, h - 1 - y as u32);
    let bar = 80; // clamp(width / 4, 64, 256)
                  // The scale is the frame's largest tile count.
    weft_tests::legend::assert_legend(at, bar, [0, most / 2, most]);
}
