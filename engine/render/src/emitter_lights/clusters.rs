//! Many-triangle emitters to a light budget: when a scene's emissive
//! polygons outnumber what raster passes shade
//! ([`super::MAX_EMITTER_LIGHTS`]), polygons that face about
//! the same way and lie near each other become one square light each.
//!
//! Polygons are grouped by their normal (each component rounded to the
//! nearest half, so members are at most 51° apart; to the nearest whole,
//! 90°, if that cannot fit the budget) and by a cell of a spatial grid, which
//! doubles in size until the groups fit it.
//! A group's light faces its members' area-weighted mean normal N, has their
//! area projected onto N (a member's a max(0, n·N)), and emits so that its
//! power is the members' projected power, from their power-weighted centre.
//! So the power lost is exactly the projection's (reported as
//! [`Clustered::lost_power`]), and no member's direction is more than
//! [`Clustered::worst_angle`] off its light's. A group of one keeps its
//! polygon as it is.

use super::EmitterPolygon;
use crate::emitters::luminance;
use glam::Vec3;
use std::collections::BTreeMap;

/// Emissive polygons after clustering.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Clustered {
    /// The lights: kept polygons and one square per cluster.
    pub polygons: Vec<EmitterPolygon>,
    /// Lights that stand for more than one polygon.
    pub clusters: usize,
    /// Polygons merged into those clusters.
    pub members: usize,
    /// Largest angle, in degrees, between a member's normal and its light's.
    pub worst_angle: f32,
    /// Share of the emitted power lost to projecting members onto their
    /// light's plane (0 to 1).
    pub lost_power: f64,
}

/// A polygon's group: its normal's components rounded to steps of
/// 1 / `steps`, and its cell at grid size `cell` from the corner `origin`
/// of the bounds.
fn group_key(p: &EmitterPolygon, steps: f32, origin: Vec3, cell: f32) -> ([i32; 3], [i32; 3]) {
    let centre = p.corners.iter().copied().sum::<Vec3>() / 4.0;
    (
        (p.normal() * steps).round().as_ivec3().to_array(),
        ((centre - origin) / cell).floor().as_ivec3().to_array(),
    )
}

/// Groups `polygons` into at most `budget` lights where the grid allows:
/// past a cell as large as all the polygons' bounds, normals alone part
/// them, and more groups than `budget` may remain (the caller keeps the most
/// powerful).
pub fn cluster(polygons: Vec<EmitterPolygon>, budget: usize) -> Clustered {
    if polygons.len() <= budget {
        return Clustered {
            polygons,
            ..Clustered::default()
        };
    }
    let (lo, hi) = polygons
        .iter()
        .flat_map(|p| p.corners)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| {
            (lo.min(c), hi.max(c))
        });
    let extent = (hi - lo).max_element().max(1e-6);
    // Half steps of the normal first (members at most 51° apart); whole
    // steps (at most 90°) when even one cell for everything leaves too many
    // groups. The measured worst angle is reported either way.
    let (mut steps, mut cell) = (2.0, extent / 64.0);
    let groups = loop {
        let mut groups: BTreeMap<([i32; 3], [i32; 3]), Vec<EmitterPolygon>> = BTreeMap::new();
        for p in &polygons {
            groups
                .entry(group_key(p, steps, lo, cell))
                .or_default()
                .push(*p);
        }
        if groups.len() <= budget || (cell > extent && steps == 1.0) {
            break groups;
        }
        if cell > extent {
            (steps, cell) = (1.0, extent / 64.0);
        } else {
            cell *= 2.0;
        }
    };
    let total: f64 = polygons.iter().map(EmitterPolygon::power).sum();
    let mut out = Clustered::default();
    let mut lost = 0.0f64;
    for members in groups.into_values() {
        if let [single] = members[..] {
            out.polygons.push(single);
            continue;
        }
        out.clusters += 1;
        out.members += members.len();
        let (light, projected_power) = merge(&members);
        lost += members.iter().map(EmitterPolygon::power).sum::<f64>() - projected_power;
        let normal = light.normal();
        for m in &members {
            let angle = m.normal().dot(normal).clamp(-1.0, 1.0).acos().to_degrees();
            out.worst_angle = out.worst_angle.max(angle);
        }
        out.polygons.push(light);
    }
    out.lost_power = if total > 0.0 {
        (lost / total).max(0.0)
    } else {
        0.0
    };
    out
}

