//! The metallic-roughness BRDF of `shaders/include/brdf.glsl` and the
//! area-light quadrature of `shaders/include/lighting.glsl` on the CPU, term
//! for term and with the same constants and tables (a unit test reads the
//! constants back from the shader source): the GGX math and its energy
//! conservation are tested here without a GPU, and GPU tests compare
//! rendered radiance with it.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use weft_ltc::energy::Albedo;
pub use weft_render::AreaGeometry;

/// Roughness is raised to at least this (`MIN_ROUGHNESS` in `brdf.glsl`).
pub const MIN_ROUGHNESS: f32 = 0.045;
/// Reflectance at normal incidence of non-metals (`DIELECTRIC_F0`).
pub const DIELECTRIC_F0: f32 = 0.04;
/// Cells per side of the area-light quadrature the tests run the shaders with
/// (graph parameter `area_samples` 8; 0, the default, integrates analytically).
pub const AREA_SAMPLES: u32 = 8;

/// GGX (Trowbridge-Reitz) normal distribution for `alpha²` = `a2`.
pub fn distribution(ndh: f32, a2: f32) -> f32 {
    let q = ndh * ndh * (a2 - 1.0) + 1.0;
    a2 / (PI * q * q)
}

/// Smith height-correlated visibility term `G / (4 N.L N.V)`.
pub fn visibility(ndl: f32, ndv: f32, a2: f32) -> f32 {
    0.5 / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt() + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt())
}

/// Schlick's Fresnel approximation.
pub fn fresnel(f0: Vec3, vdh: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * (1.0 - vdh).powi(5)
}

/// Single-scattering GGX's albedo entries at perceptual `roughness` seen at
/// `cos`, from the committed table as the shaders interpolate it
/// (`ggx_albedo` in `ltc_tables.glsl`).
pub fn ggx_albedo(roughness: f32, cos: f32) -> Albedo {
    let (table, averages) =
        weft_ltc::energy::AlbedoTable::committed().expect("the committed GGX albedo table reads");
    table.lookup(averages, roughness, cos)
}

/// Kulla-Conty's share of lost energy that returns through Fresnel
/// (`ggx_multiple_scattering`).
fn multiple_scattering(f0: Vec3, e_avg: f32) -> Vec3 {
    let f_avg = f0 + (Vec3::ONE - f0) / 21.0;
    f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg))
}

/// What the specular layer reflects from a direction with entries `t`
/// (`ggx_layer_albedo`).
fn layer_albedo(f0: Vec3, t: &Albedo, multiple: Vec3) -> Vec3 {
    f0 * (t.integral - t.fresnel) + Vec3::splat(t.fresnel) + multiple * (1.0 - t.integral)
}

/// The layer's cosine-weighted average (`ggx_layer_average`).
fn layer_average(f0: Vec3, t: &Albedo, multiple: Vec3) -> Vec3 {
    f0 * (t.average - t.average_fresnel)
        + Vec3::splat(t.average_fresnel)
        + multiple * (1.0 - t.average)
}

/// The lobes separable in view and light, times pi (`ggx_separable`):
/// multiple scattering of the dielectric and the metal, and the dielectric's
/// diffuse base under what its specular layer leaves, blended by `metallic`.
fn separable(base: Vec3, metallic: f32, tv: &Albedo, tl: &Albedo) -> Vec3 {
    let lost = (1.0 - tv.integral) * (1.0 - tl.integral) / (1.0 - tv.average).max(1e-6);
    let f0 = Vec3::splat(DIELECTRIC_F0);
    let m_dielectric = multiple_scattering(f0, tv.average);
    let left = (Vec3::ONE - layer_average(f0, tv, m_dielectric)).max(Vec3::splat(1e-6));
    let dielectric = m_dielectric * lost
        + base
            * (Vec3::ONE - layer_albedo(f0, tv, m_dielectric))
            * (Vec3::ONE - layer_albedo(f0, tl, m_dielectric))
            / left;
    dielectric.lerp(multiple_scattering(base, tv.average) * lost, metallic)
}

