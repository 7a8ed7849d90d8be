//! A light tree for next-event estimation among many lights (Conty Estevez
//! and Kulla, "Importance Sampling of Many Lights with Adaptive Tree
//! Splitting", 2018; pbrt-v4's `BVHLightSampler` is the model): a binary
//! tree over the lights with a position (points, spots, area lights), each
//! node bounding its lights' positions, power, emission directions and
//! cutoff range. The path tracer (`shaders/pathtrace/light_tree.glsl`, under
//! the graph's `light_choice` 2) walks it from the root for a shading point,
//! at each node taking a child with probability in proportion to the
//! child's importance there: its power over the squared distance, zero
//! where its lights face away or where the point lies beyond every light's
//! range. The probability of the light it reaches is the product of those
//! choices, and the light's own trail leads the same walk back to it for
//! MIS. `LightTree::sample` and `LightTree::pmf` walk it on the CPU as the
//! shader does, for the tests.

use crate::gpu_types::GpuLight;
use crate::light_bounds::{bounds_of, LightBounds};
use glam::Vec3;

/// One node: an inner node's second child (its first is the next node), or
/// a leaf's light record index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightNode {
    pub bounds: LightBounds,
    pub child_or_light: u32,
    pub leaf: bool,
}

/// The tree, nodes in depth-first order (the root first), and per light
/// record the way down to its leaf.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightTree {
    pub nodes: Vec<LightNode>,
    /// Per light record: bit k says which child leads to it at depth k (1:
    /// the second), and the leaf's depth; (0, u32::MAX) for lights outside
    /// the tree (suns, emissive polygons).
    pub trails: Vec<(u32, u32)>,
}

impl LightTree {
    /// The tree over the lights of `lights` that have a position; empty when
    /// none has.
    pub fn build(lights: &[GpuLight]) -> Self {
        let mut items: Vec<(u32, LightBounds)> = lights
            .iter()
            .enumerate()
            .filter_map(|(i, l)| bounds_of(l).map(|b| (i as u32, b)))
            .collect();
        let mut tree = LightTree {
            nodes: Vec::with_capacity(2 * items.len()),
            trails: vec![(0, u32::MAX); lights.len()],
        };
        if !items.is_empty() {
            tree.add(&mut items, 0, 0);
        }
        tree
    }

