//! The promise `weft graph check --shaders` makes, as a property: every
//! mutant of the shipped graphs and shaders it accepts renders the demo scene
//! with zero validation messages (synchronization validation on), under no
//! features and under all of them; and nothing panics, whatever the mutant.
//!
//! Mutants are made from a fixed seed, so a failure repeats. `make test` runs
//! `WEFT_MUTANTS` of them (default 40); `make fuzz` runs many more. A failure
//! prints the mutation, so it can be replayed by hand in a copy of the tree.

use weft_tests::render as common;

use common::{demo_scene, root};
use std::collections::BTreeSet;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use weft_gpu::Gpu;
use weft_graph::feature_names;
use weft_graph::plan::Extent;
use weft_render::{check_graph_and_shaders, render_with_progress, RenderSettings, ShaderTarget};
use weft_scene::rng::Rng;

mod known;

/// Words of one kind that may replace each other.
const SWAPS: &[&[&str]] = &[
    &[
        "R16G16B16A16_SFLOAT",
        "R8G8B8A8_UNORM",
        "R8G8B8A8_SRGB",
        "R32_UINT",
        "R16G16_SFLOAT",
        "D32_SFLOAT",
        "R32G32B32A32_SFLOAT",
    ],
    &[
        "Load",
        "DontCare",
        "Clear([0.0])",
        "Clear([0.0, 0.0, 0.0, 1.0])",
    ],
    &["Raster", "Fullscreen", "Compute"],
    &["Opaque", "Transparent", "All"],
    &["Additive", "Alpha"],
    &[
        "Output",
        "Scale(0.5, 0.5)",
        "Absolute(64, 64)",
        "Like(\"hdr\", 0.5, 0.5)",
    ],
    &["true", "false"],
    &["sampled", "storage_read", "storage_write"],
    &[
        "sampler2D ",
        "usampler2D ",
        "isampler2D ",
        "sampler2DShadow ",
        "sampler2DArray ",
    ],
    &["vec2 ", "vec3 ", "vec4 ", "float ", "uint ", "int "],
    &["set = 0", "set = 1", "set = 2", "set = 3"],
    &["readonly buffer", "buffer", "uniform"],
];

/// Numbers a mutant may put in place of another.
const NUMBERS: &[&str] = &["-1", "0", "1", "2", "9", "1e9", "NaN", "inf", "0.5"];

/// One edit of one file's text, described for the failure report.
fn mutate(text: &str, rng: &mut Rng) -> Option<(String, String)> {
    let lines: Vec<&str> = text.lines().collect();
    match rng.below(10) {
        0 => {
            let i = rng.below(lines.len());
            let mut out = lines.clone();
            out.remove(i);
            Some((
                out.join("\n"),
                format!("deleted line {}: {}", i + 1, lines[i].trim()),
            ))
        }
        1 => {
            let i = rng.below(lines.len());
            let mut out = lines.clone();
            out.insert(i, lines[i]);
            Some((
                out.join("\n"),
                format!("duplicated line {}: {}", i + 1, lines[i].trim()),
            ))
        }
        2 => {
            let quoted: Vec<(usize, usize)> = quoted_spans(text);
            if quoted.len() < 2 {
                return None;
            }
            let a = *rng.pick(&quoted);
            let b = *rng.pick(&quoted);
            let (first, second) = if a.0 < b.0 { (a, b) } else { (b, a) };
            if first.1 > second.0 || first == second {
                return None;
            }
            let (x, y) = (&text[first.0..first.1], &text[second.0..second.1]);
            let out = format!(
                "{}{y}{}{x}{}",
                &text[..first.0],
                &text[first.1..second.0],
                &text[second.1..]
            );
            Some((out, format!("swapped {x} and {y}")))
        }
        3 | 4 => {
            let group = rng.pick(SWAPS);
            let present: Vec<&&str> = group.iter().filter(|w| text.contains(**w)).collect();
            if present.is_empty() {
                return None;
            }
            let from = **rng.pick(&present);
            let to = *rng.pick(group);
            let at: Vec<usize> = text.match_indices(from).map(|(i, _)| i).collect();
            let i = *rng.pick(&at);
            let out = format!("{}{to}{}", &text[..i], &text[i + from.len()..]);
            Some((out, format!("replaced {from:?} with {to:?} at byte {i}")))
        }
        6 | 7 => {
            let slots = layout_number_spans(text);
            if slots.is_empty() {
                return None;
            }
            let (start, end) = *rng.pick(&slots);
            let to = rng.below(10).to_string();
            let out = format!("{}{to}{}", &text[..start], &text[end..]);
            Some((
                out,
                format!(
                    "changed layout number {} to {to} at byte {start}",
                    &text[start..end]
                ),
            ))
        }
        8 | 9 => compute_mutation(text, rng),
        _ => {
            let numbers = number_spans(text);
            if numbers.is_empty() {
                return None;
            }
            let (start, end) = *rng.pick(&numbers);
            let to = *rng.pick(NUMBERS);
            let out = format!("{}{to}{}", &text[..start], &text[end..]);
            Some((
                out,
                format!(
                    "replaced number {} with {to} at byte {start}",
                    &text[start..end]
                ),
            ))
        }
    }
}

