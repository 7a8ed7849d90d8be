//! `weft graph check --shaders` compares every pass's shaders — scene-drawing
//! passes included — with the graph and with what the engine binds, and names
//! the pass's `.ron` line and the shader file:line. Each case edits a copy of
//! the shipped graphs and shaders the way a user might.

use crate::harness::{command_in, repo};
use std::path::{Path, PathBuf};
use std::process::Output;

/// A copy of `graphs/` and `shaders/` in a fresh folder, removed on drop.
struct Copy(PathBuf);

impl Copy {
    fn new(name: &str) -> Self {
        static MADE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let n = MADE.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let dir =
            crate::harness::scratch_path(&format!("weft-iface-{}-{name}-{n}", std::process::id()));
        for sub in [
            "graphs",
            "graphs/bench",
            "shaders",
            "shaders/include",
            "shaders/bench",
            "shaders/pathtrace",
        ] {
            std::fs::create_dir_all(dir.join(sub)).expect("temp dir");
            for entry in std::fs::read_dir(repo().join(sub)).expect("read dir") {
                let path = entry.expect("entry").path();
                if path.is_file() {
                    std::fs::copy(&path, dir.join(sub).join(path.file_name().expect("name")))
                        .expect("copy");
                }
            }
        }
        Self(dir)
    }

    /// Replaces the first `from` in `file` with `to`.
    fn edit(&self, file: &str, from: &str, to: &str) {
        let path = self.0.join(file);
        let text = std::fs::read_to_string(&path).expect("read");
        assert!(text.contains(from), "{file} has no {from:?}");
        std::fs::write(&path, text.replacen(from, to, 1)).expect("write");
    }

    fn check(&self, graph: &str) -> (Option<i32>, String) {
        let out = weft(
            &self.0,
            &["graph", "check", "--shaders", &format!("graphs/{graph}")],
        );
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }
}

impl Drop for Copy {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn weft(dir: &Path, args: &[&str]) -> Output {
    command_in(dir, args).output().expect("weft runs")
}

/// The line number of the first line of `file` containing `text`.
fn line_of(file: &Path, text: &str) -> usize {
    std::fs::read_to_string(file)
        .expect("read")
        .lines()
        .position(|l| l.contains(text))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{} has no {text:?}", file.display()))
}

#[test]
fn a_scene_binding_the_engine_does_not_write_is_refused_at_check_and_at_render() {
    // Binding 29: beyond both the scene's bindings and the ray tracer's (5..19).
    let copy = Copy::new("set1");
    copy.edit(
        "shaders/include/scene.glsl",
        "set = SET_SCENE, binding = BINDING_MATERIALS)",
        "set = SET_SCENE, binding = 29)",
    );
    let (code, err) = copy.check("forward.ron");
    assert_eq!(code, Some(1), "{err}");
    // The pass's `name` line follows its `Pass(` line (the graph is called "forward" too).
    let ron = std::fs::read_to_string(copy.0.join("graphs/forward.ron")).expect("read");
    let lines: Vec<&str> = ron.lines().collect();
    let pass_line = 1
        + (1..lines.len())
            .find(|&i| lines[i - 1].trim() == "Pass(" && lines[i].contains("name: \"forward\","))
            .expect("the forward pass");
    let glsl_line = line_of(&copy.0.join("shaders/include/scene.glsl"), "binding = 29");
    // The forward pass declares `RayTracing` (its shadow rays under
    // `rt_shadows`), so the ray tracer's bindings are offered to it too.
    let expected = format!(
        "graphs/forward.ron:{pass_line}:19: error: pass \"forward\": shader binding `material_table` (set 1 binding 29) is not scene data the engine binds; set 1 has 0: the Frame block, 1: the lights, 2: the draw records, 3: the materials, 4: the shadow views, 20: the area-light LTC tables, 21: the vertices, 22: the indices, 25: the environment map, 5: the ray tracer's triangles, 6: the BVH nodes, 7: the BVH's leaf triangles, 8: the corners' normals, 9: the corners' UVs, 10: the triangles' materials and draws, 11: the emissive triangles, 12: the 256-texel colour texture array, 13: the 512-texel colour texture array, 14: the 1024-texel colour texture array, 15: the 256-texel data texture array, 16: the 512-texel data texture array, 17: the 1024-texel data texture array, 18: the materials' texture slots, 19: the corners' tangents, 23: the light choice table, 24: the per-pass ray counters, 26: the environment's sampling table, 27: the top-level acceleration structure (hardware ray queries) (declared at graphs/../shaders/include/scene.glsl:{glsl_line})"
    );
    assert!(err.lines().any(|l| l == expected), "{expected}\n{err}");
    // `weft render` refuses it too, located at the pass, instead of a draw
    // that reads an unbound descriptor (or a crash in the validation layer).
    let scene = repo().join("scenes/demo.scene");
    let out = weft(
        &copy.0,
        &[
            "render",
            scene.to_str().expect("utf-8"),
            "--graph",
            "graphs/forward.ron",
            "--size",
            "32x18",
            "--validate",
            "--out",
            copy.0.join("out.png").to_str().expect("utf-8"),
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "error: graphs/forward.ron:{pass_line}:19: pass `forward`: shader binding `material_table` (set 1 binding 29) is not scene data"
        )),
        "{err}"
    );
}

