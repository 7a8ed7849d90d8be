//! Helpers for the tests that render scenes: scenes rendered through shipped
//! graphs on a validating context, and image agreement measured in 8-bit units.

use image::RgbaImage;
use std::path::{Path, PathBuf};
use weft_gpu::ValidationMessage;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};

/// The repository root.
pub fn root() -> PathBuf {
    crate::repo()
}

/// The project's demo scene.
pub fn demo_scene() -> PathBuf {
    root().join("scenes/demo.scene")
}

/// The 15-462 `cube.scene`, read in place from the shared assets.
pub fn cube_scene() -> PathBuf {
    root().join("../shared/assets/462/scenes/cube.scene")
}

/// A glTF model (FlightHelmet: metallic-roughness textures) under every light type.
pub fn gltf_scene() -> PathBuf {
    root().join("scenes/flight_helmet.scene")
}

/// A shipped graph.
pub fn graph(name: &str) -> PathBuf {
    root().join("graphs").join(name)
}

/// `text` of a shipped graph with its fragment and shader paths made absolute,
/// so a copy written elsewhere finds them.
pub fn absolute_paths(text: &str) -> String {
    let graphs = root().join("graphs");
    let mut text = text.to_string();
    // Every graph file beside the shipped ones may be included by name.
    let fragments = std::fs::read_dir(&graphs)
        .expect("graphs/")
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".ron"));
    for fragment in fragments {
        text = text.replace(
            &format!("(file: \"{fragment}\""),
            &format!("(file: \"{}\"", graphs.join(fragment).display()),
        );
    }
    text.replace(
        "\"../shaders/",
        &format!("\"{}/", root().join("shaders").display()),
    )
}

/// What one validated render produced.
pub struct Output {
    pub image: RgbaImage,
    /// Every validation message, creation and destruction included.
    pub messages: Vec<ValidationMessage>,
    /// Passes that ran, in order.
    pub passes: Vec<String>,
    pub draw_calls: u64,
    /// Per view: (name, meshes drawn, meshes culled by the view's frustum).
    pub culling: Vec<(String, u64, u64)>,
}

/// Renders `scene` through `graph` at `width`x`height` with validation and
/// synchronization validation on.
pub fn render_validated(
    scene: &Path,
    graph: &Path,
    width: u32,
    height: u32,
    features: &[&str],
) -> Output {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = crate::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: graph.to_path_buf(),
        extent: Extent { width, height },
        features: features.iter().map(|f| f.to_string()).collect(),
        ..RenderSettings::default()
    };
    let rendered = match render(&gpu, &scene, &settings) {
        Ok(r) => r,
        Err(e) => panic!("render failed: {e}"),
    };
    drop(gpu);
    Output {
        image: rendered.report.output.expect("readback").to_rgba8(),
        messages: log.messages(),
        passes: rendered
            .plan
            .passes
            .iter()
            .map(|p| p.name.clone())
            .collect(),
        draw_calls: rendered.draw_calls,
        culling: rendered
            .culling
            .iter()
            .map(|c| (c.view.clone(), c.drawn, c.culled))
            .collect(),
    }
}

/// Agreement of two images over their RGB channels, in 8-bit units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Agreement {
    pub mean: f64,
    pub p99: u8,
    pub max: u8,
}

/// Mean, 99th percentile and maximum of the absolute RGB channel differences.
pub fn agreement(a: &RgbaImage, b: &RgbaImage) -> Agreement {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut diffs: Vec<u8> = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p.0[c].abs_diff(q.0[c])))
        .collect();
    diffs.sort_unstable();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len().max(1) as f64;
    let p99 = diffs
        .get((diffs.len() * 99).div_ceil(100).saturating_sub(1))
        .copied()
        .unwrap_or(0);
    Agreement {
        mean,
        p99,
        max: diffs.last().copied().unwrap_or(0),
    }
}

/// Writes a 2x2 quad at z = 0 facing a camera at z = 3, with material
/// `material` (MTL statements), lit head-on by a unit white sun with no
/// ambient; returns the scene file.
pub fn write_quad_scene(dir: &Path, material: &str) -> PathBuf {
    std::fs::create_dir_all(dir).expect("temp dir");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nusemtl quad\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(dir.join("quad.mtl"), format!("newmtl quad\n{material}")).expect("mtl");
    let scene = dir.join("quad.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"quad.obj\"\n}\nsunlight\n{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n\tambient 0\n}\ncamera \"front\"\n{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 40\n}\n",
    )
    .expect("scene");
    scene
}

