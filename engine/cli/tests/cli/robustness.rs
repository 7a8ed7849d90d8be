//! Bad input as an adversary gives it: devices and FIFOs where files belong,
//! system files as includes, oversized textures, damaged and swapped cache
//! entries, files outside a scene's folder, stray commas. Each is a clean,
//! located error or a warning and a right image: never a hang, a crash or a
//! silently wrong result. Every child runs under a deadline, so a hang fails
//! the test instead of stopping the suite.

use crate::harness::{command_in, repo};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// `weft ARGS` in `dir`, killed (and the test failed) after `seconds`.
fn weft_within(dir: &Path, args: &[&str], seconds: u64) -> Output {
    finish_within(&mut command_in(dir, args), seconds)
}

/// Runs `command`, killing it (and failing the test) after `seconds`.
fn finish_within(command: &mut Command, seconds: u64) -> Output {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft runs");
    let deadline = Instant::now() + Duration::from_secs(seconds);
    while child.try_wait().expect("wait").is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().expect("output");
            panic!(
                "{command:?} still ran after {seconds} s: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A fresh temporary folder for one test.
fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-robust-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo");
    assert!(made.success());
}

#[test]
fn devices_and_fifos_named_as_graphs_are_refused_at_once() {
    let dir = temp("graph-devices");
    let fifo = dir.join("g.ron");
    mkfifo(&fifo);
    let fifo = fifo.to_string_lossy().into_owned();
    for graph in ["/dev/zero", fifo.as_str()] {
        for args in [
            vec!["graph", "check", graph],
            vec!["graph", "check", "--shaders", graph],
            vec!["graph", "dot", graph],
            vec![
                "render",
                "scenes/demo.scene",
                "--graph",
                graph,
                "--size",
                "8x8",
            ],
        ] {
            let out = weft_within(&repo(), &args, 60);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.contains("is a device, not a regular file")
                    || err.contains("is a FIFO, not a regular file"),
                "{args:?}: {err}"
            );
        }
    }
    // An include of a device, and of a system file whose content must not be
    // echoed (it would print the environment).
    for (include, expected) in [
        ("/dev/zero", "it is a device, not a regular file"),
        (
            "/proc/self/environ",
            "RON syntax error (the file is outside the graph's folder, so its content is not shown)",
        ),
    ] {
        let graph = dir.join("inc.ron");
        std::fs::write(
            &graph,
            format!("Graph(\n    include: [(file: \"{include}\")],\n    output: \"x\",\n)\n"),
        )
        .expect("write");
        let out = command_in(&repo(), &["graph", "check", &graph.to_string_lossy()])
            .env("WEFT_SECRET_FOR_TEST", "do-not-print-me")
            .stdin(Stdio::null())
            .output()
            .expect("weft runs");
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{include}: {err}");
        assert!(err.contains(expected), "{include}: {err}");
        assert!(!err.contains("do-not-print-me"), "{include} echoed: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn devices_and_fifos_named_as_scenes_print_their_error_and_end() {
    let dir = temp("scene-devices");
    let fifo = dir.join("s.scene");
    mkfifo(&fifo);
    for scene in [Path::new("/dev/zero"), fifo.as_path()] {
        let out = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 30);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{scene:?}: {err}");
        assert!(err.contains("not a regular file"), "{scene:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A quad with a texture `width` x `height`, lit head-on, in `dir`.
fn textured_quad(dir: &Path, width: u32, height: u32) -> PathBuf {
    image::RgbaImage::from_pixel(width, height, image::Rgba([200, 120, 40, 255]))
        .save(dir.join("wide.png"))
        .expect("png");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd wide.png\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nusemtl m\nf 1/1/1 4/4/1 3/3/1 2/2/1\n",
    )
    .expect("obj");
    let scene = dir.join("quad.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"quad.obj\"\n}\n\ncamera \"main\"\n{\n\tposition 0 3 0.01\n\ttarget 0 0 0\n}\n\nsunlight\n{\n\tdirection 0 -1 0\n\tcolor 1 1 1\n}\n",
    )
    .expect("scene");
    scene
}

#[test]
fn textures_over_the_device_limit_are_downscaled_with_a_warning() {
    let dir = temp("wide-texture");
    let scene = textured_quad(&dir, 65536, 1);
    let check = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 60);
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(check.status.success(), "{}", stderr(&check));
    assert!(
        text.contains("texture is 65536x1, over 16384 texels per side (maxImageDimension2D): it is downscaled to 16384x1 before upload"),
        "{text}"
    );
    for graph in ["graphs/forward.ron", "graphs/pathtrace.ron"] {
        let png = dir.join("out.png");
        let out = weft_within(
            &repo(),
            &[
                "render",
                &scene.to_string_lossy(),
                "--graph",
                graph,
                "--size",
                "16x16",
                "--validate",
                "--out",
                &png.to_string_lossy(),
            ],
            300,
        );
        let err = stderr(&out);
        assert!(out.status.success(), "{graph}: {err}");
        if graph.ends_with("forward.ron") {
            assert!(
                err.contains("is 65536x1, over the device's maxImageDimension2D of 16384: downscaled to 16384x1"),
                "{graph}: {err}"
            );
        }
        let image = image::open(&png).expect("png").to_rgba8();
        let centre = image.get_pixel(8, 8);
        assert!(
            centre[0] > centre[1] && centre[1] > centre[2],
            "{graph}: textured, not white: {centre:?}"
        );
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// Renders `scene` with forward at 24x16 using `cache` as the user cache.
fn render_with_cache(scene: &str, cache: &Path, png: &Path) -> Output {
    finish_within(
        command_in(
            &repo(),
            &[
                "render",
                scene,
                "--size",
                "24x16",
                "--out",
                &png.to_string_lossy(),
            ],
        )
        .env("WEFT_CACHE_DIR", cache),
        300,
    )
}

#[test]
fn damaged_or_swapped_cache_entries_give_the_uncached_image_with_a_warning() {
    let dir = temp("cache-damage");
    let cache = dir.join("cache");
    let clean = dir.join("clean.png");
    let out = command_in(
        &repo(),
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "24x16",
            "--no-cache",
            "--out",
            &clean.to_string_lossy(),
        ],
    )
    .output()
    .expect("weft runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let reference = std::fs::read(&clean).expect("png");
    let png = dir.join("cached.png");
    assert!(render_with_cache("scenes/demo.scene", &cache, &png)
        .status
        .success());
    let entries = |sub: &str| -> Vec<PathBuf> {
        let mut found: Vec<PathBuf> = std::fs::read_dir(cache.join(sub))
            .map(|d| d.map(|e| e.expect("entry").path()).collect())
            .unwrap_or_default();
        found.sort();
        found
    };
    let spirv = entries("spirv");
    let models = entries("models");
    assert!(
        !spirv.is_empty() && !models.is_empty(),
        "{spirv:?} {models:?}"
    );
    // Four bytes flipped in every SPIR-V entry, every model entry truncated.
    for entry in &spirv {
        let mut bytes = std::fs::read(entry).expect("entry");
        let at = bytes.len() / 2;
        bytes[at..at + 4].iter_mut().for_each(|b| *b ^= 0x5A);
        std::fs::write(entry, bytes).expect("damage");
    }
    for entry in &models {
        let bytes = std::fs::read(entry).expect("entry");
        std::fs::write(entry, &bytes[..bytes.len() / 2]).expect("truncate");
    }
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("is damaged (its checksum does not match its payload); compiled again"),
        "{err}"
    );
    assert!(err.contains("is damaged (it is truncated"), "{err}");
    assert_eq!(
        std::fs::read(&png).expect("png"),
        reference,
        "the same image as without a cache"
    );
    // Rewritten: the next run is clean.
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    assert!(!stderr(&out).contains("damaged"), "{}", stderr(&out));
    // Every SPIR-V entry replaced by a link to a device: no hang, same image.
    for entry in entries("spirv") {
        std::fs::remove_file(&entry).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", &entry).expect("link");
    }
    let out = render_with_cache("scenes/demo.scene", &cache, &png);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("is damaged (it is a device); compiled again"),
        "{err}"
    );
    assert_eq!(std::fs::read(&png).expect("png"), reference);
    // Two model entries swapped: each model still renders as itself.
    let swap_scene = dir.join("two.scene");
    let models_dir = repo().join("scenes/models");
    std::fs::write(
        &swap_scene,
        format!(
            "model\n{{\n\tfile \"{}\"\n}}\n\nmodel\n{{\n\tfile \"{}\"\n\tposition 0 1 0\n}}\n\ncamera \"c\"\n{{\n\tposition 0 2 6\n\ttarget 0 0.5 0\n}}\n\nsunlight\n{{\n\tdirection -0.3 -1 -0.4\n\tcolor 1 1 1\n}}\n",
            models_dir.join("floor.obj").display(),
            models_dir.join("glass_sphere.obj").display()
        ),
    )
    .expect("scene");
    let swap = swap_scene.to_string_lossy().into_owned();
    let first = dir.join("first.png");
    assert!(render_with_cache(&swap, &cache, &first).status.success());
    let named = |stem: &str| {
        entries("models")
            .into_iter()
            .find(|e| {
                e.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with(stem))
            })
            .expect("entry")
    };
    let (floor, sphere) = (named("floor.obj-"), named("glass_sphere.obj-"));
    let (floor_bytes, sphere_bytes) = (
        std::fs::read(&floor).expect("e"),
        std::fs::read(&sphere).expect("e"),
    );
    std::fs::write(&floor, &sphere_bytes).expect("swap");
    std::fs::write(&sphere, &floor_bytes).expect("swap");
    let swapped = dir.join("swapped.png");
    let out = render_with_cache(&swap, &cache, &swapped);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("(it was stored for another input); imported again"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&swapped).expect("png"),
        std::fs::read(&first).expect("png")
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn output_folders_negative_times_and_empty_feature_names() {
    let out = weft_within(
        &repo(),
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "8x8",
            "--out",
            "/nonexistent/dir/x.png",
        ],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--out /nonexistent/dir/x.png: the folder /nonexistent/dir does not exist"),
        "{err}"
    );
    assert!(!Path::new("/nonexistent").exists());
    let dir = temp("negative-time");
    let png = dir.join("t.png");
    let out = weft_within(
        &repo(),
        &[
            "render",
            "scenes/animation.scene",
            "--size",
            "8x8",
            "--time",
            "-5",
            "--out",
            &png.to_string_lossy(),
        ],
        120,
    );
    assert!(
        out.status.success(),
        "--time -5 is a value: {}",
        stderr(&out)
    );
    let unknown = "unknown feature \"bench_floors\"; this graph's features are:";
    let empty = "an empty feature name (a stray comma, or `!` alone)";
    for (features, expected) in [
        ("bench_floors", unknown),
        ("!", empty),
        (",,,", empty),
        ("bloom,,shadow_casters", empty),
    ] {
        let out = weft_within(
            &repo(),
            &[
                "render",
                "scenes/demo.scene",
                "--size",
                "8x8",
                "--features",
                features,
                "--out",
                &png.to_string_lossy(),
            ],
            60,
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{features}: {err}");
        assert!(err.contains(expected), "{features}: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn scenes_and_gltf_files_read_only_inside_their_folder_unless_allowed() {
    let dir = temp("outside");
    let inner = dir.join("scene");
    std::fs::create_dir_all(&inner).expect("dir");
    std::fs::write(
        dir.join("outside.rhai"),
        "point_light(#{ position: [0, 2, 0], color: [1, 1, 1] });\n",
    )
    .expect("script");
    let scene = inner.join("s.scene");
    std::fs::write(&scene, "script \"../outside.rhai\"\n").expect("scene");
    let out = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 60);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("s.scene:1: script "), "{err}");
    assert!(err.contains("outside.rhai lies outside"), "{err}");
    assert!(
        err.contains("weft reads it only with --allow-outside"),
        "{err}"
    );
    let out = weft_within(
        &repo(),
        &[
            "--allow-outside",
            "scene",
            "check",
            &scene.to_string_lossy(),
        ],
        60,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // A glTF buffer that climbs out of the glTF's folder.
    let gltf = inner.join("m.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"../../../../../../../../etc/passwd","byteLength":12}],"bufferViews":[{"buffer":0,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#,
    )
    .expect("gltf");
    let out = weft_within(
        &repo(),
        &["scene", "check", "--no-cache", &gltf.to_string_lossy()],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("buffer 0: buffer ") && err.contains("etc/passwd lies outside"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn params_are_held_to_the_type_and_range_their_graph_declares() {
    for (param, expected) in [
        (
            "max_depth=-1",
            "pathtrace.ron:12:22: error: parameter \"max_depth\" set to -1: it must be at least 1",
        ),
        (
            "sampling=99",
            "parameter \"sampling\" set to 99: it must be one of 0, 1, 2",
        ),
        (
            "exposure=true",
            "parameter \"exposure\" set to true: it must be a number, like its default",
        ),
        (
            "samples_per_frame=0.5",
            "parameter \"samples_per_frame\" set to 0.5: it must be a whole number",
        ),
    ] {
        let out = weft_within(
            &repo(),
            &[
                "render",
                "scenes/demo.scene",
                "--graph",
                "graphs/pathtrace.ron",
                "--size",
                "8x8",
                "--param",
                param,
                "--out",
                "/tmp/weft-never-written.png",
            ],
            60,
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{param}: {err}");
        assert!(err.contains(expected), "{param}: {err}");
    }
}

/// SplitMix64, so the random damage below repeats from its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// The cache as a property: random damage to random entries (SPIR-V, models,
/// the path tracer's BVH) in rounds; every render exits 0 and writes the
/// image a `--no-cache` render writes, byte for byte.
#[test]
fn random_damage_to_random_cache_entries_never_changes_the_image() {
    let dir = temp("cache-property");
    let cache = dir.join("cache");
    let render = |graph: &str, out: &Path, cached: bool| {
        let mut args = vec![
            "render",
            "scenes/demo.scene",
            "--graph",
            graph,
            "--size",
            "24x16",
            "--out",
        ];
        let out = out.to_string_lossy().into_owned();
        args.push(&out);
        if !cached {
            args.push("--no-cache");
        }
        finish_within(
            command_in(&repo(), &args).env("WEFT_CACHE_DIR", &cache),
            300,
        )
    };
    let graphs = ["graphs/forward.ron", "graphs/pathtrace.ron"];
    let mut clean = Vec::new();
    for graph in graphs {
        let png = dir.join("clean.png");
        let out = render(graph, &png, false);
        assert!(out.status.success(), "{}", stderr(&out));
        clean.push(std::fs::read(&png).expect("png"));
        assert!(render(graph, &dir.join("warm.png"), true).status.success());
    }
    let entries = || -> Vec<PathBuf> {
        let mut found = Vec::new();
        for sub in ["spirv", "models", ""] {
            if let Ok(read) = std::fs::read_dir(cache.join(sub)) {
                found.extend(
                    read.map(|e| e.expect("entry").path())
                        .filter(|p| p.is_file() || p.is_symlink()),
                );
            }
        }
        found.sort();
        found
    };
    let mut rng = Rng(0x000C_AC4E);
    for round in 0..6 {
        let all = entries();
        assert!(all.len() > 3, "{all:?}");
        let mut damaged = Vec::new();
        for _ in 0..1 + rng.below(3) {
            let entry = &all[rng.below(all.len())];
            let bytes = std::fs::read(entry).unwrap_or_default();
            let kind = rng.below(6);
            let _ = std::fs::remove_file(entry);
            match kind {
                0 => std::fs::write(entry, &bytes[..rng.below(bytes.len().max(1))])
                    .expect("truncate"),
                1 => {
                    let mut flipped = bytes.clone();
                    for _ in 0..1 + rng.below(8) {
                        let at = rng.below(flipped.len().max(1));
                        if let Some(b) = flipped.get_mut(at) {
                            *b ^= 1 << rng.below(8);
                        }
                    }
                    std::fs::write(entry, flipped).expect("flip");
                }
                2 => {
                    let noise: Vec<u8> = (0..rng.below(256)).map(|_| rng.next() as u8).collect();
                    std::fs::write(entry, noise).expect("replace");
                }
                3 => {
                    let other = std::fs::read(&all[rng.below(all.len())]).unwrap_or_default();
                    std::fs::write(entry, other).expect("swap");
                }
                4 => std::os::unix::fs::symlink("/dev/zero", entry).expect("link"),
                _ => std::fs::create_dir(entry).expect("folder"),
            }
            damaged.push(format!("{} ({kind})", entry.display()));
        }
        for (graph, clean) in graphs.iter().zip(&clean) {
            let png = dir.join(format!("round{round}.png"));
            let out = render(graph, &png, true);
            let err = stderr(&out);
            assert!(
                out.status.success(),
                "round {round} {graph} after {damaged:?}: {err}"
            );
            assert_eq!(
                &std::fs::read(&png).expect("png"),
                clean,
                "round {round} {graph} after {damaged:?}: {err}"
            );
        }
        // A folder left in an entry's place cannot be replaced by a rename (the
        // render warns and goes on uncached); clear it so later rounds cache again.
        for sub in ["spirv", "models", ""] {
            for entry in std::fs::read_dir(cache.join(sub)).expect("cache folder") {
                let path = entry.expect("entry").path();
                let is_entry = path.extension().is_some_and(|e| {
                    ["spv", "weftcache", "weftbvh"].contains(&e.to_str().unwrap_or(""))
                });
                if is_entry && path.is_dir() && !path.is_symlink() {
                    std::fs::remove_dir_all(&path).expect("rm folder");
                }
            }
        }
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
