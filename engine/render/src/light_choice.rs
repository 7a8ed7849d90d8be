//! Which light next-event estimation samples (`light_choice_table` in
//! `shaders/include/trace.glsl`): one choice per analytic light in record
//! order, then one for "an emissive triangle" when the scene has any. A
//! choice is picked with probability half uniform, half in proportion to an
//! estimate of the power it emits, through an alias table (Vose).
//!
//! The estimate only has to be positive for the estimator to stay unbiased;
//! the better it follows what reaches the camera, the less noise. Uniform
//! choice wastes samples on dim lights where one light dominates; pure power
//! choice starves a dim light that is the only one near what the camera sees.
//! The even mixture keeps every light at least half its uniform share, so no
//! light's noise grows more than twofold, while bright lights get most of the
//! samples.

use crate::emitters::{alias_table, table_bytes};
use crate::gpu_types::GpuLight;
use crate::light_bounds::power;
use crate::light_tree::LightTree;
use crate::lights::SUN;

/// Share of the probability spread evenly over the choices.
const UNIFORM_SHARE: f64 = 0.5;

/// The alias table the shaders read, and the light tree after it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightChoices {
    /// Per choice: alias, threshold below which the choice itself is kept
    /// (f32 bits), the probability of the choice (f32 bits), 0.
    pub records: Vec<[u32; 4]>,
    /// What `light_choice` 2 reads (`shaders/pathtrace/light_tree.glsl`): a
    /// header (top choices, tree nodes, 0, 0), the top choices among the
    /// suns, the tree and the emissive triangles (alias, threshold bits,
    /// probability bits, what), then [`LightTree::records`].
    pub tree: Vec<[u32; 4]>,
}

/// A top choice that walks the tree (`TREE_CHOICE` in light_tree.glsl).
pub const TREE_CHOICE: u32 = u32::MAX;

impl LightChoices {
    /// The table over `lights` (the analytic light records, suns to area
    /// lights) and, when `emitter_power` is given, the emissive triangles as
    /// one more choice; `scene_radius` sizes a sun's power.
    pub fn build(lights: &[GpuLight], emitter_power: Option<f32>, scene_radius: f32) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| f64::from(power(l, scene_radius)))
            .chain(emitter_power.map(|p| f64::from(p.max(0.0))))
            .map(|p| if p.is_finite() { p } else { 0.0 })
            .collect();
        let probabilities = mixture(&powers);
        let records = alias_records(&probabilities, |i| i as u32);
        Self {
            records,
            tree: tree_records(lights, emitter_power, scene_radius),
        }
    }

    /// The GPU buffer: a header (choice count, the tree header's index, 0,
    /// 0), the records, then the tree's.
    pub fn bytes(&self) -> Vec<u8> {
        let count = self.records.len() as u32;
        let all: Vec<[u32; 4]> = self.records.iter().chain(&self.tree).copied().collect();
        table_bytes([count, count, 0, 0], &all)
    }
}

/// Alias-table records over `probabilities`, each with `what(i)` in w.
fn alias_records(probabilities: &[f64], what: impl Fn(usize) -> u32) -> Vec<[u32; 4]> {
    let (threshold, alias) = alias_table(probabilities);
    probabilities
        .iter()
        .zip(threshold.iter().zip(&alias))
        .enumerate()
        .map(|(i, (&p, (&t, &a)))| [a, t.to_bits(), (p as f32).to_bits(), what(i)])
        .collect()
}