/// An edit that asks more of the device than a compute shader did: a large
/// `shared` array, a larger workgroup, or float atomics on shared memory
/// (an extension weft does not enable). `None` for other files.
fn compute_mutation(text: &str, rng: &mut Rng) -> Option<(String, String)> {
    let main = text.find("void main()")?;
    let body = main + text[main..].find('{')? + 1;
    text.find("local_size_x")?;
    match rng.below(3) {
        0 => {
            let vec4s = *rng.pick(&[512usize, 1024, 2048, 8192]);
            let declaration = format!("shared vec4 mutant_hoard[{vec4s}];\n");
            let out = format!(
                "{}{declaration}{}\n    mutant_hoard[gl_LocalInvocationIndex % {vec4s}u] = vec4(1.0);{}",
                &text[..main],
                &text[main..body],
                &text[body..]
            );
            Some((out, format!("added {} bytes of shared memory", vec4s * 16)))
        }
        1 => {
            let at = text.find("local_size_x = ")? + "local_size_x = ".len();
            let digits = text[at..].bytes().take_while(u8::is_ascii_digit).count();
            let to = *rng.pick(&["64", "256", "1024"]);
            let out = format!("{}{to}{}", &text[..at], &text[at + digits..]);
            Some((out, format!("set local_size_x to {to}")))
        }
        _ => {
            let version = text.find("#version")?;
            let line_end = version + text[version..].find('\n')? + 1;
            let out = format!(
                "{}#extension GL_EXT_shader_atomic_float : require\n{}shared float mutant_total;\n{}\n    atomicAdd(mutant_total, 1.0);{}",
                &text[..line_end],
                &text[line_end..main],
                &text[main..body],
                &text[body..]
            );
            Some((out, "added float atomics on shared memory".to_string()))
        }
    }
}

/// Byte ranges of `"..."` strings, quotes included.
fn quoted_spans(text: &str) -> Vec<(usize, usize)> {
    let starts: Vec<usize> = text.match_indices('"').map(|(i, _)| i).collect();
    starts
        .chunks(2)
        .filter(|c| c.len() == 2)
        .map(|c| (c[0], c[1] + 1))
        .collect()
}

/// Byte ranges of the numbers in `binding = N`, `location = N` and `set = N`:
/// where a shader meets the graph and the engine.
fn layout_number_spans(text: &str) -> Vec<(usize, usize)> {
    ["binding = ", "location = ", "set = "]
        .iter()
        .flat_map(|key| text.match_indices(key).map(move |(i, _)| i + key.len()))
        .map(|start| {
            let digits = text[start..].bytes().take_while(u8::is_ascii_digit).count();
            (start, start + digits)
        })
        .filter(|(start, end)| end > start)
        .collect()
}

/// Byte ranges of numbers outside words and comments (a digit run, with a
/// fraction and exponent), e.g. `16`, `0.75`, `1e-3`.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
            i += 1;
        }
        spans.push((start, i));
    }
    spans
}

/// The shipped files a mutant may edit, relative to the repository root:
/// every graph and shader under `graphs/` and `shaders/`, however deep.
fn mutable_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    let mut dirs = vec![PathBuf::from("graphs"), PathBuf::from("shaders")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(root().join(&dir)).expect("read dir") {
            let path = entry.expect("entry").path();
            let name = dir.join(path.file_name().expect("name"));
            if path.is_dir() {
                dirs.push(name);
            } else if path.extension().is_some_and(|e| {
                ["ron", "frag", "vert", "comp", "glsl"].contains(&e.to_str().unwrap_or(""))
            }) {
                files.push(name);
            }
        }
    }
    files.sort();
    files
}

/// A copy of `graphs/` and `shaders/`, removed on drop.
struct Tree(PathBuf);

