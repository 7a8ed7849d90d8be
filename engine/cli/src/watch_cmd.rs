//! `weft render --watch`: render once, then re-render on every change to the
//! graph, its shaders or the scene, replacing the output file atomically and
//! printing one line per change, until SIGINT or SIGTERM.

use anyhow::{anyhow, Context, Result};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use weft_gpu::{Gpu, GpuOptions, ValidationLog};
use weft_render::{startup_files, LiveRender, RenderSettings};
use weft_render::{FileWatcher, QUIET};

/// How often the loop looks for an interrupt while no file changes.
const POLL: Duration = Duration::from_millis(100);

/// What `weft render --watch` was asked to do.
pub struct WatchRequest<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// The image to keep replacing.
    pub out: &'a Path,
    /// Read-back images to save instead of the output, the first the frame
    /// reads back (`hdr` for EXR files); none for the output.
    pub images: &'a [String],
    /// Graph, size, camera, features and timing.
    pub settings: RenderSettings,
    /// `settings.graph` as the command loaded it, for the first attempt;
    /// `None` when it did not load (the watch waits for a fix).
    pub graph: Option<weft_graph::Prepared>,
    /// Validation and device choice.
    pub gpu: GpuOptions,
}

/// Runs the watch loop; returns success when interrupted, failure when validation
/// reported anything. A first version that does not load is waited for, not fatal.
pub fn run(mut request: WatchRequest) -> Result<ExitCode> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
        .context("installing the SIGINT/SIGTERM handler")?;
    let gpu = Gpu::new(&request.gpu)?;
    let log = gpu.validation();
    let graph = request.settings.graph.clone();
    let mut watcher = FileWatcher::new(QUIET)?;
    let Some(mut live) = first_version(&gpu, &mut request, &mut watcher, &stop)? else {
        return Ok(exit_code(report_validation(&log)));
    };
    let started = Instant::now();
    write_frame(&mut live, request.out, request.images).map_err(|e| anyhow!("{e}"))?;
    watcher.watch(&live.sources().all())?;
    println!(
        "wrote {} in {:.1} ms; watching {} files (Ctrl-C to stop)",
        request.out.display(),
        started.elapsed().as_secs_f64() * 1e3,
        live.sources().all().len()
    );
    let mut clean = report_validation(&log);
    while !stop.load(Ordering::SeqCst) {
        let changed = watcher.next_batch(POLL)?;
        if changed.is_empty() {
            continue;
        }
        let line = reload(&mut live, &changed, request.out, request.images, &graph);
        // Watch the new set before saying so: an edit made on seeing the line is caught.
        if let Err(err) = watcher.watch(&live.sources().all()) {
            println!("error: {err} (still watching the other files)");
        }
        println!("{line}");
        std::io::stdout().flush()?;
        clean &= report_validation(&log);
    }
    Ok(exit_code(clean))
}

/// Success unless validation reported something.
fn exit_code(clean: bool) -> ExitCode {
    if clean {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Loads the first version; while it fails, prints the error and waits for one of
/// the files it reads to change. `None` when interrupted first.
fn first_version<'g>(
    gpu: &'g Gpu,
    request: &mut WatchRequest,
    watcher: &mut FileWatcher,
    stop: &AtomicBool,
) -> Result<Option<LiveRender<'g>>> {
    let mut watched = BTreeSet::new();
    loop {
        // The command's graph on the first attempt; loaded afresh after an edit.
        let started = match request.graph.take() {
            Some(graph) => {
                LiveRender::with_graph(gpu, request.scene, graph, request.settings.clone())
            }
            None => LiveRender::new(gpu, request.scene, request.settings.clone()),
        };
        let err = match started {
            Ok(live) => return Ok(Some(live)),
            Err(err) => err,
        };
        let files = startup_files(gpu, request.scene, &request.settings, &err);
        if files != watched {
            watcher.watch(&files)?;
            watched = files;
            // A fix saved before the watch was set raises no event: try again first.
            continue;
        }
        println!("error: {err} (no good version yet; waiting for a fix)");
        loop {
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            if !watcher.next_batch(POLL)?.is_empty() {
                break;
            }
        }
    }
}

/// Applies one batch of changes and writes the new image; the line to print.
fn reload(
    live: &mut LiveRender<'_>,
    changed: &BTreeSet<PathBuf>,
    out: &Path,
    images: &[String],
    graph: &Path,
) -> String {
    let started = Instant::now();
    let paths = match live.apply(changed) {
        Ok(paths) => paths,
        Err(e) => return format!("error: {e} (kept last good)"),
    };
    match write_frame(live, out, images) {
        Ok(frame_ms) => format!(
            "reloaded {} in {:.1} ms (frame {frame_ms:.1} ms)",
            paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            started.elapsed().as_secs_f64() * 1e3
        ),
        Err(e) => format!("error: {}: {e} (kept last good)", graph.display()),
    }
}

/// Renders a frame and replaces `out` with it; returns the frame's milliseconds
/// (render and readback, without the file write).
fn write_frame(live: &mut LiveRender<'_>, out: &Path, images: &[String]) -> Result<f64> {
    let started = Instant::now();
    let report = live.frame()?;
    if let Some(error) = live.take_script_error() {
        eprintln!("error: {error} (the lights of the last good step kept)");
    }
    let frame_ms = started.elapsed().as_secs_f64() * 1e3;
    let picked = report
        .first_read_back(images)
        .or(report.output.as_ref())
        .context("the frame produced no output image")?;
    replace_atomically(out, |tmp| Ok(picked.save(tmp)?))?;
    Ok(frame_ms)
}

/// Writes `out` through a temporary file in the same folder renamed over it, so
/// readers never see a half-written image.
fn replace_atomically(out: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .context("--out names no file")?;
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("png");
    let tmp = out.with_file_name(format!(".{name}.{}.tmp.{ext}", std::process::id()));
    write(&tmp)?;
    std::fs::rename(&tmp, out)
        .with_context(|| format!("renaming {} to {}", tmp.display(), out.display()))
}

/// Prints validation messages collected since the last call; whether there were none.
fn report_validation(log: &ValidationLog) -> bool {
    let messages = log.take();
    for m in &messages {
        eprintln!("validation {:?}: {}: {}", m.severity, m.id, m.text);
    }
    messages.is_empty()
}
