//! The directional albedo of single-scattering GGX, for energy compensation
//! (Kulla and Conty, "Revisiting Physically Based Shading at Imageworks",
//! 2017): single scattering loses the energy of light that would bounce
//! between microfacets, 0.69 of it at roughness 1 head-on; the shaders add it
//! back as a lobe `M (1 − E(μo))(1 − E(μi)) / (π (1 − E_avg))` and weight the
//! diffuse base by what the specular layer leaves (`shaders/include/brdf.glsl`).
//!
//! The table (`engine/ltc/tables/ggx_albedo.txt`, written by `ltc-fit`) holds
//! `E` and its Fresnel moment on 64 rows of 128: rows are perceptual
//! roughness from 0.045 to 1 in equal steps, columns the view cosine
//! `(k / 127)³`, which crowds
//! entries near grazing, where smooth lobes lose their energy over a range of
//! cosines as narrow as alpha. The 32 × 32 LTC tables interpolated there
//! underestimate `E` by up to 0.02, and every underestimate is energy the
//! diffuse base gains. `E_avg = 2 ∫ E(μ) μ dμ` is integrated from the
//! interpolant the shaders read, so a white surface reflects 1 to the
//! interpolation's accuracy (engine/testkit/src/brdf.rs tests it).

use crate::fit::moments;
use crate::lobe::Ggx;
use crate::tables::{parse_numbers, ParseError};
use crate::MIN_ROUGHNESS;
use glam::Vec3;
use std::fmt::Write;

/// Columns (view cosines) of the albedo table.
pub const COLUMNS: usize = 128;
/// Rows (roughness) of the albedo table.
pub const ROWS: usize = 64;

/// The committed table's text.
pub const TEXT: &str = include_str!("../tables/ggx_albedo.txt");

/// The view cosine at column `k`: `(k / (COLUMNS − 1))³`, at least 1e-4.
pub fn column_cos(k: usize) -> f32 {
    (k as f32 / (COLUMNS - 1) as f32).powi(3).max(1e-4)
}

/// The perceptual roughness at row `j`: from [`MIN_ROUGHNESS`] (row 0) to 1
/// (the last) in equal steps, so every row is a roughness the shaders use.
pub fn row_roughness(j: usize) -> f32 {
    MIN_ROUGHNESS + (1.0 - MIN_ROUGHNESS) * j as f32 / (ROWS - 1) as f32
}

/// One entry: `E = ∫ f cos` with F = 1, and `∫ f cos (1 − v·h)⁵`; with
/// Schlick's Fresnel single scattering reflects `F0 (E − moment) + moment`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Single scattering's albedo with F = 1.
    pub integral: f32,
    /// Its Fresnel moment.
    pub fresnel: f32,
}

/// The table, row-major by roughness.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoTable {
    /// `ROWS × COLUMNS` entries.
    pub entries: Vec<Entry>,
}

/// A table with its [`AlbedoTable::row_averages`], as lookups need them.
pub type WithAverages = (AlbedoTable, Vec<[f32; 2]>);

/// An entry interpolated as the shaders read it, with the averages over view
/// directions at the same roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Albedo {
    /// `E` at the looked-up cosine.
    pub integral: f32,
    /// The Fresnel moment there.
    pub fresnel: f32,
    /// `2 ∫ E(μ) μ dμ`.
    pub average: f32,
    /// `2 ∫ moment(μ) μ dμ`.
    pub average_fresnel: f32,
}

/// Four-point Gauss–Legendre nodes and weights on [0, 1]: exact for the
/// sextic a linear segment times `6c⁵` makes.
const GAUSS: [(f64, f64); 4] = [
    (0.069_431_844_202_973_7, 0.173_927_422_568_726_9),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_1),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_1),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_9),
];

impl AlbedoTable {
    /// Integrates every entry by sampling visible normals (`fit::moments`).
    pub fn compute() -> Self {
        let entries = (0..ROWS * COLUMNS)
            .map(|i| {
                let (r, cos) = (row_roughness(i / COLUMNS), column_cos(i % COLUMNS));
                let v = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
                let (integral, fresnel, _) = moments(&Ggx { alpha: r * r }, v);
                Entry {
                    integral: integral.min(1.0),
                    fresnel: fresnel.min(integral),
                }
            })
            .collect();
        AlbedoTable { entries }
    }

