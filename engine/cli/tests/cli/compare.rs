//! `weft compare` as a user runs it: every file it promises written, the
//! reference cached and re-rendered when its entry is damaged, validation
//! clean, and bad references reported.

use crate::harness::{command_in, repo};
use std::path::{Path, PathBuf};
use std::process::Output;

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-compare-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Runs weft with its user cache in `cache`.
fn weft(args: &[&str], cache: &Path) -> Output {
    command_in(&repo(), args)
        .env("WEFT_CACHE_DIR", cache)
        .output()
        .expect("weft runs")
}

fn report(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    serde_json::from_str(&text).expect("report.json is JSON")
}

fn compare(out: &Path, cache: &Path) -> Output {
    let out_arg = out.to_string_lossy().into_owned();
    weft(
        &[
            "compare",
            "scenes/demo.scene",
            "--graphs",
            "graphs/forward.ron,graphs/deferred.ron",
            "--size",
            "48x32",
            "--spp",
            "4",
            "--frames",
            "2",
            "--validate",
            "--out",
            &out_arg,
        ],
        cache,
    )
}

#[test]
fn a_compare_run_writes_every_file_and_caches_its_reference() {
    let cache = temp("cache");
    let out = temp("out");
    let run = compare(&out, &cache);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("validation: 0 errors, 0 warnings"),
        "{stdout}"
    );
    for file in [
        "report.json",
        "report.md",
        "contact_sheet.png",
        "reference.exr",
        "reference.png",
        "forward.png",
        "forward.exr",
        "forward.flip.png",
        "deferred.png",
        "deferred.exr",
        "deferred.flip.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    let first = report(&out);
    assert_eq!(first["reference"]["cached"], false);
    assert_eq!(first["reference"]["spp"], 4);
    let configurations = first["configurations"].as_array().expect("configurations");
    assert_eq!(configurations.len(), 2);
    for c in configurations {
        for key in [
            "graph",
            "features",
            "params",
            "flip",
            "flip_ldr",
            "rmse",
            "rel_mse",
            "psnr",
            "luminance_ratio",
            "frame_ms",
            "passes",
            "transient_bytes",
            "device_bytes",
            "caveats",
        ] {
            assert!(c.get(key).is_some(), "{key} missing in {c}");
        }
        // The graphs' caveats under the demo's features: bloom (on by
        // default), no bounces, unshadowed area lights (the demo has some).
        let caveats: Vec<&str> = c["caveats"]
            .as_array()
            .expect("caveats")
            .iter()
            .filter_map(|n| n.as_str())
            .collect();
        for start in [
            "bloom spreads",
            "direct light and",
            "area lights and emissive",
        ] {
            assert!(
                caveats.iter().any(|n| n.starts_with(start)),
                "{start}: {caveats:?}"
            );
        }
        let flip = c["flip"].as_f64().expect("flip");
        assert!(flip > 0.0 && flip < 1.0, "{flip}");
        let ratio = c["luminance_ratio"].as_f64().expect("luminance_ratio");
        assert!(ratio.is_finite() && ratio > 0.0, "{ratio}");
        let passes = c["passes"].as_array().expect("passes");
        assert!(passes.iter().any(|p| p["name"] == "tonemap"), "{passes:?}");
        assert!(passes
            .iter()
            .all(|p| p["timer"].as_str().is_some_and(|t| !t.is_empty())));
    }
    assert_eq!(configurations[0]["name"], "forward");
    let markdown = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(markdown.contains("| forward | "), "{markdown}");
    assert!(
        stdout.contains("Caveats: where a configuration differs from the reference by design")
            && markdown.contains(". bloom spreads bright pixels"),
        "{stdout}"
    );

    // The same inputs again: the reference comes from the cache, bit for bit.
    let again = compare(&out, &cache);
    assert!(again.status.success());
    let second = report(&out);
    assert_eq!(second["reference"]["cached"], true);
    assert_eq!(
        second["configurations"][0]["rmse"],
        first["configurations"][0]["rmse"]
    );
    assert_eq!(
        second["reference"]["image"].as_str(),
        Some(out.join("reference.exr").to_string_lossy().as_ref()),
        "the report links to an EXR in the output folder"
    );
    // A damaged entry is rendered again, with a warning.
    let entries: Vec<PathBuf> = std::fs::read_dir(cache.join("references"))
        .expect("the reference cache")
        .map(|e| e.expect("entry").path())
        .collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    let mut bytes = std::fs::read(&entries[0]).expect("entry");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&entries[0], &bytes).expect("damage the entry");
    let third = compare(&out, &cache);
    assert!(third.status.success());
    assert!(
        String::from_utf8_lossy(&third.stderr)
            .contains("is damaged (its checksum does not match its payload); rendered again"),
        "{}",
        String::from_utf8_lossy(&third.stderr)
    );
    assert_eq!(report(&out)["reference"]["cached"], false);
}

