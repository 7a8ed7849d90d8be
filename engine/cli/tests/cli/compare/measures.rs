//! What `weft compare` measures: one scene state, timings with their spread
//! and a budget, one definition of memory, the reference's noise floor and
//! post effects only when asked.

use super::{render_exr, report, temp, weft_ok};

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
    render_exr("scenes/demo.scene", "48x32", &reference, &cache);
    let run = |budget: &str| {
        weft_ok(
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
    render_exr("scenes/demo.scene", "96x54", &reference, &cache);
    for graph in ["forward", "deferred"] {
        let file = format!("graphs/{graph}.ron");
        weft_ok(
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
        let reported = report(&out)["configurations"][0]["transient_bytes"].clone();
        let plan = weft_ok(
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
    weft_ok(
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
    // The one configuration is the most accurate, and so within the floor.
    assert!(
        markdown.contains("so not ranked by accuracy: forward."),
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
    render_exr("scenes/animation.scene", "48x32", &reference, &cache);
    for frames in ["1", "6"] {
        weft_ok(
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
        weft_ok(&args, &cache);
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
