//! The environment map prefiltered for glossy reflections in raster graphs
//! (the split-sum approximation, Karis 2013): for each of
//! [`PREFILTER_LEVELS`] roughnesses, an equirectangular image whose texel in
//! direction R holds ∫ L(l) D(h) (R·l) dl / ∫ D(h) (R·l) dl with the normal
//! and the view along R, D the GGX distribution of `brdf.glsl`. Shaders
//! multiply it by the single-scattering albedo (`ggx_single_albedo`), the
//! split sum's other half. Integrated by GGX importance sampling from a box-
//! filtered mip chain of the map, each sample read at the mip whose texel
//! covers its solid angle (filtered importance sampling, Křivánek and
//! Colbert 2008), on the CPU when the map is loaded.

use crate::environment::{bilinear, direction_uv, uv_direction};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::f32::consts::PI;
use weft_scene::environment::Environment;

/// Prefiltered roughnesses: level k (from 0) is perceptual roughness
/// (k + 1) / PREFILTER_LEVELS; roughness 0 is the map itself.
pub const PREFILTER_LEVELS: usize = 5;
/// Each level's width in texels (`ENVIRONMENT_PREFILTER_WIDTH` in
/// environment.glsl).
pub const PREFILTER_WIDTH: u32 = 64;
/// Each level's height in texels.
pub const PREFILTER_HEIGHT: u32 = 32;
/// GGX samples per texel.
const SAMPLES: u32 = 256;
/// Mips finer by one than the sample's solid angle asks for: coarser ones
/// blur past the lobe where the equirectangular texels are far from square
/// (2.7% from brute force at the pole with no bias; within the test's 2%
/// with −1).
const LOD_BIAS: f32 = -1.0;

/// One image of the mip chain: RGB texels, rows from the top.
struct Level {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
    /// Whether row y holds v in [y, y + 1) / H (levels made by averaging)
    /// rather than v = y / (H - 1) (the map).
    cell_rows: bool,
}

impl Level {
    /// Bilinear at `uv` with the map's convention (wrapping in x).
    fn lookup(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        // The map's rows sit at v = y / (H - 1); a coarser level's texel
        // averages a cell, so its row sits at the cell's centre.
        let y = if self.cell_rows {
            uv.y * self.height as f32 - 0.5
        } else {
            uv.y * (self.height - 1) as f32
        };
        bilinear(self.width, self.height, |i| self.texels[i], x, y)
    }

    /// The next coarser level: 2×2 box averages (odd sizes keep their last
    /// row or column).
    fn halved(&self) -> Level {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let at = |x: u32, y: u32| {
            self.texels[(y.min(self.height - 1) * self.width + x.min(self.width - 1)) as usize]
        };
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                (at(2 * x, 2 * y)
                    + at(2 * x + 1, 2 * y)
                    + at(2 * x, 2 * y + 1)
                    + at(2 * x + 1, 2 * y + 1))
                    * 0.25
            })
            .collect();
        Level {
            width: w,
            height: h,
            texels,
            cell_rows: true,
        }
    }
}

/// The map's mip chain down to a few texels.
fn mip_chain(env: &Environment) -> Vec<Level> {
    let mut chain = vec![Level {
        width: env.width,
        height: env.height,
        texels: env.texels.iter().map(|t| Vec3::from(*t)).collect(),
        cell_rows: false,
    }];
    while chain.last().is_some_and(|l| l.width > 4 && l.height > 2) {
        let next = chain.last().map(Level::halved).expect("a level");
        chain.push(next);
    }
    chain
}

/// Trilinear lookup at fractional mip `lod`.
fn lookup_lod(chain: &[Level], uv: Vec2, lod: f32) -> Vec3 {
    let lod = lod.clamp(0.0, (chain.len() - 1) as f32);
    let lo = lod.floor() as usize;
    let hi = (lo + 1).min(chain.len() - 1);
    chain[lo]
        .lookup(uv)
        .lerp(chain[hi].lookup(uv), lod - lo as f32)
}

/// The i-th of `n` points of the Hammersley set.
fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new(
        i as f32 / n as f32,
        i.reverse_bits() as f32 * 2.328_306_4e-10,
    )
}

/// An orthonormal frame (t, b) around unit `n`.
fn frame(n: Vec3) -> (Vec3, Vec3) {
    let t = if n.y.abs() < 0.999 {
        Vec3::Y.cross(n).normalize()
    } else {
        Vec3::X.cross(n).normalize()
    };
    (t, n.cross(t))
}

/// GGX D for the cosine `cos_h` of the half vector, alpha = roughness².
fn ggx_d(cos_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let q = cos_h * cos_h * (a2 - 1.0) + 1.0;
    a2 / (PI * q * q)
}

