//! Chi-square tests of the path tracer's BSDF sampling, on the GPU and on the
//! shader's own code (pbrt-v4's `bsdfs_test.cpp` is the model). For each
//! material, `tests/shaders/bsdf_sample.comp` draws 2^20 directions with
//! `bsdf_sample` and `tests/shaders/bsdf_pdf.comp` tabulates `bsdf_eval`'s
//! pdf on a 1024 x 512 grid over the hemisphere (phi x cos theta). The
//! directions are binned 32 x 16 in (phi, cos theta); each bin's expected count
//! is the grid's integral of the pdf over it; samples the routine rejects
//! and a mirror's delta samples get a bin each. Bins expecting fewer than 5
//! are pooled. The test fails when the chi-square statistic's p-value is below
//! 0.01 after Sidak's correction for the number of materials; p-values come
//! from the Wilson-Hilferty normal approximation of the chi-square
//! distribution (accurate to about 1e-3 in p at these degrees of freedom).
//! Every sample's reported pdf must also equal the tabulated pdf's kind: a
//! direction above the surface with a positive pdf.

use std::collections::BTreeMap;
use weft_graph::schema::ParamValue;

const PHI_BINS: usize = 32;
const COS_BINS: usize = 16;
/// The pdf grid (`density` in tests/graphs/bsdf_sampling.ron).
const GRID_PHI: usize = 1024;
const GRID_COS: usize = 512;

struct Case {
    name: &'static str,
    /// 0 Blinn-Phong, 1 metallic-roughness, 2 mirror (scene.glsl SHADING_*).
    model: f64,
    diffuse: f64,
    specular: f64,
    exponent: f64,
    metallic: f64,
    roughness: f64,
    wo_theta: f64,
}

const CASES: [Case; 8] = [
    Case {
        name: "Lambert",
        model: 0.0,
        diffuse: 0.8,
        specular: 0.0,
        exponent: 0.0,
        metallic: 0.0,
        roughness: 0.0,
        wo_theta: 0.5,
    },
    Case {
        name: "Blinn-Phong Ns 20",
        model: 0.0,
        diffuse: 0.5,
        specular: 0.5,
        exponent: 20.0,
        metallic: 0.0,
        roughness: 0.0,
        wo_theta: 0.5,
    },
    Case {
        name: "Blinn-Phong Ns 200, grazing",
        model: 0.0,
        diffuse: 0.2,
        specular: 0.6,
        exponent: 200.0,
        metallic: 0.0,
        roughness: 0.0,
        wo_theta: 1.0,
    },
    Case {
        name: "GGX dielectric r 0.5",
        model: 1.0,
        diffuse: 0.8,
        specular: 0.0,
        exponent: 0.0,
        metallic: 0.0,
        roughness: 0.5,
        wo_theta: 0.5,
    },
    Case {
        name: "GGX metal r 0.3, grazing",
        model: 1.0,
        diffuse: 0.9,
        specular: 0.0,
        exponent: 0.0,
        metallic: 1.0,
        roughness: 0.3,
        wo_theta: 1.2,
    },
    Case {
        name: "GGX metal r 0.8",
        model: 1.0,
        diffuse: 0.9,
        specular: 0.0,
        exponent: 0.0,
        metallic: 1.0,
        roughness: 0.8,
        wo_theta: 0.2,
    },
    Case {
        name: "GGX half metal r 0.2",
        model: 1.0,
        diffuse: 0.7,
        specular: 0.0,
        exponent: 0.0,
        metallic: 0.5,
        roughness: 0.2,
        wo_theta: 0.8,
    },
    Case {
        name: "mirror over Lambert",
        model: 2.0,
        diffuse: 0.3,
        specular: 0.6,
        exponent: 1000.0,
        metallic: 0.0,
        roughness: 0.0,
        wo_theta: 0.7,
    },
];

/// The two images the fixture graph produces for `case`: samples, density.
fn run(case: &Case) -> (Vec<f32>, Vec<f32>) {
    let grey = |v: f64| ParamValue::Vector(vec![v, v, v, 1.0]);
    let params = BTreeMap::from([
        ("model".to_string(), ParamValue::Number(case.model)),
        ("diffuse".to_string(), grey(case.diffuse)),
        ("specular".to_string(), grey(case.specular)),
        ("exponent".to_string(), ParamValue::Number(case.exponent)),
        ("metallic".to_string(), ParamValue::Number(case.metallic)),
        ("roughness".to_string(), ParamValue::Number(case.roughness)),
        ("wo_theta".to_string(), ParamValue::Number(case.wo_theta)),
    ]);
    weft_tests::render::fixture_floats("bsdf_sampling.ron", "density", params)
}

/// erfc(x) for x >= 0 (Abramowitz and Stegun 7.1.26, error under 1.5e-7).
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    poly * (-x * x).exp()
}

/// P(X >= chi2) for a chi-square variable with `dof` degrees of freedom,
/// by the Wilson-Hilferty cube-root normal approximation.
fn chi2_p_value(chi2: f64, dof: f64) -> f64 {
    let s = 2.0 / (9.0 * dof);
    let z = ((chi2 / dof).powf(1.0 / 3.0) - (1.0 - s)) / s.sqrt();
    if z <= 0.0 {
        1.0 - 0.5 * erfc(-z / std::f64::consts::SQRT_2)
    } else {
        0.5 * erfc(z / std::f64::consts::SQRT_2)
    }
}

