//! The path-traced reference (`graphs/pathtrace.ron`) against answers known
//! without it, every render with validation and synchronization validation on.
//!
//! - **Furnace.** Inside a closed sphere that emits radiance 1 inward, a convex
//!   object of albedo a shows exactly a (Lambert), and a mirror of Ks = 1 shows
//!   exactly 1. Every pixel is held to it at 2048 spp: within 0.025 for albedo
//!   1 and 0.0125 for albedo 0.5 (measured worst 0.0041 and 0.0020 with the
//!   Sobol sampler, 0.0158 and 0.0079 with independent numbers: the noise of
//!   NEE and BSDF samples combined), and the mean over the object within 0.1%
//!   of a (measured 0.009%, so no energy is gained or lost).
//! - **No light counted twice**: `sampling.rs`.
//! - **Raster agreement.** With direct light only (max_depth 2), the inside of
//!   a closed box lit by one point light (nothing can shadow anything; the
//!   back wall textured, so texture slots, sRGB and UV orientation count) matches
//!   the forward graph away from the box's edges, where the path tracer's box
//!   filter and the rasteriser's pixel centres see different things: mean
//!   relative difference under 0.5%, every pixel under 2% (measured 0.05% and
//!   0.22% at 256 spp, 0.15% and 0.96% with independent numbers: what is left
//!   is the box filter's average over each pixel against the rasteriser's
//!   value at its centre).
//!
//! The figures each test measures are printed (`--nocapture`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use weft_graph::plan::Extent;
use weft_render::RenderSettings;

mod caustics;
mod glass;
mod light_tree;
mod roulette;
mod sampler;
mod sampling;
mod wavefront;

/// Linear RGB per pixel, row by row.
struct Hdr {
    width: u32,
    pixels: Vec<[f32; 3]>,
}

