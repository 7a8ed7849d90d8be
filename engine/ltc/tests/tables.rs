//! The committed tables (`engine/ltc/tables/ltc_tables.txt`) against brute
//! force: at table entries, the LTC's integral over rectangular lights is
//! compared with the lobe's integral over them (quadrature over the light's
//! area), as the share of the lobe's energy misplaced (|LTC - lobe| / the
//! lobe's integral, every light) and as a relative error (lights that catch
//! at least 10% of the lobe); and the tables hold the lobes' integrals.
//! docs/lights.md ("Analytic area lights") lists the measured figures.

use glam::Vec3;
use weft_ltc::fit::{moments, Entry};
use weft_ltc::lobe::{BlinnPhong, Ggx, Lobe};
use weft_ltc::{blinn_phong_exponent, column_cos, row_roughness, TABLE_SIZE};

fn table(name: &str) -> Vec<Entry> {
    let tables = weft_ltc::tables::committed().expect("the committed tables read");
    match name {
        "LTC_GGX" => tables.ggx.clone(),
        _ => tables.blinn_phong.clone(),
    }
}

/// The lobe's integral over the rectangle `corner + [0, 1] x + [0, 1] y`
/// (the shading point at the origin, normal +Z) by an n x n quadrature.
fn brute_force<L: Lobe>(lobe: &L, v: Vec3, corner: Vec3, x: Vec3, y: Vec3, n: usize) -> f64 {
    let normal = x.cross(y).normalize();
    let cell = x.cross(y).length() as f64 / (n * n) as f64;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let p = corner + x * ((i as f32 + 0.5) / n as f32) + y * ((j as f32 + 0.5) / n as f32);
            let d2 = p.length_squared();
            let l = p / d2.sqrt();
            let solid_angle = l.dot(normal).abs() as f64 * cell / d2 as f64;
            sum += lobe.eval(v, l).0 as f64 * solid_angle;
        }
    }
    sum
}

/// Rectangles around the shading point: overhead, towards the mirror
/// direction, off to the side, and one crossing the horizon.
fn lights(v: Vec3) -> Vec<(Vec3, Vec3, Vec3)> {
    let mirror = Vec3::new(-v.x, 0.0, v.z) * 2.0;
    vec![
        (Vec3::new(-0.5, -0.5, 1.5), Vec3::X, Vec3::Y),
        (
            mirror - Vec3::new(0.4, 0.4, 0.0),
            Vec3::new(0.8, 0.0, 0.0),
            Vec3::new(0.0, 0.8, 0.0),
        ),
        (
            Vec3::new(0.5, 1.0, 0.5),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ),
        (
            Vec3::new(-1.0, -1.0, -0.5),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.5),
        ),
    ]
}

/// Errors of `entries` at rows `rows` and every fourth column, over the
/// lights of [`lights`] that receive at least 1% of the lobe: the misplaced
/// share of the lobe, and the relative error where the light catches at
/// least 10% of it.
fn errors<L: Lobe>(
    entries: &[Entry],
    rows: &[usize],
    lobe_at: impl Fn(f32) -> L,
) -> (Vec<f64>, Vec<f64>) {
    let (mut misplaced, mut relative) = (Vec::new(), Vec::new());
    for &row in rows {
        let lobe = lobe_at(row_roughness(row));
        for column in (0..TABLE_SIZE).step_by(4) {
            let cos_v = column_cos(column);
            let v = Vec3::new((1.0 - cos_v * cos_v).sqrt(), 0.0, cos_v);
            let entry = entries[row * TABLE_SIZE + column];
            let ltc = entry.ltc();
            for (corner, x, y) in lights(v) {
                let reference = brute_force(&lobe, v, corner, x, y, 300);
                if reference < 0.01 * entry.magnitude as f64 {
                    continue;
                }
                let quad = [corner, corner + x, corner + x + y, corner + y];
                let fitted = entry.magnitude as f64 * ltc.polygon_integral(&quad).abs() as f64;
                let magnitude = entry.magnitude as f64;
                misplaced.push((fitted - reference).abs() / magnitude);
                if reference >= 0.1 * magnitude {
                    relative.push((fitted - reference).abs() / reference);
                }
            }
        }
    }
    (misplaced, relative)
}

