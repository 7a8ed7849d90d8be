//! Ray-traced specular (graphs/rt_specular.ron, feature `rt_specular`): the
//! deferred and tiled graphs trace what mirrors and glass send to the camera
//! along their delta lobes, ending in the direct light of the first diffuse
//! surface. A scene built so that nothing else reaches the camera there: a
//! white back wall lit by a sun (no ambient sky), a black mirror floor
//! (`Kd 0`, `Ks 1`, `illum 3`) and a clear glass ball. The only diffuse
//! surface is one plane, which cannot light itself, and the mirror and glass
//! have no diffuse part, so with at most four segments the path tracer's
//! light at the mirror and glass pixels is exactly the light of delta chains
//! ending in the sun's direct light at the wall: what `rt_specular` traces.
//! So at those pixels the raster image equals the reference in expectation
//! (its Blinn-Phong highlight of `Ks 1` left out), and at the same number of
//! paths it is no noisier than the path tracer drawing independent random
//! numbers as it does (feature `independent_sampler`). A glossy floor (Blinn-Phong,
//! `Kd 0`) under the same wall reflects it through its lobe: the sun's
//! highlight is the raster passes', the wall's light the traced ray's, and
//! together they are the path tracer's image at three segments.

use std::path::{Path, PathBuf};
use weft_compare::LinearImage;
use weft_tests::TempDir;

const SIZE: u32 = 64;
const MAX_DEPTH: f64 = 4.0;

/// The scene described above, written to `dir` (the glass ball's model
/// copied beside it); `floor` is the floor's material.
fn scene(dir: &Path, floor: &str) -> PathBuf {
    let models = weft_tests::repo().join("scenes/models");
    for file in ["glass_sphere.obj", "glass_sphere.mtl"] {
        std::fs::copy(models.join(file), dir.join(file)).expect("glass ball model");
    }
    std::fs::write(
        dir.join("room.mtl"),
        "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\n\
         newmtl mirror\nKd 0 0 0\nKs 1 1 1\nillum 3\n\
         newmtl glossy\nKd 0 0 0\nKs 0.8 0.8 0.8\nNs 40\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("room.obj"),
        "mtllib room.mtl\n\
         v -4 -1 -1.5\nv 4 -1 -1.5\nv 4 4 -1.5\nv -4 4 -1.5\n\
         v -2 0 2\nv 2 0 2\nv 2 0 -1.4\nv -2 0 -1.4\n\
         usemtl white\nf 1 2 3\nf 1 3 4\n\
         usemtl FLOOR\nf 5 6 7\nf 5 7 8\n"
            .replace("FLOOR", floor),
    )
    .expect("obj");
    let path = dir.join("room.scene");
    std::fs::write(
        &path,
        "model\n{\n\tfile \"room.obj\"\n}\n\
         model\n{\n\tfile \"glass_sphere.obj\"\n\tposition 0.4 1 -0.6\n\tscale 0.5\n}\n\
         sunlight\n{\n\tdirection -1 -0.6 -0.7\n\tcolor 0.6 0.6 0.6\n\tambient 0 0 0\n}\n\
         camera\n{\n\tposition 0 1.1 4\n\ttarget 0 0.7 0\n\tfov_deg 45\n}\n",
    )
    .expect("scene");
    path
}

/// Image `image` of `scene` through shipped `graph` (one frame, bloom off),
/// validated.
fn render(
    scene: &Path,
    graph: &str,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
    image: &str,
) -> LinearImage {
    let mut settings =
        weft_tests::render::square_settings_without_bloom(graph, SIZE, samples, params, features);
    settings.frame_time = 0.0;
    weft_tests::render::linear_image_validated(scene, settings, image)
}

fn luminance(p: [f32; 3]) -> f64 {
    f64::from(p[0] + p[1] + p[2])
}

/// The pixels `rt_specular` lit that lie away from the reference's edges
/// (`flat_at`, within a fifth), so the reference's box-filtered edges, which
/// the pixel-centre paths of the raster graph do not average, do not count.
fn traced_interior(traced: &LinearImage, reference: &LinearImage) -> Vec<usize> {
    let (w, h) = (reference.width, reference.height);
    let lit = |i: usize| luminance(traced.pixels[i]) > 0.0 && luminance(reference.pixels[i]) > 0.0;
    (1..h - 1)
        .flat_map(|y| (1..w - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            lit((y * w + x) as usize) && weft_tests::render::flat_at(reference, x, y, 0.2)
        })
        .map(|(x, y)| (y * w + x) as usize)
        .collect()
}

/// Root-mean-square difference of `a` from `b` over `pixels`, relative to
/// `b`'s mean there.
fn relative_rmse(a: &LinearImage, b: &LinearImage, pixels: &[usize]) -> f64 {
    let (mut squares, mut mean) = (0.0, 0.0);
    for &i in pixels {
        squares += (luminance(a.pixels[i]) - luminance(b.pixels[i])).powi(2);
        mean += luminance(b.pixels[i]);
    }
    let n = pixels.len() as f64;
    (squares / n).sqrt() / (mean / n)
}

