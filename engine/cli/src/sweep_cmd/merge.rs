//! `weft sweep merge`: the shard folders of one sweep joined into one, every
//! row checked against the sweep's grid and its shard before it is taken.

use super::folder::{
    grid_line, lock_folder, read_noise_floor, write_noise_floor, GRID_LINE, SHARD_LINE,
};
use super::report::write_report;
use super::{parse_shard, MergeArgs, Shard};
use anyhow::{bail, Context, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_compare::sweep::{
    check_rows, document, grid_document, read_grid, read_named, SweepPoint, SweepRow, GRID_FILE,
};

/// One shard folder of a sharded sweep: its settings (less the shard and
/// grid lines), which shard it is, its grid line and its rows.
struct ShardFolder {
    dir: PathBuf,
    settings: String,
    shard: Shard,
    grid: String,
    names: Vec<String>,
    rows: Vec<SweepRow>,
}

/// Reads a shard's `sweep.settings` and `sweep.csv`.
fn read_shard(dir: &Path) -> Result<ShardFolder> {
    let path = dir.join("sweep.settings");
    let text = weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut settings = String::new();
    let (mut shard, mut grid) = (None, None);
    for line in text.lines() {
        if let Some(k_of_n) = line.strip_prefix(SHARD_LINE) {
            shard = Some(parse_shard(k_of_n).map_err(anyhow::Error::msg)?);
        } else if line.starts_with(GRID_LINE) {
            grid = Some(line.to_string());
        } else {
            settings += &format!("{line}\n");
        }
    }
    let shard = shard.with_context(|| {
        format!(
            "{} is not a shard's: it names no `shard K/N`",
            path.display()
        )
    })?;
    let grid = grid.with_context(|| {
        format!(
            "{} names no `grid`: the shard was measured by an older weft; measure it again",
            path.display()
        )
    })?;
    let (names, rows) = read_named(&dir.join("sweep.csv"))?;
    Ok(ShardFolder {
        dir: dir.to_path_buf(),
        settings,
        shard,
        grid,
        names,
        rows,
    })
}

/// The sweep's grid as the shard `first` recorded it, checked against the
/// fingerprint its settings hold.
fn shard_grid(first: &ShardFolder) -> Result<Vec<SweepPoint>> {
    let path = first.dir.join(GRID_FILE);
    let grid = read_grid(&path, &first.names)?;
    // The fingerprint of the grid as read, in the form the sweep wrote it.
    if grid_line(&grid_document(&first.names, &grid), grid.len()) != first.grid {
        bail!(
            "{} does not match the `{}` its sweep.settings names: the file was changed after the shard measured it",
            path.display(),
            first.grid
        );
    }
    Ok(grid)
}

/// Whether `a` and `b` are one folder.
fn same_folder(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Runs `weft sweep merge`: every shard of one sweep, with the same
/// settings and grid, each row a point of the grid its shard measures,
/// joined in the order the unsharded sweep measures its points.
pub(super) fn merge_shards(args: &MergeArgs) -> Result<ExitCode> {
    if let Some(shard) = args.shards.iter().find(|s| same_folder(s, &args.out)) {
        bail!(
            "--out {} is the shard folder {}: the merge would overwrite the shard it reads; use another --out",
            args.out.display(),
            shard.display()
        );
    }
    let mut shards = args
        .shards
        .iter()
        .map(|dir| read_shard(dir))
        .collect::<Result<Vec<_>>>()?;
    shards.sort_by_key(|s| s.shard.k);
    let first = &shards[0];
    let n = first.shard.n;
    for s in &shards {
        if s.settings != first.settings
            || s.names != first.names
            || s.shard.n != n
            || s.grid != first.grid
        {
            bail!(
                "{} was measured with other settings than shard {}/{n}; only shards of one sweep merge",
                s.dir.display(),
                first.shard.k
            );
        }
    }
    let found: Vec<usize> = shards.iter().map(|s| s.shard.k).collect();
    let missing: Vec<String> = (1..=n)
        .filter(|k| !found.contains(k))
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() || found.len() != n {
        bail!(
            "the shards given are {:?} of {n}; missing: {}",
            found,
            if missing.is_empty() {
                "none, but one is given twice".to_string()
            } else {
                missing.join(", ")
            }
        );
    }
    let grid = shard_grid(first)?;
    for s in &shards {
        let owned = |i: usize| s.shard.takes(i);
        check_rows(&s.dir.join("sweep.csv"), &s.rows, Some((&grid, &owned)))?;
    }
    // In the unsharded sweep's order: the grid's.
    let at: HashMap<&SweepPoint, usize> = grid.iter().enumerate().map(|(i, p)| (p, i)).collect();
    let mut rows: Vec<&SweepRow> = shards.iter().flat_map(|s| &s.rows).collect();
    rows.sort_by_key(|r| at.get(&r.point).copied().unwrap_or(usize::MAX));
    let _lock = lock_folder(&args.out)?;
    weft_io::write_output(
        &args.out.join("sweep.csv"),
        document(&first.names, rows.iter().copied()).as_bytes(),
    )?;
    weft_io::write_output(&args.out.join("sweep.settings"), first.settings.as_bytes())?;
    let field = |name: &str| {
        first
            .settings
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .unwrap_or_default()
            .to_string()
    };
    println!(
        "{} points from {n} shards ({} in the grid)",
        rows.len(),
        grid.len()
    );
    let noise_floor = read_noise_floor(&first.dir)?;
    if let Some(floor) = noise_floor {
        write_noise_floor(&args.out, floor)?;
    }
    write_report(
        &args.out,
        (&field("scene "), &field("graph ")),
        &rows,
        (args.budget_ms, noise_floor),
    )?;
    Ok(ExitCode::SUCCESS)
}