fn summary(errors: &[f64]) -> (f64, f64) {
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    (mean, errors.iter().copied().fold(0.0, f64::max))
}

/// Checks and prints the errors against (mean, max) bounds for each measure.
fn assert_within(what: &str, (misplaced, relative): (Vec<f64>, Vec<f64>), bounds: [(f64, f64); 2]) {
    let m = summary(&misplaced);
    let r = summary(&relative);
    eprintln!(
        "{what}: {} lights, misplaced share mean {:.4} max {:.4}; {} lights with >= 10% of the lobe, relative error mean {:.4} max {:.4}",
        misplaced.len(), m.0, m.1, relative.len(), r.0, r.1
    );
    assert!(misplaced.len() >= 60 && relative.len() >= 30);
    assert!(
        m.0 <= bounds[0].0 && m.1 <= bounds[0].1,
        "{what}: misplaced {m:?}"
    );
    assert!(
        r.0 <= bounds[1].0 && r.1 <= bounds[1].1,
        "{what}: relative {r:?}"
    );
}

#[test]
fn the_ggx_table_matches_brute_force_over_rectangles() {
    let ggx = table("LTC_GGX");
    let e = errors(&ggx, &[8, 16, 24, 31], |r| Ggx { alpha: r * r });
    assert_within("GGX", e, [(0.01, 0.04), (0.03, 0.1)]);
}

/// A scaled clamped cosine has heavier tails than the near-Gaussian
/// Blinn-Phong highlight: sharp highlights (row 8, n = 457) lose up to 17%
/// of their energy outside a light that holds 93% of the lobe.
#[test]
fn the_blinn_phong_table_matches_brute_force_over_rectangles() {
    let table = table("LTC_BLINN_PHONG");
    let e = errors(&table, &[8, 16, 24, 31], |r| BlinnPhong {
        exponent: blinn_phong_exponent(r),
    });
    assert_within("Blinn-Phong", e, [(0.03, 0.2), (0.08, 0.25)]);
}

#[test]
fn the_tables_hold_the_lobes_integrals() {
    for (name, lobe_at) in [
        (
            "LTC_GGX",
            Box::new(|r: f32| Box::new(Ggx { alpha: r * r }) as Box<dyn Lobe>)
                as Box<dyn Fn(f32) -> Box<dyn Lobe>>,
        ),
        (
            "LTC_BLINN_PHONG",
            Box::new(|r: f32| {
                Box::new(BlinnPhong {
                    exponent: blinn_phong_exponent(r),
                }) as Box<dyn Lobe>
            }),
        ),
    ] {
        let entries = table(name);
        for (row, column) in [(31, 0), (16, 10), (5, 20), (24, 31)] {
            let cos_v = column_cos(column);
            let v = Vec3::new((1.0 - cos_v * cos_v).sqrt(), 0.0, cos_v);
            let (magnitude, fresnel, _) = moments(&DynLobe(lobe_at(row_roughness(row))), v);
            let e = entries[row * TABLE_SIZE + column];
            assert!(
                (e.magnitude - magnitude).abs() <= 1e-5 * magnitude.max(1.0),
                "{name} {row} {column}"
            );
            assert!(
                (e.fresnel - fresnel).abs() <= 1e-5 * magnitude.max(1.0),
                "{name} {row} {column}"
            );
        }
    }
}

struct DynLobe(Box<dyn Lobe>);

impl Lobe for DynLobe {
    fn eval(&self, v: Vec3, l: Vec3) -> (f32, f32) {
        self.0.eval(v, l)
    }
    fn sample(&self, v: Vec3, u1: f32, u2: f32) -> Vec3 {
        self.0.sample(v, u1, u2)
    }
}
