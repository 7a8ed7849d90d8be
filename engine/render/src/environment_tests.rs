use super::*;
use std::path::PathBuf;

fn map(width: u32, height: u32, texel: impl Fn(u32, u32) -> [f32; 3]) -> Environment {
    Environment {
        file: PathBuf::from("test.exr"),
        intensity: 1.0,
        rotation_deg: 0.0,
        width,
        height,
        texels: (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| texel(x, y))
            .collect(),
    }
}

/// Mitsuba 3.9's `envmap` (scalar_rgb) evaluated on this 8×4 map with
/// `scale` 2 and `to_world` a 37° rotation about +y, at five directions
/// (the script is in docs/environment.md).
#[test]
fn lookup_matches_mitsubas_envmap_orientation_and_filter() {
    let mut env = map(8, 4, |x, y| {
        let (x, y) = ((x + 1) as f32, (y + 1) as f32);
        [x, y, x * y]
    });
    env.intensity = 2.0;
    env.rotation_deg = 37.0;
    let mitsuba = [
        ([0.6, 0.0, -0.8], [4.283107, 5.0, 10.707767]),
        ([0.0, 0.6, 0.8], [10.644444, 3.771003, 20.070116]),
        ([-0.48, -0.6, 0.64], [12.283106, 6.228997, 38.25571]),
        ([0.0, -1.0, 0.0], [9.0, 8.0, 36.0]),
        ([0.36, 0.8, 0.48], [9.005783, 3.2289965, 14.53982]),
    ];
    for (dir, expected) in mitsuba {
        let got = radiance(&env, Vec3::from(dir));
        assert!(
            (got - Vec3::from(expected)).abs().max_element() < 2e-4,
            "{dir:?}: {got} against Mitsuba's {expected:?}"
        );
    }
}

#[test]
fn quadrants_land_where_mitsubas_convention_puts_them() {
    // Columns 0-1: u in [0, ½) (azimuth from −z towards +x); rows 0: up.
    let env = map(4, 2, |x, y| [(x / 2) as f32, y as f32, 0.0]);
    let up_plus_x = radiance(&env, Vec3::new(1.0, 0.2, 0.0).normalize());
    let down_minus_x = radiance(&env, Vec3::new(-1.0, -0.2, 0.0).normalize());
    assert_eq!(up_plus_x.x, 0.0);
    assert_eq!(down_minus_x.x, 1.0);
    assert!(up_plus_x.y < 0.5 && down_minus_x.y > 0.5);
    // A quarter turn brings +x's texels to −z... and −z's to +x.
    let turned = Environment {
        rotation_deg: 90.0,
        ..env.clone()
    };
    let at_minus_z = radiance(&turned, Vec3::new(0.0, 0.2, -1.0).normalize());
    assert!((at_minus_z - up_plus_x).abs().max_element() < 1e-5);
}

#[test]
fn directions_and_map_coordinates_round_trip() {
    for uv in [[0.1, 0.2], [0.75, 0.5], [0.999, 0.9], [0.3, 0.01]] {
        let uv = Vec2::from(uv);
        let back = direction_uv(uv_direction(uv));
        assert!((back - uv).abs().max_element() < 1e-5, "{uv} → {back}");
    }
    let d = Vec3::new(0.3, -0.5, 0.81).normalize();
    let round = world_direction(local_direction(d, 123.0), 123.0);
    assert!((round - d).length() < 1e-6);
}

/// A map with a sun: a 2×2 bright patch over a dim gradient.
fn sun_map() -> Environment {
    let mut env = map(32, 16, |x, y| {
        let base = 0.1 + 0.05 * x as f32 / 32.0;
        if (11..13).contains(&x) && (4..6).contains(&y) {
            [500.0, 450.0, 300.0]
        } else {
            [base, base * 1.2, base * 1.5 + y as f32 * 0.01]
        }
    });
    env.rotation_deg = 25.0;
    env
}

#[test]
fn the_sampling_density_integrates_to_one_and_covers_every_lit_direction() {
    let env = sun_map();
    let table = EnvironmentTable::build(&env);
    let (nu, nv) = (512, 256);
    let mut integral = 0.0f64;
    for j in 0..nv {
        for i in 0..nu {
            let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let theta = uv.y * PI;
            let d_omega = (2.0 * PI / nu as f32) * (PI / nv as f32) * theta.sin();
            let dir = world_direction(uv_direction(uv), env.rotation_deg);
            let pdf = table.pdf(&env, dir);
            assert!(
                radiance(&env, dir).max_element() == 0.0 || pdf > 0.0,
                "lit direction {dir} with no density"
            );
            integral += f64::from(pdf * d_omega);
        }
    }
    assert!((integral - 1.0).abs() < 2e-3, "∫ pdf dω = {integral}");
}

