//! The integral of the clamped cosine `max(z, 0) / pi` over a spherical
//! polygon: the form factor of a polygonal light towards a surface facing
//! +Z. [`cosine_integral`] clips the polygon to the upper hemisphere and
//! integrates it exactly (Lambert's closed form); [`cap_approximation`] is
//! what the shaders do (`ltc_integral` in `shaders/include/ltc.glsl`): the
//! unclipped vector form factor, with the horizon accounted for by the
//! spherical cap of the same vector form factor, exact above the horizon.

use glam::Vec3;
use std::f32::consts::PI;

/// The polygon `vertices` (seen from the origin, any length) cut to z >= 0.
pub fn clip_to_horizon(vertices: &[Vec3]) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(vertices.len() + 1);
    for (i, &a) in vertices.iter().enumerate() {
        let b = vertices[(i + 1) % vertices.len()];
        if a.z >= 0.0 {
            out.push(a);
        }
        if (a.z >= 0.0) != (b.z >= 0.0) {
            let t = a.z / (a.z - b.z);
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// `theta / sin(theta) / (2 pi)` for `x = cos(theta)` as the shaders compute
/// it: a rational fit in `|x|` (`tools/fit_ltc_edge.py`), and for negative
/// cosines `pi / sin - (pi - theta) / sin` over 2 pi.
pub fn edge_factor(x: f32) -> f32 {
    let x = x.clamp(-1.0, 1.0);
    let y = x.abs();
    let fit =
        (0.867_194_9 + (0.498_650_05 + 0.014_268_17 * y) * y) / (3.468_784 + (4.202_714 + y) * y);
    if x >= 0.0 {
        fit
    } else {
        0.5 / (1.0 - x * x).max(1e-7).sqrt() - fit
    }
}

/// One edge's share of the vector form factor: `theta / sin(theta) (a × b)`
/// for unit `a`, `b` at angle theta, over 2 pi.
pub fn edge(a: Vec3, b: Vec3) -> Vec3 {
    let c = a.dot(b).clamp(-1.0, 1.0);
    let theta = c.acos();
    let s = theta.sin();
    let k = if s > 1e-6 { theta / s } else { 1.0 };
    a.cross(b) * (k / (2.0 * PI))
}

/// The vector form factor of the polygon `vertices` (no clipping).
pub fn vector_form_factor(vertices: &[Vec3]) -> Vec3 {
    let unit: Vec<Vec3> = vertices.iter().map(|p| p.normalize()).collect();
    (0..unit.len())
        .map(|i| edge(unit[i], unit[(i + 1) % unit.len()]))
        .sum()
}

/// The integral of `max(z, 0) / pi` over a spherical cap with
/// `sin²(radius)` = `sin2_radius` centred at height `cos_elevation`,
/// clipped to the horizon (Snyder's closed form).
pub fn cap_integral(sin2_radius: f32, cos_elevation: f32) -> f32 {
    if cos_elevation * cos_elevation > sin2_radius {
        return cos_elevation.max(0.0) * sin2_radius;
    }
    let sin_elevation = (1.0 - cos_elevation * cos_elevation).max(1e-12).sqrt();
    let x = (1.0 / sin2_radius - 1.0).max(0.0).sqrt();
    let y = (-x * cos_elevation / sin_elevation).clamp(-1.0, 1.0);
    let w = sin_elevation * (1.0 - y * y).sqrt();
    let integral = (cos_elevation * y.acos() - x * w) * sin2_radius + w.atan2(x);
    (integral / PI).max(0.0)
}

/// The shaders' integral: the cap of the polygon's vector form factor
/// (turned by `side`, +1 for counter-clockwise about +Z), clipped.
pub fn cap_approximation(vertices: &[Vec3], side: f32) -> f32 {
    let f = vector_form_factor(vertices) * side;
    let len = f.length();
    if len > 0.0 {
        cap_integral(len.min(1.0), f.z / len)
    } else {
        0.0
    }
}

/// `integral over the polygon of max(z, 0) / pi`, signed by winding
/// (positive when the vertices turn counter-clockwise about +Z).
pub fn cosine_integral(vertices: &[Vec3]) -> f32 {
    let clipped = clip_to_horizon(vertices);
    if clipped.len() < 3 {
        return 0.0;
    }
    vector_form_factor(&clipped).z
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same integral by brute force over the polygon's plane (a
    /// rectangle at height h, counter-clockwise seen from below).
    fn brute_force(corner: Vec3, x: Vec3, y: Vec3, n: usize) -> f64 {
        let normal = x.cross(y).normalize();
        let area = x.cross(y).length() as f64;
        let mut sum = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                let p =
                    corner + x * ((i as f32 + 0.5) / n as f32) + y * ((j as f32 + 0.5) / n as f32);
                let d2 = p.length_squared();
                let l = p / d2.sqrt();
                let cos_light = l.dot(normal).abs();
                sum += (l.z.max(0.0) * cos_light / d2) as f64 * area / (n * n) as f64;
            }
        }
        sum / PI as f64
    }

    #[test]
    fn the_closed_form_matches_brute_force_above_and_across_the_horizon() {
        let cases = [
            (Vec3::new(-0.5, -0.5, 1.0), Vec3::X, Vec3::Y),
            (
                Vec3::new(0.3, -2.0, 0.5),
                Vec3::new(1.0, 0.0, 0.2),
                Vec3::new(0.0, 3.0, 0.1),
            ),
            // Crossing the horizon: half the rectangle is below z = 0.
            (
                Vec3::new(-1.0, 0.5, -1.0),
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 2.0),
            ),
        ];
        for (corner, x, y) in cases {
            let quad = [corner, corner + x, corner + x + y, corner + y];
            let exact = cosine_integral(&quad).abs() as f64;
            let brute = brute_force(corner, x, y, 1000);
            assert!((exact - brute).abs() <= 2e-3 * brute, "{exact} vs {brute}");
        }
        // A polygon wholly below the horizon contributes nothing.
        let below = [
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 1.0, -1.0),
        ];
        assert_eq!(cosine_integral(&below), 0.0);
        // The whole upper hemisphere (a huge quad just above the horizon): 1.
        let r = 1e4;
        let hemisphere = [
            Vec3::new(-r, -r, 1e-3),
            Vec3::new(r, -r, 1e-3),
            Vec3::new(r, r, 1e-3),
            Vec3::new(-r, r, 1e-3),
        ];
        assert!((cosine_integral(&hemisphere) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn the_cap_is_exact_above_the_horizon_and_close_across_it() {
        let quad =
            |corner: Vec3, x: Vec3, y: Vec3| [corner, corner + x, corner + x + y, corner + y];
        // Wholly above: the same as clipping.
        let above = quad(
            Vec3::new(0.3, -2.0, 0.5),
            Vec3::new(1.0, 0.0, 0.2),
            Vec3::new(0.0, 3.0, 0.1),
        );
        let exact = cosine_integral(&above);
        assert!((cap_approximation(&above, exact.signum()) - exact.abs()).abs() < 1e-5);
        // A unit square light 1 above the plane, tilted and slid across the
        // horizon: the worst error, as a share of the light's integral when
        // wholly above.
        let mut worst = 0.0f32;
        for step in 0..=20 {
            let h = 1.0 - step as f32 * 0.1;
            let (x, y) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.3, 0.0, 1.0));
            let light = quad(Vec3::new(1.0, -0.5, h - 0.5), x, y);
            // The side as the shaders find it: the centre against x × y.
            let centre = light[0] + (x + y) * 0.5;
            let side = if centre.dot(x.cross(y)) >= 0.0 {
                1.0
            } else {
                -1.0
            };
            let exact = cosine_integral(&light) * side;
            let cap = cap_approximation(&light, side);
            worst = worst.max((cap - exact).abs());
        }
        let reference = cosine_integral(&quad(
            Vec3::new(1.0, -0.5, 0.5),
            Vec3::Y,
            Vec3::new(0.3, 0.0, 1.0),
        ))
        .abs();
        eprintln!("horizon: worst error {worst:.5} of a light worth {reference:.5}");
        assert!(worst <= 0.03 * reference, "{worst} vs {reference}");
    }

    #[test]
    fn the_shaders_edge_factor_matches_theta_over_sine() {
        let mut worst = 0.0f64;
        for i in 0..=20000 {
            let x = -0.9999 + 1.9998 * f64::from(i) / 20000.0;
            let theta = x.acos();
            let exact = theta / theta.sin() / (2.0 * std::f64::consts::PI);
            let fit = f64::from(edge_factor(x as f32));
            worst = worst.max((fit - exact).abs() / exact);
        }
        // f32 near cos = -1 loses digits to the subtraction: at most 1.1e-4 there.
        assert!(worst < 2e-4, "largest relative error {worst}");
    }
}
