//! `LiveRender` hot reload on a private copy of the forward graph, the shaders and
//! a tiny scene: a refused reload changes nothing that renders, files changed
//! meanwhile are reloaded with the next good version, and the watched sources
//! cover graph includes, shader includes and the scene's model. Reloads prepared on
//! a `ReloadWorker` thread leave frames coming and the live version untouched
//! until committed; a newer request supersedes an older one.

/// The repository root.
fn repo_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

use ash::vk::SubgroupFeatureFlags;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use weft_gpu::{Gpu, GpuOptions, ShaderStage};
use weft_graph::plan::Extent;
use weft_render::normalize_path as normalize;
use weft_render::WorkerReply;
use weft_render::{Committed, LiveRender, ReloadWorker, RenderSettings};

const QUAD_OBJ: &str =
    "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nvn 0 1 0\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\n";
const SCENE: &str = "model\n{\n\tfile \"quad.obj\"\n}\n\ncamera\n{\n\tposition 0 3 5\n\ttarget 0 0 0\n}\n\nsunlight\n{\n\tdirection -0.3 -1 -0.4\n\tcolor 0.3 0.3 0.3\n}\n";
const TONEMAP_OUT: &str = "color = vec4(c / (1.0 + c), 1.0);";

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create folder");
    for entry in std::fs::read_dir(from).expect("read folder") {
        let entry = entry.expect("entry");
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("copy");
        }
    }
}

/// A temporary copy of `graphs/` and `shaders/` with the tiny scene.
fn fixture(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-reload-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    copy_dir(&repo_root().join("graphs"), &dir.join("graphs"));
    copy_dir(&repo_root().join("shaders"), &dir.join("shaders"));
    std::fs::create_dir_all(dir.join("scenes")).expect("scenes");
    std::fs::write(dir.join("scenes/quad.obj"), QUAD_OBJ).expect("obj");
    std::fs::write(dir.join("scenes/tiny.scene"), SCENE).expect("scene");
    dir
}

fn settings(dir: &Path) -> RenderSettings {
    RenderSettings {
        graph: dir.join("graphs/forward.ron"),
        extent: Extent {
            width: 64,
            height: 36,
        },
        ..RenderSettings::default()
    }
}

fn pixels(live: &mut LiveRender<'_>) -> Vec<u8> {
    let report = live.frame().expect("frame");
    report.output.expect("output").to_rgba8().into_raw()
}

fn edit(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).expect("read");
    assert!(text.contains(from), "{} lacks {from}", path.display());
    std::fs::write(path, text.replace(from, to)).expect("write");
}

