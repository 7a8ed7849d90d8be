//! Random and mutated `.scene`, `.obj`, `.mtl` and `.glb` input must give a result or a located
//! error, never a panic.

use crate::common;

use common::{asset, fuzz_cases, temp_dir};
use proptest::prelude::*;
use std::path::Path;
use weft_scene::{scene_desc_from_str, Diagnostics, Location, SceneError};

/// Tokens that stress the parsers: structure, numbers in odd spellings, non-finite values.
const PIECES: &[&str] = &[
    "model",
    "sunlight",
    "spotlight",
    "pointlight",
    "camera",
    "arealight",
    "pointlights",
    "boundingbox",
    "include",
    "{",
    "}",
    "\"",
    "\"a.obj\"",
    "#",
    ":",
    "position",
    "direction",
    "color",
    "ambient",
    "orientation",
    "slerp",
    "swivel",
    "key",
    "count",
    "radius",
    "shape",
    "disc",
    "rect",
    "fov",
    "fov_deg",
    "attenuation",
    "velocity",
    "1",
    "-2.5",
    "1e39",
    "nan",
    "inf",
    "-inf",
    "0x10",
    "1.2.3",
    ".",
    "-",
    "+",
    "0",
    "3",
    "1e-40",
    "99999999999",
    "\n",
    " ",
    "\t",
    "\r\n",
    "é",
    "\u{0}",
    "v",
    "vt",
    "vn",
    "f",
    "o",
    "g",
    "usemtl",
    "mtllib",
    "newmtl",
    "Kd",
    "Ns",
    "d",
    "Tr",
    "map_Kd",
    "map_bump",
    "-bm",
    "1/2/3",
    "-1",
    "//",
    "1//1",
    "s",
    "l",
    "p",
    "illum",
];

fn text_from(pieces: Vec<usize>) -> String {
    pieces
        .iter()
        .map(|&i| PIECES[i % PIECES.len()])
        .collect::<Vec<_>>()
        .join(" ")
}

/// Applies byte edits (delete, duplicate, insert a piece) at the given positions.
fn mutate(base: &str, edits: &[(usize, usize, u8)]) -> String {
    let mut bytes = base.as_bytes().to_vec();
    for &(at, len, kind) in edits {
        if bytes.is_empty() {
            break;
        }
        let at = at % bytes.len();
        let end = (at + len % 16).min(bytes.len());
        match kind % 3 {
            0 => {
                bytes.drain(at..end);
            }
            1 => {
                let copy = bytes[at..end].to_vec();
                bytes.splice(at..at, copy);
            }
            _ => {
                let piece = PIECES[len % PIECES.len()].as_bytes().to_vec();
                bytes.splice(at..at, piece);
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

fn parse_scene(text: &str) {
    let mut diag = Diagnostics::default();
    let path = Path::new("/nonexistent/fuzz.scene");
    if let Err(e) = scene_desc_from_str(text, path, &mut diag) {
        assert!(!e.to_string().is_empty());
        if let SceneError::Syntax { at, .. } = &e {
            assert!(at.line.is_some_and(|l| l >= 1), "{e}");
        }
    }
}

fn load_obj_text(dir: &Path, obj: &str, mtl: &str) {
    std::fs::write(dir.join("f.mtl"), mtl).expect("write mtl");
    let path = dir.join("f.obj");
    std::fs::write(&path, format!("mtllib f.mtl\n{obj}")).expect("write obj");
    let mut diag = Diagnostics::default();
    // Unguarded on purpose: a panic in the OBJ path (ours or tobj's) must fail this test.
    let _ = weft_scene::load_obj(&path, &Location::file(&path), &mut diag);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(fuzz_cases(256)))]

    #[test]
    fn random_scene_text_never_panics(pieces in proptest::collection::vec(0usize..1000, 0..200)) {
        parse_scene(&text_from(pieces));
    }

    #[test]
    fn mutated_real_scenes_never_panic(
        which in 0usize..3,
        edits in proptest::collection::vec((0usize..100_000, 0usize..1000, 0u8..3), 1..12),
    ) {
        let file = ["462/scenes/cube.scene", "462/scenes/toy.scene", "462/scenes/sibenik/sibenik.scene"][which];
        let base = std::fs::read_to_string(asset(file)).expect("read");
        parse_scene(&mutate(&base, &edits));
    }

    #[test]
    fn random_and_mutated_obj_mtl_never_panic(
        obj_pieces in proptest::collection::vec(0usize..1000, 0..150),
        edits in proptest::collection::vec((0usize..100_000, 0usize..1000, 0u8..3), 1..10),
    ) {
        let dir = temp_dir("fuzz-obj");
        let obj = std::fs::read_to_string(asset("cornell/CornellBox-Original.obj")).expect("read");
        let mtl = std::fs::read_to_string(asset("cornell/CornellBox-Original.mtl")).expect("read");
        load_obj_text(&dir, &text_from(obj_pieces.clone()), &mutate(&mtl, &edits));
        load_obj_text(&dir, &mutate(&obj, &edits), &text_from(obj_pieces));
    }
}

#[test]
fn oversized_scene_is_a_located_error() {
    let dir = temp_dir("huge");
    let path = dir.join("huge.scene");
    let line = "# padding padding padding padding padding padding padding padding\n";
    std::fs::write(&path, line.repeat((16 << 20) / line.len() + 1)).expect("write");
    let err = weft_scene::load_scene(&path).expect_err("too large");
    assert!(
        matches!(err, SceneError::TooLarge { limit, .. } if limit == 16 << 20),
        "{err}"
    );
    assert!(err.to_string().starts_with(&path.display().to_string()));
}

#[test]
fn unreadable_and_binary_files_are_errors() {
    let dir = temp_dir("binary");
    let path = dir.join("bin.scene");
    std::fs::write(&path, b"model\n{\n\xff\xfe\n}\n").expect("write");
    let err = weft_scene::load_scene(&path).expect_err("not utf-8");
    assert_eq!(err.location().line, Some(3));
    let err = weft_scene::load_scene(&dir.join("absent.scene")).expect_err("missing");
    assert!(matches!(err, SceneError::MissingFile { .. }));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(fuzz_cases(512)))]

    #[test]
    fn mutated_glb_never_panics(edits in proptest::collection::vec((0usize..100_000, any::<u8>()), 1..8)) {
        let dir = temp_dir("fuzz-glb");
        let mut bytes = std::fs::read(asset("gltf/rise/BoxTextured.glb")).expect("read");
        for (at, value) in edits {
            let at = at % bytes.len();
            bytes[at] = value;
        }
        let path = dir.join("m.glb");
        std::fs::write(&path, &bytes).expect("write");
        let mut diag = Diagnostics::default();
        let options = weft_scene::LoadOptions::default();
        let _ = weft_scene::load_model(&path, &Location::file(&path), &options, &mut diag);
    }
}
