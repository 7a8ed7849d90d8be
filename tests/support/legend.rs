//! The debug views' legend (shaders/include/legend.glsl), checked pixel by
//! pixel: the tests of the views and of tiled's heat map share it.

/// Rows of the 3x5 digits the legend draws, top first.
const FONT: [[&str; 5]; 10] = [
    ["###", "#.#", "#.#", "#.#", "###"],
    [".#.", "##.", ".#.", ".#.", "###"],
    ["###", "..#", "###", "#..", "###"],
    ["###", "..#", "###", "..#", "###"],
    ["#.#", "#.#", "###", "..#", "..#"],
    ["###", "#..", "###", "..#", "###"],
    ["###", "#..", "###", "#.#", "###"],
    ["###", "..#", "..#", "..#", "..#"],
    ["###", "#.#", "###", "#.#", "###"],
    ["###", "#.#", "###", "..#", "###"],
];

/// Viridis' first and last colours as published (sRGB bytes).
pub const VIRIDIS_START: [u8; 3] = [68, 1, 84];
/// See [`VIRIDIS_START`].
pub const VIRIDIS_END: [u8; 3] = [253, 231, 37];

/// Whether a pixel's RGB is within 1 of `expected` (8-bit rounding).
pub fn close(pixel: [u8; 4], expected: [u8; 3]) -> bool {
    (0..3).all(|c| pixel[c].abs_diff(expected[c]) <= 1)
}

/// Asserts the legend of an image whose pixels `at(x, y)` gives, `y` up
/// from the bottom row: the black box, a viridis bar `bar` pixels long and the
/// three labels (white digits on black) under its start, middle and end.
pub fn assert_legend(at: impl Fn(i32, i32) -> [u8; 4], bar: i32, labels: [u32; 3]) {
    assert_eq!(at(12, 44), [0, 0, 0, 255], "legend box");
    assert!(
        close(at(16, 34), VIRIDIS_START),
        "bar start {:?}",
        at(16, 34)
    );
    assert!(
        close(at(16 + bar - 1, 34), VIRIDIS_END),
        "bar end {:?}",
        at(16 + bar - 1, 34)
    );
    for (i, label) in labels.into_iter().enumerate() {
        let text = label.to_string();
        let width = text.len() as i32 * 8 - 2;
        let centre = 16 + (bar - 1) * i as i32 / 2;
        let left = (centre - width / 2).clamp(10, 22 + bar - width);
        for (k, digit) in text.bytes().enumerate() {
            let glyph = FONT[usize::from(digit - b'0')];
            for row in 0..10 {
                for col in 0..8 {
                    let lit =
                        col < 6 && glyph[row as usize / 2].as_bytes()[col as usize / 2] == b'#';
                    let expected = if lit {
                        [255, 255, 255, 255]
                    } else {
                        [0, 0, 0, 255]
                    };
                    assert_eq!(
                        at(left + k as i32 * 8 + col, 24 - row),
                        expected,
                        "label {label} digit {k} row {row} col {col}"
                    );
                }
            }
        }
    }
}
