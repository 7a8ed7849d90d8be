//! Emissive geometry as area lights for raster shading. The path tracer
//! samples emissive triangles themselves (`emitters`); raster passes shade
//! area lights analytically, so each emissive triangle of a placed mesh
//! becomes a polygon light (`LIGHT_AREA_POLYGON`, `shaders/include/area_light.glsl`):
//! pairs of coplanar triangles sharing an edge that form a convex quad (a
//! triangulated OBJ quad, a glTF panel) merge into one quad; when more than
//! [`MAX_EMITTER_LIGHTS`] polygons remain, neighbours facing about the same
//! way are clustered into square lights (`clusters`, which
//! reports the power and the angle that costs), and if still too many, the
//! most powerful are kept and the power left out is reported (docs/lights.md).
//!
//! Emission is what the tracer uses: the material's factor (MTL `Ke`, glTF
//! `emissiveFactor` times `KHR_materials_emissive_strength`, `.scene`
//! `emission`), times, where an emissive texture modulates it, the
//! texture's mean over each triangle (`textured`; such meshes are counted in
//! [`EmitterLights::textured`]).

mod clusters;
mod textured;

pub use textured::TextureMeans;

use crate::emitters::luminance;
use crate::geometry::SceneGeometry;
use crate::gpu_types::GpuLight;
use crate::lights::AREA_POLYGON;
use crate::sanitize;
use glam::Vec3;
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// The most emissive polygons raster passes shade: each costs every shaded
/// pixel one LTC integral per lobe (about as much as a rectangle light).
pub const MAX_EMITTER_LIGHTS: usize = 64;

/// One emissive polygon: a quad, or a triangle whose last corner repeats.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterPolygon {
    /// World-space corners, counter-clockwise about the side that emits.
    pub corners: [Vec3; 4],
    /// Emitted radiance.
    pub radiance: Vec3,
}

impl EmitterPolygon {
    /// The unit normal of the emitting side.
    pub fn normal(&self) -> Vec3 {
        self.winding().normalize_or_zero()
    }

    /// The polygon's area.
    pub fn area(&self) -> f32 {
        0.5 * self.winding().length()
    }

    /// Emitted power up to a constant: luminance times area.
    pub fn power(&self) -> f64 {
        f64::from(luminance(self.radiance)) * f64::from(self.area())
    }

    /// Twice the area along the emitting normal (the diagonals' cross product).
    fn winding(&self) -> Vec3 {
        let [a, b, c, d] = self.corners;
        (c - a).cross(d - b)
    }

    /// The light record (`scene.glsl`): the corners reversed, so they wind
    /// about the side the light does not emit towards, as a rectangle's do.
    pub fn record(&self) -> GpuLight {
        let [a, b, c, d] = self.corners;
        let [s0, s1, s2, s3] = [a, d, c, b];
        GpuLight {
            position_range: s0.extend(s3.x),
            direction_type: s1.extend(AREA_POLYGON),
            attenuation_cos: s2.extend(s3.y),
            color_exponent: sanitize::radiance(self.radiance).extend(s3.z),
        }
    }
}

/// The emissive polygons of a scene and what was merged or left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmitterLights {
    /// The polygons raster passes shade, most powerful first.
    pub polygons: Vec<EmitterPolygon>,
    /// Emissive triangles with area and light.
    pub triangles: usize,
    /// Pairs of triangles merged into quads.
    pub quads: usize,
    /// Lights that stand for a cluster of polygons.
    pub clusters: usize,
    /// Polygons merged into those clusters.
    pub clustered: usize,
    /// Largest angle (degrees) between a clustered polygon's normal and its light's.
    pub cluster_angle: f32,
    /// Share of the emitted power clustering lost to projection (0 to 1).
    pub cluster_loss: f64,
    /// Polygons left out past [`MAX_EMITTER_LIGHTS`].
    pub dropped: usize,
    /// The share of the emitted power the dropped polygons had (0 to 1).
    pub dropped_power: f64,
    /// Placed meshes whose emission an emissive texture modulates (lit by
    /// the texture's mean per triangle).
    pub textured: usize,
    /// Those meshes' texture means, kept so moved emitters need no decoding.
    pub means: Arc<TextureMeans>,
}

impl EmitterLights {
    /// The records to append after the scene's other lights.
    pub fn records(&self) -> Vec<GpuLight> {
        self.polygons.iter().map(EmitterPolygon::record).collect()
    }

