//! The LTC tables analytic area lights read, packed as the shader reads them.

/// The LTC tables as `ltc_tables.glsl` reads them, in vec4s: the GGX
/// inverses, the GGX (integral, Fresnel moment, 0, 0), the same for
/// Blinn-Phong, then GGX's albedo for energy compensation (integral,
/// Fresnel moment, and the averages of both over the entry's row,
/// [`weft_ltc::energy::AlbedoTable::row_averages`]).
pub fn ltc_table_words(
    tables: &weft_ltc::tables::Tables,
    (albedo, averages): &weft_ltc::energy::WithAverages,
) -> Vec<f32> {
    let mut words = Vec::with_capacity(4 * (4 * tables.ggx.len() + albedo.entries.len()));
    for table in [&tables.ggx, &tables.blinn_phong] {
        words.extend(table.iter().flat_map(|e| e.inverse));
        words.extend(
            table
                .iter()
                .flat_map(|e| [e.magnitude, e.fresnel, 0.0, 0.0]),
        );
    }
    words.extend(albedo.entries.iter().enumerate().flat_map(|(i, e)| {
        let [average, average_fresnel] = averages[i / weft_ltc::energy::COLUMNS];
        [e.integral, e.fresnel, average, average_fresnel]
    }));
    words
}
