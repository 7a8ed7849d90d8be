//! The world-space radiance cache (graphs/radiance_cache.ron, feature
//! `radiance_cache` of the deferred graph): inside a closed sphere of
//! Lambertian albedo rho lit by a point light at its centre, every point
//! gets the same direct irradiance E, and the light of every bounce adds up
//! to radiance rho E / (pi (1 - rho)): the image with the cache is the
//! direct-only image times 1 / (1 - rho), which the cache reaches within 1%
//! once its bounces have accumulated (160 frames; 1.6% short at 64, as each
//! frame adds a bounce and a cell averages its last 16 updates).

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

fn render(scene: &Path, frames: u32, features: &[&str]) -> LinearImage {
    let params = [
        ("radiance_cache.cells", 64.0),
        ("cache_cell_scale", 0.2),
        ("radiance_cache.frames", 16.0),
    ];
    let mut settings = weft_tests::render::square_settings_without_bloom(
        "deferred.ron",
        SIZE,
        None,
        &params,
        features,
    );
    settings.frames = frames;
    settings.frame_time = 0.0;
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
