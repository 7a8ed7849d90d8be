//! glTF files built to hurt (issue 60): a node graph that expands
//! exponentially, accessors that overrun their views, sparse indices past
//! their accessor, a GLB header that lies about its length, a stride under
//! its element. Each is a located error at once, never an expansion, a
//! silently shortened mesh or a panic.

use crate::gltf_import::{base64, triangle_gltf};
use weft_scene::load_scene;

/// Loads glTF `text` written to `name` in a fresh folder: its triangle
/// count, or the error's text.
fn load(name: &str, text: &[u8]) -> Result<usize, String> {
    let dir = crate::common::temp_dir(&format!("gltf-hostile-{name}"));
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    load_scene(&path)
        .map(|s| s.triangle_count())
        .map_err(|e| e.to_string())
}

const VERSION: &str = r#"{"version":"2.0"}"#;

/// The one-triangle file with `from` replaced by `to` in its JSON.
fn edited(from: &str, to: &str) -> Vec<u8> {
    let text = triangle_gltf(VERSION, "VEC3", 5125);
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1).into_bytes()
}

#[test]
fn a_node_graph_that_doubles_at_every_level_is_refused_before_it_is_walked() {
    // 40 nodes, each listing the next twice: 2^40 - 1 instances if expanded.
    let nodes: Vec<String> = (0..40)
        .map(|i| {
            if i == 39 {
                r#"{"mesh":0}"#.to_string()
            } else {
                format!(r#"{{"mesh":0,"children":[{},{}]}}"#, i + 1, i + 1)
            }
        })
        .collect();
    let text = String::from_utf8(edited(
        r#""nodes":[{"mesh":0}]"#,
        &format!(r#""nodes":[{}]"#, nodes.join(",")),
    ))
    .expect("utf-8");
    let started = std::time::Instant::now();
    let error = load("doubling.gltf", text.as_bytes()).expect_err("refused");
    assert!(
        started.elapsed() < std::time::Duration::from_secs(5),
        "{:?}",
        started.elapsed()
    );
    assert!(
        error.ends_with("doubling.gltf: the node hierarchy expands to 1099511627775 node instances, over the limit of 100000; node 1 has 2 parents (or is listed twice), where glTF 2.0 allows one"),
        "{error}"
    );
    // Two levels of sharing stay within the limit: loaded once per path,
    // with a warning naming the node.
    let small = edited(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"children":[1,1]},{"mesh":0}]"#,
    );
    assert_eq!(load("shared.gltf", &small), Ok(2));
    // A cycle is named, not walked to a depth limit.
    let cycle = edited(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0,"children":[1]},{"children":[0]}]"#,
    );
    let error = load("cycle.gltf", &cycle).expect_err("cycle");
    assert!(
        error.contains("the node hierarchy has a cycle through node 0"),
        "{error}"
    );
}

#[test]
fn accessors_are_held_to_their_views_and_buffers() {
    // An index count of 2^32 - 1 over a 12-byte view.
    let error = load(
        "count.gltf",
        &edited(
            r#""componentType":5125,"count":3,"type":"SCALAR""#,
            r#""componentType":5125,"count":4294967295,"type":"SCALAR""#,
        ),
    )
    .expect_err("overrun");
    assert!(
        error.ends_with("primitive 'mesh#0': accessor 1 needs 17179869180 bytes of buffer view 1 (4294967295 elements of 4 bytes, stride 4, offset 0), which has 12"),
        "{error}"
    );
    // A view past its buffer.
    let error = load(
        "view.gltf",
        &edited(
            r#"{"buffer":0,"byteLength":36}"#,
            r#"{"buffer":0,"byteLength":60}"#,
        ),
    )
    .expect_err("view overrun");
    assert!(
        error.ends_with("buffer view 0 ends at byte 60, past buffer 0's 48 bytes"),
        "{error}"
    );
    // A stride under its 12-byte element (the reader would panic).
    let error = load(
        "stride.gltf",
        &edited(
            r#"{"buffer":0,"byteLength":36}"#,
            r#"{"buffer":0,"byteLength":36,"byteStride":4}"#,
        ),
    )
    .expect_err("stride");
    assert!(
        error.ends_with("buffer view 0 has a byteStride of 4, less than its 12-byte elements"),
        "{error}"
    );
}