#[test]
fn a_reference_image_of_the_wrong_size_or_kind_is_an_error() {
    let cache = temp("bad-cache");
    let out = temp("bad");
    let wrong = out.join("small.exr");
    image_of_size(&wrong, 8, 8);
    let run = |reference: &Path| {
        weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                "graphs/forward.ron",
                "--size",
                "48x32",
                "--reference-image",
                &reference.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        )
    };
    let result = run(&wrong);
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("is 8x8, but --size asks for 48x32 (images are not resampled)"),
        "{stderr}"
    );
    let junk = out.join("junk.exr");
    std::fs::write(&junk, b"not an image").expect("write");
    let result = run(&junk);
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("junk.exr: not a readable RGB(A) EXR"),
        "{stderr}"
    );
    let fifo = out.join("fifo.exr");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    let result = run(&fifo);
    assert!(!result.status.success(), "a FIFO is refused, not waited on");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("fifo.exr: it is a FIFO, not a regular file"),
        "{stderr}"
    );
}

#[test]
fn a_reference_image_with_non_finite_or_negative_pixels_is_refused() {
    let cache = temp("nan-cache");
    let out = temp("nan");
    for (name, value) in [
        ("nan", f32::NAN),
        ("inf", f32::INFINITY),
        ("negative", -1e30),
    ] {
        let path = out.join(format!("{name}.exr"));
        let mut pixels = vec![[0.5f32, 0.5, 0.5]; 48 * 32];
        pixels[3 * 48 + 5] = [0.5, value, 0.5];
        pixels[10 * 48 + 7] = [value, 0.5, 0.5];
        let image = weft_compare::LinearImage {
            width: 48,
            height: 32,
            pixels,
        };
        image.write_exr(&path).expect("write");
        let result = weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                "graphs/forward.ron",
                "--size",
                "48x32",
                "--reference-image",
                &path.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert_eq!(result.status.code(), Some(1), "{name}");
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(
            stderr.contains(&format!(
                "{name}.exr: 2 pixel(s) are not finite, non-negative radiance; the first is at (5, 3)"
            )),
            "{name}: {stderr}"
        );
    }
}

