//! The world-space radiance cache (graphs/radiance_cache.ron, feature
//! `radiance_cache` of the deferred graph): inside a closed sphere of
//! Lambertian albedo rho lit by a point light at its centre, every point
//! gets the same direct irradiance E, and the light of every bounce adds up
//! to radiance rho E / (pi (1 - rho)): the image with the cache is the
//! direct-only image times 1 / (1 - rho), which the cache reaches within 1%
//! once its bounces have accumulated (160 frames; 1.6% short at 64, as each
//! frame adds a bounce and a cell averages its last 16 updates). A block
//! moved away takes its bounce light with it at once (the sweep empties the
//! cells that see where it was), and `budget` bounds the cells updated a
//! frame exactly.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use weft_compare::LinearImage;
use weft_tests::TempDir;

const SIZE: u32 = 32;
const ALBEDO: f32 = 0.5;

/// A unit sphere (`rings` x `segments` quads), wound to face its centre,
/// of albedo ALBEDO, with a point light and the camera at the centre.
fn furnace(dir: &Path) -> PathBuf {
    let (rings, segments) = (24, 48);
    let mut obj = String::from("mtllib sphere.mtl\nusemtl grey\n");
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * PI * s as f32 / segments as f32;
            obj += &format!(
                "v {} {} {}\n",
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin()
            );
        }
    }
    for r in 0..rings {
        for s in 0..segments {
            let at = |r: usize, s: usize| 1 + r * segments + s % segments;
            // Counter-clockwise seen from the centre.
            obj += &format!(
                "f {} {} {}\nf {} {} {}\n",
                at(r, s),
                at(r, s + 1),
                at(r + 1, s + 1),
                at(r, s),
                at(r + 1, s + 1),
                at(r + 1, s)
            );
        }
    }
    std::fs::write(dir.join("sphere.obj"), obj).expect("obj");
    std::fs::write(
        dir.join("sphere.mtl"),
        format!("newmtl grey\nKd {ALBEDO} {ALBEDO} {ALBEDO}\nKs 0 0 0\n"),
    )
    .expect("mtl");
    let path = dir.join("furnace.scene");
    std::fs::write(
        &path,
        "model\n{\n\tfile \"sphere.obj\"\n}\n\
         pointlight\n{\n\tposition 0 0 0\n\tcolor 1 1 1\n\tattenuation 1 0 0\n\tradius 10\n}\n\
         camera\n{\n\tposition 0 0 0\n\ttarget 0 -0.3 -1\n\tfov_deg 70\n}\n",
    )
    .expect("scene");
    path
}

/// The deferred graph, bloom off, with `params` and `features`, for
/// `frames` frames `frame_time` seconds apart.
fn deferred(
    params: &[(&str, f64)],
    features: &[&str],
    (frames, frame_time): (u32, f64),
) -> weft_render::RenderSettings {
    let mut settings = weft_tests::render::square_settings_without_bloom(
        "deferred.ron",
        SIZE,
        None,
        params,
        features,
    );
    settings.frames = frames;
    settings.frame_time = frame_time;
    settings
}

fn render(scene: &Path, frames: u32, features: &[&str]) -> LinearImage {
    let params = [
        ("radiance_cache.cells", 64.0),
        ("cache_cell_scale", 0.2),
        ("radiance_cache.frames", 16.0),
    ];
    let settings = deferred(&params, features, (frames, 0.0));
    weft_tests::render::linear_image_validated(scene, settings, "hdr")
}

fn mean(image: &LinearImage) -> f64 {
    let sum: f64 = image
        .pixels
        .iter()
        .map(|p| p.iter().map(|&c| f64::from(c)).sum::<f64>())
        .sum();
    sum / (3 * image.pixels.len()) as f64
}

#[test]
fn a_closed_furnace_sphere_converges_to_every_bounce() {
    let dir = TempDir::new("cache-furnace");
    let scene = furnace(&dir.0);
    let direct = mean(&render(&scene, 1, &[]));
    let cached = mean(&render(&scene, 160, &["radiance_cache"]));
    let want = 1.0 / (1.0 - f64::from(ALBEDO));
    let report = format!(
        "direct {direct:.4}, with the cache {cached:.4}: ratio {:.4}, every bounce {want:.4}",
        cached / direct
    );
    println!("{report}");
    assert!(direct > 0.1, "{report}");
    assert!((cached / direct / want - 1.0).abs() < 0.01, "{report}");
}