impl Hdr {
    fn at(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Pixels with any channel above zero.
    fn lit_pixels(&self) -> usize {
        self.pixels
            .iter()
            .filter(|p| p.iter().any(|&v| v > 0.0))
            .count()
    }

    /// Pixels whose value is not bit for bit `other`'s.
    fn pixels_differing_from(&self, other: &Hdr) -> usize {
        self.pixels
            .iter()
            .zip(&other.pixels)
            .filter(|(a, b)| a.map(f32::to_bits) != b.map(f32::to_bits))
            .count()
    }

    fn mean(&self) -> [f64; 3] {
        block_mean(
            self,
            0..self.width,
            0..self.pixels.len() as u32 / self.width,
        )
    }
}

fn block_mean(image: &Hdr, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    let mut n = 0.0;
    for y in ys {
        for x in xs.clone() {
            let p = image.at(x, y);
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
            n += 1.0;
        }
    }
    sum.map(|s| s / n)
}

/// Renders `scene` through `graph` at `size`x`size` and returns its `hdr`
/// image; `samples` makes it a progressive render to that many spp.
fn render_hdr(
    scene: &Path,
    graph: &str,
    size: u32,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
) -> Hdr {
    let settings = weft_tests::render::square_settings(graph, size, samples, params, features);
    let (rendered, values) = weft_tests::render::render_hdr_validated(scene, settings);
    if let Some(spp) = samples {
        assert_eq!(rendered.samples, Some(spp), "the render reached its spp");
    }
    Hdr {
        width: size,
        pixels: values.chunks(4).map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

/// OBJ text for a UV sphere of `stacks` x `slices` flat facets (each face
/// gets its own normal, so shading and geometric normals agree), facing
/// outward or, with `inward`, towards its centre. `base` is the number of
/// vertices and normals already in the file.
fn sphere(centre: [f32; 3], radius: f32, inward: bool, material: &str, base: &mut usize) -> String {
    const STACKS: usize = 24;
    const SLICES: usize = 48;
    let point = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / STACKS as f32;
        let phi = 2.0 * std::f32::consts::PI * j as f32 / SLICES as f32;
        glam::Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        ) * radius
            + glam::Vec3::from(centre)
    };
    let mut text = format!("usemtl {material}\n");
    let mut triangle = |a: glam::Vec3, b: glam::Vec3, c: glam::Vec3| {
        let (b, c) = if inward { (c, b) } else { (b, c) };
        let n = (b - a).cross(c - a).normalize();
        for p in [a, b, c] {
            writeln!(text, "v {} {} {}", p.x, p.y, p.z).expect("write");
        }
        writeln!(text, "vn {} {} {}", n.x, n.y, n.z).expect("write");
        let v = *base * 3;
        let vn = *base + 1;
        writeln!(text, "f {}//{vn} {}//{vn} {}//{vn}", v + 1, v + 2, v + 3).expect("write");
        *base += 1;
    };
    for i in 0..STACKS {
        for j in 0..SLICES {
            let (a, b) = (point(i, j), point(i, j + 1));
            let (c, d) = (point(i + 1, j), point(i + 1, j + 1));
            // Outward winding: the normal (b - a) x (c - a) points away from the centre.
            if i > 0 {
                triangle(a, b, d);
            }
            if i + 1 < STACKS {
                triangle(a, d, c);
            }
        }
    }
    text
}

fn temp_dir(name: &str) -> PathBuf {
    weft_testkit::scratch::scratch(&format!("weft-pathtrace-{name}-{}", std::process::id()))
}

/// A furnace: a unit sphere of material `object` (MTL statements) inside a
/// sphere of radius 10 that emits radiance 1 inward and reflects nothing.
fn furnace_scene(name: &str, object: &str) -> PathBuf {
    furnace_scene_with(name, object, "")
}

/// [`furnace_scene`] with further statements in the model block
/// (`absorption`, say).
fn furnace_scene_with(name: &str, object: &str, model: &str) -> PathBuf {
    let dir = temp_dir(name);
    let mut base = 0;
    let mut obj = String::from("mtllib furnace.mtl\n");
    obj += &sphere([0.0; 3], 10.0, true, "glow", &mut base);
    obj += &sphere([0.0; 3], 1.0, false, "object", &mut base);
    std::fs::write(dir.join("furnace.obj"), obj).expect("obj");
    std::fs::write(
        dir.join("furnace.mtl"),
        format!("newmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 1 1 1\nnewmtl object\n{object}\n"),
    )
    .expect("mtl");
    let scene = dir.join("furnace.scene");
    std::fs::write(
        &scene,
        format!("model\n{{\n\tfile \"furnace.obj\"\n{model}}}\ncamera\n{{\n\tposition 0 0 4\n\ttarget 0 0 0\n\tfov_deg 40\n}}\n"),
    )
    .expect("scene");
    scene
}

/// Runs a furnace and checks every pixel: `object_value` where the pixel's
/// whole footprint sees the object, 1 where it sees only the enclosure.
/// Returns the largest error found.
fn furnace(name: &str, object: &str, object_value: f32, tolerance: f32) -> f32 {
    furnace_with(name, object, object_value, tolerance, 2048, &[])
}

/// [`furnace`] with graph parameters.
fn furnace_with(
    name: &str,
    object: &str,
    object_value: f32,
    tolerance: f32,
    samples: u64,
    params: &[(&str, f64)],
) -> f32 {
    let scene = furnace_scene(name, object);
    furnace_checked(
        name,
        &scene,
        object_value,
        [tolerance, 1e-3],
        samples,
        params,
    )
}

/// Renders the furnace `scene` and checks it as [`furnace`] says, each pixel
/// within `tolerance[0]` of its value and the object's mean within the
/// relative `tolerance[1]`.
fn furnace_checked(
    name: &str,
    scene: &Path,
    object_value: f32,
    [tolerance, mean_tolerance]: [f32; 2],
    samples: u64,
    params: &[(&str, f64)],
) -> f32 {
    const SIZE: u32 = 32;
    let image = render_hdr(scene, "pathtrace.ron", SIZE, Some(samples), params, &[]);
    let FurnacePixels { object, enclosure } = furnace_pixels(&image, SIZE, 0.85);
    let checked = [object.len(), enclosure.len()];
    assert!(checked[0] > 200 && checked[1] > 100, "{checked:?}");
    let mut worst = 0.0f32;
    let expected = object
        .iter()
        .map(|(b, pixel)| (*b, object_value, pixel))
        .chain(enclosure.iter().map(|pixel| (f64::INFINITY, 1.0, pixel)));
    for (b, expected, pixel) in expected {
        for c in pixel {
            let error = (c - expected).abs();
            worst = worst.max(error);
            assert!(
                error <= tolerance,
                "{name}: the pixel whose ray passes the centre at {b:.3} is {c}, expected {expected} +- {tolerance}"
            );
        }
    }
    let mean = object.iter().map(|(_, p)| f64::from(p[0])).sum::<f64>() / checked[0] as f64;
    let bias = (mean / f64::from(object_value) - 1.0).abs();
    println!("{name}: worst pixel error {worst:.4} over {checked:?} object/enclosure pixels; object mean {mean:.5}");
    assert!(
        bias < f64::from(mean_tolerance),
        "{name}: the object's mean is {mean}, not {object_value}"
    );
    worst
}

#[test]
fn furnace_white_lambert_is_one_everywhere() {
    furnace("white", "Kd 1 1 1\nKs 0 0 0", 1.0, 0.025);
}

#[test]
fn furnace_grey_lambert_shows_its_albedo() {
    furnace("grey", "Kd 0.5 0.5 0.5\nKs 0 0 0", 0.5, 0.0125);
}

#[test]
fn furnace_mirror_reflects_the_enclosure_exactly() {
    let worst = furnace("mirror", "Kd 0 0 0\nKs 1 1 1\nNs 1000\nillum 3", 1.0, 1e-5);
    assert!(worst <= 1e-5);
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The inside of a closed 2x2x2 box (white walls, a red one on the left, the
/// ceiling of material `ceiling`: `white`, `glow`, which emits radiance 1 and
/// reflects nothing, or `black`, which does neither) seen from inside, with `lights` (.scene blocks). The
/// back wall, facing the camera, is white too, or with `poster` white times
/// a 256 x 256 texture of four coloured quadrants (`map_Kd`).
fn box_scene(name: &str, ceiling: &str, poster: bool, lights: &str) -> PathBuf {
    let dir = temp_dir(name);
    // Four flat quadrants: red high on the left, blue high at the bottom, so
    // a mirrored u or v shows; flat, so mip filtering and the tracer's box
    // filter agree away from the quadrants' borders.
    let quadrants = image::RgbaImage::from_fn(256, 256, |x, y| {
        let level = |high: bool| if high { 200 } else { 60 };
        image::Rgba([level(x < 128), 128, level(y >= 128), 255])
    });
    quadrants.save(dir.join("poster.png")).expect("png");
    let mut obj = String::from("mtllib box.mtl\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n");
    // Each face: four corners counter-clockwise seen from inside the box.
    let faces: [(&str, [[f32; 3]; 4]); 6] = [
        (
            "back",
            [
                [-1., -1., -1.],
                [1., -1., -1.],
                [1., 1., -1.],
                [-1., 1., -1.],
            ],
        ),
        (
            "white",
            [[-1., -1., 1.], [-1., 1., 1.], [1., 1., 1.], [1., -1., 1.]],
        ),
        (
            "red",
            [
                [-1., -1., -1.],
                [-1., 1., -1.],
                [-1., 1., 1.],
                [-1., -1., 1.],
            ],
        ),
        (
            "white",
            [[1., -1., -1.], [1., -1., 1.], [1., 1., 1.], [1., 1., -1.]],
        ),
        (
            "white",
            [
                [-1., -1., -1.],
                [-1., -1., 1.],
                [1., -1., 1.],
                [1., -1., -1.],
            ],
        ),
        (
            ceiling,
            [[-1., 1., -1.], [1., 1., -1.], [1., 1., 1.], [-1., 1., 1.]],
        ),
    ];
    for (i, (material, corners)) in faces.iter().enumerate() {
        let [a, b, c, _] = corners.map(glam::Vec3::from);
        let n = (b - a).cross(c - a).normalize();
        writeln!(obj, "usemtl {material}").expect("write");
        for p in corners {
            writeln!(obj, "v {} {} {}", p[0], p[1], p[2]).expect("write");
        }
        writeln!(obj, "vn {} {} {}", n.x, n.y, n.z).expect("write");
        let (v, vn) = (i * 4, i + 1);
        writeln!(
            obj,
            "f {}/1/{vn} {}/2/{vn} {}/3/{vn} {}/4/{vn}",
            v + 1,
            v + 2,
            v + 3,
            v + 4
        )
        .expect("write");
    }
    std::fs::write(dir.join("box.obj"), obj).expect("obj");
    std::fs::write(
        dir.join("box.mtl"),
        format!(
            "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\nnewmtl red\nKd 0.7 0.1 0.1\nKs 0 0 0\n\
             newmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 1 1 1\nnewmtl black\nKd 0 0 0\nKs 0 0 0\n\
             newmtl back\nKd 0.8 0.8 0.8\nKs 0 0 0\n{}",
            if poster { "map_Kd poster.png\n" } else { "" }
        ),
    )
    .expect("mtl");
    let scene = dir.join("box.scene");
    std::fs::write(
        &scene,
        format!(
            "model\n{{\n\tfile \"box.obj\"\n}}\n{lights}\
             camera\n{{\n\tposition 0 0 0.9\n\ttarget 0 0 -1\n\tfov_deg 70\n\tnear 0.05\n}}\n"
        ),
    )
    .expect("scene");
    scene
}

#[test]
fn direct_light_matches_the_forward_graph() {
    const SIZE: u32 = 48;
    let scene = box_scene(
        "point-lit-box",
        "white",
        true,
        "pointlight\n{\n\tposition 0.3 0.4 -0.2\n\tcolor 0.5 0.5 0.4\n\tattenuation 0 0 1\n}\n",
    );
    let traced = render_hdr(
        &scene,
        "pathtrace.ron",
        SIZE,
        Some(256),
        &[("max_depth", 2.0)],
        &[],
    );
    let raster = render_hdr(&scene, "forward.ron", SIZE, None, &[], &["!bloom"]);
    let mut errors = Vec::new();
    for y in 1..SIZE - 1 {
        for x in 1..SIZE - 1 {
            let centre = raster.at(x, y);
            // Away from the box's edges: in every channel the pixel is within
            // 2% of its eight neighbours' mean, as where the image is smooth.
            let smooth = (0..3).all(|c| {
                let around = (0..9)
                    .filter(|&k| k != 4)
                    .map(|k| raster.at(x + k % 3 - 1, y + k / 3 - 1)[c])
                    .sum::<f32>()
                    / 8.0;
                centre[c] > 0.0 && (around / centre[c] - 1.0).abs() < 0.02
            });
            if smooth {
                for (t, r) in traced.at(x, y).iter().zip(centre) {
                    errors.push((t / r - 1.0).abs());
                }
            }
        }
    }
    errors.sort_by(f32::total_cmp);
    let mean = errors.iter().sum::<f32>() / errors.len() as f32;
    let p99 = errors[errors.len() * 99 / 100];
    let worst = errors[errors.len() - 1];
    println!(
        "direct light: {} pixels; relative difference mean {:.3}%, 99th percentile {:.3}%, worst {:.3}%",
        errors.len() / 3,
        100.0 * mean,
        100.0 * p99,
        100.0 * worst
    );
    assert!(
        errors.len() / 3 > 1000,
        "{} pixels compared",
        errors.len() / 3
    );
    assert!(mean < 0.005, "mean relative difference {mean}");
    assert!(worst < 0.02, "worst relative difference {worst}");
}

/// A quad facing the camera, Lambert with a constant normal map tilting every
/// normal towards +u and +v, under a sun from the side: the path tracer's
/// MikkTSpace frame (baked tangents) must bend the normal the way the raster
/// path's frame does, or the two disagree by far more than the tolerance
/// (a flipped u or v changes the cosine from 0.97 to 0.60 or 0.83).
#[test]
fn normal_maps_bend_normals_as_the_raster_path_does() {
    let dir = temp_dir("normal-map");
    image::RgbaImage::from_pixel(4, 4, image::Rgba([179, 166, 238, 255]))
        .save(dir.join("tilt.png"))
        .expect("png");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         vn 0 0 1\nusemtl tilted\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl tilted\nKd 0.8 0.8 0.8\nKs 0 0 0\nnorm tilt.png\n",
    )
    .expect("mtl");
    let scene = dir.join("quad.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"quad.obj\"\n}\nsunlight\n{\n\tdirection -0.4 -0.5 -0.77\n\tcolor 1 1 1\n\tambient 0\n}\n\
         camera\n{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 20\n}\n",
    )
    .expect("scene");
    const SIZE: u32 = 16;
    let traced = render_hdr(
        &scene,
        "pathtrace.ron",
        SIZE,
        Some(16),
        &[("max_depth", 2.0)],
        &[],
    );
    let raster = render_hdr(
        &scene,
        "forward.ron",
        SIZE,
        None,
        &[],
        &["!bloom", "!shadow_casters"],
    );
    let centre = |image: &Hdr| block_mean(image, 4..12, 4..12);
    let (t, r) = (centre(&traced), centre(&raster));
    let flat = 0.8 * 0.77 / (0.4f64 * 0.4 + 0.5 * 0.5 + 0.77 * 0.77).sqrt();
    println!("normal map: traced {t:?}, forward {r:?}; unbent the quad would show {flat:.4}");
    for c in 0..3 {
        assert!(
            (t[c] / r[c] - 1.0).abs() < 0.01,
            "traced {t:?} vs forward {r:?}"
        );
    }
    assert!(
        (t[0] / flat - 1.0).abs() > 0.1,
        "the normal map bends the normal: {t:?}"
    );
}

/// The furnace's pixels split by what the centre ray meets.
struct FurnacePixels {
    /// Every pixel that sees only the object, with its impact parameter b
    /// (the centre ray's distance from the sphere's centre).
    object: Vec<(f64, [f32; 3])>,
    /// Every pixel that sees only the enclosure (b > 1.15).
    enclosure: Vec<[f32; 3]>,
}

/// Splits a furnace image: object pixels are those of b < `object_below`.
fn furnace_pixels(image: &Hdr, size: u32, object_below: f32) -> FurnacePixels {
    let tan = (20.0f32).to_radians().tan();
    let (mut object, mut enclosure) = (Vec::new(), Vec::new());
    for y in 0..size {
        for x in 0..size {
            let ndc = [
                (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
                (y as f32 + 0.5) / size as f32 * 2.0 - 1.0,
            ];
            let dir = glam::Vec3::new(ndc[0] * tan, ndc[1] * tan, -1.0).normalize();
            let b = glam::Vec3::new(0.0, 0.0, 4.0).cross(dir).length();
            if b < object_below {
                object.push((f64::from(b), image.at(x, y)));
            } else if b > 1.15 {
                enclosure.push(image.at(x, y));
            }
        }
    }
    FurnacePixels { object, enclosure }
}