impl Tree {
    /// One per test at a time, always at the same path for that test
    /// (`name`): the shaders a mutant leaves alone then preprocess to the
    /// same text (their `#line` paths included) and come from the SPIR-V
    /// cache the tests share.
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("weft-mutant-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for file in mutable_files() {
            let to = dir.join(&file);
            std::fs::create_dir_all(to.parent().expect("parent")).expect("dir");
            std::fs::copy(root().join(&file), to).expect("copy");
        }
        Self(dir)
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Root graphs whose files (the graph, its fragments, their shaders) mention
/// `file`'s name; every root for shared includes.
fn roots_using(file: &Path) -> Vec<&'static str> {
    let roots = [
        "forward.ron",
        "deferred.ron",
        "tiled.ron",
        "hybrid.ron",
        "bench/forward_floors.ron",
        "bench/deferred_floors.ron",
        "bench/tiled_floors.ron",
    ];
    let name = file
        .file_name()
        .expect("name")
        .to_string_lossy()
        .into_owned();
    if file.starts_with("shaders/include") {
        return roots.to_vec();
    }
    // The denoiser's files are rendered through the denoised path tracer
    // (the raster graphs run them too, under `denoise`); its shaders' many
    // variants make it too slow a root for every shared file.
    if file.starts_with("shaders/denoise")
        || [
            "denoise.ron",
            "denoise_guides.ron",
            "pathtrace_denoised.ron",
            "guides.comp",
        ]
        .contains(&name.as_str())
    {
        return vec!["pathtrace_denoised.ron"];
    }
    let text_of =
        |f: &str| std::fs::read_to_string(root().join("graphs").join(f)).unwrap_or_default();
    roots
        .into_iter()
        .filter(|r| {
            let mut text = text_of(r);
            // Included files as the including text names them, and where they
            // are: the bench graphs include a shipped graph and the floors,
            // hybrid.ron includes deferred.ron beside it.
            for (named, fragment) in [
                ("../forward.ron", "forward.ron"),
                ("../deferred.ron", "deferred.ron"),
                ("../tiled.ron", "tiled.ron"),
                ("\"deferred.ron\"", "deferred.ron"),
                ("\"mesh_floor.ron", "bench/mesh_floor.ron"),
                ("\"gbuffer_floor.ron", "bench/gbuffer_floor.ron"),
                ("shadows.ron", "shadows.ron"),
                ("bloom.ron", "bloom.ron"),
                ("gbuffer.ron", "gbuffer.ron"),
                ("debug_views.ron", "debug_views.ron"),
                ("raster_caveats.ron", "raster_caveats.ron"),
                ("scene_shading.ron", "scene_shading.ron"),
                ("rt_ao.ron", "rt_ao.ron"),
                ("gi.ron", "gi.ron"),
                ("path_tracer.ron", "path_tracer.ron"),
                ("denoise.ron", "denoise.ron"),
            ] {
                if text.contains(named) {
                    text.push_str(&text_of(fragment));
                }
            }
            *r == name || text.contains(&name)
        })
        .collect()
}

/// What happened to one mutant.
enum Outcome {
    Refused,
    Rendered,
}

/// What went wrong with a mutant check accepted.
enum Failure {
    /// The render refused it (or failed): "check said ok, render refused".
    RenderRefused(String),
    /// Anything else: a validation message, a check that could not run.
    Other(String),
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::RenderRefused(m) | Self::Other(m) => f.write_str(m),
        }
    }
}

/// Checks the mutant's `graph`; when accepted, renders the demo with the
/// scene's own features, under no features and under all, and names
/// anything wrong.
fn run_mutant(gpu: &Gpu, scene: &weft_scene::Scene, graph: &Path) -> Result<Outcome, Failure> {
    let loaded = weft_graph::load(graph);
    let diags = check_graph_and_shaders(&loaded, &ShaderTarget::of(gpu))
        .map_err(|e| Failure::Other(format!("check failed: {e}")))?;
    if diags.iter().any(weft_graph::Diagnostic::is_error) {
        return Ok(Outcome::Refused);
    }
    let prepared =
        weft_graph::Prepared::new(loaded).map_err(|d| Failure::RenderRefused(format!("{d:?}")))?;
    let mut names: BTreeSet<String> = feature_names(prepared.ir());
    names.extend(prepared.graph().default_features.iter().cloned());
    // The renderer's own: on exactly when passes trace in hardware.
    names.remove(weft_render::RAY_QUERY_FEATURE);
    let none: Vec<String> = names.iter().map(|n| format!("!{n}")).collect();
    let all: Vec<String> = names.iter().cloned().collect();
    for features in [Vec::new(), none, all] {
        let before = gpu.validation().messages().len();
        let settings = RenderSettings {
            graph: graph.to_path_buf(),
            extent: Extent {
                width: 32,
                height: 18,
            },
            features: features.clone(),
            ..RenderSettings::default()
        };
        let result = render_with_progress(gpu, scene, &prepared, &settings, &mut |_| {});
        let messages = gpu.validation().messages();
        let new: Vec<String> = messages[before..]
            .iter()
            .map(|m| format!("{}: {}", m.id, m.text))
            .collect();
        if let Err(e) = result {
            return Err(Failure::RenderRefused(format!(
                "accepted by check, but rendering with {features:?} failed: {e}"
            )));
        }
        if !new.is_empty() {
            return Err(Failure::Other(format!(
                "accepted by check, but rendering with {features:?} gave {} validation message(s):\n{}",
                new.len(),
                new.join("\n")
            )));
        }
    }
    Ok(Outcome::Rendered)
}

