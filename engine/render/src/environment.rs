//! The environment map as shaders read it (`shaders/include/environment.glsl`,
//! `shaders/pathtrace/environment_sampling.glsl`) and its CPU model: the
//! lookup oriented and filtered exactly as Mitsuba 3's `envmap` (a local
//! direction d has u = atan2(d.x, −d.z)/2π, v = acos(d.y)/π; the texel
//! coordinate is (u·W − ½, v·(H − 1)), wrapped in x, clamped in y, bilinear),
//! the table the path tracer samples directions from (piecewise constant
//! over the texel grid in (u, v), in proportion to the lookup's luminance
//! times the cell's solid angle, through alias tables), and the nine
//! spherical-harmonic coefficients of its irradiance that raster passes
//! light with.

use crate::emitters::{alias_table, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use weft_scene::environment::Environment;

/// `(cos, sin)` of the map's rotation about +y.
fn turn(rotation_deg: f32) -> (f32, f32) {
    let r = rotation_deg.to_radians();
    (r.cos(), r.sin())
}

/// A world direction in the map's frame (Mitsuba's `to_world` inverse for a
/// rotation of `rotation_deg` about +y).
pub fn local_direction(world: Vec3, rotation_deg: f32) -> Vec3 {
    let (c, s) = turn(rotation_deg);
    Vec3::new(
        c * world.x - s * world.z,
        world.y,
        s * world.x + c * world.z,
    )
}

/// A direction in the map's frame, in the world.
pub fn world_direction(local: Vec3, rotation_deg: f32) -> Vec3 {
    let (c, s) = turn(rotation_deg);
    Vec3::new(
        c * local.x + s * local.z,
        local.y,
        -s * local.x + c * local.z,
    )
}

/// The map coordinates of a unit direction in the map's frame, u in [0, 1).
pub fn direction_uv(local: Vec3) -> Vec2 {
    let u = local.x.atan2(-local.z) / (2.0 * PI);
    Vec2::new(u - u.floor(), local.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The unit direction in the map's frame at map coordinates `uv`.
pub fn uv_direction(uv: Vec2) -> Vec3 {
    let (sin_phi, cos_phi) = (2.0 * PI * uv.x).sin_cos();
    let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
    Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
}

/// The bilinear value at texel coordinates (`x`, `y`) of a `width`×`height`
/// image whose texel number `i` (row by row) is `texel(i)`, wrapping in x
/// and clamping in y as the map's lookup does (the prefiltered levels are
/// read the same way).
pub(crate) fn bilinear(
    width: u32,
    height: u32,
    texel: impl Fn(usize) -> Vec3,
    x: f32,
    y: f32,
) -> Vec3 {
    let (w, h) = (i64::from(width), i64::from(height));
    let at = |x: i64, y: i64| texel((y.clamp(0, h - 1) * w + x.rem_euclid(w)) as usize);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let row = |y| at(x0, y).lerp(at(x0 + 1, y), fx);
    row(y0).lerp(row(y0 + 1), fy)
}

/// The map's bilinear value at `uv`, before `intensity`.
fn lookup_uv(env: &Environment, uv: Vec2) -> Vec3 {
    let x = uv.x * env.width as f32 - 0.5;
    let y = uv.y * (env.height - 1) as f32;
    bilinear(env.width, env.height, |i| Vec3::from(env.texels[i]), x, y)
}

/// The radiance arriving from world direction `dir` (unit).
pub fn radiance(env: &Environment, dir: Vec3) -> Vec3 {
    env.intensity * lookup_uv(env, direction_uv(local_direction(dir, env.rotation_deg)))
}

/// The table the path tracer samples directions from, and its densities.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentTable {
    /// Per texel cell, row by row: keep threshold (f32 bits), alias column,
    /// the cell's density in (u, v) (f32 bits), 0; then per row: threshold,
    /// alias row, 0, 0.
    pub records: Vec<[u32; 4]>,
    /// Whether any direction has light (a black map is not sampled).
    pub sampled: bool,
}

/// The cell weights: for cell (x, y) (u in [x, x+1)/W, v in [y, y+1)/H),
/// the luminance the bilinear lookup takes there, averaged over its columns
/// (weights ⅛, ¾, ⅛) and the rows it touches, times the cell's solid angle.
/// A cell has weight wherever the lookup can be non-zero, so sampling is
/// unbiased.
fn cell_weights(env: &Environment) -> Vec<f64> {
    let (w, h) = (env.width as usize, env.height as usize);
    let lum: Vec<f64> = env
        .texels
        .iter()
        .map(|t| f64::from(luminance(Vec3::from(*t))))
        .collect();
    let mut weights = vec![0.0; w * h];
    let span = (h - 1) as f64 / h as f64;
    for y in 0..h {
        let first = (y as f64 * span).floor() as usize;
        let last = (((y + 1) as f64 * span).ceil() as usize).min(h - 1);
        let theta = |v: f64| v * std::f64::consts::PI;
        let solid = theta(y as f64 / h as f64).cos() - theta((y + 1) as f64 / h as f64).cos();
        for x in 0..w {
            let mut sum = 0.0;
            for r in first..=last {
                let at = |c: usize| lum[r * w + c];
                sum += 0.125 * at((x + w - 1) % w) + 0.75 * at(x) + 0.125 * at((x + 1) % w);
            }
            weights[y * w + x] = sum / (last - first + 1) as f64 * solid;
        }
    }
    weights
}

impl EnvironmentTable {
    /// The table for `env`.
    pub fn build(env: &Environment) -> Self {
        let (w, h) = (env.width as usize, env.height as usize);
        let weights = cell_weights(env);
        let total: f64 = weights.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Self {
                records: vec![[0; 4]; w * h + h],
                sampled: false,
            };
        }
        let mut records = Vec::with_capacity(w * h + h);
        let mut rows = Vec::with_capacity(h);
        for row in weights.chunks(w) {
            let sum: f64 = row.iter().sum();
            rows.push(sum);
            let (threshold, alias) = if sum > 0.0 {
                alias_table(row)
            } else {
                (vec![1.0; w], (0..w as u32).collect())
            };
            for (x, weight) in row.iter().enumerate() {
                let density = (weight / total * (w * h) as f64) as f32;
                records.push([threshold[x].to_bits(), alias[x], density.to_bits(), 0]);
            }
        }
        let (threshold, alias) = alias_table(&rows);
        records.extend(
            threshold
                .iter()
                .zip(&alias)
                .map(|(t, a)| [t.to_bits(), *a, 0, 0]),
        );
        Self {
            records,
            sampled: true,
        }
    }

    /// The density by solid angle of sampling world direction `dir`.
    pub fn pdf(&self, env: &Environment, dir: Vec3) -> f32 {
        let local = local_direction(dir, env.rotation_deg);
        let uv = direction_uv(local);
        let sin_theta = (1.0 - local.y * local.y).max(0.0).sqrt();
        if !self.sampled || sin_theta == 0.0 {
            return 0.0;
        }
        let (w, h) = (env.width as usize, env.height as usize);
        let x = ((uv.x * w as f32) as usize).min(w - 1);
        let y = ((uv.y * h as f32) as usize).min(h - 1);
        f32::from_bits(self.records[y * w + x][2]) / (2.0 * PI * PI * sin_theta)
    }

    /// A world direction sampled from four uniform numbers, and its density
    /// by solid angle, as `environment_sample` draws it.
    pub fn sample(&self, env: &Environment, u: [f32; 4]) -> Option<(Vec3, f32)> {
        if !self.sampled {
            return None;
        }
        let (w, h) = (env.width as usize, env.height as usize);
        let pick = |u: f32, n: usize, record: &dyn Fn(usize) -> [u32; 4]| {
            let scaled = u * n as f32;
            let slot = (scaled as usize).min(n - 1);
            let [threshold, alias, ..] = record(slot);
            if scaled - (slot as f32) < f32::from_bits(threshold) {
                slot
            } else {
                alias as usize
            }
        };
        let y = pick(u[0], h, &|r| self.records[w * h + r]);
        let x = pick(u[1], w, &|c| self.records[y * w + c]);
        let uv = Vec2::new((x as f32 + u[2]) / w as f32, (y as f32 + u[3]) / h as f32);
        let local = uv_direction(uv);
        let dir = world_direction(local, env.rotation_deg);
        let pdf = self.pdf(env, dir);
        (pdf > 0.0).then_some((dir, pdf))
    }
}

/// The nine real spherical harmonics (bands 0 to 2) at unit direction `d`.
pub fn sh9(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_095,
        0.488_603 * y,
        0.488_603 * z,
        0.488_603 * x,
        1.092_548 * x * y,
        1.092_548 * y * z,
        0.315_392 * (3.0 * z * z - 1.0),
        1.092_548 * x * z,
        0.546_274 * (x * x - y * y),
    ]
}

