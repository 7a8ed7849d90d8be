//! ReSTIR's estimator on its own (the reservoirs of
//! shaders/restir/stream.glsl): a CPU model of resampled importance sampling
//! over mixed light kinds, merged by the generalized balance heuristic, is
//! unbiased against a closed form; and the GPU's reservoirs, run through
//! that model's steps on the same random numbers by the fixture
//! tests/shaders/reservoir_model.comp, give its result.

use std::collections::BTreeMap;
use weft_scene::rng::Rng;

/// The CPU model: lights of two kinds for a surface at `x` in [0, 1] — a
/// point light (one choice, contribution `point(x)`) and a unit segment
/// light (contribution `segment(x, u)` for u uniform) — chosen with
/// probability 0.3 and 0.7. Each pixel draws `m` candidates and keeps one by
/// resampled importance sampling with the contribution as target; a pixel
/// then merges its reservoir with its neighbours' by the generalized balance
/// heuristic. The estimate's mean over seeds is the closed form
/// point(x) + integral of segment(x, u) du within 4 standard errors.
#[test]
fn the_estimator_model_is_unbiased_for_mixed_lights_after_merging() {
    #[derive(Clone, Copy)]
    struct Sample {
        light: usize,
        u: f64,
    }
    #[derive(Clone, Copy)]
    struct Reservoir {
        sample: Option<Sample>,
        weight: f64,
        m: f64,
    }
    let point = |x: f64| 0.5 + x;
    let segment = |x: f64, u: f64| 3.0 * (u - x) * (u - x) + 0.1;
    let target = |x: f64, s: Sample| {
        if s.light == 0 {
            point(x)
        } else {
            segment(x, s.u)
        }
    };
    let p_select = [0.3, 0.7];
    let exact = |x: f64| point(x) + (1.0 - x).powi(3) + x.powi(3) + 0.1;
    let ris = |x: f64, m: usize, rng: &mut Rng| {
        let (mut kept, mut w_sum) = (None, 0.0);
        for _ in 0..m {
            let light = usize::from(rng.next_f32() >= 0.3);
            let s = Sample {
                light,
                u: f64::from(rng.next_f32()),
            };
            let w = target(x, s) / p_select[light];
            w_sum += w;
            if f64::from(rng.next_f32()) * w_sum < w {
                kept = Some(s);
            }
        }
        let weight = kept.map_or(0.0, |s| w_sum / (m as f64 * target(x, s)));
        Reservoir {
            sample: kept,
            weight,
            m: m as f64,
        }
    };
    let surfaces = [0.2, 0.35, 0.6];
    let counts = [4, 1, 8];
    let runs = 20_000;
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    let mut rng = Rng::new(7);
    for _ in 0..runs {
        let reservoirs: Vec<Reservoir> = surfaces
            .iter()
            .zip(counts)
            .map(|(&x, m)| ris(x, m, &mut rng))
            .collect();
        let here = surfaces[0];
        let (mut kept, mut w_sum) = (None, 0.0);
        for (i, r) in reservoirs.iter().enumerate() {
            let Some(s) = r.sample else { continue };
            let all: f64 = surfaces
                .iter()
                .zip(&reservoirs)
                .map(|(&x, q)| q.m * target(x, s))
                .sum();
            let w = r.m * target(surfaces[i], s) / all * target(here, s) * r.weight;
            w_sum += w;
            if f64::from(rng.next_f32()) * w_sum < w {
                kept = Some(s);
            }
        }
        // f(kept) W = target(here, kept) w_sum / target(here, kept).
        let estimate = if kept.is_some() { w_sum } else { 0.0 };
        sum += estimate;
        sum_sq += estimate * estimate;
    }
    let mean = sum / f64::from(runs);
    let error = ((sum_sq / f64::from(runs) - mean * mean) / f64::from(runs)).sqrt();
    let want = exact(surfaces[0]);
    assert!(
        (mean - want).abs() < 4.0 * error,
        "mean {mean:.5} ± {error:.5}, closed form {want:.5}"
    );
    assert!(
        error < 0.01 * want,
        "standard error {error:.5} too large to test"
    );
}