/// Timings come with their spread: configurations take turns over
/// `--rounds`, every measured frame of every round counts (2 rounds × 2
/// frames = 4 samples a configuration and a pass), the report gives medians
/// and interquartile ranges, and `--budget-ms` names the most accurate
/// configuration within the budget, or says none is.
#[test]
fn timings_carry_their_spread_and_a_budget_picks_a_configuration() {
    let cache = temp("rounds-cache");
    let out = temp("rounds");
    let reference = out.join("reference-given.exr");
    let render = weft(
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "48x32",
            "--out",
            &reference.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        render.status.success(),
        "{}",
        String::from_utf8_lossy(&render.stderr)
    );
    let run = |budget: &str| {
        let result = weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                "graphs/forward.ron,graphs/deferred.ron",
                "--size",
                "48x32",
                "--frames",
                "2",
                "--rounds",
                "2",
                "--budget-ms",
                budget,
                "--reference-image",
                &reference.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert!(
            result.status.success(),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
        std::fs::read_to_string(out.join("report.md")).expect("report.md")
    };
    let markdown = run("1e9");
    let json = report(&out);
    assert_eq!(json["rounds"], 2);
    let configurations = json["configurations"].as_array().expect("configurations");
    for c in configurations {
        let spread = &c["frame_spread"];
        assert_eq!(spread["samples"], 4, "{c}");
        let q = |k: &str| spread[k].as_f64().expect("number");
        assert!(
            q("min") <= q("p25") && q("p25") <= q("median") && q("median") <= q("p75"),
            "{spread}"
        );
        assert_eq!(c["frame_ms"], spread["median"]);
        for pass in c["passes"].as_array().expect("passes") {
            assert_eq!(pass["spread"]["samples"], 4, "{pass}");
        }
    }
    // Forward against its own render is exact, so it is the most accurate.
    assert_eq!(configurations[0]["flip"], 0.0);
    assert!(
        markdown.contains(
            "Within 1000000000 ms a frame: **forward**, the most accurate (HDR-FLIP 0.0000)"
        ),
        "{markdown}"
    );
    assert!(
        markdown.contains("2 round(s), the configurations taking turns"),
        "{markdown}"
    );
    assert!(markdown.contains("Frame times: "), "{markdown}");
    let markdown = run("0.000001");
    assert!(
        markdown.contains("No configuration's median frame time is within 0.000001 ms."),
        "{markdown}"
    );
}

/// One definition of transient memory: what compare reports for a graph is
/// what `weft graph plan --on-device` prints for the same graph, scene and
/// size (the plan as the graph runs, sized by the device), not the plan
/// compare measures with, which keeps the image it reads back whole.
#[test]
fn compare_reports_the_transient_memory_graph_plan_prints_on_the_device() {
    let cache = temp("memory-cache");
    let out = temp("memory");
    let reference = out.join("given.exr");
    let render = weft(
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "96x54",
            "--out",
            &reference.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        render.status.success(),
        "{}",
        String::from_utf8_lossy(&render.stderr)
    );
    for graph in ["forward", "deferred"] {
        let file = format!("graphs/{graph}.ron");
        let run = weft(
            &[
                "compare",
                "scenes/demo.scene",
                "--graphs",
                &file,
                "--size",
                "96x54",
                "--frames",
                "1",
                "--rounds",
                "1",
                "--reference-image",
                &reference.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let reported = report(&out)["configurations"][0]["transient_bytes"].clone();
        let plan = weft(
            &[
                "graph",
                "plan",
                &file,
                "--scene",
                "scenes/demo.scene",
                "--size",
                "96x54",
                "--on-device",
                "--json",
            ],
            &cache,
        );
        assert!(
            plan.status.success(),
            "{}",
            String::from_utf8_lossy(&plan.stderr)
        );
        assert!(String::from_utf8_lossy(&plan.stderr).contains("memory: sized for "));
        let plan: serde_json::Value = serde_json::from_slice(&plan.stdout).expect("JSON");
        assert_eq!(reported, plan["stats"]["transient_bytes"], "{graph}");
        assert!(
            reported.as_u64().is_some_and(|b| b > 0),
            "{graph}: {reported}"
        );
    }
}

/// `--noise-floor` renders the reference again with the next seed and
/// reports the HDR-FLIP between the two renders, which the test recomputes
/// from the two EXRs written.
#[test]
fn the_noise_floor_is_the_flip_between_two_seeds_of_the_reference() {
    let cache = temp("floor-cache");
    let out = temp("floor");
    let run = weft(
        &[
            "compare",
            "scenes/demo.scene",
            "--graphs",
            "graphs/forward.ron",
            "--size",
            "48x32",
            "--spp",
            "4",
            "--seed",
            "5",
            "--frames",
            "1",
            "--rounds",
            "1",
            "--noise-floor",
            "--out",
            &out.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let floor = report(&out)["reference"]["noise_floor"].clone();
    assert_eq!(floor["seed"], 6, "{floor}");
    let read = |name: &str| weft_compare::LinearImage::read_exr(&out.join(name)).expect(name);
    let expected =
        weft_compare::hdr_flip(&read("reference.exr"), &read("reference-seed6.exr")).mean;
    assert!(expected > 0.0);
    assert_eq!(floor["flip"].as_f64(), Some(expected));
    let markdown = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    assert!(
        markdown.contains(&format!("Reference noise floor: HDR-FLIP {expected:.4} between this reference and the same render with seed 6")),
        "{markdown}"
    );
}

/// Every configuration frame shows the scene at the reference's time: on a
/// scene whose lights move, forward's own render at time 0 as the reference
/// scores exactly 0 however many frames are timed (the frames used to move
/// on by 1/60 s each, and scored 0.0014 to 0.0035 against themselves).
#[test]
fn a_graph_against_its_own_render_of_the_same_scene_state_scores_zero() {
    let cache = temp("self-cache");
    let out = temp("self");
    let reference = out.join("forward.exr");
    let render = weft(
        &[
            "render",
            "scenes/animation.scene",
            "--size",
            "48x32",
            "--out",
            &reference.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        render.status.success(),
        "{}",
        String::from_utf8_lossy(&render.stderr)
    );
    for frames in ["1", "6"] {
        let run = weft(
            &[
                "compare",
                "scenes/animation.scene",
                "--graphs",
                "graphs/forward.ron",
                "--size",
                "48x32",
                "--frames",
                frames,
                "--reference-image",
                &reference.to_string_lossy(),
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let configuration = &report(&out)["configurations"][0];
        assert_eq!(
            configuration["flip"], 0.0,
            "{frames} frames: {configuration}"
        );
        assert_eq!(
            configuration["rmse"], 0.0,
            "{frames} frames: {configuration}"
        );
    }
}

/// Writes a black RGBA EXR of `width` x `height` with weft itself (a render
/// of the demo scene at that size).
fn image_of_size(path: &Path, width: u32, height: u32) {
    let out = weft(
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            &format!("{width}x{height}"),
            "--out",
            &path.to_string_lossy(),
        ],
        &temp("render-cache"),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Bloom, which the reference does not model, is not error by default: the
/// LDR measures of forward with bloom equal those of forward without it (its
/// HDR image, before bloom, goes through the reference's tonemap), and with
/// `--post` they measure the bloomed output and differ. report.md says which.
#[test]
fn post_effects_count_as_error_only_when_asked() {
    let cache = temp("post-cache");
    let measure = |features: &str, post: bool| {
        let out = temp(&format!("post-{}-{post}", features.replace('!', "no-")));
        let mut args = vec![
            "compare",
            "scenes/demo.scene",
            "--graphs",
            "graphs/forward.ron",
            "--features",
            features,
            "--size",
            "48x32",
            "--spp",
            "4",
            "--frames",
            "1",
            "--rounds",
            "1",
        ];
        if post {
            args.push("--post");
        }
        let out_arg = out.to_string_lossy().into_owned();
        args.extend(["--out", &out_arg]);
        let run = weft(&args, &cache);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let markdown = std::fs::read_to_string(out.join("report.md")).expect("report.md");
        let said = if post {
            "post effects such as bloom included (`--post`)"
        } else {
            "post effects the reference does not model (bloom) are not counted as error"
        };
        assert!(markdown.contains(said), "{markdown}");
        let c = report(&out)["configurations"][0].clone();
        (
            c["flip_ldr"].as_f64().expect("flip_ldr"),
            c["psnr"].as_f64().expect("psnr"),
        )
    };
    let bloom = measure("bloom", false);
    let no_bloom = measure("!bloom", false);
    assert_eq!(bloom, no_bloom);
    let bloom_post = measure("bloom", true);
    assert_ne!(bloom_post, bloom);
    // Without bloom the graph's output is its HDR image through the same
    // tonemap (on the GPU, to 8 bits), so the two ways agree closely.
    let (flip, psnr) = measure("!bloom", true);
    assert!(
        (flip - no_bloom.0).abs() < 2e-3 && (psnr - no_bloom.1).abs() < 0.5,
        "{flip} {psnr} against {no_bloom:?}"
    );
}

/// Every point's parameters and features are checked before the reference
/// renders: a value out of its declared range in the last point, or a
/// misspelt parameter, fails at once with the file and line, and nothing is
/// rendered (no reference in the output folder, nothing cached).
#[test]
fn a_sweep_checks_every_point_before_it_renders_the_reference() {
    let cache = temp("sweep-check-cache");
    let out = temp("sweep-check");
    for (param, expected) in [
        (
            "area_samples=4,65",
            "parameter \"area_samples\" set to 65: it must be at most 64",
        ),
        ("area_sample=4,8", "unknown parameter \"area_sample\""),
    ] {
        let run = weft(
            &[
                "sweep",
                "scenes/demo.scene",
                "--graph",
                "graphs/forward.ron",
                "--param",
                param,
                "--size",
                "48x32",
                "--spp",
                "4",
                "--out",
                &out.to_string_lossy(),
            ],
            &cache,
        );
        assert!(!run.status.success(), "{param}");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            stderr.contains(expected) && stderr.contains("forward.ron:"),
            "{param}: {stderr}"
        );
        assert!(!out.join("reference.exr").exists(), "{param}: rendered");
    }
}

/// A sweep split into 3 shards run as 3 processes at once, sharing one
/// cache folder (the reference rendered by whichever gets there, written
/// atomically), then merged, has the unsharded sweep's rows in its order,
/// with the same figures but frame time (which is measured again).
#[test]
fn three_shards_run_at_once_and_merged_equal_the_whole_sweep() {
    let cache = temp("shard-cache");
    let root = temp("shards");
    let sweep_args = |out: &Path, shard: Option<&str>| {
        let mut args: Vec<String> = [
            "sweep",
            "scenes/demo.scene",
            "--graph",
            "graphs/forward.ron",
            "--param",
            "shadows.pcf_radius=0,2",
            "--features-set",
            "bloom;!bloom",
            "--size",
            "48x32",
            "--spp",
            "4",
            "--frames",
            "1",
            "--out",
        ]
        .map(String::from)
        .to_vec();
        args.push(out.to_string_lossy().into_owned());
        if let Some(shard) = shard {
            args.extend(["--shard".to_string(), shard.to_string()]);
        }
        args
    };
    let shards: Vec<PathBuf> = (1..=3).map(|k| root.join(format!("shard{k}"))).collect();
    let running: Vec<_> = shards
        .iter()
        .enumerate()
        .map(|(i, dir)| {
            let args = sweep_args(dir, Some(&format!("{}/3", i + 1)));
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            command_in(&repo(), &args)
                .env("WEFT_CACHE_DIR", &cache)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("weft starts")
        })
        .collect();
    for child in running {
        let done = child.wait_with_output().expect("weft runs");
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
    }
    let whole = root.join("whole");
    let args = sweep_args(&whole, None);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let run = weft(&args, &cache);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let merged = root.join("merged");
    let mut merge: Vec<String> = vec!["sweep".into(), "merge".into()];
    merge.extend(
        shards
            .iter()
            .rev()
            .map(|d| d.to_string_lossy().into_owned()),
    );
    merge.extend(["--out".to_string(), merged.to_string_lossy().into_owned()]);
    let merge: Vec<&str> = merge.iter().map(String::as_str).collect();
    let run = weft(&merge, &cache);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(stdout.starts_with("4 points from 3 shards"), "{stdout}");
    assert!(merged.join("pareto.png").is_file() && merged.join("sweep.md").is_file());
    // Every column but the frame times (frame_ms, frame_p25, frame_p75).
    let rows = |dir: &Path| -> Vec<Vec<String>> {
        let csv = std::fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
        csv.lines()
            .map(|l| {
                let fields: Vec<&str> = l.split(',').collect();
                let n = fields.len();
                fields
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| ![n - 4, n - 2, n - 1].contains(i))
                    .map(|(_, f)| f.to_string())
                    .collect()
            })
            .collect()
    };
    assert_eq!(rows(&merged), rows(&whole));
    assert_eq!(
        std::fs::read_to_string(merged.join("sweep.settings")).expect("settings"),
        std::fs::read_to_string(whole.join("sweep.settings")).expect("settings")
    );
    // Two shards of three are not a whole sweep.
    let partial = weft(
        &[
            "sweep",
            "merge",
            &shards[0].to_string_lossy(),
            &shards[2].to_string_lossy(),
            "--out",
            &root.join("partial").to_string_lossy(),
        ],
        &cache,
    );
    assert!(!partial.status.success());
    let stderr = String::from_utf8_lossy(&partial.stderr);
    assert!(stderr.contains("missing: 2/3"), "{stderr}");
}

#[test]
fn a_sweep_writes_its_csv_plot_and_frontier_and_resumes() {
    let cache = temp("sweep-cache");
    let out = temp("sweep");
    let out_arg = out.to_string_lossy().into_owned();
    let sweep = |spp: &str| {
        weft(
            &[
                "sweep",
                "scenes/demo.scene",
                "--graph",
                "graphs/forward.ron",
                "--param",
                "shadows.pcf_radius=0,2",
                "--features-set",
                "bloom;!bloom",
                "--size",
                "48x32",
                "--spp",
                spp,
                "--frames",
                "1",
                "--budget-ms",
                "1000000",
                "--validate",
                "--out",
                &out_arg,
            ],
            &cache,
        )
    };
    let first = sweep("4");
    let stdout = String::from_utf8_lossy(&first.stdout);
    assert!(
        first.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert!(stdout.starts_with("4 points, 0 already in"), "{stdout}");
    assert!(
        stdout.contains("validation: 0 errors, 0 warnings"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("sweep.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "shadows.pcf_radius,features,flip,rmse,frame_ms,device_bytes,frame_p25,frame_p75"
    );
    assert_eq!(lines.len(), 5, "{csv}");
    assert!(lines[1].starts_with("0,bloom,"), "{csv}");
    assert!(lines[4].starts_with("2,!bloom,"), "{csv}");
    assert!(out.join("pareto.png").is_file());
    let table = std::fs::read_to_string(out.join("sweep.md")).expect("sweep.md");
    assert!(
        table.contains("Pareto frontier of HDR-FLIP against frame time"),
        "{table}"
    );
    // The budget names the most accurate point within it: the frontier's last.
    let within = table
        .lines()
        .find(|l| l.starts_with("Within 1000000 ms a frame: **"))
        .expect("a budget verdict");
    let frontier_settings: Vec<&str> = table
        .lines()
        .filter(|l| {
            l.split('|')
                .nth(1)
                .is_some_and(|n| n.trim().parse::<u32>().is_ok())
        })
        .filter_map(|l| l.split('|').nth(2).map(str::trim))
        .collect();
    let most_accurate = frontier_settings.last().expect("a frontier");
    assert!(
        within.contains(&format!("**{most_accurate}**")),
        "{within}\n{table}"
    );
    // Every point is in a table, on the frontier (numbered) or off it (lettered).
    let listed = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| #") && !l.starts_with("| mark"))
        .count();
    assert_eq!(listed, 4, "{table}");

    // Run again: nothing left to measure, the CSV unchanged.
    let again = sweep("4");
    let stdout = String::from_utf8_lossy(&again.stdout);
    assert!(again.status.success());
    assert!(stdout.starts_with("4 points, 4 already in"), "{stdout}");
    assert_eq!(
        std::fs::read_to_string(out.join("sweep.csv")).expect("csv"),
        csv
    );

    // A sweep.csv from before the frame-time range was recorded resumes: it
    // is rewritten in the current form, each row's range its median.
    let old_form: String = csv
        .lines()
        .map(|l| l.rsplitn(3, ',').nth(2).unwrap_or_default().to_string() + "\n")
        .collect();
    assert!(old_form.starts_with("shadows.pcf_radius,features,flip,rmse,frame_ms,device_bytes\n"));
    std::fs::write(out.join("sweep.csv"), &old_form).expect("old form");
    let resumed = sweep("4");
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let rewritten = std::fs::read_to_string(out.join("sweep.csv")).expect("csv");
    for (new, old) in rewritten.lines().zip(old_form.lines()).skip(1) {
        let median = old.split(',').nth(4).expect("frame_ms");
        assert_eq!(new, format!("{old},{median},{median}"));
    }

    // Other settings in the same folder are refused, not mixed in.
    let other = sweep("8");
    assert!(!other.status.success());
    let stderr = String::from_utf8_lossy(&other.stderr);
    assert!(
        stderr.contains("holds points measured with other settings"),
        "{stderr}"
    );
}