/// The coefficients c of the map's irradiance in its own frame, scaled so
/// that Σ cᵢ Yᵢ(n) is E(n)/π (the radiance of a uniform sky with that
/// irradiance, what the ambient term multiplies by the albedo), intensity
/// included: the radiance projected on [`sh9`] by integrating the lookup
/// over a 2×2 grid per texel, then convolved with the clamped cosine
/// (Ramamoorthi and Hanrahan 2001: Â = π, 2π/3, π/4 per band).
pub fn irradiance_sh(env: &Environment) -> [Vec3; 9] {
    let (nu, nv) = (2 * env.width as usize, 2 * env.height as usize);
    let mut sums = [glam::DVec3::ZERO; 9];
    for j in 0..nv {
        let v0 = j as f64 / nv as f64;
        let v1 = (j + 1) as f64 / nv as f64;
        let pi = std::f64::consts::PI;
        let solid = 2.0 * pi / nu as f64 * ((v0 * pi).cos() - (v1 * pi).cos());
        for i in 0..nu {
            let uv = Vec2::new((i as f32 + 0.5) / nu as f32, ((v0 + v1) * 0.5) as f32);
            let value = lookup_uv(env, uv).as_dvec3() * solid;
            for (sum, y) in sums.iter_mut().zip(sh9(uv_direction(uv))) {
                *sum += value * f64::from(y);
            }
        }
    }
    let band = [
        1.0,
        2.0 / 3.0,
        2.0 / 3.0,
        2.0 / 3.0,
        0.25,
        0.25,
        0.25,
        0.25,
        0.25,
    ];
    let mut out = [Vec3::ZERO; 9];
    for ((o, s), a) in out.iter_mut().zip(sums).zip(band) {
        *o = (s * a).as_vec3() * env.intensity;
    }
    out
}

#[cfg(test)]
#[path = "environment_tests.rs"]
mod tests;