    /// One line for `weft scene check`, or `None` without emissive geometry.
    pub fn summary(&self) -> Option<String> {
        if self.triangles == 0 && self.textured == 0 {
            return None;
        }
        let mut line = format!(
            "emissive geometry: {} triangles -> {} polygon lights ({} quads merged)",
            self.triangles,
            self.polygons.len(),
            self.quads
        );
        if self.clusters > 0 {
            line += &format!(
                "; {} polygons clustered into {} lights (normals within {:.0} degrees of their light's, {:.2}% of the emitted power lost)",
                self.clustered,
                self.clusters,
                self.cluster_angle,
                100.0 * self.cluster_loss
            );
        }
        if self.dropped > 0 {
            line += &format!(
                "; {} more left out past the budget of {MAX_EMITTER_LIGHTS}, {:.2}% of the emitted power",
                self.dropped,
                100.0 * self.dropped_power
            );
        }
        if self.textured > 0 {
            line += &format!(
                "; {} meshes light through their emissive texture's mean over each triangle",
                self.textured
            );
        }
        Some(line)
    }
}

/// Whether a material's emission becomes polygon lights: it emits (an
/// emissive texture scales each triangle's light by its mean there).
pub fn lights_raster(m: &weft_scene::Material) -> bool {
    m.emissive.max_element() > 0.0
}

/// The emissive polygons of the placed meshes of `geometry`, their emissive
/// textures decoded to take their means.
pub fn emitter_lights(geometry: &SceneGeometry) -> EmitterLights {
    emitter_lights_with(geometry, Arc::new(TextureMeans::gather(geometry)))
}

/// [`emitter_lights`] with the texture means already taken (a moved emitter
/// keeps its texture's).
pub fn emitter_lights_with(geometry: &SceneGeometry, means: Arc<TextureMeans>) -> EmitterLights {
    let mut out = EmitterLights::default();
    let mut polygons = Vec::new();
    for draw in &geometry.draws {
        let Some(material) = geometry.materials.get(draw.material as usize) else {
            continue;
        };
        if !lights_raster(material) {
            continue;
        }
        let factor = sanitize::radiance(material.emissive);
        let texture = means.of(draw);
        out.textured += usize::from(texture.is_some());
        // Triangles of one radiance merge into quads among themselves.
        let mut by_radiance: BTreeMap<[u32; 3], Vec<[Vec3; 3]>> = BTreeMap::new();
        for (i, t) in geometry.world_triangles(draw).enumerate() {
            let radiance = factor * texture.and_then(|m| m.get(i)).copied().unwrap_or(Vec3::ONE);
            if t.iter().all(|p| p.is_finite()) && area(&t) > 0.0 && luminance(radiance) > 0.0 {
                by_radiance
                    .entry(radiance.to_array().map(f32::to_bits))
                    .or_default()
                    .push(t);
            }
        }
        for (radiance, triangles) in by_radiance {
            let radiance = Vec3::from_array(radiance.map(f32::from_bits));
            out.triangles += triangles.len();
            let merged = merge_quads(&triangles);
            out.quads += merged.iter().filter(|p| p[2] != p[3]).count();
            polygons.extend(
                merged
                    .into_iter()
                    .map(|corners| EmitterPolygon { corners, radiance }),
            );
        }
    }
    out.means = means;
    let clustered = clusters::cluster(polygons, MAX_EMITTER_LIGHTS);
    out.clusters = clustered.clusters;
    out.clustered = clustered.members;
    out.cluster_angle = clustered.worst_angle;
    out.cluster_loss = clustered.lost_power;
    (out.polygons, out.dropped, out.dropped_power) =
        within_budget(clustered.polygons, MAX_EMITTER_LIGHTS);
    out
}

/// The `budget` most powerful polygons, most powerful first, with how many
/// were left out and their share of the total power.
fn within_budget(
    mut polygons: Vec<EmitterPolygon>,
    budget: usize,
) -> (Vec<EmitterPolygon>, usize, f64) {
    polygons.sort_by(|a, b| b.power().total_cmp(&a.power()));
    if polygons.len() <= budget {
        return (polygons, 0, 0.0);
    }
    let total: f64 = polygons.iter().map(EmitterPolygon::power).sum();
    let dropped: f64 = polygons[budget..].iter().map(EmitterPolygon::power).sum();
    let count = polygons.len() - budget;
    polygons.truncate(budget);
    let share = if total > 0.0 { dropped / total } else { 0.0 };
    (polygons, count, share)
}

fn area(t: &[Vec3; 3]) -> f32 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Merges pairs of triangles (counter-clockwise about their front) that share
/// an edge, lie in one plane and together form a convex quad; the rest stay
/// triangles (last corner repeated). Each triangle joins at most one pair,
/// the first neighbour found in order.
fn merge_quads(triangles: &[[Vec3; 3]]) -> Vec<[Vec3; 4]> {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let mut by_edge: HashMap<([u32; 3], [u32; 3]), usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge.entry((key(t[k]), key(t[(k + 1) % 3]))).or_insert(i);
        }
    }
    let mut used = vec![false; triangles.len()];
    let mut out = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let mut polygon = [t[0], t[1], t[2], t[2]];
        for k in 0..3 {
            let (from, to) = (t[k], t[(k + 1) % 3]);
            // The neighbour runs the shared edge the other way.
            let Some(&j) = by_edge.get(&(key(to), key(from))) else {
                continue;
            };
            if used[j] {
                continue;
            }
            let other = triangles[j];
            let Some(far) = other
                .iter()
                .copied()
                .find(|&p| key(p) != key(from) && key(p) != key(to))
            else {
                continue;
            };
            let quad = [t[(k + 2) % 3], from, far, to];
            if coplanar_convex(&quad) {
                used[j] = true;
                polygon = quad;
                break;
            }
        }
        out.push(polygon);
    }
    out
}