/// Luminance of a grey colour: the value itself.
fn p_specular_of_mirror(case: &Case) -> f64 {
    case.specular / (case.specular + case.diffuse)
}

#[test]
fn chi2_p_values_of_the_tail_approximation_are_right() {
    // Reference values from the exact chi-square distribution.
    assert!((chi2_p_value(100.0, 100.0) - 0.4812).abs() < 2e-3);
    assert!((chi2_p_value(150.0, 100.0) - 0.000_954).abs() < 2e-4);
    assert!((chi2_p_value(400.0, 400.0) - 0.4906).abs() < 2e-3);
}

#[test]
fn every_bsdf_samples_directions_as_its_pdf_says() {
    let significance = 1.0 - (1.0f64 - 0.01).powf(1.0 / CASES.len() as f64);
    let mut failures = Vec::new();
    for case in &CASES {
        let (samples, density) = run(case);
        let n = (samples.len() / 4) as f64;
        // Observed counts: the hemisphere bins, then rejected, then delta.
        let mut observed = vec![0.0f64; PHI_BINS * COS_BINS + 2];
        for s in samples.chunks(4) {
            let (x, y, z, pdf) = (s[0], s[1], s[2], s[3]);
            let slot = if pdf < 0.0 {
                PHI_BINS * COS_BINS
            } else if pdf == 0.0 {
                PHI_BINS * COS_BINS + 1
            } else {
                assert!(z > 0.0 && pdf.is_finite(), "{}: sample {s:?}", case.name);
                let phi = f64::from(y.atan2(x)).rem_euclid(std::f64::consts::TAU);
                let i = ((phi / std::f64::consts::TAU) * PHI_BINS as f64) as usize;
                let j = (f64::from(z) * COS_BINS as f64) as usize;
                j.min(COS_BINS - 1) * PHI_BINS + i.min(PHI_BINS - 1)
            };
            observed[slot] += 1.0;
        }
        // Expected counts from the tabulated pdf.
        let cell = (1.0 / GRID_COS as f64) * (std::f64::consts::TAU / GRID_PHI as f64);
        let mut expected = vec![0.0f64; PHI_BINS * COS_BINS + 2];
        let (mut integral, mut albedo) = (0.0, 0.0);
        for j in 0..GRID_COS {
            for i in 0..GRID_PHI {
                let p = f64::from(density[(j * GRID_PHI + i) * 4]) * cell;
                let bin = (j * COS_BINS / GRID_COS) * PHI_BINS + i * PHI_BINS / GRID_PHI;
                expected[bin] += p * n;
                integral += p;
                albedo += f64::from(density[(j * GRID_PHI + i) * 4 + 1]) * cell;
            }
        }
        // The tracer's GGX on the GPU reflects what the energy-conserving
        // model's closed form says (weft_testkit::brdf, held to the white
        // furnace there): the grid's integral of f cos, within its
        // resolution.
        if case.model == 1.0 {
            let base = glam::Vec3::splat(case.diffuse as f32);
            let closed = weft_testkit::brdf::directional_albedo(
                base,
                case.metallic as f32,
                case.roughness as f32,
                (case.wo_theta as f32).cos(),
            );
            let closed = f64::from(closed.dot(glam::Vec3::new(0.2126, 0.7152, 0.0722)));
            println!("{}: albedo {albedo:.5}, closed form {closed:.5}", case.name);
            if (albedo - closed).abs() > 1e-3 * closed {
                failures.push(format!(
                    "{}: bsdf_eval reflects {albedo} of a white environment; the model says {closed}",
                    case.name
                ));
            }
        }
        let delta = if case.model == 2.0 {
            p_specular_of_mirror(case)
        } else {
            0.0
        };
        if integral + delta > 1.002 {
            failures.push(format!(
                "{}: the pdf integrates to {} over the hemisphere, more than 1",
                case.name,
                integral + delta
            ));
            continue;
        }
        expected[PHI_BINS * COS_BINS + 1] = delta * n;
        expected[PHI_BINS * COS_BINS] = (1.0 - integral - delta).max(0.0) * n;
        // Pool the bins expecting fewer than 5.
        let (mut chi2, mut dof) = (0.0, -1.0);
        let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
        for (o, e) in observed.iter().zip(&expected) {
            if *e < 5.0 {
                pooled_observed += o;
                pooled_expected += e;
            } else {
                chi2 += (o - e) * (o - e) / e;
                dof += 1.0;
            }
        }
        if pooled_expected > 0.0 {
            chi2 += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
            dof += 1.0;
        } else {
            assert_eq!(
                pooled_observed, 0.0,
                "{}: samples where the pdf is 0",
                case.name
            );
        }
        let p = chi2_p_value(chi2, dof);
        println!(
            "{}: chi2 {chi2:.1}, {dof} dof, p {p:.4}; pdf integrates to {integral:.5}, {} rejected",
            case.name,
            observed[PHI_BINS * COS_BINS]
        );
        if case.model == 0.0 && case.specular == 0.0 {
            assert!(
                (integral - 1.0).abs() < 1e-3,
                "Lambert's pdf integrates to {integral}"
            );
        }
        if p < significance {
            failures.push(format!("{}: p = {p} (chi2 {chi2}, {dof} dof)", case.name));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
