//! The emissive triangles a path tracer samples for next-event estimation.
//! Each is chosen in proportion to the power it emits (the luminance of its
//! emitted radiance times its area) through an alias table (Vose's method),
//! so picking one costs two random numbers and one lookup on the GPU.

use glam::Vec3;

/// Rec. 709 luminance: the weight power-proportional choice uses.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The table the shaders read (`emitter_table` in `shaders/include/trace.glsl`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EmitterTable {
    /// Per emitter: triangle index, alias (an index into this list), the
    /// threshold below which the emitter itself is kept (as f32 bits), 0.
    pub records: Vec<[u32; 4]>,
    /// Sum over emitters of luminance times area: the pdf of a point on
    /// emitter `t` by area is `luminance(Le_t) / total`.
    pub total: f32,
}

impl EmitterTable {
    /// The table over every triangle whose `emission(t)` has positive
    /// luminance; degenerate (zero-area) triangles are left out.
    pub fn build(corners: &[[Vec3; 3]], emission: impl Fn(usize) -> Vec3) -> Self {
        let mut triangles = Vec::new();
        let mut weights = Vec::new();
        for (t, [a, b, c]) in corners.iter().enumerate() {
            let area = 0.5 * (*b - *a).cross(*c - *a).length();
            let weight = f64::from(luminance(emission(t))) * f64::from(area);
            if weight.is_finite() && weight > 0.0 {
                triangles.push(t as u32);
                weights.push(weight);
            }
        }
        let total: f64 = weights.iter().sum();
        let (threshold, alias) = alias_table(&weights);
        let records = triangles
            .iter()
            .zip(threshold.iter().zip(&alias))
            .map(|(&t, (&p, &a))| [t, a, p.to_bits(), 0])
            .collect();
        Self {
            records,
            total: total as f32,
        }
    }

    /// The GPU buffer: a header (count, total as f32 bits, 0, 0), then the records.
    pub fn bytes(&self) -> Vec<u8> {
        table_bytes(
            [self.records.len() as u32, self.total.to_bits(), 0, 0],
            &self.records,
        )
    }
}

/// An alias table's GPU buffer: a `uvec4` header, then a `uvec4` per record.
pub(crate) fn table_bytes(header: [u32; 4], records: &[[u32; 4]]) -> Vec<u8> {
    std::iter::once(header)
        .chain(records.iter().copied())
        .flat_map(|r| r.into_iter().flat_map(u32::to_ne_bytes))
        .collect()
}

/// Vose's alias method: for `n` weights, per slot a threshold in [0, 1] and
/// an alias, so that picking a slot uniformly and keeping it when a uniform
/// number is below its threshold (else taking its alias) picks slot `i` with
/// probability `weights[i] / sum`.
pub(crate) fn alias_table(weights: &[f64]) -> (Vec<f32>, Vec<u32>) {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
    let mut threshold = vec![1.0f32; n];
    let mut alias: Vec<u32> = (0..n as u32).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        threshold[s] = scaled[s] as f32;
        alias[s] = l as u32;
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    (threshold, alias)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probability the table gives each slot: its own threshold share
    /// plus the shares of every slot that aliases to it.
    fn probabilities(threshold: &[f32], alias: &[u32]) -> Vec<f64> {
        let n = threshold.len() as f64;
        let mut p = vec![0.0; threshold.len()];
        for (i, (&t, &a)) in threshold.iter().zip(alias).enumerate() {
            p[i] += f64::from(t) / n;
            p[a as usize] += (1.0 - f64::from(t)) / n;
        }
        p
    }

    #[test]
    fn alias_table_reproduces_the_weights() {
        let weights = [1.0, 7.0, 0.5, 2.5, 0.0, 13.0, 1.0];
        let (threshold, alias) = alias_table(&weights);
        let total: f64 = weights.iter().sum();
        for (p, w) in probabilities(&threshold, &alias).iter().zip(weights) {
            assert!((p - w / total).abs() < 1e-6, "{p} vs {}", w / total);
        }
    }

    #[test]
    fn only_emissive_nondegenerate_triangles_are_listed() {
        let tri = |x: f32| {
            [
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 1.0, 0.0, 0.0),
                Vec3::new(x, 2.0, 0.0),
            ]
        };
        let flat = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        let corners = [tri(0.0), tri(5.0), flat, tri(9.0)];
        let emission = |t: usize| match t {
            0 => Vec3::ONE,
            1 => Vec3::ZERO,
            2 => Vec3::ONE,
            _ => Vec3::new(3.0, 3.0, 3.0),
        };
        let table = EmitterTable::build(&corners, emission);
        let listed: Vec<u32> = table.records.iter().map(|r| r[0]).collect();
        assert_eq!(listed, [0, 3]);
        // Areas 1 and 1, luminances 1 and 3.
        assert!((table.total - 4.0).abs() < 1e-5, "{}", table.total);
        let bytes = table.bytes();
        assert_eq!(bytes.len(), 16 * 3);
        assert_eq!(u32::from_ne_bytes(bytes[0..4].try_into().unwrap()), 2);
    }
}