/// Applies `edits` (file, from, to) to a fresh copy, checks `graph` and
/// asserts the check fails with `expected` among its messages.
fn assert_refused(graph: &str, edits: &[(&str, &str, &str)], expected: &str) {
    assert_refused_saying(graph, edits, &[expected]);
}

/// [`assert_refused`] with every one of `expected` in the error.
fn assert_refused_saying(graph: &str, edits: &[(&str, &str, &str)], expected: &[&str]) {
    let copy = Copy::new("edit");
    for (file, from, to) in edits {
        copy.edit(file, from, to);
    }
    let (code, err) = copy.check(graph);
    assert_eq!(code, Some(1), "{edits:?}: {err}");
    for expected in expected {
        assert!(
            err.contains(expected),
            "{edits:?}: expected {expected:?} in\n{err}"
        );
    }
}

#[test]
fn scene_pass_shaders_are_compiled_and_their_interfaces_compared() {
    assert_refused(
        "deferred.ron",
        &[("shaders/mesh.vert", "void main()", "garbage(\nvoid main()")],
        "pass \"gbuffer\": graphs/../shaders/mesh.vert:",
    );
    let texcoord = line_of(
        &repo().join("shaders/forward.frag"),
        "layout(location = 2) in vec2 texcoord;",
    );
    assert_refused(
        "forward.ron",
        &[("shaders/forward.frag", "layout(location = 2) in vec2 texcoord;", "layout(location = 5) in vec2 texcoord;")],
        &format!("pass \"forward\": fragment input `texcoord` at location 5 is not written by the vertex shader (declared at graphs/../shaders/forward.frag:{texcoord})"),
    );
    assert_refused(
        "forward.ron",
        &[
            ("shaders/mesh.vert", "flat out uint material;", "flat out int material;"),
            ("shaders/mesh.vert", "material = draws[draw].material.x;", "material = int(draws[draw].material.x);"),
        ],
        "pass \"forward\": fragment input `material` at location 3 is uint, but the vertex shader writes `material` there as int",
    );
    assert_refused(
        "deferred.ron",
        &[("shaders/gbuffer.frag", "layout(location = 2) out", "layout(location = 3) out")],
        "pass \"gbuffer\": the fragment shader writes outputs at locations [0, 1, 3] but the pass has 3 colour attachment(s)",
    );
    assert_refused(
        "forward.ron",
        &[("shaders/mesh.vert", "layout(location = 2) in vec2 uv;", "layout(location = 4) in vec2 uv;")],
        "pass \"forward\": vertex input `uv` at location 4 is not supplied; this pass's vertices have 0: position, 1: packed tangent frame, 2: UV (declared at graphs/../shaders/mesh.vert:13)",
    );
}

#[test]
fn sampled_image_types_are_compared_with_the_graph_format() {
    assert_refused(
        "forward.ron",
        &[("shaders/tonemap.frag", "uniform sampler2D hdr;", "uniform usampler2D hdr;"),
          ("shaders/tonemap.frag", "texture(hdr, uv).rgb", "vec3(texture(hdr, uv).rgb)")],
        "pass \"tonemap\": shader binding 0 `hdr` reads Uint values (the format gives Float), but graph image `hdr` is R16G16B16A16_SFLOAT with 1 layer(s) and 1 sample(s) (declared at graphs/../shaders/tonemap.frag:5)",
    );
    assert_refused(
        "forward.ron",
        &[("shaders/tonemap.frag", "uniform sampler2D hdr;", "uniform sampler2DArray hdr;"),
          ("shaders/tonemap.frag", "texture(hdr, uv).rgb", "texture(hdr, vec3(uv, 0.0)).rgb")],
        "pass \"tonemap\": shader binding 0 `hdr` is an array image, but graph image `hdr` is R16G16B16A16_SFLOAT with 1 layer(s) and 1 sample(s)",
    );
}

#[test]
fn compute_shaders_over_the_devices_limits_or_features_are_refused() {
    // lavapipe: 32 KiB of shared memory, 1024 invocations per workgroup, no
    // float atomics enabled; each is named with the limit it breaks.
    assert_refused_saying(
        "tiled.ron",
        &[(
            "shaders/light_cull.comp",
            "shared uint count;",
            "shared uint count;\nshared vec4 hoard[8192];",
        )],
        &[
            "pass \"cull_lights\": graphs/../shaders/light_cull.comp needs 131",
            "bytes of shared memory (`maxComputeSharedMemorySize` is 32768), which the device `llvmpipe",
        ],
    );
    assert_refused(
        "pathtrace.ron",
        &[(
            "shaders/pathtrace/trace.comp",
            "layout(local_size_x = 8, local_size_y = 8) in;",
            "layout(local_size_x = 64, local_size_y = 64) in;",
        )],
        "4096 invocations per workgroup (64x64x1; `maxComputeWorkGroupInvocations` is 1024)",
    );
    assert_refused(
        "tiled.ron",
        &[
            ("shaders/light_cull.comp", "#version 450", "#version 450\n#extension GL_EXT_shader_atomic_float : require"),
            ("shaders/light_cull.comp", "shared uint count;", "shared uint count;\nshared float total;"),
            ("shaders/light_cull.comp", "void main() {", "void main() {\n    atomicAdd(total, 1.0);"),
        ],
        "the SPIR-V capability AtomicFloat32AddEXT (not one weft enables: it needs a device feature or extension)",
    );
}
