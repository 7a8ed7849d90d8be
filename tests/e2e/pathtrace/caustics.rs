//! A glass ball focuses light where geometric optics says: caustic rings
//! traced against the path tracer's image.

use super::*;

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