/// The tree's header, its top choices (the suns, the tree as one choice
/// standing for all its lights, the emissive triangles as one) with the
/// probabilities the table gives them together, and the tree.
fn tree_records(
    lights: &[GpuLight],
    emitter_power: Option<f32>,
    scene_radius: f32,
) -> Vec<[u32; 4]> {
    let tree = LightTree::build(lights);
    let finite = |p: f32| {
        if p.is_finite() {
            f64::from(p.max(0.0))
        } else {
            0.0
        }
    };
    // (what, lights it stands for, their power as the table counts it)
    let mut top: Vec<(u32, f64, f64)> = lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.direction_type.w == SUN)
        .map(|(i, l)| (i as u32, 1.0, finite(power(l, scene_radius))))
        .collect();
    if !tree.nodes.is_empty() {
        let in_tree = lights
            .iter()
            .zip(&tree.trails)
            .filter(|(_, t)| t.1 != u32::MAX);
        let (count, phi) = in_tree.fold((0.0, 0.0), |(n, p), (l, _)| {
            (n + 1.0, p + finite(power(l, scene_radius)))
        });
        top.push((TREE_CHOICE, count, phi));
    }
    if let Some(p) = emitter_power {
        top.push((lights.len() as u32, 1.0, finite(p)));
    }
    let choices: Vec<(f64, f64)> = top.iter().map(|&(_, n, p)| (n, p)).collect();
    let probabilities = grouped_mixture(&choices);
    let mut records = vec![[top.len() as u32, tree.nodes.len() as u32, 0, 0]];
    records.extend(alias_records(&probabilities, |i| top[i].0));
    records.extend(tree.records());
    records
}

/// Each choice's probability: [`UNIFORM_SHARE`] spread evenly, the rest in
/// proportion to `powers` (all even when they sum to nothing).
fn mixture(powers: &[f64]) -> Vec<f64> {
    let each: Vec<(f64, f64)> = powers.iter().map(|&p| (1.0, p)).collect();
    grouped_mixture(&each)
}

/// Each choice's probability when choice i stands for `counts[i]` lights
/// of total power `powers[i]`: their summed probabilities under
/// [`mixture`] over the lights themselves.
fn grouped_mixture(choices: &[(f64, f64)]) -> Vec<f64> {
    let n: f64 = choices.iter().map(|&(count, _)| count).sum();
    let total: f64 = choices.iter().map(|&(_, p)| p).sum();
    choices
        .iter()
        .map(|&(count, p)| {
            if total > 0.0 && total.is_finite() {
                UNIFORM_SHARE * count / n + (1.0 - UNIFORM_SHARE) * p / total
            } else {
                count / n
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light_bounds::test_light as light;
    use crate::lights::{POINT, SPOT_CONE};

    /// The probability the table gives each choice: its own threshold share
    /// plus the shares of every choice that aliases to it.
    fn picked(table: &LightChoices) -> Vec<f64> {
        let n = table.records.len() as f64;
        let mut p = vec![0.0; table.records.len()];
        for (i, r) in table.records.iter().enumerate() {
            let keep = f64::from(f32::from_bits(r[1]));
            p[i] += keep / n;
            p[r[0] as usize] += (1.0 - keep) / n;
        }
        p
    }

    #[test]
    fn the_table_picks_each_choice_with_its_stored_probability() {
        let lights = [
            light(POINT, 1.0),
            light(POINT, 100.0),
            light(SPOT_CONE, 3.0),
            light(SUN, 0.1),
        ];
        let table = LightChoices::build(&lights, Some(50.0), 10.0);
        assert_eq!(table.records.len(), 5);
        let stored: Vec<f64> = table
            .records
            .iter()
            .map(|r| f64::from(f32::from_bits(r[2])))
            .collect();
        for (p, s) in picked(&table).iter().zip(&stored) {
            assert!((p - s).abs() < 1e-6, "{p} vs {s}");
        }
        assert!((stored.iter().sum::<f64>() - 1.0).abs() < 1e-6);
        // Half spread evenly: no choice below half its uniform share.
        assert!(stored.iter().all(|&p| p >= 0.5 / 5.0 - 1e-7), "{stored:?}");
        // The bright point light gets most of the rest.
        assert!(stored[1] > 0.4 && stored[1] > stored[0] * 3.0, "{stored:?}");
    }

    #[test]
    fn equal_or_powerless_lights_are_chosen_evenly() {
        let same = LightChoices::build(&[light(POINT, 2.0), light(POINT, 2.0)], None, 1.0);
        let dark = LightChoices::build(&[light(POINT, 0.0), light(POINT, f32::NAN)], None, 1.0);
        for table in [same, dark] {
            for r in &table.records {
                assert_eq!(f32::from_bits(r[2]), 0.5);
            }
        }
        assert!(LightChoices::build(&[], None, 1.0).records.is_empty());
    }
}