/// Single-scattering GGX times N.L: Smith height-correlated visibility,
/// Schlick's Fresnel with `F0 = mix(0.04, base, metallic)`.
pub fn single_scattering(
    base: Vec3,
    metallic: f32,
    roughness: f32,
    n: Vec3,
    v: Vec3,
    l: Vec3,
) -> Vec3 {
    let ndl = n.dot(l);
    if ndl <= 0.0 {
        return Vec3::ZERO;
    }
    let ndv = n.dot(v).max(1e-4);
    let h = (l + v).normalize();
    let ndh = n.dot(h).max(0.0);
    let vdh = v.dot(h).max(0.0);
    let r = roughness.max(MIN_ROUGHNESS);
    let a2 = r * r * r * r;
    let f0 = Vec3::splat(DIELECTRIC_F0).lerp(base, metallic);
    distribution(ndh, a2) * visibility(ndl, ndv, a2) * fresnel(f0, vdh) * ndl
}

/// Energy-conserving Cook-Torrance times N.L (`cook_torrance` in
/// `brdf.glsl`): [`single_scattering`], Kulla-Conty multiple scattering, and
/// the dielectric's diffuse base under what its specular layer leaves, as
/// glTF's blend of dielectric and metal: the radiance reflected towards `v`
/// per unit irradiance arriving along `l`.
pub fn cook_torrance(base: Vec3, metallic: f32, roughness: f32, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
    let ndl = n.dot(l);
    if ndl <= 0.0 {
        return Vec3::ZERO;
    }
    let r = roughness.max(MIN_ROUGHNESS);
    let lobes = separable(
        base,
        metallic,
        &ggx_albedo(r, n.dot(v).max(1e-4)),
        &ggx_albedo(r, ndl),
    );
    single_scattering(base, metallic, roughness, n, v, l) + lobes / PI * ndl
}

/// What a metallic-roughness surface reflects of a constant environment of
/// radiance 1 seen at `ndv` (`ggx_directional_albedo`).
pub fn directional_albedo(base: Vec3, metallic: f32, roughness: f32, ndv: f32) -> Vec3 {
    let t = ggx_albedo(roughness.max(MIN_ROUGHNESS), ndv);
    let f0 = Vec3::splat(DIELECTRIC_F0);
    let dielectric = layer_albedo(f0, &t, multiple_scattering(f0, t.average));
    let metal = layer_albedo(base, &t, multiple_scattering(base, t.average));
    (dielectric + base * (Vec3::ONE - dielectric)).lerp(metal, metallic)
}

/// Shirley-Chiu concentric map of `[-1, 1]²` onto the unit disc (area-preserving).
pub fn concentric(p: Vec2) -> Vec2 {
    if p == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, phi) = if p.x.abs() > p.y.abs() {
        (p.x, PI / 4.0 * p.y / p.x)
    } else {
        (p.y, PI / 2.0 - PI / 4.0 * p.x / p.y)
    };
    r * Vec2::new(phi.cos(), phi.sin())
}

/// The area-light quadratures of `shaders/include/lighting.glsl` on the CPU,
/// for an area light as the renderer packs it
/// ([`weft_render::AreaGeometry`]).
pub trait AreaIrradiance {
    /// Irradiance at `p` on a surface with normal `n` per unit emitted radiance,
    /// as the shaders estimate it: `AREA_SAMPLES²` equal-area cells, each seen
    /// from its centre with weight `cos(theta_light) A / (d² + A / pi)`.
    fn irradiance(&self, p: Vec3, n: Vec3) -> f32;

    /// The same irradiance integrated by brute force: the point-source formula
    /// `cos(theta_light) cos(theta) dA / d²` at the centres of `n × n` cells
    /// (points outside a disc dropped), for references.
    fn irradiance_brute_force(&self, p: Vec3, normal: Vec3, n: u32) -> f64;
}

/// `L cos(theta_light) / d²`-style weight of `light` seen from a point in
/// direction `l` at squared distance `d2` with cell area `cell`, or 0 from behind.
fn cell_weight(light: &AreaGeometry, l: Vec3, d2: f32, cell: f32) -> f32 {
    let c = -l.dot(light.facing());
    let c = if light.two_sided { c.abs() } else { c };
    if c > 0.0 {
        c * cell / (d2 + cell / PI)
    } else {
        0.0
    }
}

impl AreaIrradiance for AreaGeometry {
    fn irradiance(&self, p: Vec3, n: Vec3) -> f32 {
        let cells = AREA_SAMPLES * AREA_SAMPLES;
        let cell = self.area() / cells as f32;
        (0..cells)
            .map(|k| {
                let ij = Vec2::new((k % AREA_SAMPLES) as f32, (k / AREA_SAMPLES) as f32);
                let mut uv = (ij + 0.5) * (2.0 / AREA_SAMPLES as f32) - 1.0;
                if self.disc {
                    uv = concentric(uv);
                }
                let to_light = self.centre + uv.x * self.x + uv.y * self.y - p;
                let d2 = to_light.length_squared();
                let l = to_light / d2.max(1e-12).sqrt();
                cell_weight(self, l, d2, cell) * n.dot(l).max(0.0)
            })
            .sum()
    }