#[test]
fn sparse_indices_must_lie_within_their_accessor() {
    // Three positions, one sparse value at index 60000 (u16 index, then a VEC3).
    let mut bytes: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    bytes.extend(60000u16.to_le_bytes());
    bytes.extend([0u8, 0]);
    bytes.extend([5.0f32, 5.0, 5.0].iter().flat_map(|v| v.to_le_bytes()));
    let text = format!(
        r#"{{"asset":{VERSION},"buffers":[{{"uri":"data:application/octet-stream;base64,{}","byteLength":{}}}],
"bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":2}},{{"buffer":0,"byteOffset":40,"byteLength":12}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[5,5,5],
"sparse":{{"count":1,"indices":{{"bufferView":1,"componentType":5123}},"values":{{"bufferView":2}}}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]}}"#,
        base64(&bytes),
        bytes.len()
    );
    let error = load("sparse.gltf", text.as_bytes()).expect_err("sparse index");
    assert!(
        error.ends_with(
            "primitive 'mesh#0': accessor 0's sparse index 60000 is past its 3 elements"
        ),
        "{error}"
    );
    // The same file with the index at 2 loads, the third vertex moved.
    let fixed = text.replace(&base64(&bytes), &{
        let mut ok = bytes.clone();
        ok[36..38].copy_from_slice(&2u16.to_le_bytes());
        base64(&ok)
    });
    assert_eq!(load("sparse-ok.gltf", fixed.as_bytes()), Ok(1));
}

#[test]
fn a_glb_header_must_give_the_files_length() {
    let json = triangle_gltf(VERSION, "VEC3", 5125);
    let mut chunk = json.into_bytes();
    while !chunk.len().is_multiple_of(4) {
        chunk.push(b' ');
    }
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(20u32.to_le_bytes());
    glb.extend((chunk.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&chunk);
    let error = load("short.glb", &glb).expect_err("header length");
    assert!(
        error.ends_with(&format!(
            "short.glb: the GLB header gives a length of 20 bytes, but the file has {}",
            glb.len()
        )),
        "{error}"
    );
    let total = glb.len() as u32;
    glb[8..12].copy_from_slice(&total.to_le_bytes());
    assert_eq!(load("right.glb", &glb), Ok(1));
}

#[test]
fn offsets_and_counts_at_the_integer_limits_are_refused_not_wrapped() {
    for (from, to, expected) in [
        (
            r#""componentType":5125,"count":3,"type":"SCALAR""#,
            r#""componentType":5125,"count":3,"type":"SCALAR","byteOffset":18446744073709551610"#,
            "accessor 1 needs 18446744073709551615 bytes of buffer view 1",
        ),
        (
            r#"{"buffer":0,"byteLength":36}"#,
            r#"{"buffer":0,"byteLength":36,"byteOffset":18446744073709551610}"#,
            "buffer view 0 ends at byte 18446744073709551615, past buffer 0's 48 bytes",
        ),
    ] {
        let error = load("limits.gltf", &edited(from, to)).expect_err("refused");
        assert!(error.contains(expected), "{error}");
    }
}

/// A sparse POSITION accessor with no view may declare any count, and the
/// reader would make that many vertices: counted before it is read.
#[test]
fn a_huge_accessor_without_a_view_is_counted_before_it_is_read() {
    let text = edited(
        r#"{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}"#,
        r#"{"componentType":5126,"count":10000000000,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
           "sparse":{"count":1,"indices":{"bufferView":1,"componentType":5125},"values":{"bufferView":0}}}"#,
    );
    let started = std::time::Instant::now();
    let error = load("viewless.gltf", &text).expect_err("refused");
    assert!(started.elapsed() < std::time::Duration::from_secs(5));
    assert!(
        error.ends_with("the node hierarchy places 3333333334 triangles (each primitive counted by its largest accessor, vertices or indices), over the limit of 50000000"),
        "{error}"
    );
}