/// χ² test of the sampler against its density, over 8×8 bins in (u, v)
/// (pbrt-v4's sampling tests): 400k samples.
#[test]
fn sampled_directions_follow_the_density_chi_square() {
    let env = sun_map();
    let table = EnvironmentTable::build(&env);
    let (bu, bv) = (8usize, 8usize);
    let mut observed = vec![0.0f64; bu * bv];
    let mut rng = weft_scene::rng::Rng::new(7);
    let n = 400_000;
    for _ in 0..n {
        let u = [
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
            rng.next_f32(),
        ];
        let (dir, pdf) = table.sample(&env, u).expect("a lit map samples");
        assert!((pdf - table.pdf(&env, dir)).abs() <= 1e-3 * pdf);
        let uv = direction_uv(local_direction(dir, env.rotation_deg));
        let b = ((uv.y * bv as f32) as usize).min(bv - 1) * bu
            + ((uv.x * bu as f32) as usize).min(bu - 1);
        observed[b] += 1.0;
    }
    // Expected: the cells' probabilities (density × cell area in uv).
    let (w, h) = (env.width as usize, env.height as usize);
    let mut expected = vec![0.0f64; bu * bv];
    for y in 0..h {
        for x in 0..w {
            let p = f64::from(f32::from_bits(table.records[y * w + x][2])) / (w * h) as f64;
            expected[(y * bv / h) * bu + x * bu / w] += p * n as f64;
        }
    }
    let (mut chi2, mut dof) = (0.0, 0usize);
    for (o, e) in observed.iter().zip(&expected) {
        if *e > 5.0 {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        } else {
            assert!(
                *o <= 5.0 + 4.0 * e.sqrt().max(1.0),
                "{o} where {e} expected"
            );
        }
    }
    // The 99.9% quantile of χ² with 63 degrees of freedom is 103.4.
    assert!(dof > 40 && chi2 < 103.4, "χ² = {chi2} over {dof} bins");
}

#[test]
fn a_black_map_is_not_sampled() {
    let env = map(4, 2, |_, _| [0.0; 3]);
    let table = EnvironmentTable::build(&env);
    assert!(!table.sampled);
    assert_eq!(table.sample(&env, [0.5; 4]), None);
    assert_eq!(table.pdf(&env, Vec3::Y), 0.0);
}

/// The irradiance a surface facing `n` gets, over π, by brute force.
fn brute_irradiance(env: &Environment, n: Vec3) -> Vec3 {
    let (nu, nv) = (1024, 512);
    let mut sum = glam::DVec3::ZERO;
    for j in 0..nv {
        for i in 0..nu {
            let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let d = world_direction(uv_direction(uv), env.rotation_deg);
            let cos = n.dot(d);
            if cos > 0.0 {
                let d_omega = (2.0 * PI / nu as f32) * (PI / nv as f32) * (uv.y * PI).sin();
                sum += (radiance(env, d) * cos * d_omega).as_dvec3();
            }
        }
    }
    (sum / std::f64::consts::PI).as_vec3()
}

/// SH9 irradiance of a smooth sky (a gradient and a broad warm lobe)
/// against brute-force integration, within 1% at seven normals.
#[test]
fn sh_irradiance_matches_numerical_integration() {
    let mut env = map(64, 32, |x, y| {
        let d = uv_direction(Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 32.0));
        let lobe = (2.0 * (d.dot(Vec3::new(0.6, 0.6, 0.52).normalize()) - 1.0)).exp();
        [
            0.3 + 2.0 * lobe,
            0.4 + 1.5 * lobe + 0.2 * d.y,
            0.6 + 0.5 * lobe + 0.3 * d.y,
        ]
    });
    env.rotation_deg = 60.0;
    env.intensity = 1.5;
    let sh = irradiance_sh(&env);
    for n in [
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::X,
        Vec3::NEG_Z,
        Vec3::new(0.5, 0.7, -0.3),
        Vec3::new(-0.4, -0.2, 0.9),
        Vec3::new(0.6, 0.6, 0.52),
    ] {
        let n = n.normalize();
        let basis = sh9(local_direction(n, env.rotation_deg));
        let from_sh: Vec3 = sh.iter().zip(basis).map(|(c, y)| *c * y).sum();
        let brute = brute_irradiance(&env, n);
        let error = ((from_sh - brute) / brute).abs().max_element();
        assert!(
            error < 0.01,
            "n {n}: SH {from_sh} against {brute} ({error})"
        );
    }
}
