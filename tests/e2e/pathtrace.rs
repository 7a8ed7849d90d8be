//! The path-traced reference (`graphs/pathtrace.ron`) against answers known
//! without it, every render with validation and synchronization validation on.
//!
//! - **Furnace.** Inside a closed sphere that emits radiance 1 inward, a convex
//!   object of albedo a shows exactly a (Lambert), and a mirror of Ks = 1 shows
//!   exactly 1. Every pixel is held to it at 2048 spp: within 0.025 for albedo
//!   1 and 0.0125 for albedo 0.5 (measured worst 0.0158 and 0.0079: the noise of
//!   NEE and BSDF samples combined, 0.56% per pixel), and the mean over the
//!   object within 0.1% of a (measured 0.005%, so no energy is gained or lost).
//! - **No light counted twice.** NEE only, BSDF sampling only and MIS converge
//!   to the same image of a box lit by an emissive ceiling, a two-sided disc
//!   and a one-sided rectangle light, at 512 spp: image means within 1%
//!   (measured 0.54% NEE only, 0.11% BSDF only), 8x8-pixel block luminance
//!   within 6% (measured 3.6% and 1.8%).
//! - **Raster agreement.** With direct light only (max_depth 2), the inside of
//!   a closed box lit by one point light (nothing can shadow anything; the
//!   back wall textured, so texture slots, sRGB and UV orientation count) matches
//!   the forward graph away from the box's edges, where the path tracer's box
//!   filter and the rasteriser's pixel centres see different things: mean
//!   relative difference under 0.5%, every pixel under 2% (measured 0.15% and
//!   0.96% at 256 spp: what is left is the box filter's average over each
//!   pixel against the rasteriser's value at its centre).
//!
//! The figures each test measures are printed (`--nocapture`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use weft_graph::plan::Extent;
use weft_render::RenderSettings;

/// Linear RGB per pixel, row by row.
struct Hdr {
    width: u32,
    pixels: Vec<[f32; 3]>,
}