/// Whether four corners lie in one plane (to 1e-5 of their size) and wind
/// convexly about its normal.
fn coplanar_convex(q: &[Vec3; 4]) -> bool {
    let normal = (q[2] - q[0]).cross(q[3] - q[1]);
    let size = (q[2] - q[0]).length().max((q[3] - q[1]).length());
    let Some(n) = normal.try_normalize() else {
        return false;
    };
    let flat = q.iter().all(|p| (*p - q[0]).dot(n).abs() <= 1e-5 * size);
    let convex = (0..4).all(|k| {
        let (a, b, c) = (q[k], q[(k + 1) % 4], q[(k + 2) % 4]);
        (b - a).cross(c - b).dot(n) > 0.0
    });
    flat && convex
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> [[Vec3; 3]; 2] {
        // A unit square in z = 0, counter-clockwise about +z, split along a diagonal.
        let [a, b, c, d] = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        [[a, b, c], [a, c, d]]
    }

    #[test]
    fn a_triangulated_square_merges_into_one_quad_facing_its_front() {
        let merged = merge_quads(&square());
        assert_eq!(merged.len(), 1);
        let polygon = EmitterPolygon {
            corners: merged[0],
            radiance: Vec3::ONE,
        };
        assert_eq!(polygon.normal(), Vec3::Z);
        assert!((polygon.area() - 1.0).abs() < 1e-6);
        // The record winds the other way: about -z, the side that does not emit.
        let r = polygon.record();
        let corners = [
            r.position_range.truncate(),
            r.direction_type.truncate(),
            r.attenuation_cos.truncate(),
            Vec3::new(r.position_range.w, r.attenuation_cos.w, r.color_exponent.w),
        ];
        let winding = (corners[2] - corners[0]).cross(corners[3] - corners[1]);
        assert!(
            winding.normalize().dot(Vec3::NEG_Z) > 0.999_999,
            "{winding}"
        );
        assert_eq!(r.direction_type.w, AREA_POLYGON);
    }

    #[test]
    fn folded_or_concave_pairs_stay_triangles() {
        let [t0, mut t1] = square();
        // Lift the far corner: no longer one plane.
        t1[2].z = 0.5;
        let merged = merge_quads(&[t0, t1]);
        assert_eq!(merged.len(), 2);
        assert!(merged.iter().all(|q| q[2] == q[3]));
        // A dart: the shared edge's far corner pulled inside makes it concave.
        let [t0, mut t1] = square();
        t1[2] = Vec3::new(0.7, 0.6, 0.0);
        assert_eq!(merge_quads(&[t0, t1]).len(), 2);
        // Back-facing pair (one flipped): edges run the same way, no merge.
        let [t0, t1] = square();
        assert_eq!(merge_quads(&[t0, [t1[0], t1[2], t1[1]]]).len(), 2);
    }

    #[test]
    fn past_the_budget_the_weakest_are_dropped_and_their_power_reported() {
        // Half-unit triangles: six of radiance 0.5 (power 0.25 each), 64 of 1 (0.5 each).
        let polygons: Vec<EmitterPolygon> = (0..MAX_EMITTER_LIGHTS + 6)
            .map(|i| {
                let x = i as f32 * 2.0;
                EmitterPolygon {
                    corners: [
                        Vec3::new(x, 0.0, 0.0),
                        Vec3::new(x + 1.0, 0.0, 0.0),
                        Vec3::new(x, 1.0, 0.0),
                        Vec3::new(x, 1.0, 0.0),
                    ],
                    radiance: Vec3::splat(if i < 6 { 0.5 } else { 1.0 }),
                }
            })
            .collect();
        let (kept, dropped, share) = within_budget(polygons, MAX_EMITTER_LIGHTS);
        assert_eq!(kept.len(), MAX_EMITTER_LIGHTS);
        assert!(kept.iter().all(|p| p.radiance == Vec3::ONE));
        assert_eq!(dropped, 6);
        let expected = 6.0 * 0.25 / (6.0 * 0.25 + MAX_EMITTER_LIGHTS as f64 * 0.5);
        assert!((share - expected).abs() < 1e-6, "{share} vs {expected}");
    }
}
