//! A sweep's folder: the settings every point shares (and the fingerprint
//! of the files they are rendered from), the grid, the reference's noise
//! floor, and the lock that keeps a second sweep or merge out while one
//! writes it.

use super::SweepRun;
use anyhow::{bail, Context, Result};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use weft_compare::sweep::{grid_document, SweepPoint, GRID_FILE};
use weft_render::RenderSettings;

/// The lock file a sweep or merge holds in its `--out` folder.
const LOCK_FILE: &str = "sweep.lock";

/// Holds `dir` (created if need be) for one sweep or merge until dropped:
/// a second one writing the same folder fails at once instead of
/// appending the same points again. The lock is the system's advisory
/// file lock, released when the process ends however it ends.
pub(super) fn lock_folder(dir: &Path) -> Result<std::fs::File> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join(LOCK_FILE);
    // A FIFO put there would block the open: refused, and opened without
    // waiting in case one appears in between.
    weft_io::check_output(&path)?;
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => bail!(
            "{} is being written by another weft sweep or merge; wait for it to end, or use another --out",
            dir.display()
        ),
        Err(std::fs::TryLockError::Error(e)) => {
            Err(e).with_context(|| format!("locking {}", path.display()))
        }
    }
}

/// The whole sweep's grid as `sweep.grid` holds it, and its `grid` line
/// for a shard's settings: the grid's fingerprint and size, so shards of
/// different grids never merge.
pub(super) fn grid(names: &[String], every: &[SweepPoint]) -> (String, String) {
    let text = grid_document(names, every);
    let line = grid_line(&text, every.len());
    (text, line)
}

/// Writes `text` as the folder's `sweep.grid`, once its settings are
/// known to match ([`check_settings`]): a refused sweep leaves it alone.
pub(super) fn write_grid(dir: &Path, text: &str) -> Result<()> {
    Ok(weft_io::write_output(
        &dir.join(GRID_FILE),
        text.as_bytes(),
    )?)
}

/// The `grid` line of a grid file's `text` of `count` points.
pub(super) fn grid_line(text: &str, count: usize) -> String {
    let mut hasher = weft_io::hash::Hasher::new();
    hasher.field(text.as_bytes());
    format!(
        "{GRID_LINE}{} ({count} points)",
        weft_io::hash::hex(hasher.finish())
    )
}

/// How `sweep.settings` names a shard's grid.
pub(super) const GRID_LINE: &str = "grid ";

/// A fingerprint of the contents of every file the sweep's points are
/// rendered from: the scene and its includes, and each measured graph's
/// files, shaders and their includes ([`weft_render::graph_source_files`]).
/// A resumed sweep must match it, so an edited shader or graph never mixes
/// old points with new ones; a missing file hashes as missing.
pub(super) fn sources_fingerprint(args: &SweepRun) -> Result<String> {
    let mut files = weft_render::scene_path_files(args.common.scene());
    for graph in args.graph_names() {
        let prepared = weft_render::load_graph(&RenderSettings {
            graph: PathBuf::from(&graph),
            ..RenderSettings::default()
        })?;
        files.extend(weft_render::graph_source_files(&prepared));
    }
    let mut hasher = weft_io::hash::Hasher::new();
    for file in &files {
        hasher.field(file.to_string_lossy().as_bytes());
        match std::fs::read(file) {
            Ok(bytes) => hasher.field(b"present").field(&bytes),
            Err(_) => hasher.field(b"missing"),
        };
    }
    Ok(format!(
        "{} ({} files)",
        weft_io::hash::hex(hasher.finish()),
        files.len()
    ))
}

/// What every point of a sweep shares; a resumed sweep must share it too:
/// the settings, and `sources`, the fingerprint of the files the points
/// are rendered from ([`sources_fingerprint`]); a shard's also name the
/// shard and its whole sweep's `grid` line ([`write_grid`]).
fn settings_text(args: &SweepRun, sources: &str, grid: &str) -> String {
    let c = &args.common;
    let reference = match &c.reference_image {
        Some(image) => format!("image {}", image.display()),
        None => format!(
            "{} at {} spp, seed {}, params {:?}",
            c.reference.display(),
            c.spp,
            c.seed,
            c.reference_params
        ),
    };
    format!(
        "scene {}\ngraph {}\nsize {}x{}\ncamera {}\nreference {reference}\nfeatures {}\nframes {}\nsources {sources}\n",
        c.scene().display(),
        args.graph_names().join(","),
        c.size.width,
        c.size.height,
        c.camera.as_deref().unwrap_or("(first)"),
        c.features.join(","),
        c.frames
    ) + args
        .shard
        .map(|s| format!("{SHARD_LINE}{}/{}\n{grid}\n", s.k, s.n))
        .unwrap_or_default()
        .as_str()
}