    /// Per row, the cosine-weighted averages of the integral and the
    /// Fresnel moment: with `c = μ^(1/3)` the column coordinate,
    /// `2 ∫ E μ dμ = ∫ E(c) 6c⁵ dc`, exact for the interpolant that is
    /// linear in `c` between columns.
    pub fn row_averages(&self) -> Vec<[f32; 2]> {
        let step = 1.0 / (COLUMNS - 1) as f64;
        (0..ROWS)
            .map(|row| {
                let entries = &self.entries[row * COLUMNS..(row + 1) * COLUMNS];
                let mut sums = [0.0f64; 2];
                for k in 0..COLUMNS - 1 {
                    let (a, b) = (entries[k], entries[k + 1]);
                    for (t, w) in GAUSS {
                        let c = (k as f64 + t) * step;
                        let weight = w * step * 6.0 * c.powi(5);
                        let lerp =
                            |x: f32, y: f32| f64::from(x) + (f64::from(y) - f64::from(x)) * t;
                        sums[0] += weight * lerp(a.integral, b.integral);
                        sums[1] += weight * lerp(a.fresnel, b.fresnel);
                    }
                }
                [sums[0] as f32, sums[1] as f32]
            })
            .collect()
    }

    /// The entry at perceptual `roughness` seen at `cos`, interpolated
    /// bilinearly as `ggx_albedo` in `shaders/include/ltc_tables.glsl`
    /// does; `averages` is [`AlbedoTable::row_averages`].
    pub fn lookup(&self, averages: &[[f32; 2]], roughness: f32, cos: f32) -> Albedo {
        let at = [
            cos.clamp(0.0, 1.0).cbrt() * (COLUMNS - 1) as f32,
            ((roughness - MIN_ROUGHNESS) / (1.0 - MIN_ROUGHNESS)).clamp(0.0, 1.0)
                * (ROWS - 1) as f32,
        ];
        let i0 = [
            (at[0] as usize).min(COLUMNS - 2),
            (at[1] as usize).min(ROWS - 2),
        ];
        let f = [at[0] - i0[0] as f32, at[1] - i0[1] as f32];
        let lerp = |x: f32, y: f32, t: f32| x + (y - x) * t;
        let bilinear = |value: &dyn Fn(usize, usize) -> f32| {
            let (c, r) = (i0[0], i0[1]);
            lerp(
                lerp(value(r, c), value(r, c + 1), f[0]),
                lerp(value(r + 1, c), value(r + 1, c + 1), f[0]),
                f[1],
            )
        };
        Albedo {
            integral: bilinear(&|r, c| self.entries[r * COLUMNS + c].integral),
            fresnel: bilinear(&|r, c| self.entries[r * COLUMNS + c].fresnel),
            average: bilinear(&|r, _| averages[r][0]),
            average_fresnel: bilinear(&|r, _| averages[r][1]),
        }
    }

    /// The table as text: a comment header, then `ROWS × COLUMNS` lines
    /// `integral fresnel`, row-major by roughness.
    pub fn write(&self) -> String {
        let (rows, columns) = (ROWS - 1, COLUMNS - 1);
        let mut out = format!(
            "# Generated by `cargo run -p weft-ltc --release --bin ltc-fit` (engine/ltc); do not edit.\n\
             # Single-scattering GGX (height-correlated Smith, alpha = r^2) albedo for energy\n\
             # compensation: {ROWS} rows of {COLUMNS}, row j = perceptual roughness r = 0.045 + 0.955 j\n\
             # / {rows}, column k = view cosine (k / {columns})^3 (at least 1e-4). Each line: the\n\
             # integral of f cos with F = 1, and of f cos (1 - v.h)^5.\n"
        );
        for e in &self.entries {
            let _ = writeln!(out, "{:.7e} {:.7e}", e.integral, e.fresnel);
        }
        out
    }