/// One square light for `members` (see the module comment) and the power
/// it emits.
fn merge(members: &[EmitterPolygon]) -> (EmitterPolygon, f64) {
    let normal = members
        .iter()
        .map(|m| m.normal() * m.area())
        .sum::<Vec3>()
        .normalize_or(Vec3::Y);
    let mut area = 0.0f32;
    let mut flux = Vec3::ZERO;
    let (mut centre, mut weight) = (Vec3::ZERO, 0.0f32);
    for m in members {
        let projected = m.area() * m.normal().dot(normal).max(0.0);
        area += projected;
        flux += m.radiance * projected;
        let w = luminance(m.radiance) * m.area();
        centre += m.corners.iter().copied().sum::<Vec3>() / 4.0 * w;
        weight += w;
    }
    let centre = if weight > 0.0 {
        centre / weight
    } else {
        members[0].corners[0]
    };
    let radiance = if area > 0.0 { flux / area } else { Vec3::ZERO };
    let helper = if normal.x.abs() < 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let t = normal.cross(helper).normalize() * (0.5 * area.sqrt());
    let b = normal.cross(t);
    // Counter-clockwise about the normal, the side that emits.
    let light = EmitterPolygon {
        corners: [
            centre - t - b,
            centre + t - b,
            centre + t + b,
            centre - t + b,
        ],
        radiance,
    };
    (light, light.power())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square at `centre` facing `normal`, emitting `radiance`.
    fn square(centre: Vec3, normal: Vec3, radiance: f32) -> EmitterPolygon {
        let helper = if normal.x.abs() < 0.9 {
            Vec3::X
        } else {
            Vec3::Y
        };
        let t = normal.cross(helper).normalize() * 0.5;
        let b = normal.cross(t);
        EmitterPolygon {
            corners: [
                centre - t - b,
                centre + t - b,
                centre + t + b,
                centre - t + b,
            ],
            radiance: Vec3::splat(radiance),
        }
    }

    fn power(polygons: &[EmitterPolygon]) -> f64 {
        polygons.iter().map(EmitterPolygon::power).sum()
    }

    #[test]
    fn within_the_budget_nothing_changes() {
        let polygons: Vec<_> = (0..5)
            .map(|i| square(Vec3::X * i as f32, Vec3::Y, 1.0))
            .collect();
        let out = cluster(polygons.clone(), 8);
        assert_eq!(out.polygons, polygons);
        assert_eq!((out.clusters, out.members, out.lost_power), (0, 0, 0.0));
    }

    #[test]
    fn a_flat_panel_of_many_tiles_keeps_its_power_and_facing() {
        // 20 x 20 unit tiles facing down, brighter towards +x: 400 polygons.
        let polygons: Vec<_> = (0..400)
            .map(|i| {
                let (x, z) = ((i % 20) as f32, (i / 20) as f32);
                square(Vec3::new(x, 3.0, z), Vec3::NEG_Y, 1.0 + x)
            })
            .collect();
        let out = cluster(polygons.clone(), 64);
        assert!(out.polygons.len() <= 64, "{}", out.polygons.len());
        assert_eq!(out.members + out.polygons.len() - out.clusters, 400);
        assert!(
            out.lost_power < 1e-6 && out.worst_angle < 0.1,
            "{} {}",
            out.lost_power,
            out.worst_angle
        );
        let (before, after) = (power(&polygons), power(&out.polygons));
        assert!(
            (after - before).abs() < 1e-4 * before,
            "{before} vs {after}"
        );
        assert!(out
            .polygons
            .iter()
            .all(|p| p.normal().dot(Vec3::NEG_Y) > 0.9999));
        // The power-weighted centre leans towards the bright side.
        let centre = |p: &EmitterPolygon| p.corners.iter().copied().sum::<Vec3>() / 4.0;
        let mean_x = out
            .polygons
            .iter()
            .map(|p| centre(p).x * p.power() as f32)
            .sum::<f32>()
            / after as f32;
        let tiles_x = polygons
            .iter()
            .map(|p| centre(p).x * p.power() as f32)
            .sum::<f32>()
            / before as f32;
        assert!((mean_x - tiles_x).abs() < 0.01, "{mean_x} vs {tiles_x}");
    }

    #[test]
    fn a_sphere_keeps_its_power_but_what_projection_costs() {
        // 40 x 20 facets of a unit sphere facing out: 800 polygons.
        let mut polygons = Vec::new();
        for j in 0..20 {
            for i in 0..40 {
                let theta = (j as f32 + 0.5) / 20.0 * std::f32::consts::PI;
                let phi = (i as f32 + 0.5) / 40.0 * std::f32::consts::TAU;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                polygons.push(square(n, n, 2.0));
            }
        }
        let out = cluster(polygons.clone(), 64);
        assert!(out.polygons.len() <= 64, "{}", out.polygons.len());
        // Measured: 56 lights, worst angle 25.7°, 2.2% of the power lost.
        assert!(out.worst_angle <= 30.0, "{}", out.worst_angle);
        let (before, after) = (power(&polygons), power(&out.polygons));
        let expected = before * (1.0 - out.lost_power);
        assert!(
            (after - expected).abs() < 1e-3 * before,
            "{after} vs {expected}"
        );
        assert!(out.lost_power < 0.03, "{}", out.lost_power);
        println!(
            "sphere: {} lights, worst angle {:.1}, power lost {:.3}",
            out.polygons.len(),
            out.worst_angle,
            out.lost_power
        );
    }
}