/// The `sources` line's fingerprint in a `sweep.settings` text.
fn sources_line(settings: &str) -> Option<&str> {
    settings.lines().find_map(|l| l.strip_prefix("sources "))
}

/// A `sweep.settings` text without its `sources` line.
fn without_sources(settings: &str) -> String {
    settings
        .lines()
        .filter(|l| !l.starts_with("sources "))
        .collect::<Vec<_>>()
        .join("\n")
}

/// How `sweep.settings` names a shard.
pub(super) const SHARD_LINE: &str = "shard ";

/// The file a sweep run with `--noise-floor` keeps the reference's noise
/// floor in (`SEED FLIP`), so a resumed or merged sweep still reports it.
pub(super) const NOISE_FLOOR_FILE: &str = "noise_floor";

/// The reference's noise floor: the other seed and the HDR-FLIP between the
/// two renders.
pub(super) type NoiseFloor = (u32, f64);

/// The noise floor recorded in `dir`, if a run there measured one.
pub(super) fn read_noise_floor(dir: &Path) -> Result<Option<NoiseFloor>> {
    let path = dir.join(NOISE_FLOOR_FILE);
    let text = match weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES) {
        Ok(text) => text,
        Err(weft_io::ReadError::Missing { .. }) => return Ok(None),
        Err(e) => return Err(e.into_io()).with_context(|| format!("reading {}", path.display())),
    };
    let parsed = text
        .split_once(' ')
        .and_then(|(seed, flip)| Some((seed.parse().ok()?, flip.trim().parse().ok()?)));
    parsed
        .map(Some)
        .with_context(|| format!("{}: expected `SEED FLIP`, found {text:?}", path.display()))
}

pub(super) fn write_noise_floor(dir: &Path, (seed, flip): NoiseFloor) -> Result<()> {
    let path = dir.join(NOISE_FLOOR_FILE);
    Ok(weft_io::write_output(
        &path,
        format!("{seed} {flip:.6}\n").as_bytes(),
    )?)
}

/// Records the sweep's settings beside its CSV (`sweep.settings`), or, when
/// resuming, refuses to mix points measured with other settings. `grid` is
/// the whole sweep's `grid` line, which a shard's settings hold.
pub(super) fn check_settings(args: &SweepRun, grid: &str) -> Result<()> {
    let path = args.out.join("sweep.settings");
    let wanted = settings_text(args, &sources_fingerprint(args)?, grid);
    match weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES) {
        Ok(found) if found == wanted => Ok(()),
        Ok(found) if without_sources(&found) == without_sources(&wanted) => bail!(
            "{} holds points measured from other sources: a graph, shader or scene file has changed since (sources {}, now {}); use another --out or remove the folder",
            args.out.display(),
            sources_line(&found).unwrap_or("not recorded"),
            sources_line(&wanted).unwrap_or("not recorded"),
        ),
        Ok(found) => bail!(
            "{} holds points measured with other settings:\n{found}this sweep:\n{wanted}use another --out or remove the folder",
            args.out.display()
        ),
        Err(weft_io::ReadError::Missing { .. }) if args.out.join("sweep.csv").exists() => bail!(
            "{} has a sweep.csv but no sweep.settings saying how it was measured; use another --out or remove the folder",
            args.out.display()
        ),
        Err(weft_io::ReadError::Missing { .. }) => {
            Ok(weft_io::write_output(&path, wanted.as_bytes())?)
        }
        Err(e) => bail!(
            "{} cannot be read ({}), so the points in {} cannot be told from another sweep's; use another --out or remove the folder",
            path.display(),
            e.reason(),
            args.out.display()
        ),
    }
}
