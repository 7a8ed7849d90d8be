//! Glass in the path tracer: exact Fresnel with total internal reflection,
//! furnace scenes of clear, extreme-index and absorbing glass, index-1 glass
//! invisible, Beer absorption through a slab and thin panes.

use super::*;

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
/// after 400 segments (no Russian roulette), trapped by total internal
/// reflection between the faceted sphere's flat faces. Measured at 128 spp:
/// every pixel 1 within 1.2e-7 (after 100 segments two such paths were left
/// on one pixel, 1 - 2/128). Tolerance 1% per pixel and 0.1% on the mean.
#[test]
fn furnace_clear_glass_neither_gains_nor_loses_energy() {
    let params = [("max_depth", 400.0), ("rr_depth", 400.0)];
    let glass = "Kd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 1.5\nillum 7";
    let worst = furnace_with("glass", glass, 1.0, 1e-2, 128, &params);
    println!("clear glass in the furnace: worst pixel error {worst:.2e}");
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

/// A frame that adds 64 samples per pixel gives, bit for bit, the image of
/// 64 frames of one sample, even where paths are long: index-3 glass in the
/// furnace with up to 100 segments a path. The pass repeats one dispatch per
/// sample; when the shader looped over a frame's samples, lavapipe (which
/// ends all of an invocation's loops after 65,535 iterations together) cut
/// those paths short and this image came out at a mean of 0.077 where 0.993
/// is right.
#[test]
fn a_frame_of_many_samples_is_the_image_of_as_many_frames_of_one() {
    const SIZE: u32 = 8;
    let glass = "Kd 0 0 0\nKs 1 1 1\nTf 1 1 1\nNi 3\nillum 7";
    let scene = furnace_scene("samples-per-frame", glass);
    let render = |per_frame: f64| {
        let params = [
            ("max_depth", 100.0),
            ("rr_depth", 100.0),
            ("samples_per_frame", per_frame),
        ];
        render_hdr(&scene, "pathtrace.ron", SIZE, Some(64), &params, &[])
    };
    let frames_of_one = render(1.0);
    let one_frame = render(64.0);
    assert!(
        frames_of_one.pixels == one_frame.pixels,
        "the images differ"
    );
    let mean = one_frame
        .pixels
        .iter()
        .map(|p| f64::from(p[0]))
        .sum::<f64>()
        / one_frame.pixels.len() as f64;
    assert!(mean > 0.98 && mean <= 1.0 + 1e-5, "mean {mean}");
}

/// Glass that absorbs whatever enters it (σ = 1e6 per unit: e^-σd is 0
/// within microns) shows only its Fresnel reflection of the furnace. The path
/// tracer picks reflection with probability F, so at N spp a pixel is k/N
/// with k binomial: the pixel whose centre ray passes the centre at distance
/// b is held to F(asin b) at index 1.5 within 5 standard deviations plus
/// 0.01 for the faceted normals (within 3.75 degrees of the smooth sphere's)
/// and the pixel's footprint, and the mean over those pixels within 3% of
/// the mean of F. Measured at 1,024 spp over b < 0.8: mean 0.04635 against
/// 0.04596 (0.8%), worst pixel 0.7 binomial standard deviations (the Sobol
/// sampler stratifies the choice; independent numbers gave 2.9).
/// Every pixel is finite, and with `absorption 0` the same glass is clear: 1
/// everywhere (400 segments), as without the statement.
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
    let params = [("max_depth", 400.0), ("rr_depth", 400.0)];
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

/// A glass slab of index 1.5 and `absorption 0.5` (σ = 0.5 per unit, 1 unit
/// thick) seen head-on inside a white furnace of radiance 1.
pub(super) fn absorbing_slab_scene() -> PathBuf {
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
    scene
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
    let scene = absorbing_slab_scene();
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