/// A grey floor and a red block on it under a white light; the camera looks
/// straight down at the floor beside the block, which it does not see. The
/// script takes the block away (100 units down) from time `gone_at`.
fn red_block(dir: &Path, gone_at: f64) -> PathBuf {
    std::fs::write(
        dir.join("grey.mtl"),
        "newmtl grey\nKd 0.5 0.5 0.5\nKs 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("red.mtl"),
        "newmtl red\nKd 0.9 0.05 0.05\nKs 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib grey.mtl\nusemtl grey\nv -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nvn 0 1 0\n\
         f 1//1 3//1 2//1\nf 1//1 4//1 3//1\n",
    )
    .expect("obj");
    // A 1 x 2 x 1 block, faces wound outwards, centred at the origin.
    let mut block = String::from("mtllib red.mtl\nusemtl red\n");
    for (x, y, z) in [
        (-1, -1, -1),
        (1, -1, -1),
        (1, 1, -1),
        (-1, 1, -1),
        (-1, -1, 1),
        (1, -1, 1),
        (1, 1, 1),
        (-1, 1, 1),
    ] {
        block += &format!(
            "v {} {} {}\n",
            0.5 * f64::from(x),
            f64::from(y),
            0.5 * f64::from(z)
        );
    }
    block += "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n";
    std::fs::write(dir.join("block.obj"), block).expect("obj");
    let path = dir.join(format!("block_{gone_at}.rhai"));
    std::fs::write(
        &path,
        format!(
            "model(\"floor.obj\", #{{}});\n\
             model(\"block.obj\", #{{ position: [0, 1, 0] }});\n\
             camera(\"main\", #{{ position: [2.5, 2, 0], target: [2.5, 0, 0.01] }});\n\
             point_light(#{{ position: [1, 4, 1], color: [1, 1, 1], radius: 30 }});\n\
             fn update(t, dt) {{\n    if t >= {gone_at} {{ set_model_transform(1, #{{ position: [0, -100, 0] }}); }}\n}}\n"
        ),
    )
    .expect("script");
    path
}

/// The image's red over its green, summed over the pixels.
fn red_over_green(image: &LinearImage) -> f64 {
    let sum = |c: usize| -> f64 { image.pixels.iter().map(|p| f64::from(p[c])).sum() };
    sum(0) / sum(1)
}

/// A block that moves away empties the cells that saw it: six frames after
/// it goes, the floor's light has lost its red bounce as if the block had
/// never been there (red over green 1.0000, from 1.0132), where cells left
/// alone, a running mean over 64 updates, still hold 58/64 of it (1.0119
/// with the sweep's emptying switched off).
#[test]
fn a_block_moved_away_empties_the_cells_that_saw_it() {
    let dir = TempDir::new("cache-moved");
    let frames = |scene: &Path, count: u32| {
        let params = [
            ("radiance_cache.cells", 64.0),
            ("radiance_cache.rays", 8.0),
            ("radiance_cache.frames", 64.0),
            ("cache_cell_scale", 0.2),
        ];
        let settings = deferred(&params, &["radiance_cache"], (count, 1.0 / 60.0));
        red_over_green(&weft_tests::render::linear_image_validated(
            scene, settings, "hdr",
        ))
    };
    // The block goes at frame 60 (1 s); frame 59 is the last with it.
    let moved = red_block(&dir.0, 1.0);
    let (with_block, after) = (frames(&moved, 60), frames(&moved, 66));
    let never = frames(&red_block(&dir.0, 0.0), 66);
    let report = format!(
        "red over green: with the block {with_block:.4}, six frames after it went {after:.4}, \
         without it from the start {never:.4}"
    );
    println!("{report}");
    assert!(with_block > never + 0.005, "{report}");
    assert!(
        (after - never).abs() < 0.1 * (with_block - never),
        "{report}"
    );
}

/// `budget` bounds the cells updated a frame: inside the closed furnace
/// sphere every update ray meets the sphere and makes one shadow ray towards
/// the light at its centre, so the update traces exactly 2 rays a cell
/// (`rays` 1), 2 x 16 with a budget of 16, more without one.
#[test]
fn a_budget_bounds_the_cells_updated_a_frame() {
    let dir = TempDir::new("cache-budget");
    let scene = furnace(&dir.0);
    let update_rays = |budget: f64| {
        let params = [
            ("radiance_cache.cells", 64.0),
            ("cache_cell_scale", 0.2),
            ("radiance_cache.budget", budget),
        ];
        let settings = deferred(&params, &["radiance_cache"], (8, 0.0));
        let (rendered, _) = weft_tests::render::render_hdr_validated(&scene, settings);
        let last = rendered.rays.last().expect("frames");
        last.iter()
            .find(|r| r.pass == "cache_update")
            .expect("the update traces")
            .rays
    };
    let (all, budgeted) = (update_rays(0.0), update_rays(16.0));
    assert_eq!(budgeted, 2 * 16, "every cell: {all}");
    assert!(all > 2 * 16 && all % 2 == 0, "{all}");
}
