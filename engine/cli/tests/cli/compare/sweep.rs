//! `weft sweep`: its CSV, plot and frontier, resuming, every point checked
//! before work, and shards merged.

use super::{temp, weft, weft_ok, SMALL};
use crate::harness::{command_in, repo};
use std::path::{Path, PathBuf};

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

    // Points measured from other sources (a graph, shader or scene file
    // edited since: its fingerprint in sweep.settings differs) are refused.
    let settings = std::fs::read_to_string(out.join("sweep.settings")).expect("settings");
    let recorded = settings
        .lines()
        .find_map(|l| l.strip_prefix("sources "))
        .expect("a sources line")
        .to_string();
    assert!(recorded.ends_with(" files)"), "{recorded}");
    let edited = settings.replace(&recorded, "0123 (1 files)");
    std::fs::write(out.join("sweep.settings"), edited).expect("settings");
    let stale = sweep("4");
    assert!(!stale.status.success());
    let stderr = String::from_utf8_lossy(&stale.stderr);
    assert!(
        stderr.contains(&format!(
            "holds points measured from other sources: a graph, shader or scene file has changed since (sources 0123 (1 files), now {recorded})"
        )),
        "{stderr}"
    );
    std::fs::write(out.join("sweep.settings"), &settings).expect("settings");

    // Other settings in the same folder are refused, not mixed in.
    let other = sweep("8");
    assert!(!other.status.success());
    let stderr = String::from_utf8_lossy(&other.stderr);
    assert!(
        stderr.contains("holds points measured with other settings"),
        "{stderr}"
    );
}