#[test]
fn a_refused_reload_keeps_the_last_good_version_and_the_next_good_one_takes_every_change() {
    let dir = fixture("refused");
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("gpu");
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let first = pixels(&mut live);

    let tonemap = dir.join("shaders/tonemap.frag");
    let graph = dir.join("graphs/forward.ron");
    edit(&tonemap, TONEMAP_OUT, "color = vec4(1.0, 0.0, 0.0, 1.0);");
    edit(
        &graph,
        "(name: \"hdr\", enabled_if: [\"!taa\"])",
        "(name: \"hdx\", enabled_if: [\"!taa\"])",
    );
    let both = BTreeSet::from([normalize(&tonemap), normalize(&graph)]);
    let err = live
        .apply(&both)
        .expect_err("the graph names an unknown image");
    assert_eq!(err.file, graph);
    assert!(err.line.is_some() && err.message.contains("hdx"), "{err}");
    assert_eq!(
        pixels(&mut live),
        first,
        "neither the graph nor the shader edit goes live"
    );

    edit(
        &graph,
        "(name: \"hdx\", enabled_if: [\"!taa\"])",
        "(name: \"hdr\", enabled_if: [\"!taa\"])",
    );
    let reloaded = live
        .apply(&BTreeSet::from([normalize(&graph)]))
        .expect("fixed");
    assert_eq!(reloaded, both.iter().cloned().collect::<Vec<_>>());
    assert!(
        pixels(&mut live)
            .chunks_exact(4)
            .all(|p| p == [255, 0, 0, 255]),
        "the shader edit made while the graph was broken is live now"
    );

    let unrelated = BTreeSet::from([normalize(&dir.join("graphs/README.md"))]);
    assert_eq!(
        live.apply(&unrelated).expect("ignored"),
        Vec::<PathBuf>::new()
    );
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn sources_cover_graph_includes_shader_includes_and_the_scene_model() {
    let dir = fixture("sources");
    let gpu = Gpu::new(&GpuOptions::default()).expect("gpu");
    let live = LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let sources = live.sources();
    let has = |set: &BTreeSet<PathBuf>, file: &str| set.contains(&normalize(&dir.join(file)));
    assert!(has(&sources.graph, "graphs/forward.ron"));
    assert!(has(&sources.graph, "graphs/bloom.ron"));
    assert!(has(&sources.graph, "graphs/shadows.ron"));
    let shaders: BTreeSet<PathBuf> = sources.shaders.keys().cloned().collect();
    assert!(has(&shaders, "shaders/forward.frag"));
    assert!(has(&shaders, "shaders/include/lighting.glsl"));
    assert!(has(&shaders, "shaders/include/scene.glsl"));
    assert!(has(&shaders, "shaders/tonemap.frag"));
    assert!(has(&sources.scene, "scenes/tiny.scene"));
    assert!(has(&sources.scene, "scenes/quad.obj"));
    drop(live);
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn reconfigure_switches_graph_features_and_size_all_or_nothing() {
    let dir = fixture("reconfigure");
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("gpu");
    let forward = settings(&dir);
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), forward.clone()).expect("live");
    let first = pixels(&mut live);
    let has_pass =
        |live: &LiveRender<'_>, name: &str| live.plan().passes.iter().any(|p| p.name == name);

    let deferred = RenderSettings {
        graph: dir.join("graphs/deferred.ron"),
        ..forward.clone()
    };
    live.reconfigure(deferred.clone()).expect("to deferred");
    assert!(has_pass(&live, "gbuffer"));
    assert!(live
        .sources()
        .graph
        .contains(&normalize(&dir.join("graphs/deferred.ron"))));
    assert_eq!(pixels(&mut live).len(), 64 * 36 * 4);

    live.reconfigure(RenderSettings {
        features: vec!["!bloom".into()],
        extent: Extent {
            width: 32,
            height: 20,
        },
        ..forward.clone()
    })
    .expect("forward without bloom, smaller");
    assert!(!live.plan().features.iter().any(|f| f == "bloom"));
    assert!(!has_pass(&live, "bloom_bright"));
    let report = live.frame().expect("frame");
    let output = report.output.expect("output");
    assert_eq!((output.width, output.height), (32, 20));

    live.reconfigure(forward.clone()).expect("back to forward");
    assert_eq!(
        pixels(&mut live),
        first,
        "the same settings give the same image"
    );

    // A shader the live graph does not use is edited (no watcher sees it): switching
    // to the graph that uses it compiles it from disk, finds the error, and keeps
    // the forward version rendering unchanged.
    let gbuffer = dir.join("shaders/gbuffer.frag");
    let text = std::fs::read_to_string(&gbuffer).expect("read");
    let broken_line = text.lines().count() + 1;
    std::fs::write(&gbuffer, format!("{text}this is not glsl\n")).expect("break");
    let err = live
        .reconfigure(deferred)
        .expect_err("broken gbuffer shader");
    assert_eq!(normalize(&err.file), normalize(&gbuffer), "{err}");
    assert_eq!(err.line, Some(broken_line as u32), "{err}");
    assert_eq!(live.settings().graph, forward.graph);
    assert_eq!(
        pixels(&mut live),
        first,
        "the forward version still renders"
    );
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

const RED: &str = "color = vec4(1.0, 0.0, 0.0, 1.0);";

fn gpu() -> Gpu {
    Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("gpu")
}

/// Renders frames of the live version until the worker answers; returns the
/// answer and how many frames were rendered meanwhile, each checked to be `shown`.
fn frames_until_prepared(
    worker: &mut ReloadWorker,
    live: &mut LiveRender<'_>,
    shown: &[u8],
) -> (WorkerReply, u32) {
    let started = Instant::now();
    let mut frames = 0;
    loop {
        if let Some(prepared) = worker.poll() {
            return (prepared, frames);
        }
        assert!(started.elapsed() < Duration::from_secs(120), "no answer");
        assert_eq!(pixels(live), shown, "frame {frames} shows the live version");
        frames += 1;
    }
}

#[test]
fn a_slow_prepare_runs_on_the_worker_while_frames_keep_coming() {
    let dir = fixture("worker");
    let gpu = gpu();
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let first = pixels(&mut live);
    let tonemap = dir.join("shaders/tonemap.frag");
    edit(&tonemap, TONEMAP_OUT, RED);
    let delay = Duration::from_millis(500);
    std::thread::scope(|scope| {
        let mut worker = ReloadWorker::spawn(scope, &gpu, delay);
        worker.submit(live.files_job(&BTreeSet::from([normalize(&tonemap)])));
        assert!(worker.waiting());
        let (prepared, frames) = frames_until_prepared(&mut worker, &mut live, &first);
        assert!(frames > 0, "no frame was rendered during the prepare");
        assert_ne!(prepared.thread, std::thread::current().id());
        assert!(prepared.elapsed >= delay, "{:?}", prepared.elapsed);
        assert!(!worker.waiting());
        let reload = prepared.result.expect("prepared");
        assert_eq!(reload.files(), [normalize(&tonemap)]);
        assert_eq!(
            live.commit(reload).expect("committed"),
            Committed::Applied(vec![normalize(&tonemap)])
        );
    });
    assert!(
        pixels(&mut live)
            .chunks_exact(4)
            .all(|p| p == [255, 0, 0, 255]),
        "the committed shader edit is live"
    );
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_refused_prepare_never_touches_the_live_version_and_a_newer_edit_supersedes_it() {
    let dir = fixture("superseded");
    let gpu = gpu();
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let first = pixels(&mut live);
    let plan = live.plan() as *const _;
    let sources = live.sources().clone();
    let tonemap = dir.join("shaders/tonemap.frag");
    let changed = BTreeSet::from([normalize(&tonemap)]);
    std::thread::scope(|scope| {
        let mut worker = ReloadWorker::spawn(scope, &gpu, Duration::from_millis(200));
        edit(&tonemap, TONEMAP_OUT, "color = vec4(c / (1.0 + c), 1.0) +;");
        worker.submit(live.files_job(&changed));
        let (prepared, frames) = frames_until_prepared(&mut worker, &mut live, &first);
        assert!(frames > 0);
        let err = prepared.result.expect_err("syntax error");
        assert_eq!(normalize(&err.file), normalize(&tonemap));
        assert!(err.line.is_some(), "{err}");
        assert!(std::ptr::eq(live.plan(), plan), "the live plan was kept");
        assert_eq!(live.sources(), &sources);
        assert_eq!(pixels(&mut live), first, "the broken shader is not live");

        // A broken edit and, before it is answered, its fix: only the fix counts.
        let broken = worker.submit(live.files_job(&changed));
        edit(&tonemap, "color = vec4(c / (1.0 + c), 1.0) +;", RED);
        let fixed = worker.submit(live.files_job(&changed));
        assert_eq!(fixed, broken + 1);
        let (prepared, _) = frames_until_prepared(&mut worker, &mut live, &first);
        assert_eq!(prepared.generation, fixed);
        let reload = prepared.result.expect("the fix prepares");
        assert_eq!(
            live.commit(reload).expect("committed"),
            Committed::Applied(vec![normalize(&tonemap)])
        );
        drop(worker);
    });
    assert!(pixels(&mut live)
        .chunks_exact(4)
        .all(|p| p == [255, 0, 0, 255]));
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_reload_prepared_from_an_older_version_is_not_committed() {
    let dir = fixture("stale");
    let gpu = gpu();
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let tonemap = dir.join("shaders/tonemap.frag");
    edit(&tonemap, TONEMAP_OUT, RED);
    let job = live.files_job(&BTreeSet::from([normalize(&tonemap)]));
    let mut small = live.settings().clone();
    small.extent = Extent {
        width: 32,
        height: 18,
    };
    live.reconfigure(small).expect("reconfigured");
    let plan = live.plan() as *const _;
    let mut checker = weft_render::ShaderChecker::new().expect("checker");
    let prepared = job.prepare(&gpu, &mut checker).expect("prepared");
    assert_eq!(live.commit(prepared).expect("commit"), Committed::Stale);
    assert!(std::ptr::eq(live.plan(), plan));
    assert_eq!(pixels(&mut live).len(), 32 * 18 * 4, "the new size is live");
    assert!(
        live.sources().shaders.contains_key(&normalize(&tonemap)),
        "still watched"
    );
    let reloaded = live.apply(&BTreeSet::new()).expect("pending edit applies");
    assert_eq!(reloaded, vec![normalize(&tonemap)]);
    assert!(pixels(&mut live)
        .chunks_exact(4)
        .all(|p| p == [255, 0, 0, 255]));
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn shader_edits_the_gpu_would_reject_are_refused_before_commit() {
    let dir = fixture("interface");
    let gpu = gpu();
    let mut live =
        LiveRender::new(&gpu, &dir.join("scenes/tiny.scene"), settings(&dir)).expect("live");
    let first = pixels(&mut live);
    let graph = dir.join("graphs/forward.ron");
    let cases = [
        (
            "shaders/include/scene.glsl",
            "set = SET_SCENE, binding = BINDING_MATERIALS)",
            "set = SET_SCENE, binding = 29)",
            "pass `forward`: shader binding `material_table` (set 1 binding 29) is not scene data the engine binds",
        ),
        (
            "shaders/tonemap.frag",
            "uniform sampler2D hdr;",
            "uniform sampler2DShadow hdr;",
            "pass `tonemap`: shader binding 0 `hdr` is a depth-comparison sampler (sampler2DShadow)",
        ),
    ];
    for (file, from, to, expected) in cases {
        let path = dir.join(file);
        let original = std::fs::read_to_string(&path).expect("read");
        edit(&path, from, to);
        if file.ends_with("tonemap.frag") {
            edit(
                &path,
                "texture(hdr, uv).rgb",
                "vec3(texture(hdr, vec3(uv, 0.5)))",
            );
        }
        let err = live
            .apply(&BTreeSet::from([normalize(&path)]))
            .expect_err("refused");
        assert_eq!(err.file, graph, "{err}");
        assert!(err.line.is_some(), "{err}");
        assert!(err.message.contains(expected), "{err}");
        assert_eq!(pixels(&mut live), first, "the live version keeps rendering");
        std::fs::write(&path, original).expect("restore");
        live.apply(&BTreeSet::from([normalize(&path)]))
            .expect("the restored file reloads");
    }
    // A shader that needs a feature the device lacks is refused at the shader
    // before any module is created. lavapipe offers no clustered subgroup
    // operations; a device that does takes the edit.
    let path = dir.join("shaders/tonemap.frag");
    edit(
        &path,
        "#version 450",
        "#version 450\n#extension GL_KHR_shader_subgroup_clustered : require",
    );
    edit(
        &path,
        "texture(hdr, uv).rgb",
        "texture(hdr, uv).rgb * (subgroupClusteredAdd(1.0, 1u))",
    );
    let device = gpu.info();
    let offered = device
        .shaders
        .offers_subgroup(ShaderStage::Fragment, SubgroupFeatureFlags::CLUSTERED);
    let applied = live.apply(&BTreeSet::from([normalize(&path)]));
    if offered {
        applied.expect("the device offers clustered subgroup operations");
    } else {
        let err = applied.expect_err("refused");
        assert_eq!(err.file, path, "{err}");
        assert_eq!(
            err.message,
            format!(
                "needs subgroup clustered operations (`supportedOperations` lacks CLUSTERED), which the device `{}` does not offer",
                device.name
            )
        );
        assert_eq!(pixels(&mut live), first, "the live version keeps rendering");
    }
    drop(live);
    assert_eq!(gpu.validation().messages(), Vec::new());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// Writes a `value`-everywhere 8×4 environment map to `path`.
fn write_map(path: &Path, value: f32) {
    let bytes = weft_io::exr::encode_rgb(8, 4, &[[value; 3]; 32]).expect("encodes");
    std::fs::write(path, bytes).expect("write the map");
}

#[test]
fn an_edited_environment_map_reloads_and_a_broken_one_keeps_the_last_good() {
    let dir = fixture("environment");
    let map = dir.join("scenes/sky.exr");
    write_map(&map, 0.5);
    let scene = dir.join("scenes/tiny.scene");
    let text = std::fs::read_to_string(&scene).expect("scene");
    std::fs::write(
        &scene,
        format!("environment\n{{\n\tfile \"sky.exr\"\n}}\n{text}"),
    )
    .expect("scene");
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("gpu");
    let mut live = LiveRender::new(&gpu, &scene, settings(&dir)).expect("live");
    assert!(live.sources().scene.contains(&normalize(&map)));
    let first = pixels(&mut live);

    let mut texels = [[0.5f32; 3]; 32];
    texels[13] = [f32::NAN, 0.0, 0.0];
    std::fs::write(
        &map,
        weft_io::exr::encode_rgb(8, 4, &texels).expect("encodes"),
    )
    .expect("write");
    let err = live
        .apply(&BTreeSet::from([normalize(&map)]))
        .expect_err("a NaN texel");
    assert!(
        err.message.contains("texel (5, 1)") && err.message.contains("must be finite"),
        "{err}"
    );
    assert_eq!(
        pixels(&mut live),
        first,
        "the last good map keeps rendering"
    );

    write_map(&map, 2.0);
    live.apply(&BTreeSet::from([normalize(&map)]))
        .expect("a good map");
    let brighter = pixels(&mut live);
    let sum = |p: &[u8]| p.iter().map(|&v| u64::from(v)).sum::<u64>();
    assert!(sum(&brighter) > sum(&first), "the brighter map is live");
    drop(live);
    assert!(gpu.validation().messages().is_empty());
    std::fs::remove_dir_all(&dir).expect("clean up");
}