    /// Adds the subtree over `items` (at `depth`, reached by `trail`) and
    /// returns its root's bounds. Splits at the median along the widest
    /// axis of the lights' centres, so the depth is about log2 of the count
    /// and a trail's 32 bits always suffice.
    fn add(&mut self, items: &mut [(u32, LightBounds)], depth: usize, trail: u32) -> LightBounds {
        let at = self.nodes.len();
        if let [(light, bounds)] = *items {
            self.nodes.push(LightNode {
                bounds,
                child_or_light: light,
                leaf: true,
            });
            self.trails[light as usize] = (trail, depth as u32);
            return bounds;
        }
        let (lo, hi) = items.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), (_, b)| {
                let c = 0.5 * (b.lo + b.hi);
                (lo.min(c), hi.max(c))
            },
        );
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let centre = |b: &LightBounds| 0.5 * (b.lo[axis] + b.hi[axis]);
        items.sort_by(|a, b| centre(&a.1).total_cmp(&centre(&b.1)).then(a.0.cmp(&b.0)));
        let mid = items.len() / 2;
        self.nodes.push(LightNode {
            bounds: items[0].1,
            child_or_light: 0,
            leaf: false,
        });
        let (first, second) = items.split_at_mut(mid);
        let a = self.add(first, depth + 1, trail);
        self.nodes[at].child_or_light = self.nodes.len() as u32;
        let b = self.add(second, depth + 1, trail | 1 << depth);
        let merged = a.union(&b);
        self.nodes[at].bounds = merged;
        merged
    }

    /// The two children of inner node `node` and the probability of the
    /// first at `p`; None when neither can light `p`.
    #[cfg(test)]
    fn split(&self, node: usize, p: Vec3) -> Option<(usize, usize, f32)> {
        let (first, second) = (node + 1, self.nodes[node].child_or_light as usize);
        let a = self.nodes[first].bounds.importance(p);
        let b = self.nodes[second].bounds.importance(p);
        (a + b > 0.0).then(|| (first, second, a / (a + b)))
    }

    /// A light record picked for `p` by `u` in [0, 1), and the probability
    /// it had; None when no light in the tree can light `p`.
    #[cfg(test)]
    pub fn sample(&self, p: Vec3, mut u: f32) -> Option<(u32, f32)> {
        let root = self.nodes.first()?;
        if root.bounds.importance(p) <= 0.0 {
            return None;
        }
        let (mut node, mut pmf) = (0, 1.0f32);
        while !self.nodes[node].leaf {
            let (first, second, p_first) = self.split(node, p)?;
            if u < p_first {
                u = (u / p_first).min(1.0 - f32::EPSILON / 2.0);
                pmf *= p_first;
                node = first;
            } else {
                u = ((u - p_first) / (1.0 - p_first)).min(1.0 - f32::EPSILON / 2.0);
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
        Some((self.nodes[node].child_or_light, pmf))
    }

    /// The probability [`LightTree::sample`] picks light record `light` for
    /// `p`: zero for lights outside the tree and lights that cannot light p.
    #[cfg(test)]
    pub fn pmf(&self, p: Vec3, light: u32) -> f32 {
        let Some(&(trail, depth)) = self.trails.get(light as usize) else {
            return 0.0;
        };
        if depth == u32::MAX || self.nodes[0].bounds.importance(p) <= 0.0 {
            return 0.0;
        }
        let (mut node, mut pmf) = (0, 1.0f32);
        for level in 0..depth {
            let Some((first, second, p_first)) = self.split(node, p) else {
                return 0.0;
            };
            if trail >> level & 1 == 0 {
                pmf *= p_first;
                node = first;
            } else {
                pmf *= 1.0 - p_first;
                node = second;
            }
        }
        pmf
    }

    /// The records the shaders read, five per node: (lo, phi), (hi, range),
    /// (axis, cos θo), (cos θe, two-sided, second child or light, leaf),
    /// (falloff, 0), floats as bits; then one per light record, (trail,
    /// depth, 0, 0).
    pub fn records(&self) -> Vec<[u32; 4]> {
        let bits = |v: Vec3, w: f32| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits(), w.to_bits()];
        self.nodes
            .iter()
            .flat_map(|n| {
                let b = &n.bounds;
                [
                    bits(b.lo, b.phi),
                    bits(b.hi, b.range),
                    bits(b.axis, b.cos_theta_o),
                    [
                        b.cos_theta_e.to_bits(),
                        u32::from(b.two_sided),
                        n.child_or_light,
                        u32::from(n.leaf),
                    ],
                    bits(b.falloff, 0.0),
                ]
            })
            .chain(self.trails.iter().map(|&(t, d)| [t, d, 0, 0]))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light_bounds::power;
    use crate::lights::{AREA_RECT, POINT, SPOT_CONE, SPOT_SPHERE, SUN};
    use glam::Vec4;

    /// A small deterministic generator (xorshift), numbers in [0, 1).
    struct Numbers(u64);

    impl Numbers {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }

        fn point(&mut self, scale: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * scale - scale
        }
    }

    fn point_light(at: Vec3, colour: f32, range: f32) -> GpuLight {
        GpuLight {
            position_range: at.extend(range),
            direction_type: Vec3::ZERO.extend(POINT),
            color_exponent: Vec4::new(colour, colour, colour, 0.0),
            attenuation_cos: Vec4::new(1.0, 0.0, 1.0, 0.0),
        }
    }

    /// Points with and without ranges, spots down -y, one- and two-sided
    /// rectangles facing +y and -y, and a sun (outside the tree).
    fn mixed_lights(n: usize) -> Vec<GpuLight> {
        let mut numbers = Numbers(0x9e37_79b9_7f4a_7c15);
        let mut lights = vec![GpuLight {
            position_range: Vec4::ZERO,
            direction_type: Vec3::NEG_Y.extend(SUN),
            color_exponent: Vec4::ONE,
            attenuation_cos: Vec4::ZERO,
        }];
        for i in 0..n {
            let at = numbers.point(10.0);
            let colour = 0.1 + 2.0 * numbers.next();
            lights.push(match i % 4 {
                0 => point_light(at, colour, f32::INFINITY),
                1 => point_light(at, colour, 2.0 + 4.0 * numbers.next()),
                2 => GpuLight {
                    position_range: at.extend(8.0),
                    direction_type: Vec3::NEG_Y.extend(SPOT_CONE),
                    color_exponent: Vec4::new(colour, colour, colour, 2.0),
                    attenuation_cos: Vec4::new(1.0, 0.0, 1.0, 0.7),
                },
                _ => GpuLight {
                    position_range: at.extend(0.0),
                    // x × y = +y: it emits down, towards -y; two-sided for odd i / 4.
                    direction_type: Vec3::Z.extend(AREA_RECT),
                    color_exponent: Vec4::new(colour, colour, colour, ((i / 4) % 2) as f32),
                    attenuation_cos: Vec3::X.extend(0.0),
                },
            });
        }
        lights
    }

    #[test]
    fn the_tree_holds_every_positioned_light_once_in_log_depth() {
        let lights = mixed_lights(1000);
        let tree = LightTree::build(&lights);
        assert_eq!(tree.nodes.len(), 2 * 1000 - 1);
        assert_eq!(tree.trails[0], (0, u32::MAX), "the sun is outside the tree");
        let mut leaves: Vec<u32> = tree
            .nodes
            .iter()
            .filter(|n| n.leaf)
            .map(|n| n.child_or_light)
            .collect();
        leaves.sort_unstable();
        assert_eq!(leaves, (1..=1000).collect::<Vec<u32>>());
        let deepest = tree.trails[1..].iter().map(|t| t.1).max();
        assert_eq!(deepest, Some(10), "median splits: ceil(log2 1000)");
        // Spots count as point lights of their colour: 4π² C.
        let phi: f32 = lights[1..]
            .iter()
            .map(|l| {
                let kind = l.direction_type.w;
                if kind == SPOT_CONE || kind == SPOT_SPHERE {
                    4.0 * std::f32::consts::PI.powi(2)
                        * crate::emitters::luminance(l.color_exponent.truncate())
                } else {
                    power(l, 1.0)
                }
            })
            .sum();
        assert!(
            (tree.nodes[0].bounds.phi / phi - 1.0).abs() < 1e-4,
            "{} vs {phi}",
            tree.nodes[0].bounds.phi
        );
    }

    #[test]
    fn probabilities_add_up_to_at_most_one_and_sampling_reports_them() {
        let lights = mixed_lights(64);
        let tree = LightTree::build(&lights);
        let mut numbers = Numbers(7);
        let mut lit_points = 0;
        for _ in 0..200 {
            let p = numbers.point(12.0);
            let total: f32 = (0..lights.len() as u32).map(|l| tree.pmf(p, l)).sum();
            if tree.nodes[0].bounds.importance(p) > 0.0 {
                lit_points += 1;
                // Below 1 where a walk can end at a node both of whose
                // children are dark at p: then no light is picked.
                assert!(total > 0.0 && total < 1.0 + 1e-4, "{p}: {total}");
            } else {
                assert_eq!(total, 0.0);
            }
            for _ in 0..20 {
                if let Some((light, pmf)) = tree.sample(p, numbers.next()) {
                    assert_eq!(pmf, tree.pmf(p, light), "{p} light {light}");
                    assert!(pmf > 0.0);
                }
            }
        }
        assert!(lit_points > 150, "{lit_points}");
    }

    /// χ² over the lights' sampled frequencies at one point against the
    /// probabilities the trails give, 400,000 samples.
    #[test]
    fn sampling_frequencies_follow_the_probabilities() {
        let lights = mixed_lights(32);
        let tree = LightTree::build(&lights);
        let p = Vec3::new(0.5, -3.0, 1.0);
        let n = 400_000;
        let mut counts = vec![0u32; lights.len()];
        let mut numbers = Numbers(11);
        let mut none = 0u32;
        for _ in 0..n {
            match tree.sample(p, numbers.next()) {
                Some((light, _)) => counts[light as usize] += 1,
                None => none += 1,
            }
        }
        let total: f32 = (0..lights.len() as u32).map(|l| tree.pmf(p, l)).sum();
        let expected_none = (1.0 - f64::from(total)) * f64::from(n);
        println!("no light {none} times, expected {expected_none:.0}");
        assert!((f64::from(none) - expected_none).abs() <= 4.0 * expected_none.sqrt() + 1.0);
        let mut chi2 = 0.0f64;
        let mut cells = 0u32;
        for (light, &seen) in counts.iter().enumerate() {
            let expected = f64::from(tree.pmf(p, light as u32)) * f64::from(n);
            if expected == 0.0 {
                assert_eq!(seen, 0, "light {light} has probability 0");
                continue;
            }
            chi2 += (f64::from(seen) - expected).powi(2) / expected;
            cells += 1;
        }
        // With "no light" as one more cell: degrees of freedom `cells`, and
        // the 0.999 quantile by Wilson and Hilferty's approximation.
        chi2 += (f64::from(none) - expected_none).powi(2) / expected_none.max(1.0);
        let k = f64::from(cells);
        let quantile = k * (1.0 - 2.0 / (9.0 * k) + 3.09 * (2.0 / (9.0 * k)).sqrt()).powi(3);
        println!("χ² {chi2:.1} over {cells} lights and none; 0.999 quantile {quantile:.1}");
        assert!(cells >= 10 && chi2 < quantile, "χ² {chi2} over {cells}");
    }

    #[test]
    fn lights_that_cannot_reach_a_point_are_never_picked_for_it() {
        // Two points of range 1 at x = ±5, and one without a range far off.
        let lights = [
            point_light(Vec3::new(-5.0, 0.0, 0.0), 1.0, 1.0),
            point_light(Vec3::new(5.0, 0.0, 0.0), 1.0, 1.0),
            GpuLight {
                position_range: Vec3::new(0.0, 10.0, 0.0).extend(0.0),
                direction_type: Vec3::Z.extend(AREA_RECT),
                color_exponent: Vec4::new(1.0, 1.0, 1.0, 0.0),
                attenuation_cos: Vec3::X.extend(0.0),
            },
        ];
        let tree = LightTree::build(&lights);
        // Near the left light and below the area light (which faces down).
        let near_left = Vec3::new(-5.0, 0.5, 0.0);
        assert!(tree.pmf(near_left, 0) > 0.0);
        assert_eq!(tree.pmf(near_left, 1), 0.0);
        assert!(tree.pmf(near_left, 2) > 0.0);
        // Above the one-sided area light, beyond both ranges: nothing.
        let above = Vec3::new(0.0, 20.0, 0.0);
        assert_eq!(tree.sample(above, 0.5), None);
        assert_eq!((0..3).map(|l| tree.pmf(above, l)).sum::<f32>(), 0.0);
    }

    /// The demo's lights: a spot of attenuation 1 / (1 + 0.05 d + 0.01 d²)
    /// and a ceiling area light share a node; a point light of 1 / (1 +
    /// 0.8 d²) is its sibling. Half a unit from the point light, outside the
    /// spot's cone, the point light gives most of the light and must get
    /// most of the samples (with each coefficient the least of the two, the
    /// shared node's importance was 16 times too high and took them).
    #[test]
    fn mixed_attenuations_do_not_starve_a_near_light() {
        let spot = GpuLight {
            position_range: Vec3::new(0.0, 5.2, 4.5).extend(50.0),
            direction_type: Vec3::new(-0.9, -4.3, -5.2).normalize().extend(SPOT_CONE),
            color_exponent: Vec4::new(1.0, 1.0, 1.0, 8.0),
            attenuation_cos: Vec4::new(1.0, 0.05, 0.01, 25f32.to_radians().cos()),
        };
        let area = GpuLight {
            position_range: Vec3::new(0.0, 5.9, 0.0).extend(0.0),
            direction_type: (Vec3::X * 0.7).extend(AREA_RECT),
            color_exponent: Vec4::new(17.0, 12.0, 4.0, 0.0),
            attenuation_cos: (Vec3::Z * 0.57).extend(0.0),
        };
        let mut point = point_light(Vec3::new(2.2, 2.5, -1.0), 0.5, f32::INFINITY);
        point.attenuation_cos = Vec4::new(1.0, 0.0, 0.8, 0.0);
        let tree = LightTree::build(&[spot, area, point]);
        let p = Vec3::new(2.2, 2.0, -1.0);
        let share = tree.pmf(p, 2);
        println!("the point light's probability half a unit away: {share:.3}");
        assert!(share > 0.5, "{share}");
    }
}
