//! Linearly transformed cosines (Heitz, Dupuy, Hill and Neubelt, "Real-Time
//! Polygonal-Light Shading with Linearly Transformed Cosines", 2016): a
//! clamped cosine distribution warped by a 3×3 matrix approximates a BRDF
//! lobe, and the integral of the warped distribution over a polygon is the
//! cosine's integral over the polygon transformed back, which has a closed
//! form. The raster passes' area lights use tables fitted here
//! (`engine/ltc/tables/ltc_tables.txt`, written by `ltc-fit`, uploaded by the
//! engine for `shaders/include/ltc.glsl`).

pub mod energy;
pub mod fit;
pub mod lobe;
pub mod ltc;
pub mod nelder_mead;
pub mod polygon;
pub mod tables;

/// Entries along each axis of a table: view angle and roughness.
pub const TABLE_SIZE: usize = 32;

/// Smallest GGX roughness the shaders use (`MIN_ROUGHNESS` in
/// `shaders/include/brdf.glsl`); alpha = roughness².
pub const MIN_ROUGHNESS: f32 = 0.045;

/// The view angle's cosine at column `k` of a table: the column coordinate
/// is `sqrt(1 - cos)`, which spends more entries near grazing, where lobes
/// change fastest.
pub fn column_cos(k: usize) -> f32 {
    let u = k as f32 / (TABLE_SIZE - 1) as f32;
    (1.0 - u * u).max(1e-3)
}

/// The perceptual roughness at row `j` (`j / (N - 1)`, at least `MIN_ROUGHNESS`).
pub fn row_roughness(j: usize) -> f32 {
    (j as f32 / (TABLE_SIZE - 1) as f32).max(MIN_ROUGHNESS)
}

/// The Blinn-Phong exponent whose lobe is about as wide as GGX with
/// `roughness` (alpha = roughness², n = 2 / alpha² - 2, Walter et al. 2007):
/// the Blinn-Phong table is indexed by this equivalent roughness.
pub fn blinn_phong_exponent(roughness: f32) -> f32 {
    let a = roughness * roughness;
    (2.0 / (a * a) - 2.0).max(0.0)
}
