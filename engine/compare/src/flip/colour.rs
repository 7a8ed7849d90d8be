//! The colour spaces LDR-FLIP works in, with the reference implementation's
//! constants: linear sRGB (D65) to CIE XYZ and back, the opponent space
//! YCxCz its contrast-sensitivity filters run in, and Hunt-adjusted CIELAB
//! with the HyAB distance its colour difference is measured by.

/// CIE XYZ of the D65 white point (Y = 1).
const D65: [f32; 3] = [0.950_428_55, 1.0, 1.088_900_4];

/// Its reciprocal, as the reference implementation rounds it.
const INV_D65: [f32; 3] = [1.052_156_9, 1.0, 0.918_357_7];

/// The sRGB electro-optical transfer: an encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear sRGB (D65) to CIE XYZ.
pub fn linear_rgb_to_xyz([r, g, b]: [f32; 3]) -> [f32; 3] {
    [
        (10_135_552.0 / 24_577_794.0) * r
            + (8_788_810.0 / 24_577_794.0) * g
            + (4_435_075.0 / 24_577_794.0) * b,
        (2_613_072.0 / 12_288_897.0) * r
            + (8_788_810.0 / 12_288_897.0) * g
            + (887_015.0 / 12_288_897.0) * b,
        (1_425_312.0 / 73_733_382.0) * r
            + (8_788_810.0 / 73_733_382.0) * g
            + (70_074_185.0 / 73_733_382.0) * b,
    ]
}

/// CIE XYZ to linear sRGB (D65).
pub fn xyz_to_linear_rgb([x, y, z]: [f32; 3]) -> [f32; 3] {
    [
        3.241_003_3 * x + -1.537_398_9 * y + -0.498_615_87 * z,
        -0.969_224_3 * x + 1.875_930_1 * y + 0.041_554_224 * z,
        0.055_639_423 * x + -0.204_011_2 * y + 1.057_148_9 * z,
    ]
}

/// CIE XYZ to YCxCz (Y in CIELAB's lightness scale, Cx and Cz linear
/// red-green and blue-yellow opponents), relative to D65.
pub fn xyz_to_ycxcz(xyz: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = [
        xyz[0] * INV_D65[0],
        xyz[1] * INV_D65[1],
        xyz[2] * INV_D65[2],
    ];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// YCxCz back to CIE XYZ.
pub fn ycxcz_to_xyz([l, cx, cz]: [f32; 3]) -> [f32; 3] {
    let y = (l + 16.0) / 116.0;
    let (cx, cz) = (cx / 500.0, cz / 200.0);
    [(y + cx) * D65[0], y * D65[1], (y - cz) * D65[2]]
}

/// CIE XYZ to CIELAB, relative to D65.
pub fn xyz_to_lab(xyz: [f32; 3]) -> [f32; 3] {
    let delta = 6.0f32 / 29.0;
    let delta_square = delta * delta;
    let delta_cube = delta * delta_square;
    let factor = 1.0 / (3.0 * delta_square);
    let term = 4.0f32 / 29.0;
    let f = |t: f32| {
        if t > delta_cube {
            t.powf(1.0 / 3.0)
        } else {
            factor * t + term
        }
    };
    let [x, y, z] = [
        f(xyz[0] * INV_D65[0]),
        f(xyz[1] * INV_D65[1]),
        f(xyz[2] * INV_D65[2]),
    ];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// CIELAB with the Hunt effect applied: chroma scaled by lightness / 100,
/// so dark colours differ less in hue than bright ones.
pub fn hunt([l, a, b]: [f32; 3]) -> [f32; 3] {
    [l, 0.01 * l * a, 0.01 * l * b]
}

/// The HyAB distance: city-block in lightness, Euclidean in chroma.
pub fn hyab(p: [f32; 3], q: [f32; 3]) -> f32 {
    let (da, db) = (p[1] - q[1], p[2] - q[2]);
    (p[0] - q[0]).abs() + (da * da + db * db).sqrt()
}

/// Linear sRGB (clamped to [0, 1] as displayed) to Hunt-adjusted CIELAB.
pub fn linear_rgb_to_hunt_lab(rgb: [f32; 3]) -> [f32; 3] {
    hunt(xyz_to_lab(linear_rgb_to_xyz(
        rgb.map(|c| c.clamp(0.0, 1.0)),
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3], tolerance: f32) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
    }

    /// White is D65 in XYZ, lightness 100 with no chroma in YCxCz and LAB.
    #[test]
    fn white_is_the_white_point() {
        let xyz = linear_rgb_to_xyz([1.0; 3]);
        assert!(close(xyz, D65, 1e-6), "{xyz:?}");
        assert!(close(xyz_to_ycxcz(xyz), [100.0, 0.0, 0.0], 1e-4));
        assert!(close(xyz_to_lab(xyz), [100.0, 0.0, 0.0], 1e-4));
        assert!(close(linear_rgb_to_hunt_lab([0.0; 3]), [0.0; 3], 1e-6));
    }

    /// Each conversion with an inverse round-trips.
    #[test]
    fn conversions_round_trip() {
        for rgb in [[0.2, 0.5, 0.9], [1.0, 0.0, 0.3], [0.01, 0.02, 0.0]] {
            let back = xyz_to_linear_rgb(ycxcz_to_xyz(xyz_to_ycxcz(linear_rgb_to_xyz(rgb))));
            assert!(close(back, rgb, 1e-5), "{rgb:?} -> {back:?}");
        }
        for c in [0.0, 0.02, 0.5, 1.0] {
            let encoded = crate::image_io::linear_to_srgb(c);
            assert!((srgb_to_linear(encoded) - c).abs() < 1e-6);
        }
    }

    /// Pure sRGB primaries in CIELAB (published D65 values, e.g.
    /// Lindbloom's calculator: green 87.73, -86.18, 83.18; blue 32.30,
    /// 79.19, -107.86).
    #[test]
    fn primaries_in_lab() {
        let green = xyz_to_lab(linear_rgb_to_xyz([0.0, 1.0, 0.0]));
        let blue = xyz_to_lab(linear_rgb_to_xyz([0.0, 0.0, 1.0]));
        assert!(close(green, [87.73, -86.18, 83.18], 0.02), "{green:?}");
        assert!(close(blue, [32.30, 79.19, -107.86], 0.02), "{blue:?}");
    }

    #[test]
    fn hyab_is_city_block_in_lightness_and_euclidean_in_chroma() {
        assert_eq!(hyab([10.0, 0.0, 0.0], [7.0, 3.0, 4.0]), 8.0);
    }
}