/// The HDR value (RGBA) at the centre of a 16x16 render of `scene` through the
/// shipped `graph`, bloom off, with `params` set; asserts no validation message.
pub fn centre_hdr(
    scene: &Path,
    graph: &str,
    params: std::collections::BTreeMap<String, weft_graph::schema::ParamValue>,
) -> [f32; 4] {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = crate::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: self::graph(graph),
        extent: Extent {
            width: 16,
            height: 16,
        },
        features: vec!["!bloom".into()],
        extra_readback: vec!["hdr".into()],
        params,
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let (_, hdr) = &rendered.report.readbacks[0];
    let weft_gpu::Pixels::RgbaF32(values) = &hdr.pixels else {
        panic!("hdr is float");
    };
    let at = (8 * 16 + 8) * 4;
    [values[at], values[at + 1], values[at + 2], values[at + 3]]
}

/// Settings for a `size` x `size` render of shipped graph `graph` with
/// feature toggles, graph parameters and, with `samples`, a progressive render
/// to that many samples per pixel.
pub fn square_settings(
    graph: &str,
    size: u32,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
) -> RenderSettings {
    RenderSettings {
        graph: crate::shipped(graph),
        extent: Extent {
            width: size,
            height: size,
        },
        features: features.iter().map(|f| f.to_string()).collect(),
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), weft_graph::schema::ParamValue::Number(*v)))
            .collect(),
        samples,
        ..RenderSettings::default()
    }
}

/// Renders `scene` with `settings` and `hdr` read back, on a validating
/// context; asserts no validation message and returns the render and the
/// `hdr` image as RGBA floats, row by row.
pub fn render_hdr_validated(
    scene: &Path,
    settings: RenderSettings,
) -> (weft_render::Rendered, Vec<f32>) {
    render_image_validated(scene, settings, "hdr")
}

/// [`render_hdr_validated`] reading back the float image `image`.
pub fn render_image_validated(
    scene: &Path,
    mut settings: RenderSettings,
    image: &str,
) -> (weft_render::Rendered, Vec<f32>) {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = crate::gpu();
    let log = gpu.validation();
    settings.extra_readback = vec![image.into()];
    settings.readback_asked = true;
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{}", settings.graph.display());
    let (_, read) = &rendered.report.readbacks[0];
    let weft_gpu::Pixels::RgbaF32(values) = &read.pixels else {
        panic!("{image} is a float image");
    };
    let values = values.clone();
    (rendered, values)
}

/// A test fixture graph (`tests/graphs/NAME`) run once at 8x8 over the
/// Cornell box with `params`, on a validating context: its float output and
/// its float image `readback`, as RGBA floats row by row.
pub fn fixture_floats(
    name: &str,
    readback: &str,
    params: std::collections::BTreeMap<String, weft_graph::schema::ParamValue>,
) -> (Vec<f32>, Vec<f32>) {
    let settings = RenderSettings {
        graph: crate::graph(name),
        extent: Extent {
            width: 8,
            height: 8,
        },
        params,
        ..RenderSettings::default()
    };
    let (rendered, read) =
        render_image_validated(&root().join("scenes/cornell.scene"), settings, readback);
    let output = rendered.report.output.expect("the fixture's output");
    let weft_gpu::Pixels::RgbaF32(values) = output.pixels else {
        panic!("{name}: the output is a float image");
    };
    (values, read)
}

/// [`render_image_validated`] as a linear RGB image, its size taken from
/// `settings`.
pub fn linear_image_validated(
    scene: &Path,
    settings: RenderSettings,
    image: &str,
) -> weft_compare::LinearImage {
    let (width, height) = (settings.extent.width, settings.extent.height);
    let (_, values) = render_image_validated(scene, settings, image);
    weft_compare::LinearImage {
        width,
        height,
        pixels: values.chunks(4).map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

/// [`square_settings`] with bloom off, as the comparisons against the path
/// tracer want it (the reference models no post effects).
pub fn square_settings_without_bloom(
    graph: &str,
    size: u32,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
) -> RenderSettings {
    let features: Vec<&str> = ["!bloom"]
        .into_iter()
        .chain(features.iter().copied())
        .collect();
    square_settings(graph, size, samples, params, &features)
}

/// Whether pixel (`x`, `y`) of `image` (not on its border) lies away from
/// edges: no pixel of its 3 x 3 neighbourhood differs from it in RGB sum by
/// more than `tolerance` times its own. Comparisons of raster images, whose
/// pixels are sampled at their centres, against the path tracer's
/// box-filtered ones keep to such pixels.
pub fn flat_at(image: &weft_compare::LinearImage, x: u32, y: u32, tolerance: f64) -> bool {
    let sum = |x: u32, y: u32| {
        let p = image.pixels[(y * image.width + x) as usize];
        f64::from(p[0] + p[1] + p[2])
    };
    let centre = sum(x, y);
    (y - 1..=y + 1)
        .flat_map(|ny| (x - 1..=x + 1).map(move |nx| (nx, ny)))
        .all(|(nx, ny)| (sum(nx, ny) - centre).abs() <= tolerance * centre)
}
