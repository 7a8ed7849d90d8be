//! The ray-traced sun visibility of a view, and how far a shadow-mapped image
//! is from it: the share of pixels where the two disagree on lit or shadowed.

use glam::{Mat4, Vec2, Vec3};
use weft_render::material_matches as matches;
use weft_render::vocabulary::MeshFilter;
use weft_scene::{Camera, Light, Scene};
use weft_testkit::raytrace::Bvh;

/// The reference for `scene` seen by `camera` at time 0 through a `size` view:
/// [`sun_visibility`] of the first sun against every shadow-casting triangle,
/// shadow rays starting 1e-4 of the scene's diagonal off the surface; `None`
/// without a sun.
pub fn scene_sun_visibility(
    scene: &Scene,
    camera: &Camera,
    size: [u32; 2],
) -> Option<Vec<Option<bool>>> {
    let lights = weft_scene::animation::lights_at(&scene.lights, 0.0, 0);
    let sun = lights.iter().find_map(|l| match l {
        Light::Sun(s) => Some(s.direction),
        _ => None,
    })?;
    let bvh = Bvh::from_scene(scene, |model, mesh| {
        let m = &scene.models[model];
        let material = m.meshes[mesh]
            .material
            .and_then(|i| m.materials.get(i))
            .cloned()
            .unwrap_or_default();
        matches(MeshFilter::ShadowCasters, &material)
    });
    let aspect = size[0].max(1) as f32 / size[1].max(1) as f32;
    let view_proj = camera.view_projection(0.0, aspect);
    let eye = camera.pose_at(0.0).0;
    let offset = scene.effective_bounds().diagonal().max(1e-3) * 1e-4;
    Some(sun_visibility(&bvh, &view_proj, eye, size, sun, offset))
}

/// Per pixel (row by row) of a `width` x `height` view through `view_proj`
/// (reverse-Z, as `camera::view_projection` builds it) from `eye`: `None` where
/// the pixel's centre ray misses the scene or its surface faces away from the
/// sun (unlit either way), else whether the sun, travelling along `sun`, reaches
/// the surface. Shadow rays start `offset` along the surface normal.
pub fn sun_visibility(
    bvh: &Bvh,
    view_proj: &Mat4,
    eye: Vec3,
    size: [u32; 2],
    sun: Vec3,
    offset: f32,
) -> Vec<Option<bool>> {
    let inv = view_proj.inverse();
    let to_sun = -sun.normalize_or_zero();
    let [width, height] = size;
    (0..width * height)
        .map(|i| {
            let pixel = Vec2::new((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
            let ndc = pixel / Vec2::new(width as f32, height as f32) * 2.0 - 1.0;
            let far = inv.project_point3(ndc.extend(0.0));
            let dir = (far - eye).normalize_or_zero();
            let hit = bvh.closest(eye, dir, f32::MAX)?;
            let normal = if hit.normal.dot(dir) > 0.0 {
                -hit.normal
            } else {
                hit.normal
            };
            if normal.dot(to_sun) <= 0.0 {
                return None;
            }
            let p = eye + dir * hit.t + normal * offset;
            Some(!bvh.occluded(p, to_sun, f32::MAX))
        })
        .collect()
}

/// Pixels compared and pixels that disagree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Disagreement {
    /// Pixels with a reference and a lit value above the threshold.
    pub compared: usize,
    /// Of those, pixels whose shadow-mapped visibility (`shadowed / unshadowed`,
    /// lit at 0.5 or more) differs from the reference.
    pub differing: usize,
}

/// Compares a render with shadows (`shadowed`) and the same render without
/// (`unshadowed`), one value per pixel of sun light only, with `reference`;
/// pixels whose unshadowed value is at most `threshold` carry no visibility
/// information and are skipped.
pub fn compare(
    reference: &[Option<bool>],
    shadowed: &[f32],
    unshadowed: &[f32],
    threshold: f32,
) -> Disagreement {
    let mut d = Disagreement {
        compared: 0,
        differing: 0,
    };
    for ((r, s), u) in reference.iter().zip(shadowed).zip(unshadowed) {
        let Some(visible) = r else { continue };
        if *u <= threshold {
            continue;
        }
        d.compared += 1;
        if (s / u >= 0.5) != *visible {
            d.differing += 1;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_scene::reverse_z_projection;

    /// A floor at y = 0 and a square roof at y = 1 over x, z in -1..1.
    fn scene() -> Bvh {
        let quad = |y: f32, h: f32| {
            let c = |x, z| Vec3::new(x, y, z);
            [
                [c(-h, -h), c(h, -h), c(h, h)],
                [c(-h, -h), c(h, h), c(-h, h)],
            ]
        };
        let mut t = quad(0.0, 10.0).to_vec();
        t.extend(quad(1.0, 1.0));
        Bvh::new(t)
    }

    #[test]
    fn the_roof_shadows_the_floor_below_it_only() {
        let bvh = scene();
        // Seen from above and in front.
        let eye = Vec3::new(0.0, 6.0, 6.0);
        let view = Mat4::look_at_rh(eye, Vec3::ZERO, Vec3::Y);
        let vp = reverse_z_projection(1.2, 1.0, 0.1, 100.0) * view;
        let vis = sun_visibility(&bvh, &vp, eye, [64, 64], Vec3::NEG_Y, 1e-4);
        let inv = vp.inverse();
        let mut shadowed = 0;
        for (i, v) in vis.iter().enumerate() {
            let Some(visible) = v else { continue };
            let px = Vec2::new((i % 64) as f32 + 0.5, (i / 64) as f32 + 0.5) / 64.0 * 2.0 - 1.0;
            let near = inv.project_point3(px.extend(1.0));
            let far = inv.project_point3(px.extend(0.0));
            // Where the pixel's ray meets the floor, if it is below the roof, it is dark.
            let t = near.y / (near.y - far.y);
            let floor = near + (far - near) * t;
            let roof = near + (far - near) * ((near.y - 1.0) / (near.y - far.y));
            let sees_roof = roof.x.abs() < 1.0 && roof.z.abs() < 1.0;
            if !sees_roof && floor.x.abs() < 0.95 && floor.z.abs() < 0.95 {
                assert!(!visible, "pixel {i}");
                shadowed += 1;
            }
            if !sees_roof && (floor.x.abs() > 1.05 || floor.z.abs() > 1.05) {
                assert!(*visible, "pixel {i}");
            }
        }
        assert!(shadowed > 20, "{shadowed}");
    }

    #[test]
    fn compare_counts_disagreements_over_informative_pixels() {
        let reference = [Some(true), Some(false), None, Some(true), Some(false)];
        let shadowed = [0.5, 0.5, 0.0, 0.0, 0.001];
        let unshadowed = [1.0, 1.0, 1.0, 0.0, 0.002];
        let d = compare(&reference, &shadowed, &unshadowed, 0.01);
        assert_eq!(
            d,
            Disagreement {
                compared: 2,
                differing: 1
            }
        );
    }
}