    fn irradiance_brute_force(&self, p: Vec3, normal: Vec3, n: u32) -> f64 {
        let step = 2.0 / f64::from(n);
        let cell = f64::from(self.x.length() * self.y.length()) * step * step;
        let mut sum = 0.0;
        for j in 0..n {
            for i in 0..n {
                let u = (f64::from(i) + 0.5) * step - 1.0;
                let v = (f64::from(j) + 0.5) * step - 1.0;
                if self.disc && u * u + v * v > 1.0 {
                    continue;
                }
                let q = self.centre.as_dvec3() + u * self.x.as_dvec3() + v * self.y.as_dvec3();
                let to_light = q - p.as_dvec3();
                let d2 = to_light.length_squared();
                let l = to_light / d2.sqrt();
                let c = -l.dot(self.facing().as_dvec3());
                let c = if self.two_sided { c.abs() } else { c };
                let cos = l.dot(normal.as_dvec3());
                if c > 0.0 && cos > 0.0 {
                    sum += c * cos * cell / d2;
                }
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions over the hemisphere around +Z in `n × 4n` midpoint cells of
    /// (t, phi) with cos theta = 1 - t² (cells crowd towards the pole, where
    /// glossy lobes are), each with its solid angle 2t dt dphi.
    fn hemisphere(n: u32) -> impl Iterator<Item = (Vec3, f32)> {
        let dt = 1.0 / n as f32;
        let d_phi = 2.0 * PI / (4 * n) as f32;
        (0..n).flat_map(move |i| {
            (0..4 * n).map(move |j| {
                let t = (i as f32 + 0.5) * dt;
                let c = 1.0 - t * t;
                let s = (1.0 - c * c).sqrt();
                let phi = (j as f32 + 0.5) * d_phi;
                (
                    Vec3::new(s * phi.cos(), s * phi.sin(), c),
                    2.0 * t * dt * d_phi,
                )
            })
        })
    }

    fn shader_constant(file: &str, name: &str) -> f32 {
        let path = format!(
            "{}/../../shaders/include/{file}",
            env!("CARGO_MANIFEST_DIR")
        );
        let source = std::fs::read_to_string(&path).expect("the shader include");
        let line = source
            .lines()
            .find(|l| l.starts_with("const ") && l.contains(&format!(" {name} = ")))
            .unwrap_or_else(|| panic!("{name} not in {file}"));
        let value = line.split('=').nth(1).expect("a value");
        value
            .trim()
            .trim_end_matches(';')
            .parse()
            .expect("a number")
    }

    #[test]
    fn constants_match_the_shader() {
        assert_eq!(shader_constant("brdf.glsl", "MIN_ROUGHNESS"), MIN_ROUGHNESS);
        assert_eq!(shader_constant("brdf.glsl", "DIELECTRIC_F0"), DIELECTRIC_F0);
        // The tables are fitted and integrated down to the same roughness.
        assert_eq!(weft_ltc::MIN_ROUGHNESS, MIN_ROUGHNESS);
        assert_eq!(
            shader_constant("ltc_tables.glsl", "MIN_ALBEDO_ROUGHNESS"),
            MIN_ROUGHNESS
        );
        assert_eq!(
            shader_constant("ltc_tables.glsl", "GGX_ALBEDO_ROWS"),
            weft_ltc::energy::ROWS as f32
        );
        assert_eq!(
            shader_constant("ltc_tables.glsl", "GGX_ALBEDO_COLUMNS"),
            weft_ltc::energy::COLUMNS as f32
        );
    }

    #[test]
    fn normal_incidence_has_the_closed_form() {
        // n = v = l: D = 1 / (pi a2), V = 1/4, F = F0, so specular = F0 / (4 pi a2).
        let z = Vec3::Z;
        let base = Vec3::new(0.8, 0.4, 0.2);
        let dielectric = single_scattering(base, 0.0, 0.5, z, z, z);
        let expected = Vec3::splat(0.04 / (4.0 * PI * 0.0625));
        assert!(
            (dielectric - expected).abs().max_element() < 1e-6,
            "{dielectric}"
        );
        let metal = single_scattering(base, 1.0, 0.5, z, z, z);
        let expected = base / (4.0 * PI * 0.0625);
        assert!((metal - expected).abs().max_element() < 1e-6, "{metal}");
        // Below the horizon nothing is reflected.
        assert_eq!(cook_torrance(base, 0.0, 0.5, z, z, -z), Vec3::ZERO);
    }

    #[test]
    fn the_ndf_is_normalised() {
        // The projected microfacet area integrates to one: ∫ D(h) (n.h) dω = 1.
        for roughness in [0.2f32, 0.5, 1.0] {
            let a2 = roughness.powi(4);
            let total: f32 = hemisphere(400)
                .map(|(h, dw)| distribution(h.z, a2) * h.z * dw)
                .sum();
            assert!((total - 1.0).abs() < 2e-3, "roughness {roughness}: {total}");
        }
    }

    #[test]
    fn the_brdf_is_reciprocal() {
        let n = Vec3::Z;
        let dirs = [
            Vec3::new(0.3, 0.1, 0.9),
            Vec3::new(-0.7, 0.2, 0.4),
            Vec3::new(0.1, -0.9, 0.2),
            Vec3::new(0.0, 0.5, 0.8),
        ];
        for a in dirs {
            for b in dirs {
                let (a, b) = (a.normalize(), b.normalize());
                for (metal, rough) in [(0.0, 0.3), (1.0, 0.6), (0.5, 0.9)] {
                    let base = Vec3::new(0.9, 0.5, 0.1);
                    let f_ab = cook_torrance(base, metal, rough, n, a, b) / n.dot(b);
                    let f_ba = cook_torrance(base, metal, rough, n, b, a) / n.dot(a);
                    assert!((f_ab - f_ba).abs().max_element() < 1e-5, "{f_ab} {f_ba}");
                }
            }
        }
    }

    /// `∫ f cos dω` of `cook_torrance` seen from `v` (normal +Z), in two
    /// parts. Single scattering by sampling visible GGX normals (stratified
    /// 256 x 256, weights at most 1). The rest, `cook_torrance` minus
    /// [`single_scattering`], by quadrature over (cos θ = t³, φ): at low
    /// roughness its mass lies at grazing light directions (within
    /// cos θ < 0.05), which cosine sampling all but misses.
    fn furnace(base: Vec3, metallic: f32, roughness: f32, v: Vec3) -> Vec3 {
        use weft_ltc::lobe::{Ggx, Lobe};
        let r = roughness.max(MIN_ROUGHNESS);
        let lobe = Ggx { alpha: r * r };
        let m = 256;
        let mut single = glam::DVec3::ZERO;
        for j in 0..m {
            for i in 0..m {
                let l = lobe.sample(v, (i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                let pdf = lobe.eval(v, l).1;
                if l.z > 0.0 && pdf > 0.0 {
                    let f = single_scattering(base, metallic, roughness, Vec3::Z, v, l);
                    single += f.as_dvec3() / f64::from(pdf);
                }
            }
        }
        let (steps, azimuths) = (600, 48);
        let mut rest = glam::DVec3::ZERO;
        for i in 0..steps {
            let t = (i as f32 + 0.5) / steps as f32;
            let cos = t * t * t;
            let d_cos = 3.0 * t * t / steps as f32;
            for j in 0..azimuths {
                let phi = (j as f32 + 0.5) / azimuths as f32 * 2.0 * PI;
                let sin = (1.0 - cos * cos).sqrt();
                let l = Vec3::new(sin * phi.cos(), sin * phi.sin(), cos);
                let f = cook_torrance(base, metallic, roughness, Vec3::Z, v, l)
                    - single_scattering(base, metallic, roughness, Vec3::Z, v, l);
                rest += f.as_dvec3() * f64::from(d_cos * 2.0 * PI / azimuths as f32);
            }
        }
        (single / f64::from(m * m) + rest).as_vec3()
    }

    fn view(cos: f32) -> Vec3 {
        Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos)
    }

    #[test]
    fn white_furnace_reflects_everything_at_every_angle_and_roughness() {
        // White metals, dielectrics and blends reflect 1 of a uniform white
        // environment: multiple scattering returns what single scattering
        // loses (0.69 at roughness 1 head-on), the diffuse base takes what
        // the specular layer leaves. Never above 1 + 1e-3; below only by the
        // tables' interpolation between their 32 x 32 entries. Roughness
        // and cosines off the table's nodes on purpose.
        let mut worst = (0.0f32, String::new());
        for metallic in [0.0f32, 0.5, 1.0] {
            for roughness in [0.0f32, 0.1, 0.23, 0.37, 0.5, 0.77, 1.0] {
                for cos in [1.0f32, 0.8, 0.5, 0.3, 0.12, 0.05, 0.02] {
                    let albedo = furnace(Vec3::ONE, metallic, roughness, view(cos)).x;
                    let what = format!("metallic {metallic}, roughness {roughness}, N.V {cos}");
                    assert!(albedo <= 1.0 + 1e-3, "{what}: {albedo}");
                    if (1.0 - albedo).abs() > worst.0 {
                        worst = ((1.0 - albedo).abs(), format!("{what}: {albedo}"));
                    }
                }
            }
        }
        eprintln!(
            "white furnace: worst |1 - albedo| {:.1e} at {}",
            worst.0, worst.1
        );
        assert!(worst.0 < 2e-3, "worst {}", worst.1);
    }

    #[test]
    fn the_directional_albedo_is_the_integral_of_the_brdf() {
        // What the raster environment term shows equals what rays escaping
        // to a constant environment sum in the path tracer.
        for (base, metallic) in [
            (Vec3::new(0.9, 0.5, 0.1), 0.0),
            (Vec3::new(0.9, 0.6, 0.3), 1.0),
            (Vec3::splat(0.5), 0.4),
        ] {
            for roughness in [0.1f32, 0.5, 0.9] {
                for cos in [1.0f32, 0.4, 0.1] {
                    let integral = furnace(base, metallic, roughness, view(cos));
                    let closed = directional_albedo(base, metallic, roughness, cos);
                    assert!(
                        (integral - closed).abs().max_element() < 4e-3,
                        "{base} {metallic} {roughness} {cos}: {integral} vs {closed}"
                    );
                }
            }
        }
    }

    #[test]
    fn single_scattering_loses_energy_that_compensation_returns() {
        // The single-scattering lobe alone: 1 - ln 2 = 0.307 at roughness 1
        // head-on (the closed form), nearly everything when smooth.
        let single = |roughness: f32, cos: f32| -> f32 {
            hemisphere(300)
                .map(|(l, dw)| {
                    single_scattering(Vec3::ONE, 1.0, roughness, Vec3::Z, view(cos), l).x * dw
                })
                .sum()
        };
        assert!((single(1.0, 1.0) - (1.0 - 2f32.ln())).abs() < 2e-3);
        assert!(single(0.2, 1.0) > 0.995);
        // The table the compensation reads holds the same integrals.
        for (roughness, cos) in [(1.0f32, 1.0f32), (0.6, 0.5), (0.3, 0.2)] {
            let table = ggx_albedo(roughness, cos).integral;
            let integral = single(roughness, cos);
            assert!(
                (table - integral).abs() < 2e-3,
                "{roughness} {cos}: {table} vs {integral}"
            );
        }
        // A white metal at roughness 1 reflects 1 all the same.
        let metal = furnace(Vec3::ONE, 1.0, 1.0, Vec3::Z).x;
        assert!((metal - 1.0).abs() < 2e-3, "{metal}");
    }

    #[test]
    fn blinn_phong_reflects_at_most_kd_plus_ks() {
        // The raster Blinn-Phong lobe (N.H)^n N.L / pi never exceeds the
        // cosine's, so a white split Kd + Ks = 1 reflects at most 1; its
        // lobe integral is what the environment term reads from the table.
        use weft_ltc::lobe::{BlinnPhong, Lobe};
        for exponent in [0.0f32, 1.0, 10.0, 100.0] {
            for cos in [1.0f32, 0.5, 0.1, 0.02] {
                let lobe = BlinnPhong { exponent };
                let integral: f32 = hemisphere(200)
                    .map(|(l, dw)| lobe.eval(view(cos), l).0 * dw)
                    .sum::<f32>()
                    / PI;
                assert!(
                    integral <= 1.0 + 1e-3,
                    "n {exponent}, N.V {cos}: {integral}"
                );
                let (kd, ks) = (0.6, 0.4);
                assert!(kd + ks * integral <= 1.0 + 1e-3);
            }
        }
    }

    #[test]
    fn concentric_map_fills_the_disc_evenly() {
        assert_eq!(concentric(Vec2::new(1.0, 0.0)), Vec2::new(1.0, 0.0));
        assert!((concentric(Vec2::new(1.0, 1.0)).length() - 1.0).abs() < 1e-6);
        // Equal cells stay equal: the mean squared radius of a uniform disc is 1/2.
        let n = 64;
        let mean_r2: f32 = (0..n * n)
            .map(|k| {
                let p = (Vec2::new((k % n) as f32, (k / n) as f32) + 0.5) * (2.0 / n as f32) - 1.0;
                concentric(p).length_squared()
            })
            .sum::<f32>()
            / (n * n) as f32;
        assert!((mean_r2 - 0.5).abs() < 1e-3, "{mean_r2}");
    }

    #[test]
    fn area_light_quadrature_error_against_brute_force() {
        // A 1 x 0.5 panel at height 1 facing down, and a disc of radius 0.4; receivers on
        // the floor below and beside them, facing up or tilted. The 8 x 8 estimate stays
        // within 0.5% of a 1000 x 1000 brute-force integral where the receiver is one
        // light size away (measured at most 0.24%) and within 5% at a quarter of it
        // (measured at most 4.1%).
        let rect = AreaGeometry {
            centre: Vec3::new(0.0, 1.0, 0.0),
            x: Vec3::new(0.5, 0.0, 0.0),
            y: Vec3::new(0.0, 0.0, -0.25),
            disc: false,
            two_sided: false,
        };
        assert_eq!(rect.facing(), Vec3::NEG_Y);
        let disc = AreaGeometry {
            x: Vec3::new(0.4, 0.0, 0.0),
            y: Vec3::new(0.0, 0.0, -0.4),
            disc: true,
            ..rect
        };
        let up = Vec3::Y;
        let tilted = Vec3::new(0.5, 1.0, 0.0).normalize();
        for light in [rect, disc] {
            for (offset, tolerance) in [(1.0f32, 0.005f64), (0.25, 0.05)] {
                for (x, n) in [(0.0, up), (0.7, up), (0.3, tilted), (-1.2, tilted)] {
                    let p = light.centre - Vec3::Y * offset + Vec3::X * x;
                    let estimate = f64::from(light.irradiance(p, n));
                    let reference = light.irradiance_brute_force(p, n, 1000);
                    let error = (estimate - reference).abs() / reference;
                    assert!(
                        error <= tolerance,
                        "{light:?} at {p} n {n}: {estimate} vs {reference}"
                    );
                }
            }
        }
        // Behind a one-sided light nothing arrives; a two-sided one lights both sides equally.
        let above = rect.centre + Vec3::Y * 0.5;
        assert_eq!(rect.irradiance(above, Vec3::NEG_Y), 0.0);
        let both = AreaGeometry {
            two_sided: true,
            ..rect
        };
        let below = rect.centre - Vec3::Y * 0.5;
        assert!((both.irradiance(above, Vec3::NEG_Y) - both.irradiance(below, up)).abs() < 1e-6);
        // Far away the light is a point source of intensity L A.
        let far = rect.centre - Vec3::Y * 100.0;
        let point = f64::from(rect.area()) / 1e4;
        assert!((f64::from(rect.irradiance(far, up)) - point).abs() / point < 1e-3);
    }

    #[test]
    fn cook_torrance_is_finite_and_bounded_at_grazing_angles_and_extreme_roughness() {
        // Every roughness from 0 up, views and lights from head-on to exactly
        // grazing and below: finite, non-negative.
        let n = Vec3::Z;
        let dir = |cos: f32, azimuth: f32| {
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            Vec3::new(sin * azimuth.cos(), sin * azimuth.sin(), cos)
        };
        let cosines = [1.0, 0.5, 1e-3, 1e-7, 0.0, -1e-7, -0.5];
        for roughness in [0.0, 1e-6, MIN_ROUGHNESS, 0.5, 1.0] {
            for metallic in [0.0, 1.0] {
                for &cv in &cosines {
                    for &cl in &cosines {
                        for azimuth in [0.0, 1.0, std::f32::consts::PI] {
                            let f = cook_torrance(
                                Vec3::ONE,
                                metallic,
                                roughness,
                                n,
                                dir(cv, 0.0),
                                dir(cl, azimuth),
                            );
                            assert!(
                                f.is_finite() && f.min_element() >= 0.0,
                                "roughness {roughness}, metallic {metallic}, N.V {cv}, N.L {cl}: {f}"
                            );
                        }
                    }
                }
            }
        }
    }
}
