//! Normal maps from baked tangent frames (MikkTSpace, packed into the 20-byte
//! vertex): the glTF sample models NormalTangentMirrorTest and
//! NormalTangentTest, whose designs show the same bump in every tile when
//! tangents are right, rendered forward and deferred under validation and
//! synchronization validation (zero messages).
//!
//! Tolerances (8-bit RGB units): on the mirror test, each mirrored tile ("V
//! Mirror", "U Mirror") within a mean of 4 of the unmirrored "Normal" tile of
//! its row (measured at most 3.1); the screen-space derivative frame (feature
//! `screen_space_tangents`, the shading before baked frames) differs there by a
//! mean of at least 15 in three or more tiles (measured 22.8-26.6 in six).
//! Without mirroring (NormalTangentTest) the two frames agree: mean <= 0.05,
//! max <= 4 (measured 0.001, 2).

use weft_tests::render as common;

use common::{agreement, graph, render_validated};
use image::RgbaImage;
use std::path::PathBuf;

/// A scene with `model` (a file under ../shared/assets/gltf/rise) facing a
/// camera, lit by a sun from the upper left of colour 1/pi: irradiance 1, the
/// exposure these tolerances were measured at (scenes/FORMAT.md, "Units").
fn scene(model: &str) -> (tempdir::Dir, PathBuf) {
    let dir = tempdir::Dir::new(model);
    let path = dir.0.join(format!("{model}.scene"));
    let file = common::root().join(format!("../shared/assets/gltf/rise/{model}.glb"));
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"{}\"\n}}\n\
             sunlight\n{{\n\tdirection 0.4 -0.5 -1\n\tcolor 0.31831 0.31831 0.31831\n}}\n\
             camera \"front\"\n{{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 45\n}}\n",
            file.display()
        ),
    )
    .expect("scene written");
    (dir, path)
}

mod tempdir {
    /// A scratch folder removed when dropped.
    pub struct Dir(pub std::path::PathBuf);

    impl Dir {
        pub fn new(name: &str) -> Self {
            let dir = std::env::temp_dir()
                .join(format!("weft-normal-maps-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).expect("scratch folder");
            Self(dir)
        }
    }

    impl Drop for Dir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Pixel columns and rows of the mirror test's front tiles at 480x400 from the
/// camera above: columns Geometry, Normal, V Mirror, U Mirror; five rows.
const COLUMNS: [(u32, u32); 4] = [(11, 58), (62, 109), (115, 162), (169, 216)];
const ROWS: [(u32, u32); 5] = [(47, 94), (111, 159), (176, 223), (240, 288), (305, 352)];

/// Mean RGB difference between the insides of two tiles (10 pixels in from each edge).
fn tile_difference(image: &RgbaImage, a: (u32, u32), b: (u32, u32), rows: (u32, u32)) -> f64 {
    let (mut sum, mut count) = (0u64, 0u64);
    for y in rows.0 + 10..rows.1 - 10 {
        for dx in 0..(a.1 - a.0 - 20) {
            let p = image.get_pixel(a.0 + 10 + dx, y).0;
            let q = image.get_pixel(b.0 + 10 + dx, y).0;
            for c in 0..3 {
                sum += u64::from(p[c].abs_diff(q[c]));
                count += 1;
            }
        }
    }
    sum as f64 / count as f64
}

/// Per row, the mirrored tiles' differences from the row's Normal tile.
fn mirrored_differences(image: &RgbaImage) -> Vec<f64> {
    ROWS.iter()
        .flat_map(|&rows| [2, 3].map(|c| tile_difference(image, COLUMNS[c], COLUMNS[1], rows)))
        .collect()
}

#[test]
fn mirrored_uvs_shade_like_unmirrored_ones_with_baked_frames() {
    let (_dir, path) = scene("NormalTangentMirrorTest");
    let baked = render_validated(&path, &graph("forward.ron"), 480, 400, &["!bloom"]);
    let screen = render_validated(
        &path,
        &graph("forward.ron"),
        480,
        400,
        &["!bloom", "screen_space_tangents"],
    );
    let deferred = render_validated(&path, &graph("deferred.ron"), 480, 400, &["!bloom"]);
    for out in [&baked, &screen, &deferred] {
        assert_eq!(out.messages, Vec::new());
    }
    let lit = baked.image.pixels().filter(|p| p.0[0] > 60).count();
    assert!(lit > 480 * 400 / 10, "the tiles are lit: {lit} pixels");
    let with_baked = mirrored_differences(&baked.image);
    let with_screen = mirrored_differences(&screen.image);
    eprintln!(
        "mirrored tiles against Normal: baked {with_baked:.2?}, screen-space {with_screen:.2?}"
    );
    assert!(with_baked.iter().all(|d| *d <= 4.0), "{with_baked:?}");
    let wrong = with_screen.iter().filter(|d| **d >= 15.0).count();
    assert!(
        wrong >= 3,
        "the derivative frame gets mirrored tiles wrong: {with_screen:?}"
    );
    let fd = agreement(&baked.image, &deferred.image);
    eprintln!("forward vs deferred: {fd:?}");
    assert!(fd.mean <= 0.25 && fd.p99 <= 1, "{fd:?}");
}

#[test]
fn without_mirroring_baked_and_derivative_frames_agree() {
    let (_dir, path) = scene("NormalTangentTest");
    let baked = render_validated(&path, &graph("forward.ron"), 480, 400, &["!bloom"]);
    let screen = render_validated(
        &path,
        &graph("forward.ron"),
        480,
        400,
        &["!bloom", "screen_space_tangents"],
    );
    assert_eq!(baked.messages, Vec::new());
    assert_eq!(screen.messages, Vec::new());
    let lit = baked.image.pixels().filter(|p| p.0[0] > 40).count();
    assert!(lit > 480 * 400 / 10, "the tiles are lit: {lit} pixels");
    let a = agreement(&baked.image, &screen.image);
    eprintln!("baked vs screen-space frames: {a:?}");
    assert!(a.mean <= 0.05 && a.max <= 4, "{a:?}");
}
