//! A sweep's folder under hostile use (issue 60): a second sweep into a
//! folder one is writing, rows damaged or duplicated between runs, merges
//! given rows outside the grid or told to write over a shard, and a sweep
//! whose every point matches the reference exactly.

use super::temp;
use crate::harness::{command_in, finish_within, repo};
use std::path::Path;
use std::process::Output;

/// `weft ARGS` with its user cache in `cache`, failed if it runs past 5 min.
fn weft(args: &[&str], cache: &Path) -> Output {
    finish_within(command_in(&repo(), args).env("WEFT_CACHE_DIR", cache), 300)
}

/// [`weft`], which must succeed.
fn weft_ok(args: &[&str], cache: &Path) -> Output {
    let run = weft(args, cache);
    assert!(run.status.success(), "{}", stderr(&run));
    run
}

/// A two-point sweep of forward's `exposure` (which the HDR image the
/// reference is compared with does not see) at 16x16 into `out`, as shard
/// `shard` when given, against `reference` when given.
fn sweep(
    out: &Path,
    cache: &Path,
    shard: Option<&str>,
    reference: Option<&Path>,
) -> std::process::Output {
    sweep_over("exposure=1,2", out, cache, shard, reference)
}

/// [`sweep`] over the `--param` values `values`.
fn sweep_over(
    values: &str,
    out: &Path,
    cache: &Path,
    shard: Option<&str>,
    reference: Option<&Path>,
) -> std::process::Output {
    let mut args: Vec<String> = [
        "sweep",
        "scenes/cornell.scene",
        "--graph",
        "graphs/forward.ron",
        "--param",
        values,
        "--size",
        "16x16",
        "--spp",
        "2",
        "--frames",
        "1",
        "--out",
    ]
    .map(String::from)
    .to_vec();
    args.push(out.to_string_lossy().into_owned());
    if let Some(shard) = shard {
        args.extend(["--shard".into(), shard.into()]);
    }
    if let Some(reference) = reference {
        args.extend([
            "--reference-image".into(),
            reference.to_string_lossy().into_owned(),
        ]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    weft(&args, cache)
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// While one sweep holds its folder, a second into it fails at once, naming
/// the folder, and appends nothing.
#[test]
fn a_second_sweep_into_a_folder_being_written_fails_at_once() {
    let cache = temp("lock-cache");
    let out = temp("lock");
    std::fs::create_dir_all(&out).expect("dir");
    let held = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(out.join("sweep.lock"))
        .expect("lock file");
    held.lock().expect("the test holds the folder");
    let run = sweep(&out, &cache, None, None);
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains(&format!(
            "{} is being written by another weft sweep or merge; wait for it to end, or use another --out",
            out.display()
        )),
        "{}",
        stderr(&run)
    );
    assert!(!out.join("sweep.csv").exists(), "nothing written");
    drop(held);
    // Released, the folder takes the sweep.
    let run = sweep(&out, &cache, None, None);
    assert!(run.status.success(), "{}", stderr(&run));
}

/// A resumed sweep refuses a point measured twice and a row whose numbers
/// are not finite, each at its line; a merge refuses a row outside the grid
/// or of another shard, and an --out that is one of its shards; a sweep
/// whose points all match the reference writes its table without a plot.
#[test]
fn rows_are_checked_on_resume_and_merge_and_exact_sweeps_get_their_table() {
    let cache = temp("rows-cache");
    let root = temp("rows");
    let (one, two) = (root.join("shard1"), root.join("shard2"));
    for (dir, shard) in [(&one, "1/2"), (&two, "2/2")] {
        let run = sweep(dir, &cache, Some(shard), None);
        assert!(run.status.success(), "{}", stderr(&run));
    }
    // The same shard with another grid is refused, and leaves the grid the
    // shard was measured with.
    let grid = std::fs::read(one.join("sweep.grid")).expect("grid");
    let other_grid = sweep_over("exposure=1,2,3", &one, &cache, Some("1/2"), None);
    assert!(
        stderr(&other_grid).contains("holds points measured with other settings"),
        "{}",
        stderr(&other_grid)
    );
    assert_eq!(std::fs::read(one.join("sweep.grid")).expect("grid"), grid);
    let csv = one.join("sweep.csv");
    let good = std::fs::read_to_string(&csv).expect("csv");
    let lines: Vec<&str> = good.lines().collect();
    assert_eq!(lines.len(), 2, "{good}");
    // Measured twice.
    std::fs::write(&csv, format!("{good}{}\n", lines[1])).expect("write");
    let run = sweep(&one, &cache, Some("1/2"), None);
    assert!(
        stderr(&run).contains(&format!(
            "{}:3: point \"exposure=1\" is measured twice (lines 2 and 3); remove one of them",
            csv.display()
        )),
        "{}",
        stderr(&run)
    );
    // NaN where HDR-FLIP goes.
    let fields: Vec<&str> = lines[1].split(',').collect();
    let nan = [&fields[..2], &["NaN"], &fields[3..]].concat().join(",");
    std::fs::write(&csv, format!("{}\n{nan}\n", lines[0])).expect("write");
    let run = sweep(&one, &cache, Some("1/2"), None);
    assert!(
        stderr(&run).contains(&format!(
            "{}:2: \"NaN\" is not a finite number of at least 0",
            csv.display()
        )),
        "{}",
        stderr(&run)
    );
    // A row outside the grid, given to merge.
    let outside = lines[1].replacen("1,", "7,", 1);
    std::fs::write(&csv, format!("{}\n{outside}\n", lines[0])).expect("write");
    let merged = root.join("merged");
    let run = weft(
        &[
            "sweep",
            "merge",
            &one.to_string_lossy(),
            &two.to_string_lossy(),
            "--out",
            &merged.to_string_lossy(),
        ],
        &cache,
    );
    assert_eq!(run.status.code(), Some(1));
    assert!(
        stderr(&run).contains(&format!(
            "{}:2: point \"exposure=7\" is not in this sweep's grid (sweep.grid)",
            csv.display()
        )),
        "{}",
        stderr(&run)
    );
    // Shard 2's point in shard 1's file.
    let other = std::fs::read_to_string(two.join("sweep.csv")).expect("csv");
    std::fs::write(
        &csv,
        format!("{}\n{}\n", lines[0], other.lines().nth(1).expect("row")),
    )
    .expect("write");
    let run = weft(
        &[
            "sweep",
            "merge",
            &one.to_string_lossy(),
            &two.to_string_lossy(),
            "--out",
            &merged.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        stderr(&run)
            .contains("point \"exposure=2\" (number 2 of the grid) belongs to another shard"),
        "{}",
        stderr(&run)
    );
    // --out naming a shard.
    std::fs::write(&csv, &good).expect("write");
    let run = weft(
        &[
            "sweep",
            "merge",
            &one.to_string_lossy(),
            &two.to_string_lossy(),
            "--out",
            &two.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        stderr(&run).contains("is the shard folder")
            && stderr(&run).contains("the merge would overwrite the shard it reads"),
        "{}",
        stderr(&run)
    );
    let run = weft_ok(
        &[
            "sweep",
            "merge",
            &one.to_string_lossy(),
            &two.to_string_lossy(),
            "--out",
            &merged.to_string_lossy(),
        ],
        &cache,
    );
    assert!(
        String::from_utf8_lossy(&run.stdout).starts_with("2 points from 2 shards (2 in the grid)")
    );
    // Every point exactly the reference: the reference is forward's own
    // HDR image, which exposure does not change.
    let reference = root.join("forward.exr");
    weft_ok(
        &[
            "render",
            "scenes/cornell.scene",
            "--size",
            "16x16",
            "--out",
            &reference.to_string_lossy(),
        ],
        &cache,
    );
    let exact = root.join("exact");
    let run = sweep(&exact, &cache, None, Some(&reference));
    assert!(run.status.success(), "{}", stderr(&run));
    let table = std::fs::read_to_string(exact.join("sweep.md")).expect("sweep.md");
    assert!(table.contains("| exposure=1 | 0.0000 |"), "{table}");
    assert!(
        table.contains("No `pareto.png`: no point has both an HDR-FLIP and a frame time above 0"),
        "{table}"
    );
    assert!(!exact.join("pareto.png").exists());
}
