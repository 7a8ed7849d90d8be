//! `weft view`: a window showing a scene through a graph, flown with keyboard
//! and mouse, switching graphs and features, with per-pass times in the title,
//! screenshots, and hot reload of the graph, its shaders and the scene.

mod app;
mod bookmarks;
mod camera_block;
mod controls;
mod fly;
mod live_error;
mod overlay;
mod panel;
mod script;

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use weft_gpu::{Gpu, GpuOptions, TimingMode};
use weft_graph::plan::Extent;
use weft_render::RenderSettings;
use winit::event_loop::EventLoop;
use winit::raw_window_handle::HasDisplayHandle;

/// The controls, for `--help` and the README.
pub const CONTROLS: &str = "\
Controls:
  W A S D        move forward, left, back, right      Q / E   down / up
  mouse drag     look (left button)                   arrows  look
  Shift          move 4x faster                       wheel   change speed (x1.25 a notch)
  G / Shift+G    next / previous graph in the graph's folder
  1-9, Shift+1-9 toggle the graph's features (listed with their keys when a graph loads)
  Space          pause / resume scene time            R       back to the scene camera
  C              print the camera as a .scene `camera` block (world coordinates)
  B              save the camera as the next bookmark (--bookmarks FILE, or the user's data folder)
  F1             show / hide the panel, docked on the right (the view renders beside
                 it): graph, features, parameters, pass times, memory, plan,
                 convergence, reload errors (click to copy), bookmarks
  L              live error: path-trace the current view in the background and show
                 the HDR-FLIP map of the frame against it, updating as it converges;
                 scene time is held while it measures
  F12            save a screenshot (weft-<time>-<n>.png in --screenshot-dir, path printed;
                 the panel only with --screenshot-panel)
  Esc            quit
The title shows the graph, its features, frame time, samples per pixel for a
progressive graph such as graphs/pathtrace.ron (it converges while nothing moves;
moving the camera or a light starts it again) and per-pass GPU times, or the
last refused reload as file:line (also on stderr); edits to the graph, its includes,
its shaders or the scene reload all-or-nothing.";

/// Arguments of `weft view`.
#[derive(Args)]
#[command(after_help = CONTROLS)]
pub struct ViewArgs {
    /// The scene file.
    scene: PathBuf,
    /// The render graph.
    #[arg(long, default_value = "graphs/forward.ron", value_parser = crate::graphs::graph_path)]
    graph: PathBuf,
    /// Window size, WIDTHxHEIGHT (the graph renders at the window's size).
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Camera to start from; the scene's first by default.
    #[arg(long)]
    camera: Option<String>,
    /// Scene time in seconds at the start.
    #[arg(long, default_value_t = 0.0, value_parser = crate::render_cmd::parse_time, allow_negative_numbers = true)]
    time: f64,
    /// Start with scene time stopped (Space resumes).
    #[arg(long)]
    paused: bool,
    /// Feature toggles added after the scene's features (`name` on, `!name` off).
    #[arg(long, value_delimiter = ',')]
    features: Vec<String>,
    /// Enable the validation layer with synchronization validation; any message
    /// makes the command fail when it exits.
    #[arg(long)]
    validate: bool,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
    /// Quit after presenting this many frames, at least 1 (for scripts and tests).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    frames: Option<u32>,
    /// Ask the window to become WIDTHxHEIGHT after half of --frames (tests resizing).
    #[arg(long, value_parser = clap::value_parser!(Extent), requires = "frames")]
    resize_to: Option<Extent>,
    /// Press keys without a keyboard (for scripts and tests): FRAME:KEY,... where KEY
    /// is g, G (Shift+G), 1-9, shift+1-9, f1, f12, space, r, c, l, b or esc, pressed
    /// before frame FRAME.
    #[arg(long, value_delimiter = ',', value_parser = controls::parse_press)]
    press: Vec<(u32, controls::Action)>,
    /// Save the last presented frame, as shown in the window, to this PNG on exit
    /// (after --frames, Esc, closing the window, SIGINT or SIGTERM).
    #[arg(long)]
    screenshot_on_exit: Option<PathBuf>,
    /// Where F12 saves screenshots. Default: `weft` in the user's pictures
    /// folder (XDG `PICTURES`, e.g. ~/Pictures/weft) where one is set up, else
    /// the user cache (~/.cache/weft/screenshots); never the current directory.
    #[arg(long)]
    screenshot_dir: Option<PathBuf>,
    /// Start with the panel shown (F1 shows and hides it).
    #[arg(long)]
    panel: bool,
    /// Drive the panel without a mouse (scripts and tests): FRAME:click:NAME,
    /// FRAME:text:TEXT or FRAME:enter, before frame FRAME. NAME is a panel
    /// widget: feature:NAME, param:KEY, graph, graph:FILE, pause, live_error,
    /// copy_camera, save_bookmark, bookmark:N, error.
    #[arg(long, value_delimiter = ',', value_parser = script::parse_ui)]
    ui: Vec<(u32, script::UiStep)>,
    /// Include the panel and the live error map in screenshots (F12 and
    /// --screenshot-on-exit); by default they hold the graph's image alone.
    #[arg(long)]
    screenshot_panel: bool,
    /// Where B saves camera bookmarks (a `.scene` file of cameras). Default:
    /// the user's data folder (XDG `DATA_HOME`, e.g.
    /// ~/.local/share/weft/bookmarks/demo-1a2b3c4d.bookmarks.scene).
    #[arg(long)]
    bookmarks: Option<PathBuf>,
    /// The progressive graph the live error (L) measures against; by default
    /// pathtrace.ron beside --graph, else graphs/pathtrace.ron.
    #[arg(long, value_parser = crate::graphs::graph_path)]
    reference: Option<PathBuf>,
    /// Stop the live error's reference at this many samples per pixel.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    reference_spp: Option<u64>,
    /// On exit, write the live error's last HDR-FLIP map here (a magma PNG,
    /// as `weft compare` writes it) and print its mean.
    #[arg(long)]
    live_error_out: Option<PathBuf>,
    /// Make every reload's preparation (on the worker thread) sleep this long
    /// first, to see the frame loop keep going during a slow one (tests).
    #[arg(long, hide = true, default_value_t = 0)]
    prepare_delay_ms: u64,
    /// Make every frame take at least this long, as a slow machine's or a
    /// large image's would (tests of input on slow frames).
    #[arg(long, hide = true, default_value_t = 0)]
    frame_delay_ms: u64,
}

/// Runs `weft view`.
pub fn run(args: ViewArgs) -> Result<ExitCode> {
    // Loaded once, before the window opens: its errors and unknown toggles stop here.
    let graph = crate::graphs::load_checked(&RenderSettings {
        graph: args.graph.clone(),
        features: args.features.clone(),
        ..RenderSettings::default()
    })?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::SeqCst))
        .context("installing the SIGINT/SIGTERM handler")?;
    let event_loop =
        EventLoop::new().context("opening the display (is DISPLAY or WAYLAND_DISPLAY set?)")?;
    let display = event_loop
        .display_handle()
        .context("the display has no handle")?
        .as_raw();
    let gpu = Gpu::for_display(
        &GpuOptions {
            validation: args.validate,
            device: args.device.clone(),
        },
        display,
    )?;
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: args.graph.clone(),
        extent: args.size,
        camera: args.camera.clone(),
        time: args.time,
        features: args.features.clone(),
        timing: if gpu.info().timestamps {
            TimingMode::GpuTimestamps
        } else {
            TimingMode::Off
        },
        readback: false,
        cache_dir: weft_scene::cache::user_cache_dir(),
        ..RenderSettings::default()
    };
    let outcome = std::thread::scope(|scope| -> Result<Result<()>> {
        let mut app = app::Viewer::new(&gpu, &args, (graph, settings), stop, scope)?;
        event_loop.run_app(&mut app)?;
        Ok(app.finish())
    })?;
    drop(gpu);
    let messages = log.messages();
    for m in &messages {
        eprintln!("validation {:?}: {}: {}", m.severity, m.id, m.text);
    }
    if args.validate {
        println!("validation: {}", log.counts());
    }
    outcome?;
    Ok(if messages.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