/// Draw `n` of fixture run `run`: the fixture's lowbias32 hash of
/// (run, n), 24 bits, as tests/shaders/reservoir_model.comp draws it.
fn fixed_draw(run: u32, n: &mut u32) -> f32 {
    let mut x = run * 1024 + *n;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    *n += 1;
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The model's steps in f32, in the fixture's order, on the fixture's
/// numbers: (estimate, kept light or -1, its u, merged count).
fn fixed_run(run: u32) -> [f32; 4] {
    let surfaces = [0.2f32, 0.35, 0.6];
    let counts = [4, 1, 8];
    let p_select = [0.3f32, 0.7];
    let target = |x: f32, light: usize, u: f32| {
        if light == 0 {
            0.5 + x
        } else {
            3.0 * (u - x) * (u - x) + 0.1
        }
    };
    let mut n = 0;
    // Per surface: (kept light and u, W, M).
    let mut reservoirs = Vec::new();
    for (&x, m) in surfaces.iter().zip(counts) {
        let (mut kept, mut w_sum, mut kept_target) = (None, 0.0f32, 0.0f32);
        for _ in 0..m {
            let light = usize::from(fixed_draw(run, &mut n) >= 0.3);
            let u = fixed_draw(run, &mut n);
            let t = target(x, light, u);
            let w = t / p_select[light];
            w_sum += w;
            let xi = fixed_draw(run, &mut n);
            if w > 0.0 && xi * w_sum < w {
                kept = Some((light, u));
                kept_target = t;
            }
        }
        let weight = if kept_target > 0.0 {
            w_sum * (1.0 / m as f32) / kept_target
        } else {
            0.0
        };
        reservoirs.push((kept, weight, m as f32));
    }
    let (mut kept, mut w_sum, mut m_sum) = (None, 0.0f32, 0.0f32);
    for (k, &(sample, weight, m)) in reservoirs.iter().enumerate() {
        let Some((light, u)) = sample else { continue };
        let mut all = 0.0f32;
        for (&x, &(_, _, mj)) in surfaces.iter().zip(&reservoirs) {
            all += mj * target(x, light, u);
        }
        let here = target(surfaces[0], light, u);
        let w = m * target(surfaces[k], light, u) / all * here * weight;
        w_sum += w;
        m_sum += m;
        let xi = fixed_draw(run, &mut n);
        if w > 0.0 && xi * w_sum < w {
            kept = Some((light, u));
        }
    }
    match kept {
        Some((light, u)) => [w_sum, light as f32, u, m_sum],
        None => [0.0, -1.0, 0.0, m_sum],
    }
}

/// The GPU's reservoirs give the CPU model's result for the same random
/// numbers in every one of 256 runs: the same kept light and point, the same
/// merged count, the same estimate to float rounding.
#[test]
fn the_gpu_reservoirs_give_the_cpu_models_result_on_fixed_numbers() {
    let (estimates, kept) =
        weft_tests::render::fixture_floats("reservoir.ron", "kept", BTreeMap::new());
    assert_eq!((estimates.len(), kept.len()), (4 * 256, 4 * 256));
    let mut kept_by_light = [0; 2];
    for (run, (estimate, got)) in estimates.chunks(4).zip(kept.chunks(4)).enumerate() {
        let want = fixed_run(run as u32);
        let got = [estimate[0], got[0], got[1], got[2]];
        assert_eq!(
            (got[1], got[2], got[3]),
            (want[1], want[2], want[3]),
            "run {run}: GPU {got:?}, model {want:?}"
        );
        assert!(
            (got[0] - want[0]).abs() <= 1e-5 * want[0].abs(),
            "run {run}: GPU {got:?}, model {want:?}"
        );
        kept_by_light[got[1] as usize] += 1;
    }
    // Both kinds of light are kept in some runs, so both paths are compared.
    assert!(kept_by_light.iter().all(|&k| k > 20), "{kept_by_light:?}");
}