#[test]
fn every_mutant_check_accepts_renders_clean() {
    let count: usize = std::env::var("WEFT_MUTANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(40);
    let seed: u64 = std::env::var("WEFT_MUTANT_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x5EED);
    let gpu = weft_tests::gpu();
    let scene = weft_scene::load_scene(&demo_scene()).expect("demo scene");
    let files = mutable_files();
    let mut rng = Rng::new(seed);
    let (mut refused, mut rendered, mut failures) = (0, 0, Vec::new());
    // Mutants `graph check --shaders` accepted and a render then refused.
    let mut check_ok_render_refused = 0;
    let mut made = 0;
    while made < count {
        let file = rng.pick(&files).clone();
        let text = std::fs::read_to_string(root().join(&file)).expect("read");
        let Some((mutant, what)) = mutate(&text, &mut rng) else {
            continue;
        };
        if mutant == text {
            continue;
        }
        let roots = roots_using(&file);
        if roots.is_empty() {
            continue;
        }
        let graph = *rng.pick(&roots);
        made += 1;
        let tree = Tree::new("drawn");
        std::fs::write(tree.0.join(&file), &mutant).expect("write mutant");
        let label = format!(
            "mutant {made}: {} ({what}) through graphs/{graph}",
            file.display()
        );
        // Shown as it runs under `--nocapture` (`make fuzz`), so a crash names its mutant.
        eprintln!("{label}");
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            run_mutant(&gpu, &scene, &tree.0.join("graphs").join(graph))
        }));
        match outcome {
            Ok(Ok(Outcome::Refused)) => refused += 1,
            Ok(Ok(Outcome::Rendered)) => rendered += 1,
            Ok(Err(Failure::RenderRefused(problem))) => {
                check_ok_render_refused += 1;
                failures.push(format!("{label}: {problem}"));
            }
            Ok(Err(Failure::Other(problem))) => failures.push(format!("{label}: {problem}")),
            Err(_) => failures.push(format!("{label}: panicked")),
        }
    }
    eprintln!("{count} mutants (seed {seed:#x}): {refused} refused by check, {rendered} accepted and rendered clean, {} failed, {check_ok_render_refused} of them check said ok and render refused", failures.len());
    assert_eq!(
        check_ok_render_refused,
        0,
        "check said ok, render refused:\n{}",
        failures.join("\n\n")
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(
        refused > 0 && rendered > 0,
        "mutants exercise both sides: {refused} refused, {rendered} rendered"
    );
}

/// The compute mutations, each applied to the tiled graph's light culling:
/// what the device cannot run is refused by check (never rendered into a
/// validation message), and what it can run renders clean.
#[test]
fn compute_shaders_asking_more_than_the_device_offers_are_refused() {
    let gpu = weft_tests::gpu();
    let scene = weft_scene::load_scene(&demo_scene()).expect("demo scene");
    let file = Path::new("shaders/light_cull.comp");
    let text = std::fs::read_to_string(root().join(file)).expect("read");
    let main = text.find("void main() {").expect("main") + "void main() {".len();
    let with = |declaration: &str, statement: &str| {
        format!(
            "{}{declaration}\n{}\n    {statement}{}",
            &text[..text.find("void main()").expect("main")],
            "void main() {",
            &text[main..]
        )
    };
    let sized = |x: &str| text.replacen("local_size_x = 16", &format!("local_size_x = {x}"), 1);
    let atomics = with(
        "shared float mutant_total;",
        "atomicAdd(mutant_total, 1.0);",
    )
    .replacen(
        "#version 450",
        "#version 450\n#extension GL_EXT_shader_atomic_float : require",
        1,
    );
    let hoard = |vec4s: usize| {
        with(
            &format!("shared vec4 mutant_hoard[{vec4s}];"),
            &format!("mutant_hoard[gl_LocalInvocationIndex % {vec4s}u] = vec4(1.0);"),
        )
    };
    assert!(
        text.contains("local_size_x = 16"),
        "light_cull's workgroup changed"
    );
    for (what, mutant, refused) in [
        ("8 KiB of shared memory more", hoard(512), false),
        ("128 KiB of shared memory more", hoard(8192), true),
        ("64x16 invocations", sized("64"), false),
        ("1024x16 invocations", sized("1024"), true),
        ("float atomics on shared memory", atomics, true),
    ] {
        let tree = Tree::new("limits");
        std::fs::write(tree.0.join(file), &mutant).expect("write mutant");
        let outcome = run_mutant(&gpu, &scene, &tree.0.join("graphs/tiled.ron"))
            .unwrap_or_else(|problem| panic!("{what}: {problem}"));
        assert_eq!(matches!(outcome, Outcome::Refused), refused, "{what}");
    }
}