/// `--graphs` sweeps graphs as one more dimension against one reference:
/// sweep.csv names each point's graph first, and each graph's rows equal a
/// sweep of that graph alone (same figures but frame time), so the graph
/// column really chose the graph.
#[test]
fn a_sweep_over_graphs_measures_each_graph_as_its_own_sweep_does() {
    let cache = temp("sweep-graphs-cache");
    let root = temp("sweep-graphs");
    let sweep = |graphs: (&str, &str), out: &str, noise_floor: bool| {
        let out = root.join(out);
        let out_arg = out.to_string_lossy().into_owned();
        let flag = if noise_floor {
            "--noise-floor"
        } else {
            "--validate"
        };
        let mut args = vec!["sweep", "scenes/demo.scene", graphs.0, graphs.1, flag];
        args.extend(["--param", "shadows.pcf_radius=0,2"]);
        args.extend(SMALL);
        args.extend(["--out", out_arg.as_str()]);
        weft_ok(&args, &cache);
        std::fs::read_to_string(out.join("sweep.csv")).expect("sweep.csv")
    };
    // The figures a row holds besides frame time: flip, rmse, device bytes.
    let figures = |line: &str| -> Vec<String> {
        let fields: Vec<&str> = line.split(',').collect();
        let n = fields.len();
        vec![
            fields[n - 6].into(),
            fields[n - 5].into(),
            fields[n - 3].into(),
        ]
    };
    let both = sweep(
        ("--graphs", "graphs/forward.ron,graphs/deferred.ron"),
        "both",
        true,
    );
    let lines: Vec<&str> = both.lines().collect();
    assert_eq!(
        lines[0],
        "graph,shadows.pcf_radius,features,flip,rmse,frame_ms,device_bytes,frame_p25,frame_p75"
    );
    let starts: Vec<String> = lines[1..]
        .iter()
        .map(|l| l.splitn(3, ',').take(2).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(
        starts,
        [
            "graphs/forward.ron,0",
            "graphs/forward.ron,2",
            "graphs/deferred.ron,0",
            "graphs/deferred.ron,2"
        ]
    );
    for (k, graph) in ["forward", "deferred"].into_iter().enumerate() {
        let alone = sweep(("--graph", &format!("graphs/{graph}.ron")), graph, false);
        let alone: Vec<Vec<String>> = alone.lines().skip(1).map(figures).collect();
        let within: Vec<Vec<String>> = lines[1 + 2 * k..3 + 2 * k]
            .iter()
            .map(|l| figures(l))
            .collect();
        assert_eq!(within, alone, "{graph}\n{both}");
    }
    let table = std::fs::read_to_string(root.join("both/sweep.md")).expect("sweep.md");
    assert!(
        table.contains("| forward shadows.pcf_radius=0 |")
            || table.contains("| forward shadows.pcf_radius=2 |"),
        "{table}"
    );
    // --noise-floor: the floor is kept beside the CSV and sweep.md says
    // which points lie within it of the most accurate (that one at least).
    let floor = std::fs::read_to_string(root.join("both/noise_floor")).expect("noise_floor");
    let (seed, flip) = floor.trim().split_once(' ').expect("SEED FLIP");
    assert_eq!(seed, "1");
    let flip: f64 = flip.parse().expect("a number");
    assert!(flip > 0.0 && flip < 1.0, "{floor}");
    let note = table
        .lines()
        .find(|l| l.starts_with("Reference noise floor: HDR-FLIP "))
        .expect("the noise floor in sweep.md");
    assert!(
        note.contains(&format!(
            "{flip:.4} between the reference and its render with seed 1"
        )),
        "{note}"
    );
    // The most accurate point is the frontier's last, and lies within.
    let last = table
        .lines()
        .filter_map(|l| l.split('|').nth(1)?.trim().parse::<u32>().ok())
        .max()
        .expect("a frontier");
    assert!(note.contains(&format!("#{last}")), "{note}\n{table}");
}

/// Graphs with different parameters share one sweep: each is swept over
/// the parameters it has (forward once, the denoised path tracer at each
/// `samples_per_frame`), its cells for the others left empty; a parameter
/// no swept graph has is an error naming each graph's.
#[test]
fn a_sweep_over_graphs_sweeps_each_over_the_parameters_it_has() {
    let cache = temp("sweep-graph-params-cache");
    let out = temp("sweep-graph-params");
    let out_arg = out.to_string_lossy().into_owned();
    let graphs = "graphs/forward.ron,graphs/pathtrace_denoised.ron";
    let mut args = vec!["sweep", "scenes/cornell.scene", "--graphs", graphs];
    args.extend(["--param", "samples_per_frame=1,2", "--validate"]);
    args.extend(SMALL);
    args.extend(["--out", out_arg.as_str()]);
    weft_ok(&args, &cache);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).expect("sweep.csv");
    let starts: Vec<String> = csv
        .lines()
        .skip(1)
        .map(|l| l.splitn(3, ',').take(2).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(
        starts,
        [
            "graphs/forward.ron,",
            "graphs/pathtrace_denoised.ron,1",
            "graphs/pathtrace_denoised.ron,2"
        ],
        "{csv}"
    );
    // Run again: every point is found in sweep.csv, empty cells included.
    let again = weft_ok(&args, &cache);
    assert!(
        String::from_utf8_lossy(&again.stdout).contains("3 points, 3 already in"),
        "{}",
        String::from_utf8_lossy(&again.stdout)
    );
    let mut wrong = vec!["sweep", "scenes/cornell.scene", "--graphs", graphs];
    wrong.extend(["--param", "max_dpeth=1,2"]);
    wrong.extend(SMALL);
    wrong.extend(["--out", out_arg.as_str()]);
    let run = weft(&wrong, &cache);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("--param max_dpeth: none of the swept graphs has this parameter")
            && stderr.contains("graphs/pathtrace_denoised.ron: ")
            && stderr.contains(" max_depth "),
        "{stderr}"
    );
    // A feature set is swept on the graphs that know its toggles (forward
    // has no `denoise`); a toggle no graph knows is refused before rendering.
    let mut unknown = vec!["sweep", "scenes/cornell.scene", "--graphs", graphs];
    unknown.extend(["--features-set", ";!denoise;!denoize"]);
    unknown.extend(SMALL);
    unknown.extend(["--out", out_arg.as_str()]);
    let run = weft(&unknown, &cache);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("--features-set: none of the swept graphs has the feature in `!denoize` (graphs/forward.ron, graphs/pathtrace_denoised.ron)"),
        "{stderr}"
    );
}