    /// Reads [`AlbedoTable::write`]'s format.
    pub fn parse(text: &str) -> Result<Self, ParseError> {
        let mut entries = Vec::with_capacity(ROWS * COLUMNS);
        for (number, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let values = parse_numbers(line, number)?;
            let [integral, fresnel] = values[..] else {
                return Err(ParseError(format!(
                    "line {}: expected 2 numbers",
                    number + 1
                )));
            };
            entries.push(Entry { integral, fresnel });
        }
        if entries.len() != ROWS * COLUMNS {
            return Err(ParseError(format!(
                "{} entries, not {}",
                entries.len(),
                ROWS * COLUMNS
            )));
        }
        Ok(AlbedoTable { entries })
    }

    /// The committed table and its row averages, read once per process.
    pub fn committed() -> Result<&'static WithAverages, ParseError> {
        static TABLE: std::sync::OnceLock<Result<WithAverages, ParseError>> =
            std::sync::OnceLock::new();
        TABLE
            .get_or_init(|| {
                let table = AlbedoTable::parse(TEXT)?;
                let averages = table.row_averages();
                Ok((table, averages))
            })
            .as_ref()
            .map_err(Clone::clone)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(value: impl Fn(usize, usize) -> (f32, f32)) -> AlbedoTable {
        AlbedoTable {
            entries: (0..ROWS * COLUMNS)
                .map(|i| {
                    let (integral, fresnel) = value(i / COLUMNS, i % COLUMNS);
                    Entry { integral, fresnel }
                })
                .collect(),
        }
    }

    #[test]
    fn averages_of_constant_and_linear_rows_are_exact() {
        // E = 1 averages to 1; E = c (the column coordinate, μ^(1/3)) to
        // ∫ c 6c⁵ dc = 6/7.
        let t = table(|_, k| (1.0, k as f32 / (COLUMNS - 1) as f32));
        for [average, average_fresnel] in t.row_averages() {
            assert!((average - 1.0).abs() < 1e-6, "{average}");
            assert!(
                (average_fresnel - 6.0 / 7.0).abs() < 1e-6,
                "{average_fresnel}"
            );
        }
    }

    #[test]
    fn lookup_interpolates_between_rows_and_columns() {
        let t = table(|j, k| (j as f32, k as f32));
        let averages = t.row_averages();
        // Column coordinate 0.125^(1/3) * 127 = 63.5; row 15.75 at roughness
        // 0.045 + 0.955 * 15.75 / 63.
        let a = t.lookup(&averages, MIN_ROUGHNESS + 0.955 * 0.25, 0.125);
        assert!((a.integral - 15.75).abs() < 1e-4, "{a:?}");
        assert!((a.fresnel - 63.5).abs() < 1e-4, "{a:?}");
        assert!((a.average - 15.75).abs() < 1e-4, "{a:?}");
        // Out of range clamps to the table's edges.
        let edge = t.lookup(&averages, 2.0, 7.0);
        assert_eq!((edge.integral, edge.fresnel), (63.0, 127.0));
    }

    #[test]
    fn the_committed_table_reads_and_round_trips() {
        let (table, averages) = AlbedoTable::committed().expect("the committed table reads");
        assert_eq!(AlbedoTable::parse(&table.write()).as_ref(), Ok(table));
        // Smooth lobes keep almost everything head-on; roughness 1 keeps
        // 1 − ln 2 (the closed form).
        let smooth = table.lookup(averages, 0.0, 1.0);
        assert!(smooth.integral > 0.999, "{smooth:?}");
        let rough = table.lookup(averages, 1.0, 1.0);
        assert!(
            (rough.integral - (1.0 - 2f32.ln())).abs() < 1e-3,
            "{rough:?}"
        );
        assert!(averages.iter().all(|&[a, f]| a <= 1.0 && f <= a));
        assert_eq!(
            AlbedoTable::parse("1 2 3\n"),
            Err(ParseError("line 1: expected 2 numbers".into()))
        );
    }
}
