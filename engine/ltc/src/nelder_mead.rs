//! Nelder-Mead simplex minimisation, for the few parameters of an LTC fit.

/// Minimises `f` from `start`, with an initial simplex of `start` plus
/// `delta` along each axis, for at most `iterations` steps or until the
/// simplex's values differ by less than `tolerance`. Returns the best point.
pub fn minimise<const N: usize>(
    f: impl Fn(&[f32; N]) -> f32,
    start: [f32; N],
    delta: f32,
    tolerance: f32,
    iterations: usize,
) -> [f32; N] {
    let mut simplex: Vec<([f32; N], f32)> = (0..=N)
        .map(|i| {
            let mut p = start;
            if i > 0 {
                p[i - 1] += delta;
            }
            (p, f(&p))
        })
        .collect();
    let along = |a: &[f32; N], b: &[f32; N], t: f32| -> [f32; N] {
        let mut p = [0.0; N];
        for k in 0..N {
            p[k] = a[k] + (b[k] - a[k]) * t;
        }
        p
    };
    for _ in 0..iterations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (simplex[N].1 - simplex[0].1).abs() < tolerance {
            break;
        }
        let mut centroid = [0.0; N];
        for (p, _) in &simplex[..N] {
            for k in 0..N {
                centroid[k] += p[k] / N as f32;
            }
        }
        let worst = simplex[N];
        let reflected = along(&centroid, &worst.0, -1.0);
        let fr = f(&reflected);
        if fr < simplex[0].1 {
            let expanded = along(&centroid, &worst.0, -2.0);
            let fe = f(&expanded);
            simplex[N] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < simplex[N - 1].1 {
            simplex[N] = (reflected, fr);
        } else {
            let (toward, ft) = if fr < worst.1 { (reflected, fr) } else { worst };
            let contracted = along(&centroid, &toward, 0.5);
            let fc = f(&contracted);
            if fc < ft {
                simplex[N] = (contracted, fc);
            } else {
                let best = simplex[0].0;
                for entry in simplex.iter_mut().skip(1) {
                    let p = along(&best, &entry.0, 0.5);
                    *entry = (p, f(&p));
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex[0].0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_rosenbrock_valley() {
        let rosenbrock = |p: &[f32; 2]| (1.0 - p[0]).powi(2) + 100.0 * (p[1] - p[0] * p[0]).powi(2);
        let best = minimise(rosenbrock, [-1.2, 1.0], 0.1, 1e-12, 2000);
        assert!(
            (best[0] - 1.0).abs() < 1e-2 && (best[1] - 1.0).abs() < 2e-2,
            "{best:?}"
        );
        let bowl =
            |p: &[f32; 3]| (p[0] - 2.0).powi(2) + (p[1] + 1.0).powi(2) + (p[2] - 0.5).powi(2);
        let best = minimise(bowl, [0.0; 3], 0.5, 1e-12, 500);
        assert!(
            best.iter()
                .zip([2.0, -1.0, 0.5])
                .all(|(a, b)| (a - b).abs() < 1e-3),
            "{best:?}"
        );
    }
}
