//! A mirrored instance (negative scale) must shade like the mirror image of its
//! unmirrored twin: the winding, `gl_FrontFacing` and the normal transform all
//! follow the sign of the model matrix's determinant.

use weft_tests::render as common;

use common::{agreement, graph, render_validated, root};
use image::RgbaImage;
use std::path::{Path, PathBuf};

/// The bunny (asymmetric in x) under a sun and a camera that are both symmetric
/// about the x = 0 plane, scaled by `scale_x` in x.
fn bunny_scene(dir: &Path, name: &str, scale_x: f32) -> PathBuf {
    let bunny = root().join("../shared/assets/462/scenes/models/bunny.obj");
    let text = format!(
        "model\n{{\n\tfile \"{}\"\n\tposition 0 -0.7 0\n\tscale {} 0.09 0.09\n}}\nsunlight\n{{\n\tdirection 0 -0.6 -1\n\tcolor 1 1 1\n\tambient 0.02\n}}\ncamera \"front\"\n{{\n\tposition 0 0 3.2\n\ttarget 0 0 0\n\tfov_deg 40\n}}\n",
        bunny.display(),
        0.09 * scale_x
    );
    let path = dir.join(name);
    std::fs::write(&path, text).expect("scene");
    path
}

fn flipped(image: &RgbaImage) -> RgbaImage {
    image::imageops::flip_horizontal(image)
}

#[test]
fn a_mirrored_model_is_the_mirror_image_of_its_twin() {
    let dir = std::env::temp_dir().join(format!("weft-mirrored-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let plain = bunny_scene(&dir, "plain.scene", 1.0);
    let mirrored = bunny_scene(&dir, "mirrored.scene", -1.0);
    for graph_file in ["forward.ron", "deferred.ron"] {
        let a = render_validated(&plain, &graph(graph_file), 96, 96, &["!bloom"]);
        let b = render_validated(&mirrored, &graph(graph_file), 96, 96, &["!bloom"]);
        assert!(a.messages.is_empty(), "{:?}", a.messages);
        assert!(b.messages.is_empty(), "{:?}", b.messages);
        let lit = a.image.pixels().filter(|p| p.0[0] > 40).count();
        assert!(lit > 1000, "{graph_file}: the bunny is lit ({lit} pixels)");
        let found = agreement(&a.image, &flipped(&b.image));
        eprintln!("{graph_file}: mirrored vs flipped twin {found:?}");
        assert!(
            found.mean <= 0.05 && found.p99 <= 1,
            "{graph_file}: mirrored bunny differs from the flipped twin: {found:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
