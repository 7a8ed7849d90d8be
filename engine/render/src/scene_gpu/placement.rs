//! Placements a scene script moves and recolours, written into the draw and
//! material records in place, as ranges; and the light records that changed.

use super::GpuScene;
use crate::gpu_types::{bytes_of, GpuLight, GpuMaterial};
use crate::materials::pack_material;
use weft_gpu::GpuError;

impl GpuScene<'_> {
    /// Moves the placements the script moved: their draw records rewritten
    /// in place as one range, the scene's box refitted (unless declared),
    /// and the ray tracer's triangles and BVH rebuilt if a pass traces (the
    /// top-level acceleration structure refitted, for ray queries). A
    /// placement still again after moving only has its records rewritten
    /// (their `previous`): no geometry moved.
    pub(super) fn place_instances(&mut self, transforms: &[glam::Mat4]) -> Result<(), GpuError> {
        self.moved_boxes.clear();
        let Some(ids) =
            self.geometry
                .place_instances(transforms, &mut self.transforms, &mut self.moved_boxes)
        else {
            return Ok(());
        };
        self.draws.write_at(
            ids.start as usize * std::mem::size_of::<crate::gpu_types::GpuDraw>(),
            bytes_of(&self.geometry.draw_records[ids.start as usize..ids.end as usize]),
        )?;
        if self.moved_boxes.is_empty() {
            return Ok(());
        }
        self.moved = true;
        if !self.emitter_lights.polygons.is_empty() {
            // The light buffer was sized for the polygons at load: a moved
            // emitter keeps its count (only non-finite corners could change it).
            let means = self.emitter_lights.means.clone();
            let moved = crate::emitter_lights::emitter_lights_with(&self.geometry, means);
            if moved.polygons.len() == self.emitter_lights.polygons.len() {
                self.emitter_lights = moved;
            }
        }
        if self.declared_bounds.is_none() {
            self.bounds = self.geometry.placed_bounds();
        }
        if self.trace.is_some() {
            self.trace = None;
            self.ensure_trace_buffers()?;
            self.refit_structures()?;
            if let Some(set) = self.traced_set {
                self.write_scene_set(set, true);
            }
        }
        Ok(())
    }

    /// Repacks the material copies of the placements the script recoloured
    /// and writes them as one range of the material buffer.
    pub(super) fn recolour_instances(
        &mut self,
        colors: &[Option<glam::Vec3>],
    ) -> Result<(), GpuError> {
        let mut changed: Option<(u32, u32)> = None;
        for (i, (colour, overrides)) in colors.iter().zip(self.overrides.iter_mut()).enumerate() {
            if *colour == overrides.color {
                continue;
            }
            overrides.color = *colour;
            for &(copy, original) in &self.geometry.instance_materials[i] {
                let material = overrides.apply(&self.geometry.materials[original as usize]);
                self.geometry.materials[copy as usize] = material;
                changed = Some(changed.map_or((copy, copy), |(a, b)| (a.min(copy), b.max(copy))));
            }
        }
        let Some((first, last)) = changed else {
            return Ok(());
        };
        let records: Vec<GpuMaterial> = (first..=last)
            .map(|m| {
                pack_material(
                    &self.geometry.materials[m as usize],
                    self.normal_mapped[m as usize],
                )
            })
            .collect();
        self.materials.write_at(
            first as usize * std::mem::size_of::<GpuMaterial>(),
            bytes_of(&records),
        )
    }
}

/// The boxes of the area-light panels among records `changed` of `old` and
/// `new` (where each was and is): a `ShadowCasters` pass draws the panels,
/// so a moved one stales the shadow tiles it touched or touches.
pub(super) fn moved_panels(
    old: &[GpuLight],
    new: &[GpuLight],
    changed: std::ops::Range<usize>,
) -> Vec<weft_scene::Aabb> {
    let panel = |l: &GpuLight| {
        let kind = l.direction_type.w;
        (kind == crate::lights::AREA_RECT || kind == crate::lights::AREA_DISC).then(|| {
            let reach = l.direction_type.truncate().abs() + l.attenuation_cos.truncate().abs();
            let centre = l.position_range.truncate();
            weft_scene::Aabb {
                min: centre - reach,
                max: centre + reach,
            }
        })
    };
    changed
        .flat_map(|i| [old.get(i), new.get(i)])
        .flatten()
        .filter_map(panel)
        .collect()
}

/// The records of `new` that differ from `old` (the light buffer's
/// contents), as one range to write; all of them when the counts differ,
/// none when nothing changed: what moved or changed colour is all that is
/// written each frame.
pub(super) fn changed_records(
    old: &[GpuLight],
    new: &[GpuLight],
) -> Option<std::ops::Range<usize>> {
    if old.len() != new.len() {
        return (!new.is_empty()).then_some(0..new.len());
    }
    let same = |i: &usize| bytes_of(&old[*i..*i + 1]) == bytes_of(&new[*i..*i + 1]);
    let first = (0..new.len()).find(|i| !same(i))?;
    let last = (0..new.len()).rev().find(|i| !same(i))?;
    Some(first..last + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;
    use glam::Vec4;

    fn at(x: f32) -> GpuLight {
        GpuLight {
            position_range: Vec4::new(x, 0.0, 0.0, 1.0),
            ..GpuLight::zeroed()
        }
    }

    #[test]
    fn only_the_span_of_changed_light_records_is_written() {
        let old: Vec<GpuLight> = (0..6).map(|i| at(i as f32)).collect();
        assert_eq!(changed_records(&old, &old), None, "nothing changed");
        let mut new = old.clone();
        new[2] = at(20.0);
        new[4] = at(40.0);
        assert_eq!(changed_records(&old, &new), Some(2..5));
        new.truncate(3);
        assert_eq!(
            changed_records(&old, &new),
            Some(0..3),
            "another count: all"
        );
        assert_eq!(
            changed_records(&old, &[]),
            None,
            "no lights: nothing to write"
        );
        // NaN records compare by their bits: an unchanged NaN is not rewritten.
        let nan = vec![at(f32::NAN)];
        assert_eq!(changed_records(&nan, &nan), None);
    }

    /// A rect area light moved from x = 1 to x = 5 (half axes 0.5 along x
    /// and 0.25 along z): its panel's box where it was and where it is; a
    /// point light beside it that moved too has no panel.
    #[test]
    fn moved_panels_are_where_a_panel_was_and_is() {
        let rect = |x: f32| GpuLight {
            position_range: Vec4::new(x, 2.0, 0.0, 1.0),
            direction_type: Vec4::new(0.5, 0.0, 0.0, crate::lights::AREA_RECT),
            attenuation_cos: Vec4::new(0.0, 0.0, 0.25, 0.0),
            ..GpuLight::zeroed()
        };
        let point = |x: f32| GpuLight {
            direction_type: Vec4::new(0.0, 0.0, 0.0, crate::lights::POINT),
            ..at(x)
        };
        let boxes = moved_panels(&[point(0.0), rect(1.0)], &[point(9.0), rect(5.0)], 0..2);
        let expected = |x: f32| weft_scene::Aabb {
            min: glam::Vec3::new(x - 0.5, 2.0, -0.25),
            max: glam::Vec3::new(x + 0.5, 2.0, 0.25),
        };
        assert_eq!(boxes, vec![expected(1.0), expected(5.0)]);
    }
}