impl Hdr {
    fn at(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
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
    let dir = std::env::temp_dir().join(format!("weft-pathtrace-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
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

/// The box of [`box_scene`] with its ceiling an emitter (Ke 1 1 1), a
/// two-sided disc area light and a one-sided rectangle light inside:
/// emissive triangles and both kinds of area light, all large enough for
/// BSDF sampling alone to find them often.
fn glowing_box_scene() -> PathBuf {
    box_scene(
        "glowing-box",
        "glow",
        false,
        "arealight\n{\n\tshape disc\n\tradius 0.4\n\tposition -0.3 -0.2 -0.6\n\tdirection 1 0 1\n\temission 0.5 0.5 1.5\n\ttwo_sided 1\n}\n\
         arealight\n{\n\tshape rect\n\tsize 0.8 0.6\n\tposition 0.5 -0.9 0\n\tdirection 0 1 0\n\temission 2 1.5 1\n}\n",
    )
}

#[test]
fn nee_bsdf_sampling_and_mis_converge_to_the_same_image() {
    const SIZE: u32 = 48;
    const BLOCK: u32 = 8;
    let scene = glowing_box_scene();
    let images: Vec<Hdr> = [0.0, 1.0, 2.0]
        .iter()
        .map(|&sampling| {
            render_hdr(
                &scene,
                "pathtrace.ron",
                SIZE,
                Some(512),
                &[("sampling", sampling)],
                &[],
            )
        })
        .collect();
    let names = ["MIS", "NEE only", "BSDF only"];
    let mis = images[0].mean();
    assert!(mis.iter().all(|&c| c > 0.05), "the box is lit: {mis:?}");
    for (image, name) in images.iter().zip(names).skip(1) {
        let mean = image.mean();
        let worst_channel = (0..3)
            .map(|c| (mean[c] / mis[c] - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: image mean {mean:?} vs MIS {mis:?}: {:.3}%",
            100.0 * worst_channel
        );
        assert!(worst_channel < 0.01, "{name}: mean {mean:?} vs MIS {mis:?}");
        let mut worst_block = 0.0f64;
        for by in 0..SIZE / BLOCK {
            for bx in 0..SIZE / BLOCK {
                let xs = bx * BLOCK..(bx + 1) * BLOCK;
                let ys = by * BLOCK..(by + 1) * BLOCK;
                let (a, b) = (
                    block_mean(image, xs.clone(), ys.clone()),
                    block_mean(&images[0], xs, ys),
                );
                let (la, lb) = (luminance(a), luminance(b));
                if lb > 0.02 {
                    worst_block = worst_block.max((la / lb - 1.0).abs());
                }
            }
        }
        println!(
            "{name}: worst 8x8 block luminance differs by {:.2}%",
            100.0 * worst_block
        );
        assert!(
            worst_block < 0.06,
            "{name}: a block differs by {worst_block}"
        );
    }
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// The inside of a closed 2x2x2 box (white walls, a red one on the left, the
/// ceiling of material `ceiling`: `white` or `glow`, which emits radiance 1 and
/// reflects nothing) seen from inside, with `lights` (.scene blocks). The
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
             newmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 1 1 1\nnewmtl back\nKd 0.8 0.8 0.8\nKs 0 0 0\n{}",
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

/// Reflectance and transmittance of unpolarised light by the Fresnel
/// equations written with angles (an independent form of the shader's):
/// (R, T) going from index `n_i` to `n_t` at `cos_i`.
fn fresnel_by_angles(cos_i: f64, n_i: f64, n_t: f64) -> (f64, f64) {
    let theta_i = cos_i.acos();
    let sin_t = n_i / n_t * theta_i.sin();
    if sin_t >= 1.0 {
        return (1.0, 0.0);
    }
    let theta_t = sin_t.asin();
    let cos_t = theta_t.cos();
    let r = if theta_i < 1e-6 {
        ((n_i - n_t) / (n_i + n_t)).powi(2)
    } else {
        let rs = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
        let rp = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
        0.5 * (rs + rp)
    };
    let ts = 2.0 * n_i * cos_i / (n_i * cos_i + n_t * cos_t);
    let tp = 2.0 * n_i * cos_i / (n_t * cos_i + n_i * cos_t);
    let t = n_t * cos_t / (n_i * cos_i) * 0.5 * (ts * ts + tp * tp);
    (r, t)
}

/// The shader's Fresnel reflectance (`dielectric.glsl`) over 4,096 angles and
/// 32 indices from 1.0001 to 3, entering and leaving: equal to the angle form
/// of the equations within 2e-5, R + T = 1 within 2e-5 where T is the
/// transmission coefficients' independent expression (within 1e-2 where the
/// sine of refraction is within 0.1% of 1, as R climbs to 1 too steeply there
/// for f32), R at normal incidence ((n - 1) / (n + 1))^2, and from index 1.5
/// total internal reflection begins at asin(1 / 1.5) within 0.01 degrees.
#[test]
fn fresnel_is_exact_conserves_energy_and_reflects_totally_past_the_critical_angle() {
    let settings = RenderSettings {
        graph: weft_tests::graph("fresnel.ron"),
        extent: Extent {
            width: 8,
            height: 8,
        },
        ..RenderSettings::default()
    };
    let scene = weft_scene::load_scene(&weft_tests::repo().join("scenes/cornell.scene"))
        .expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let rendered = weft_render::render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let weft_gpu::Pixels::RgbaF32(texels) = &rendered.report.output.expect("output").pixels else {
        panic!("a float image");
    };
    let (mut worst_r, mut worst_sum, mut worst_near_critical) = (0.0f64, 0.0f64, 0.0f64);
    let mut critical = None;
    for t in texels.chunks(4) {
        let (f, cos_i, n, leaving) = (
            f64::from(t[0]),
            f64::from(t[1]),
            f64::from(t[2]),
            t[3] == 1.0,
        );
        let (n_i, n_t) = if leaving { (n, 1.0) } else { (1.0, n) };
        let (r, tr) = fresnel_by_angles(cos_i, n_i, n_t);
        if n == 1.5 && leaving && f == 1.0 && critical.is_none_or(|c| cos_i > c) {
            critical = Some(cos_i);
        }
        // Within 0.1% of the critical sine, R climbs to 1 so steeply that the
        // shader's f32 arithmetic shows; there it is held to 1e-2.
        let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).sqrt();
        if (sin_t - 1.0).abs() < 1e-3 {
            worst_near_critical = worst_near_critical.max((f - r).abs());
            continue;
        }
        worst_r = worst_r.max((f - r).abs());
        if r < 1.0 {
            worst_sum = worst_sum.max((f + tr - 1.0).abs());
        }
        if cos_i > 0.9998 {
            let normal = ((n - 1.0) / (n + 1.0)).powi(2);
            assert!(
                (f / normal - 1.0).abs() < 1e-3,
                "R({cos_i}, {n}) = {f}, normal incidence {normal}"
            );
        }
    }
    let critical_deg = critical
        .expect("total internal reflection")
        .acos()
        .to_degrees();
    let expected = (1.0f64 / 1.5).asin().to_degrees();
    println!(
        "Fresnel: worst |R - R_angles| {worst_r:.2e} ({worst_near_critical:.2e} within 0.1% of the critical sine), worst |R + T - 1| {worst_sum:.2e}; critical angle {critical_deg:.4} deg (asin(1/1.5) = {expected:.4})"
    );
    assert!(worst_r < 2e-5 && worst_sum < 2e-5 && worst_near_critical < 1e-2);
    assert!((critical_deg - expected).abs() < 0.01);
}

/// Clear glass (Ks 1, Tf 1, index 1.5) in the furnace: every path that leaves
/// the sphere carries weight exactly 1 (reflections 1, the two crossings'
/// (n_from/n_to)^2 cancel), so every pixel is 1 but for paths still inside
/// after 100 segments (no Russian roulette), trapped by total internal
/// reflection between the faceted sphere's flat faces. Measured at 128 spp:
/// one such path, on one pixel (0.9922 = 1 - 1/128; with 400 segments it
/// is 1 too), every other pixel exactly 1. Tolerance 1% per pixel and 0.1%
/// on the mean.
#[test]
fn furnace_clear_glass_neither_gains_nor_loses_energy() {
    let params = [("max_depth", 100.0), ("rr_depth", 100.0)];
    let glass = "Kd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7";
    let worst = furnace_with("glass", glass, 1.0, 1e-2, 128, &params);
    println!("clear glass in the furnace: worst pixel error {worst:.2e}");
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

/// Clear glass at the ends of its index range (issue 19): barely denser than
/// air (1.0001: the Fresnel terms near their 0/0 limits), diamond (2.42) and
/// 3.0. Every path that leaves the sphere carries weight exactly 1, so no
/// pixel may exceed 1 (held to 1e-5: energy is never gained) and the
/// enclosure is exactly 1. What falls short of 1 is paths still inside after
/// 100 segments: on the faceted sphere total internal reflection between
/// flat faces traps paths, more often the higher the index (internal
/// reflectance 0.17 at 2.42 and 0.25 at 3 head-on, so more bounces). Measured
/// at 128 spp: index 1.0001 exactly 1 everywhere; 2.42 object mean 0.9942,
/// worst pixel 0.906; 3.0 mean 0.9904, worst 0.906. Held to: mean above
/// 0.985, every pixel above 0.85.
#[test]
fn furnace_glass_at_extreme_indices_never_gains_energy() {
    const SIZE: u32 = 32;
    let params = [("max_depth", 100.0), ("rr_depth", 100.0)];
    for ior in [1.0001, 2.42, 3.0] {
        let glass = format!("Kd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi {ior}\nillum 7");
        let scene = furnace_scene(&format!("glass-{ior}"), &glass);
        let image = render_hdr(&scene, "pathtrace.ron", SIZE, Some(128), &params, &[]);
        let FurnacePixels { object, enclosure } = furnace_pixels(&image, SIZE, 0.85);
        assert!(object.len() > 200 && enclosure.len() > 100);
        for value in enclosure.iter().flatten() {
            assert!(
                (value - 1.0).abs() <= 1e-5,
                "index {ior}: enclosure {value}"
            );
        }
        let values: Vec<f32> = object.iter().flat_map(|(_, p)| *p).collect();
        let (lowest, highest) = values
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        let mean = values.iter().map(|v| f64::from(*v)).sum::<f64>() / values.len() as f64;
        println!("index {ior}: object mean {mean:.5}, pixels {lowest:.4} to {highest:.6}");
        assert!(
            values.iter().all(|v| v.is_finite()),
            "index {ior}: not finite"
        );
        assert!(
            highest <= 1.0 + 1e-5,
            "index {ior}: a pixel gained energy: {highest}"
        );
        if ior < 1.001 {
            assert!(lowest >= 1.0 - 1e-5, "index {ior}: {lowest}");
        } else {
            assert!(
                mean > 0.985 && lowest > 0.85,
                "index {ior}: mean {mean}, lowest {lowest}"
            );
        }
    }
}

/// Glass that absorbs whatever enters it (σ = 1e6 per unit: e^-σd is 0
/// within microns) shows only its Fresnel reflection of the furnace. The path
/// tracer picks reflection with probability F, so at N spp a pixel is k/N
/// with k binomial: the pixel whose centre ray passes the centre at distance
/// b is held to F(asin b) at index 1.5 within 5 standard deviations plus
/// 0.01 for the faceted normals (within 3.75 degrees of the smooth sphere's)
/// and the pixel's footprint, and the mean over those pixels within 3% of
/// the mean of F. Measured at 1,024 spp over b < 0.8: mean 0.04615 against
/// 0.04596 (0.4%), worst pixel 2.9 standard deviations.
/// Every pixel is finite, and with `absorption 0` the same glass is clear: 1
/// everywhere, as without the statement.
#[test]
fn furnace_glass_absorbing_everything_shows_only_its_reflection() {
    const SIZE: u32 = 32;
    const SAMPLES: u64 = 1024;
    let glass = "Kd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7";
    let scene = furnace_scene_with("opaque-glass", glass, "\tabsorption 1e6\n");
    let params = [("max_depth", 8.0)];
    let image = render_hdr(&scene, "pathtrace.ron", SIZE, Some(SAMPLES), &params, &[]);
    let object = furnace_pixels(&image, SIZE, 0.8).object;
    assert!(object.len() > 200, "{}", object.len());
    let (mut measured, mut expected, mut worst_sigmas) = (0.0f64, 0.0f64, 0.0f64);
    for (b, pixel) in &object {
        let (reflected, _) = fresnel_by_angles((1.0 - b * b).sqrt(), 1.0, 1.5);
        let sigma = (reflected * (1.0 - reflected) / SAMPLES as f64).sqrt();
        for c in pixel {
            let error = (f64::from(*c) - reflected).abs();
            worst_sigmas = worst_sigmas.max(error / sigma);
            assert!(
                c.is_finite() && error <= 5.0 * sigma + 0.01,
                "b {b:.3}: {c}, F = {reflected:.4}, sigma {sigma:.4}"
            );
        }
        measured += f64::from(pixel[0]);
        expected += reflected;
    }
    let ratio = measured / expected;
    println!(
        "absorption 1e6: object mean {:.5} against mean F {:.5} (ratio {ratio:.4}); worst pixel {worst_sigmas:.1} sigma",
        measured / object.len() as f64,
        expected / object.len() as f64
    );
    assert!((ratio - 1.0).abs() < 0.03, "ratio {ratio}");
    assert!(image.pixels.iter().flatten().all(|c| c.is_finite()));
    let scene = furnace_scene_with("clear-glass-zero-absorption", glass, "\tabsorption 0\n");
    let params = [("max_depth", 100.0), ("rr_depth", 100.0)];
    let worst = furnace_checked("absorption 0", &scene, 1.0, [1e-2, 1e-3], 128, &params);
    println!("absorption 0: worst pixel error {worst:.2e}");
}

/// A glass sphere of index 1 is invisible: the glowing box with it inside
/// renders the same image as without it (image means within 0.5%, 8x8
/// blocks within 5% at 256 spp; the two differ only by noise, as the sphere
/// consumes random numbers).
#[test]
fn glass_of_index_one_is_invisible() {
    let dir = temp_dir("ior-one");
    let mut base = 0;
    std::fs::write(
        dir.join("sphere.obj"),
        format!(
            "mtllib sphere.mtl\n{}",
            sphere([0.1, -0.3, -0.2], 0.45, false, "air", &mut base)
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("sphere.mtl"),
        "newmtl air\nKs 1 1 1\nTf 1 1 1\nNi 1.0\nillum 7\n",
    )
    .expect("mtl");
    let lights = "arealight\n{\n\tshape rect\n\tsize 0.8 0.6\n\tposition 0.5 -0.9 0\n\tdirection 0 1 0\n\temission 2 1.5 1\n}\n";
    let without = box_scene("ior-one-without", "glow", false, lights);
    let with = box_scene(
        "ior-one-with",
        "glow",
        false,
        &format!(
            "{lights}model\n{{\n\tfile \"{}\"\n}}\n",
            dir.join("sphere.obj").display()
        ),
    );
    // Crossing the sphere takes two path segments: allow long paths so that
    // cutting them short does not make the difference.
    let params = [("max_depth", 64.0)];
    let render = |scene: &Path| render_hdr(scene, "pathtrace.ron", 48, Some(256), &params, &[]);
    let (a, b) = (render(&without), render(&with));
    let (ma, mb) = (a.mean(), b.mean());
    let worst_mean = (0..3)
        .map(|c| (mb[c] / ma[c] - 1.0).abs())
        .fold(0.0, f64::max);
    let mut worst_block = 0.0f64;
    for by in 0..6 {
        for bx in 0..6 {
            let (xs, ys) = (bx * 8..bx * 8 + 8, by * 8..by * 8 + 8);
            let (la, lb) = (
                luminance(block_mean(&a, xs.clone(), ys.clone())),
                luminance(block_mean(&b, xs, ys)),
            );
            worst_block = worst_block.max((lb / la - 1.0).abs());
        }
    }
    println!(
        "index 1 glass: image means differ by {:.3}%, worst 8x8 block {:.2}%",
        100.0 * worst_mean,
        100.0 * worst_block
    );
    assert!(worst_mean < 0.005 && worst_block < 0.05);
}

/// OBJ text for the box `min`..`max` of material `material`, each face two
/// triangles wound so that its normal points out of the box.
fn cuboid(min: [f32; 3], max: [f32; 3], material: &str) -> String {
    let corner = |i: usize| {
        glam::Vec3::new(
            if i & 1 == 0 { min[0] } else { max[0] },
            if i & 2 == 0 { min[1] } else { max[1] },
            if i & 4 == 0 { min[2] } else { max[2] },
        )
    };
    let centre = (glam::Vec3::from(min) + glam::Vec3::from(max)) * 0.5;
    let mut text = format!("usemtl {material}\n");
    for i in 0..8 {
        let p = corner(i);
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).expect("write");
    }
    let faces = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    for f in faces {
        let [a, b, c, _] = f.map(corner);
        let outward = (b - a).cross(c - a).dot(a - centre) > 0.0;
        let order = if outward { f } else { [f[0], f[3], f[2], f[1]] };
        for tri in [
            [order[0], order[1], order[2]],
            [order[0], order[2], order[3]],
        ] {
            writeln!(text, "f {} {} {}", tri[0] + 1, tri[1] + 1, tri[2] + 1).expect("write");
        }
    }
    text
}

/// Beer–Lambert: a glass slab 1 unit thick (index 1.5, σ = 0.5 per unit,
/// set by the `.scene` model's `absorption`) seen head-on in the white
/// furnace. The light leaving it towards the camera is the furnace's
/// radiance times R_total + T_total, the sums over every number of internal
/// reflections: with R = ((n - 1)/(n + 1))^2 and τ = exp(-σd),
/// T_total = (1 - R)^2 τ / (1 - R^2 τ^2) and
/// R_total = R + (1 - R)^2 R τ^2 / (1 - R^2 τ^2). The centre 8 x 8 pixels
/// (at most 1.3 degrees off the normal) must average within 0.5% of it.
#[test]
fn a_glass_slab_absorbs_as_beer_and_fresnel_say() {
    let dir = temp_dir("slab");
    let mut base = 0;
    std::fs::write(
        dir.join("enclosure.obj"),
        format!(
            "mtllib slab.mtl\n{}",
            sphere([0.0; 3], 10.0, true, "glow", &mut base)
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("slab.obj"),
        format!(
            "mtllib slab.mtl\n{}",
            cuboid([-3.0, -3.0, -0.5], [3.0, 3.0, 0.5], "glass")
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("slab.mtl"),
        "newmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 1 1 1\nnewmtl glass\nKd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7\n",
    )
    .expect("mtl");
    let scene = dir.join("slab.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"enclosure.obj\"\n}\nmodel\n{\n\tfile \"slab.obj\"\n\tabsorption 0.5\n}\n\
         camera\n{\n\tposition 0 0 4\n\ttarget 0 0 0\n\tfov_deg 10\n}\n",
    )
    .expect("scene");
    let image = render_hdr(
        &scene,
        "pathtrace.ron",
        32,
        Some(512),
        &[("max_depth", 16.0)],
        &[],
    );
    let seen = block_mean(&image, 12..20, 12..20)[0];
    let r = (0.5f64 / 2.5).powi(2);
    let tau = (-0.5f64).exp();
    let denominator = 1.0 - r * r * tau * tau;
    let expected =
        (1.0 - r).powi(2) * tau / denominator + r + (1.0 - r).powi(2) * r * tau * tau / denominator;
    println!("glass slab: {seen:.5} against {expected:.5} (without absorption it would be 1)");
    assert!(
        (seen / expected - 1.0).abs() < 0.005,
        "{seen} vs {expected}"
    );
}

/// The coated diffuse (MTL `illum 5`): a white Lambert base under a clear
/// coat of index 1.5 (`Ks 0.04`) reflects everything, the coat's Fresnel
/// share specularly and the rest after the base and the coat's internal
/// reflections (docs/pathtrace.md), so in the furnace it shows exactly 1.
/// Measured at 2048 spp: worst pixel 0.0125 (NEE and BSDF noise), object
/// mean 1.00021.
#[test]
fn furnace_coated_white_diffuse_reflects_everything() {
    furnace("coated", "Kd 1 1 1\nKs 0.04 0.04 0.04\nillum 5", 1.0, 0.025);
}

/// A thin glass pane (`thin 1`: refracts in and straight back out) of index
/// 1.5 in front of a glowing wall, seen head-on in a black room: it passes
/// 1 - R' where R' = R + (1 - R)^2 R / (1 - R^2) sums the light bouncing
/// between its faces, so 2n / (n^2 + 1) = 0.923077 at normal incidence. The
/// wall shows where it would without the pane (thin glass does not bend
/// light): the centre 8 x 8 pixels (at most 1.3 degrees off the normal) must
/// average within 0.5% of it.
#[test]
fn a_thin_pane_passes_light_straight_through() {
    let dir = temp_dir("pane");
    let mut base = 0;
    std::fs::write(
        dir.join("room.obj"),
        format!(
            "mtllib pane.mtl\n{}",
            sphere([0.0; 3], 10.0, true, "black", &mut base)
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("wall.obj"),
        format!(
            "mtllib pane.mtl\n{}",
            cuboid([-3.0, -3.0, -3.2], [3.0, 3.0, -3.0], "glow")
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("pane.obj"),
        "mtllib pane.mtl\nusemtl glass\nv -3 -3 0\nv 3 -3 0\nv 3 3 0\nv -3 3 0\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("pane.mtl"),
        "newmtl black\nKd 0 0 0\nKs 0 0 0\nnewmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 1 1 1\n\
         newmtl glass\nKd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7\n",
    )
    .expect("mtl");
    let scene = dir.join("pane.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"room.obj\"\n}\nmodel\n{\n\tfile \"wall.obj\"\n}\nmodel\n{\n\tfile \"pane.obj\"\n\tthin 1\n}\n\
         camera\n{\n\tposition 0 0 4\n\ttarget 0 0 0\n\tfov_deg 10\n}\n",
    )
    .expect("scene");
    let image = render_hdr(&scene, "pathtrace.ron", 32, Some(512), &[], &[]);
    let seen = block_mean(&image, 12..20, 12..20)[0];
    let expected = 2.0 * 1.5 / (1.5 * 1.5 + 1.0);
    println!("thin pane: {seen:.5} against {expected:.5}");
    assert!(
        (seen / expected - 1.0).abs() < 0.005,
        "{seen} vs {expected}"
    );
}

/// The caustic scene of [`a_glass_ball_focuses_light_where_geometric_optics_says`]:
/// a 0.2 x 0.2 light of radiance 20 at height 1.98 facing down, a glass ball
/// (scenes/models/glass_sphere.obj, index 1.5) of radius 0.3 centred 1 above
/// a floor of albedo 0.5, nothing else; the camera looks at the floor under
/// the ball.
fn caustic_scene() -> PathBuf {
    let dir = temp_dir("caustic");
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib floor.mtl\nusemtl floor\nv -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("floor.mtl"),
        "newmtl floor\nKd 0.5 0.5 0.5\nKs 0 0 0\n",
    )
    .expect("mtl");
    let ball = weft_tests::repo().join("scenes/models/glass_sphere.obj");
    let scene = dir.join("caustic.scene");
    std::fs::write(
        &scene,
        format!(
            "model\n{{\n\tfile \"floor.obj\"\n}}\nmodel\n{{\n\tfile \"{}\"\n\tposition 0 1 0\n\tscale 0.3\n}}\n\
             arealight\n{{\n\tshape rect\n\tsize 0.2 0.2\n\tposition 0 1.98 0\n\tdirection 0 -1 0\n\temission 20 20 20\n}}\n\
             camera\n{{\n\tposition 0 0.45 1.3\n\ttarget 0 0 0\n\tfov_deg 40\n}}\n",
            ball.display()
        ),
    )
    .expect("scene");
    scene
}

/// Rings on the floor around the point under the ball: outer radii.
const CAUSTIC_RINGS: [f64; 6] = [0.03, 0.06, 0.09, 0.12, 0.16, 0.2];

/// Geometric optics for [`caustic_scene`] with an ideal sphere: irradiance on
/// the floor in each of [`CAUSTIC_RINGS`] from light that crosses the ball
/// (each crossing weighted by 1 - F; light reflected inside is left out, a
/// few percent). Two million rays from the light, uniform over its area and
/// cosine-distributed, each carrying an equal share of its power
/// Φ = L π A.
fn caustic_by_geometric_optics() -> Vec<f64> {
    use glam::DVec3;
    let centre = DVec3::new(0.0, 1.0, 0.0);
    let (radius, ior) = (0.3, 1.5);
    let power = 20.0 * std::f64::consts::PI * 0.04;
    let rays = 2_000_000u64;
    let fresnel = |cos_i: f64, eta: f64| {
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
        if sin2_t >= 1.0 {
            return (1.0, 0.0);
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        (0.5 * (rs * rs + rp * rp), cos_t)
    };
    // The far intersection when `inside`, else the near one.
    let hit = |o: DVec3, d: DVec3, inside: bool| {
        let oc = o - centre;
        let b = oc.dot(d);
        let disc = b * b - (oc.length_squared() - radius * radius);
        if disc < 0.0 {
            return None;
        }
        let t = if inside {
            -b + disc.sqrt()
        } else {
            -b - disc.sqrt()
        };
        (t > 0.0).then(|| o + d * t)
    };
    let refract = |d: DVec3, n: DVec3, eta: f64| {
        let cos_i = -d.dot(n);
        let (f, cos_t) = fresnel(cos_i, eta);
        (1.0 - f, (eta * d + (eta * cos_i - cos_t) * n).normalize())
    };
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut ring_power = vec![0.0f64; CAUSTIC_RINGS.len()];
    for _ in 0..rays {
        let origin = DVec3::new(uniform() * 0.2 - 0.1, 1.98, uniform() * 0.2 - 0.1);
        let (r, phi) = (uniform().sqrt(), uniform() * std::f64::consts::TAU);
        let dir = DVec3::new(r * phi.cos(), -(1.0 - r * r).sqrt(), r * phi.sin());
        let Some(p) = hit(origin, dir, false) else {
            continue;
        };
        let (t_in, inside) = refract(dir, (p - centre) / radius, 1.0 / ior);
        let Some(q) = hit(p, inside, true) else {
            continue;
        };
        let (t_out, out) = refract(inside, -(q - centre) / radius, ior);
        if out.y >= 0.0 || t_out == 0.0 {
            continue;
        }
        let floor = q + out * (-q.y / out.y);
        let r = (floor.x * floor.x + floor.z * floor.z).sqrt();
        if let Some(ring) = CAUSTIC_RINGS.iter().position(|&outer| r < outer) {
            ring_power[ring] += power / rays as f64 * t_in * t_out;
        }
    }
    let mut inner = 0.0;
    ring_power
        .iter()
        .zip(CAUSTIC_RINGS)
        .map(|(p, outer)| {
            let area = std::f64::consts::PI * (outer * outer - inner * inner);
            inner = outer;
            p / area
        })
        .collect()
}

/// Mean radiance of the floor in each of [`CAUSTIC_RINGS`], from the pixels
/// whose centre's ray (camera of [`caustic_scene`]) meets the floor there.
fn caustic_rings_seen(image: &Hdr, size: u32) -> Vec<f64> {
    use glam::DVec3;
    let eye = DVec3::new(0.0, 0.45, 1.3);
    let forward = (-eye).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let tan = 20f64.to_radians().tan();
    let mut sums = vec![(0.0f64, 0u32); CAUSTIC_RINGS.len()];
    for y in 0..size {
        for x in 0..size {
            let sx = (f64::from(x) + 0.5) / f64::from(size) * 2.0 - 1.0;
            let sy = 1.0 - (f64::from(y) + 0.5) / f64::from(size) * 2.0;
            let d = (forward + right * (sx * tan) + up * (sy * tan)).normalize();
            if d.y >= 0.0 {
                continue;
            }
            let p = eye + d * (-eye.y / d.y);
            let r = (p.x * p.x + p.z * p.z).sqrt();
            if let Some(ring) = CAUSTIC_RINGS.iter().position(|&outer| r < outer) {
                let seen = image.at(x, y);
                sums[ring].0 += f64::from(seen[0] + seen[1] + seen[2]) / 3.0;
                sums[ring].1 += 1;
            }
        }
    }
    sums.iter()
        .map(|&(sum, n)| {
            assert!(n >= 8, "a ring covers only {n} pixels");
            sum / f64::from(n)
        })
        .collect()
}

/// Caustics: light through the glass ball lands on the floor where
/// geometric optics puts it. The floor's radiance in rings around the point
/// under the ball is albedo / π times the irradiance an ideal sphere sends
/// there ([`caustic_by_geometric_optics`]); the rings lie inside the ball's
/// shadow, so what they show is the caustic alone. At 1024 spp each ring must
/// be within 15% (the path tracer's caustic noise; measured at most 7.1%, the
/// innermost ring) and the light over all six within 5% (measured +0.5%).
///
/// The Snell-bent NEE option (`nee_through_glass`) adds, on top of that, the
/// light's direct irradiance through the ball as if it did not focus: with
/// the same seed the two renders' BSDF paths are identical, so the
/// difference is that term alone. Under the ball's centre it is the
/// unoccluded irradiance 20 × 0.04 / 1.98² times the ball's near-normal
/// transmittance (1 - 0.04)², times albedo / π: 0.0299, held within 10%.
#[test]
fn a_glass_ball_focuses_light_where_geometric_optics_says() {
    const SIZE: u32 = 96;
    let scene = caustic_scene();
    let expected: Vec<f64> = caustic_by_geometric_optics()
        .iter()
        .map(|e| e * 0.5 / std::f64::consts::PI)
        .collect();
    let image = render_hdr(&scene, "pathtrace.ron", SIZE, Some(1024), &[], &[]);
    let seen = caustic_rings_seen(&image, SIZE);
    let snell = render_hdr(
        &scene,
        "pathtrace.ron",
        SIZE,
        Some(1024),
        &[("nee_through_glass", 1.0)],
        &[],
    );
    let snell = caustic_rings_seen(&snell, SIZE);
    let mut inner = 0.0;
    let (mut power_seen, mut power_expected) = (0.0, 0.0);
    for ((outer, e), (s, b)) in CAUSTIC_RINGS
        .iter()
        .zip(&expected)
        .zip(seen.iter().zip(&snell))
    {
        println!(
            "ring {inner}..{outer}: geometric optics {e:.4}, path traced {s:.4} ({:+.1}%), with Snell-bent NEE {b:.4} ({:+.4})",
            (s / e - 1.0) * 100.0,
            b - s
        );
        assert!((s / e - 1.0).abs() < 0.15, "ring to {outer}: {s} vs {e}");
        assert!(b >= s, "the Snell-bent term only adds light");
        let area = outer * outer - inner * inner;
        power_seen += s * area;
        power_expected += e * area;
        inner = *outer;
    }
    let total = power_seen / power_expected - 1.0;
    println!(
        "caustic power: {:+.2}% against geometric optics",
        total * 100.0
    );
    assert!(total.abs() < 0.05, "{total}");
    let bent = 20.0 * 0.04 / (1.98f64 * 1.98) * 0.96 * 0.96 * 0.5 / std::f64::consts::PI;
    let added = snell[0] - seen[0];
    assert!(
        (added / bent - 1.0).abs() < 0.1,
        "Snell-bent NEE adds {added} under the ball, expected {bent}"
    );
}