#[test]
fn mirrors_and_glass_equal_the_path_tracers_delta_chains() {
    let dir = TempDir::new("rt-specular");
    let scene = scene(&dir.0, "mirror");
    let depth = [("max_depth", MAX_DEPTH)];
    let reference = render(&scene, "pathtrace.ron", Some(1024), &depth, &[], "hdr");
    let traced_16 = render(
        &scene,
        "pathtrace.ron",
        Some(16),
        &depth,
        &["independent_sampler"],
        "hdr",
    );
    let mut report = Vec::new();
    for graph in ["deferred.ron", "tiled.ron"] {
        let features = ["rt_specular", "rt_shadows"];
        let params = |rays: f64| {
            [
                ("rt_specular.rays", rays),
                ("rt_specular.frames", 1.0),
                ("rt_specular.max_depth", MAX_DEPTH),
            ]
        };
        let traced = render(
            &scene,
            graph,
            None,
            &params(256.0),
            &features,
            "rt_specular",
        );
        let lit = render(&scene, graph, None, &params(256.0), &features, "hdr");
        let lit_16 = render(&scene, graph, None, &params(16.0), &features, "hdr");
        let pixels = traced_interior(&traced, &reference);
        // Mirror pixels lie below the ball on screen, glass pixels above the
        // mirror's far edge: both must be there.
        let mirror = pixels.iter().filter(|&&i| i / SIZE as usize > 40).count();
        let glass = pixels.iter().filter(|&&i| i / SIZE as usize <= 34).count();
        let sum = |image: &LinearImage| {
            pixels
                .iter()
                .map(|&i| luminance(image.pixels[i]))
                .sum::<f64>()
        };
        let ratio = sum(&lit) / sum(&reference);
        let error = relative_rmse(&lit, &reference, &pixels);
        // Noise at 16 paths, each against its own converged image: the
        // raster graph's paths start at pixel centres, the reference's
        // anywhere in the pixel.
        let (noise_16, path_tracer_16) = (
            relative_rmse(&lit_16, &lit, &pixels),
            relative_rmse(&traced_16, &reference, &pixels),
        );
        report.push(format!(
            "{graph}: {} pixels ({mirror} below the ball, {glass} above the mirror), mean ratio {ratio:.4}, \
             rel. RMSE {error:.4} at 256 paths; noise at 16: {noise_16:.4}, path tracer's {path_tracer_16:.4}",
            pixels.len()
        ));
        assert!(mirror > 100 && glass > 50, "{report:#?}");
        assert!((ratio - 1.0).abs() < 0.01, "{report:#?}");
        assert!(error < 0.05, "{report:#?}");
        assert!(noise_16 < 1.1 * path_tracer_16, "{report:#?}");
    }
    println!("{report:#?}");
}

#[test]
fn a_glossy_floor_reflects_the_scene_as_the_path_tracer_does() {
    let dir = TempDir::new("rt-glossy");
    let scene = scene(&dir.0, "glossy");
    // Floor, wall, sun: three segments hold every path from the floor.
    let reference = render(
        &scene,
        "pathtrace.ron",
        Some(1024),
        &[("max_depth", 3.0)],
        &[],
        "hdr",
    );
    let mut report = Vec::new();
    for graph in ["deferred.ron", "tiled.ron"] {
        let params = [("rt_specular.rays", 256.0), ("rt_specular.frames", 1.0)];
        let traced = render(
            &scene,
            graph,
            None,
            &params,
            &["rt_specular", "rt_shadows"],
            "rt_specular",
        );
        let lit = render(
            &scene,
            graph,
            None,
            &params,
            &["rt_specular", "rt_shadows"],
            "hdr",
        );
        let raster = render(&scene, graph, None, &[], &["rt_shadows"], "hdr");
        // The floor below the ball, where it reflects the wall.
        let pixels: Vec<usize> = traced_interior(&traced, &reference)
            .into_iter()
            .filter(|&i| i / SIZE as usize > 40)
            .collect();
        let sum = |image: &LinearImage| {
            pixels
                .iter()
                .map(|&i| luminance(image.pixels[i]))
                .sum::<f64>()
        };
        let (ratio, without) = (sum(&lit) / sum(&reference), sum(&raster) / sum(&reference));
        let error = relative_rmse(&lit, &reference, &pixels);
        report.push(format!(
            "{graph}: {} floor pixels, mean ratio {ratio:.4} (raster alone {without:.4}), rel. RMSE {error:.4}",
            pixels.len()
        ));
        assert!(pixels.len() > 300, "{report:#?}");
        assert!(without < 0.8, "{report:#?}");
        assert!((ratio - 1.0).abs() < 0.015, "{report:#?}");
        assert!(error < 0.1, "{report:#?}");
    }
    println!("{report:#?}");
}
