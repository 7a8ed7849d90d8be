//! One physics, case by case (issue 32): every light type (sun, point, spot,
//! rectangle, disc, emissive quad) over every shading model (Lambert and
//! glossy Blinn-Phong from MTL, GGX dielectric and metal from glTF), in
//! every raster graph, against the path tracer's direct light
//! (`max_depth=2`). A 2 x 2 quad filling the camera's view takes the light;
//! nothing shadows it and no light is in view, so what raster and reference
//! share is the physics, and what differs is technique: the area lights'
//! analytic integration (LTC) and the reference's noise. Held to the mean
//! within 2% and HDR-FLIP at most 0.05, but for the GGX metal under area
//! lights, where LTC's fitted tails show (`ltc_tail`): there the 16 x 16
//! quadrature is held to those bounds, and LTC to 4% and 0.35.

use std::path::{Path, PathBuf};
use weft_compare::{hdr_flip, LinearImage};
use weft_tests::gltf::write_gltf_quad;
use weft_tests::TempDir;

const SIZE: u32 = 32;

/// A shading model as the quad's file states it.
enum Model {
    Mtl(&'static str),
    Gltf(&'static str),
}

const MODELS: [(&str, Model); 4] = [
    ("Lambert", Model::Mtl("Kd 0.7 0.6 0.5\nKs 0 0 0")),
    (
        "Blinn-Phong",
        Model::Mtl("Kd 0.5 0.4 0.3\nKs 0.3 0.3 0.3\nNs 30"),
    ),
    (
        "GGX dielectric",
        Model::Gltf(
            r#""baseColorFactor": [0.7, 0.6, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.5"#,
        ),
    ),
    (
        "GGX metal",
        Model::Gltf(
            r#""baseColorFactor": [0.9, 0.6, 0.3, 1], "metallicFactor": 1, "roughnessFactor": 0.4"#,
        ),
    ),
];

/// The lights, as `.scene` blocks (the emissive quad as an OBJ of its own),
/// in front of the quad at z = 0 and out of the camera's view, so only the
/// light they give is compared, not their panels' edges.
const LIGHTS: [(&str, &str); 6] = [
    ("sun", "sunlight\n{\n\tdirection -0.3 -0.2 -1\n\tcolor 0.8 0.8 0.8\n}\n"),
    (
        "point",
        "pointlight\n{\n\tposition 0.3 0.4 1.2\n\tcolor 1 1 1\n\tattenuation 1 0 1\n\tradius 8\n}\n",
    ),
    (
        "spot",
        "spotlight\n{\n\tposition -0.2 0.1 1.6\n\tdirection 0.1 0 -1\n\tcolor 2 2 2\n\tangle 35\n\texponent 4\n\tattenuation 1 0 0\n\tlength 8\n}\n",
    ),
    (
        "rectangle",
        "arealight\n{\n\tshape rect\n\tsize 0.6 0.4\n\tposition 0 1 0.9\n\tdirection 0 -1 -0.9\n\temission 3 3 3\n}\n",
    ),
    (
        "disc",
        "arealight\n{\n\tshape disc\n\tsize 0.5 0.5\n\tposition 0.9 -0.5 0.8\n\tdirection -0.9 0.5 -0.8\n\temission 3 3 3\n}\n",
    ),
    ("emissive quad", "model\n{\n\tfile \"emitter.obj\"\n}\n"),
];

/// Writes the scene of `model` lit by `light` into `dir`.
fn scene(dir: &Path, model: &Model, light: &str) -> PathBuf {
    let file = match model {
        Model::Mtl(statements) => {
            std::fs::write(
                dir.join("quad.obj"),
                "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nusemtl surface\n\
                 f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
            )
            .expect("obj");
            std::fs::write(
                dir.join("quad.mtl"),
                format!("newmtl surface\n{statements}\n"),
            )
            .expect("mtl");
            "quad.obj"
        }
        Model::Gltf(material) => {
            write_gltf_quad(dir, material, &[]);
            "quad.gltf"
        }
    };
    // A 0.5 x 0.5 emitter at y = 1 facing down, above and in front of the quad.
    std::fs::write(
        dir.join("emitter.obj"),
        "mtllib emitter.mtl\nv -0.25 1 0.3\nv 0.25 1 0.3\nv 0.25 1 0.8\nv -0.25 1 0.8\nvn 0 -1 0\nusemtl glow\n\
         f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("emitter.mtl"),
        "newmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 4 4 4\n",
    )
    .expect("mtl");
    let path = dir.join("matrix.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"{file}\"\n}}\n{light}\
             camera\n{{\n\tposition 0.15 0.1 1.6\n\ttarget 0 0 0\n\tfov_deg 45\n}}\n"
        ),
    )
    .expect("scene");
    path
}

/// The HDR image of `scene` through `graph` (to `samples` per pixel for the
/// path tracer), validated, bloom off.
fn render(scene: &Path, graph: &str, samples: Option<u64>, params: &[(&str, f64)]) -> LinearImage {
    let settings = weft_tests::render::square_settings(graph, SIZE, samples, params, &["!bloom"]);
    let (_, values) = weft_tests::render::render_hdr_validated(scene, settings);
    LinearImage {
        width: SIZE,
        height: SIZE,
        pixels: values.chunks(4).map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

fn mean(image: &LinearImage) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in &image.pixels {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    sum.map(|s| s / image.pixels.len() as f64)
}

/// Whether the analytic area-light integration meets its known limit here:
/// LTC fits a GGX lobe with a warped cosine, whose tails are off by a few
/// percent of the lobe (docs/lights.md), and a metal shows little else.
fn ltc_tail(light: &str, model: &str) -> bool {
    model == "GGX metal" && !matches!(light, "sun" | "point" | "spot")
}

#[test]
fn every_light_and_shading_model_matches_the_direct_light_reference_in_every_raster_graph() {
    let mut failures = Vec::new();
    let mut check =
        |what: String, image: &LinearImage, reference: &LinearImage, bounds: (f64, f64)| {
            let (got, want) = (mean(image), mean(reference));
            let ratio = (0..3)
                .map(|c| got[c] / want[c].max(1e-9))
                .fold(1.0f64, |worst, r| {
                    if (r - 1.0).abs() > (worst - 1.0).abs() {
                        r
                    } else {
                        worst
                    }
                });
            let flip = hdr_flip(reference, image).mean;
            println!("{what}: mean ratio {ratio:.4}, HDR-FLIP {flip:.4}");
            if (ratio - 1.0).abs() > bounds.0 || flip > bounds.1 {
                failures.push(format!("{what}: mean ratio {ratio:.4}, HDR-FLIP {flip:.4}"));
            }
        };
    for (light_name, light) in LIGHTS {
        for (model_name, model) in &MODELS {
            let dir = TempDir::new(&format!("matrix-{light_name}-{model_name}").replace(' ', "_"));
            let scene = scene(&dir.0, model, light);
            let reference = render(&scene, "pathtrace.ron", Some(256), &[("max_depth", 2.0)]);
            // Measured: GGX metal under area lights with LTC, mean within
            // 3.3% and HDR-FLIP up to 0.32; by quadrature within 0.5% and 0.02.
            let bounds = if ltc_tail(light_name, model_name) {
                let quadrature = render(&scene, "forward.ron", None, &[("area_samples", 16.0)]);
                let what = format!("{light_name} x {model_name} x forward.ron, 16 x 16 quadrature");
                check(what, &quadrature, &reference, (0.02, 0.05));
                (0.04, 0.35)
            } else {
                (0.02, 0.05)
            };
            for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
                let image = render(&scene, graph, None, &[]);
                check(
                    format!("{light_name} x {model_name} x {graph}"),
                    &image,
                    &reference,
                    bounds,
                );
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