/// The prefiltered radiance in the map's frame toward direction `r`, for
/// perceptual roughness `roughness`, from the mip `chain` of a map of
/// `texels` texels.
fn prefilter_at(chain: &[Level], r: Vec3, roughness: f32) -> Vec3 {
    let alpha = roughness * roughness;
    let (t, b) = frame(r);
    let texel_solid_angle = 4.0 * PI / (chain[0].width * chain[0].height) as f32;
    let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
    for i in 0..SAMPLES {
        let u = hammersley(i, SAMPLES);
        // GGX's half vectors by their density D cos_h.
        let cos_h = ((1.0 - u.y) / (1.0 + (alpha * alpha - 1.0) * u.y)).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let phi = 2.0 * PI * u.x;
        let h = t * (sin_h * phi.cos()) + b * (sin_h * phi.sin()) + r * cos_h;
        let l = 2.0 * r.dot(h) * h - r;
        let cos_l = r.dot(l);
        if cos_l <= 0.0 {
            continue;
        }
        // The sample's density by solid angle is D cos_h / (4 v·h) = D / 4.
        let pdf = ggx_d(cos_h, alpha) / 4.0;
        let lod = 0.5
            * (1.0 / (SAMPLES as f32 * pdf * texel_solid_angle))
                .max(1.0)
                .log2()
            + LOD_BIAS;
        sum += lookup_lod(chain, direction_uv(l), lod) * cos_l;
        weight += cos_l;
    }
    sum / weight.max(1e-12)
}

/// The [`PREFILTER_LEVELS`] prefiltered images, level after level, each
/// [`PREFILTER_WIDTH`]×[`PREFILTER_HEIGHT`] texels, in the map's own frame
/// and before its intensity. Texel (x, y) holds direction
/// (u, v) = ((x + ½)/W, y/(H − 1)), so the map's lookup convention reads it.
pub fn prefiltered(env: &Environment) -> Vec<[f32; 3]> {
    let chain = mip_chain(env);
    let (w, h) = (PREFILTER_WIDTH as usize, PREFILTER_HEIGHT as usize);
    (0..PREFILTER_LEVELS * w * h)
        .into_par_iter()
        .map(|i| {
            let (k, y, x) = (i / (w * h) + 1, i / w % h, i % w);
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, y as f32 / (h - 1) as f32);
            let roughness = k as f32 / PREFILTER_LEVELS as f32;
            prefilter_at(&chain, uv_direction(uv), roughness).to_array()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::radiance;
    use std::path::PathBuf;

    /// A sky with a gradient and a warm lobe, 128×64.
    fn sky() -> Environment {
        let (w, h) = (128u32, 64u32);
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| {
                let d = uv_direction(Vec2::new(
                    (x as f32 + 0.5) / w as f32,
                    (y as f32 + 0.5) / h as f32,
                ));
                let lobe = (8.0 * (d.dot(Vec3::new(0.5, 0.6, -0.62).normalize()) - 1.0)).exp();
                [
                    0.2 + 6.0 * lobe,
                    0.3 + 4.0 * lobe + 0.2 * d.y,
                    0.5 + lobe + 0.3 * d.y.max(0.0),
                ]
            })
            .collect();
        Environment {
            file: PathBuf::from("sky.exr"),
            intensity: 1.0,
            rotation_deg: 0.0,
            width: w,
            height: h,
            texels,
        }
    }

    /// ∫ L D(h) (r·l) dl / ∫ D(h) (r·l) dl on a 1024×512 grid of the map.
    fn brute_force(env: &Environment, r: Vec3, roughness: f32) -> Vec3 {
        let alpha = roughness * roughness;
        let (nu, nv) = (1024, 512);
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0f64);
        for j in 0..nv {
            for i in 0..nu {
                let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
                let l = uv_direction(uv);
                let cos_l = r.dot(l);
                if cos_l <= 0.0 {
                    continue;
                }
                let h = (l + r).normalize();
                let w = f64::from(ggx_d(r.dot(h), alpha) * cos_l * (uv.y * PI).sin());
                sum += radiance(env, l).as_dvec3() * w;
                weight += w;
            }
        }
        (sum / weight).as_vec3()
    }

    #[test]
    fn prefiltered_levels_match_brute_force_integration_within_two_percent() {
        let env = sky();
        let chain = mip_chain(&env);
        for roughness in [0.4, 0.6, 1.0] {
            for r in [
                Vec3::new(0.5, 0.6, -0.62),
                Vec3::Y,
                Vec3::new(-0.7, -0.2, 0.3),
                Vec3::new(0.2, 0.1, -0.9),
            ] {
                let r = r.normalize();
                let got = prefilter_at(&chain, r, roughness);
                let expected = brute_force(&env, r, roughness);
                let error = ((got - expected) / expected).abs().max_element();
                assert!(
                    error < 0.02,
                    "roughness {roughness}, R {r}: {got} against {expected} ({error:.4})"
                );
            }
        }
    }

    #[test]
    fn a_uniform_map_prefilters_to_itself_and_levels_are_laid_out_in_order() {
        let env = Environment {
            texels: vec![[0.25, 0.5, 2.0]; 32 * 16],
            width: 32,
            height: 16,
            ..sky()
        };
        let levels = prefiltered(&env);
        assert_eq!(
            levels.len(),
            PREFILTER_LEVELS * (PREFILTER_WIDTH * PREFILTER_HEIGHT) as usize
        );
        for texel in levels {
            assert!(
                (Vec3::from(texel) - Vec3::new(0.25, 0.5, 2.0))
                    .abs()
                    .max_element()
                    < 1e-5
            );
        }
    }
}
