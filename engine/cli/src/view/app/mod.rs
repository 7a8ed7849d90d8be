//! The viewer's event loop: winit events drive the fly camera, graph and
//! feature switches and screenshots; file edits are prepared on a worker thread
//! while frames keep coming, and each redraw commits a prepared one
//! (all-or-nothing, at the frame boundary), renders the live graph from the fly
//! camera and presents it.

mod environment;
mod output;
mod reload;
mod ui;

use super::controls::{self, Action};
use super::fly::{self, FlyCamera, FlyInput};
use super::overlay::EguiOverlay;
use super::ViewArgs;
use anyhow::{anyhow, Context, Result};
use ash::vk;
use glam::Vec2;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use weft_gpu::{Capture, Gpu, PresentSource, Presented, Presenter, Swapchain};
use weft_graph::plan::Extent;
use weft_render::{FileWatcher, QUIET};
use weft_render::{LiveRender, ReloadWorker, RenderSettings};
use weft_scene::Camera;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

/// Pixels of scrolling that count as one wheel notch (touchpads).
const PIXELS_PER_NOTCH: f64 = 40.0;

/// Frame times gathered between title updates, and over the whole run.
#[derive(Default)]
struct Stats {
    total_ms: f64,
    frames: u32,
    mean_ms: f64,
    since: Option<Instant>,
    all_ms: Vec<f64>,
}

/// The viewer's state; the overlay (views of swapchain images) is declared
/// before the presenter, and the presenter before the window, so each is
/// dropped before what it uses (the surface must go before its window).
pub struct Viewer<'g> {
    gpu: &'g Gpu,
    live: LiveRender<'g>,
    watcher: FileWatcher,
    overlay: Option<EguiOverlay<'g>>,
    presenter: Option<Presenter<'g>>,
    window: Option<Window>,
    start: FlyCamera,
    camera: FlyCamera,
    lens: Camera,
    held: HashSet<KeyCode>,
    shift: bool,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    drag: Vec2,
    time: f64,
    paused: bool,
    last_frame: Option<Instant>,
    frames: u32,
    frame_limit: Option<u32>,
    /// The least time a frame takes (`--frame-delay-ms`, tests).
    frame_delay: Duration,
    resize_to: Option<Extent>,
    pending_size: Option<[u32; 2]>,
    screenshot_on_exit: Option<PathBuf>,
    screenshot_dir: Option<PathBuf>,
    screenshot_now: bool,
    screenshots: u32,
    restarts: controls::RestartWatch,
    graphs: Vec<PathBuf>,
    features: Vec<String>,
    error: Option<String>,
    stats: Stats,
    timings: Vec<weft_gpu::PassTiming>,
    failure: Option<anyhow::Error>,
    /// Scripted key presses (`--press`): before the frame numbered first, the action.
    presses: Vec<(u32, Action)>,
    /// Set by SIGINT/SIGTERM (and Esc, closing): the next frame is the last.
    stop: Arc<AtomicBool>,
    /// Prepares file edits off the frame loop.
    worker: ReloadWorker,
    /// The reload in progress, from when its first batch was taken to the frame
    /// that shows it.
    reload: Option<ReloadProgress>,
    /// A reload committed, until its frame is shown.
    reloaded: Option<(String, ReloadProgress, f64)>,
    /// The files of the last reload that went live, for the panel.
    last_reload: Option<String>,
    /// The panel (F1) and what it needs between frames.
    ui: ui::UiState<'g>,
    /// The environment map's turn the panel set (the scene's until then).
    environment_turn: Option<f32>,
}

/// What the frame loop did while a reload was on its way.
#[derive(Debug, Clone, Copy)]
struct ReloadProgress {
    /// When the first edited batch was taken.
    taken: Instant,
    /// Frames presented since.
    frames: u32,
    /// The longest frame since, from the start of one redraw (committing
    /// included) to its present, in milliseconds.
    longest_ms: f64,
}

impl<'g> Viewer<'g> {
    /// Loads the scene, compiles `graph` for it and starts watching their files; the window
    /// comes when the event loop resumes.
    pub fn new(
        gpu: &'g Gpu,
        args: &ViewArgs,
        (graph, settings): (weft_graph::Prepared, RenderSettings),
        stop: Arc<AtomicBool>,
        scope: &'g std::thread::Scope<'g, '_>,
    ) -> Result<Self> {
        let live = LiveRender::with_graph(gpu, &args.scene, graph, settings)
            .map_err(|e| anyhow!("{e}"))?;
        let lens = live.camera()?.clone();
        let (position, orientation) = lens.pose_at(args.time);
        let start = FlyCamera {
            position,
            orientation,
            speed: fly::speed_for(live.scene().effective_bounds().diagonal()),
        };
        let mut watcher = FileWatcher::new(QUIET)?;
        watcher.watch(&live.sources().all())?;
        let graph = live.settings().graph.clone();
        let ui = ui::UiState::new(args, &graph)?;
        let mut viewer = Self {
            gpu,
            watcher,
            overlay: None,
            presenter: None,
            window: None,
            start,
            camera: start,
            lens,
            held: HashSet::new(),
            shift: false,
            dragging: false,
            cursor: None,
            drag: Vec2::ZERO,
            time: args.time,
            paused: args.paused,
            last_frame: None,
            frames: 0,
            frame_limit: args.frames,
            frame_delay: Duration::from_millis(args.frame_delay_ms),
            resize_to: args.resize_to,
            pending_size: None,
            screenshot_on_exit: args.screenshot_on_exit.clone(),
            screenshot_dir: args.screenshot_dir.clone().or_else(|| {
                output::screenshot_folder(dirs::picture_dir(), weft_scene::cache::user_cache_dir())
            }),
            screenshot_now: false,
            screenshots: 0,
            restarts: controls::RestartWatch::default(),
            graphs: controls::sibling_graphs(&graph),
            features: controls::graph_features(live.graph()),
            error: None,
            stats: Stats::default(),
            timings: Vec::new(),
            failure: None,
            stop,
            presses: args.press.clone(),
            worker: ReloadWorker::spawn(scope, gpu, Duration::from_millis(args.prepare_delay_ms)),
            reload: None,
            reloaded: None,
            last_reload: None,
            ui,
            environment_turn: None,
            live,
        };
        viewer.print_features();
        // A first check of the live version compiles every shader on the
        // worker, so the first edit finds its checker warm.
        let job = viewer.live.files_job(&Default::default());
        viewer.worker.submit(job);
        Ok(viewer)
    }

    /// Releases the window, prints how many frames were shown and how long
    /// they took, and reports a failure that stopped the loop.
    pub fn finish(mut self) -> Result<()> {
        let graph = self.live.settings().graph.clone();
        let reported = self.ui.report_live_error(&graph);
        self.overlay = None;
        self.presenter = None;
        self.window = None;
        if let Some(line) = self.ui.cost.summary() {
            println!("{line}");
        }
        let mut times = std::mem::take(&mut self.stats.all_ms);
        if let Some(first) = times.first().copied() {
            let steady = if times.len() > 1 {
                &mut times[1..]
            } else {
                &mut times[..]
            };
            steady.sort_by(f64::total_cmp);
            println!(
                "presented {} frames: first {first:.1} ms, then median {:.1} ms",
                self.frames,
                steady[steady.len() / 2]
            );
        }
        match self.failure.take() {
            Some(err) => Err(err),
            None => reported.and(self.ui.no_steps_left(self.frames)),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, err: anyhow::Error) {
        self.failure.get_or_insert(err);
        event_loop.exit();
    }

    /// Creates the window, its swapchain and the presenter.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let extent = self.live.settings().extent;
        let attributes = Window::default_attributes()
            .with_title("weft view")
            .with_inner_size(PhysicalSize::new(extent.width, extent.height));
        let window = event_loop
            .create_window(attributes)
            .context("creating the window")?;
        let size = window.inner_size();
        let display = window.display_handle()?.as_raw();
        let handle = window.window_handle()?.as_raw();
        // The presenter is dropped before the window (see `finish` and field order).
        let swapchain =
            unsafe { Swapchain::new(self.gpu, display, handle, [size.width, size.height]) }?;
        let presenter = Presenter::new(self.gpu, swapchain)?;
        self.overlay = Some(EguiOverlay::new(self.gpu, &window, presenter.format())?);
        self.presenter = Some(presenter);
        self.window = Some(window);
        self.pending_size = Some([size.width, size.height]);
        Ok(())
    }

    fn key(&mut self, event: &KeyEvent) {
        let PhysicalKey::Code(code) = event.physical_key else {
            return;
        };
        if event.state == ElementState::Released {
            self.held.remove(&code);
            return;
        }
        self.held.insert(code);
        if event.repeat
            || self.ui.panel.visible
                && self
                    .overlay
                    .as_ref()
                    .is_some_and(EguiOverlay::wants_keyboard)
        {
            return;
        }
        if let Some(action) = controls::action(code, self.shift) {
            self.act(action);
        }
    }

    fn act(&mut self, action: Action) {
        match action {
            Action::Quit => self.stop.store(true, Ordering::SeqCst),
            Action::Screenshot => self.screenshot_now = true,
            Action::Pause => self.paused = !self.paused,
            Action::ResetCamera => {
                self.camera = FlyCamera {
                    speed: self.camera.speed,
                    ..self.start
                }
            }
            Action::Graph(step) => {
                let current = self.live.settings().graph.clone();
                if let Some(next) = controls::cycle(&self.graphs, &current, step) {
                    let settings = RenderSettings {
                        graph: next,
                        ..self.live.settings().clone()
                    };
                    self.reconfigure(settings);
                }
            }
            Action::Feature(index) => self.toggle_feature(index),
            Action::PrintCamera => print!("{}", self.camera_block()),
            Action::Panel => self.ui.panel.visible = !self.ui.panel.visible,
            Action::LiveError => self.toggle_live_error(),
            Action::SaveBookmark => self.save_bookmark(),
        }
    }

    /// The flown camera as a `.scene` `camera` block.
    fn camera_block(&self) -> String {
        super::camera_block::camera_block(
            "flown",
            &self.lens,
            self.live.scene().origin,
            self.camera.position,
            self.camera.orientation,
        )
    }

    fn toggle_feature(&mut self, index: usize) {
        let Some(name) = self.features.get(index).cloned() else {
            return;
        };
        let on = self.live.plan().features.contains(&name);
        let settings = RenderSettings {
            features: controls::toggle(&self.live.settings().features, &name, on),
            ..self.live.settings().clone()
        };
        self.reconfigure(settings);
    }

    /// What the held keys, drag and wheel ask for since the last frame.
    fn input(&mut self, dt: f32) -> FlyInput {
        let axis = |plus: KeyCode, minus: KeyCode| {
            f32::from(u8::from(self.held.contains(&plus)))
                - f32::from(u8::from(self.held.contains(&minus)))
        };
        let keys = Vec2::new(
            axis(KeyCode::ArrowRight, KeyCode::ArrowLeft),
            axis(KeyCode::ArrowUp, KeyCode::ArrowDown),
        );
        let look = keys * fly::KEY_LOOK * dt + self.drag * fly::DRAG_LOOK;
        self.drag = Vec2::ZERO;
        FlyInput {
            forward: axis(KeyCode::KeyW, KeyCode::KeyS),
            right: axis(KeyCode::KeyD, KeyCode::KeyA),
            up: axis(KeyCode::KeyE, KeyCode::KeyQ),
            fast: self.shift,
            look,
        }
    }

    /// One frame: reload, resize, move, render, present, screenshot.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let began = Instant::now();
        std::thread::sleep(self.frame_delay);
        self.hot_reload()?;
        let due: Vec<Action> = self
            .presses
            .iter()
            .filter(|(frame, _)| *frame == self.frames)
            .map(|&(_, action)| action)
            .collect();
        self.presses.retain(|(frame, _)| *frame != self.frames);
        for action in due {
            self.act(action);
        }
        let Some(window) = &self.window else {
            return Ok(());
        };
        let size = window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(());
        }
        let size = [size.width, size.height];
        if let Some(wanted) = self.pending_size.take() {
            self.resize(wanted)?;
        }
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32());
        self.last_frame = Some(now);
        let input = self.input(dt);
        let (position, orientation) = (self.camera.position, self.camera.orientation);
        self.camera.update(&input, dt);
        let camera_moved =
            self.camera.position != position || self.camera.orientation != orientation;
        // The live error holds scene time while it accumulates: an
        // animated scene would restart its reference every frame.
        if !self.paused && !self.ui.holds_time() {
            self.time += f64::from(dt);
        }
        let camera = Camera {
            name: "fly".into(),
            position: self.camera.position,
            orientation: self.camera.orientation,
            path: Vec::new(),
            ..self.lens.clone()
        };
        if let Some(degrees) = self.environment_turn {
            self.live.turn_environment(degrees);
        }
        let measure = self.ui.live_error_due(&self.live);
        let read_views = self.ui.panel.visible && !self.live.plan().views.is_empty();
        let report = self
            .live
            .draw(&camera, self.time, self.frames, measure || read_views)?;
        self.ui
            .step_live_error(&camera, self.time, &self.live, measure.then_some(&report))?;
        self.ui.read_under_cursor(&self.live, &report, self.cursor);
        let restarted = self.live.samples().is_some()
            && self.live.samples() == self.live.plan().samples_per_frame.map(u64::from);
        self.restarts
            .observe(restarted, camera_moved, !self.paused && dt > 0.0);
        if self.restarts.just_began() {
            println!("progressive image {}", controls::ANIMATING);
        }
        if let Some(error) = self.live.take_script_error() {
            eprintln!("error: {error} (the lights of the last good step kept)");
        }
        let output = self.live.output()?;
        let mut source = PresentSource {
            image: output.image,
            extent: vk::Extent2D {
                width: output.desc.extent.width,
                height: output.desc.extent.height,
            },
            format: vk::Format::from_raw(output.desc.format_raw),
            area: vk::Extent2D {
                width: size[0],
                height: size[1],
            },
        };
        let last = self.frame_limit.is_some_and(|n| self.frames + 1 >= n)
            || self.stop.load(Ordering::SeqCst);
        let on_exit = last && self.screenshot_on_exit.is_some();
        let capture = match (self.screenshot_now || on_exit, self.ui.screenshot_panel) {
            (false, _) => Capture::No,
            (true, false) => Capture::Image,
            (true, true) => Capture::WithOverlay,
        };
        let ui_began = Instant::now();
        let actions = self.run_panel()?;
        let ui_ms = ui_began.elapsed().as_secs_f64() * 1e3;
        // The 3D view fills what the panel, docked on the right, leaves.
        let view = self.view_extent(size);
        source.area = vk::Extent2D {
            width: view.width,
            height: view.height,
        };
        let drawn = self.ui.overlay_drawn();
        let presenter = self
            .presenter
            .as_mut()
            .context("no presenter for the window")?;
        let overlay = self
            .overlay
            .as_mut()
            .filter(|_| drawn)
            .map(|o| o as &mut dyn weft_gpu::Overlay);
        let present_began = Instant::now();
        let presented = presenter.present(source, capture, size, overlay)?;
        let present_ms = present_began.elapsed().as_secs_f64() * 1e3;
        self.ui.cost.record(drawn, ui_ms, present_ms);
        if let Some(overlay) = self.overlay.as_mut() {
            overlay.after_present()?;
        }
        for action in actions {
            self.apply_panel(action);
        }
        if self.live.settings().extent != view {
            self.reconfigure(RenderSettings {
                extent: view,
                ..self.live.settings().clone()
            });
        }
        let shown = match presented {
            Presented::Shown(pixels) => pixels,
            Presented::Recreated => return Ok(()),
        };
        self.frames += 1;
        let frame_ms = now.elapsed().as_secs_f64() * 1e3;
        self.ui.panel.history.push(
            frame_ms,
            &report.timings,
            self.live.samples(),
            Instant::now(),
        );
        self.ui.memory = [
            report.transient_bytes,
            report.dedicated_bytes,
            report.memory.allocated_bytes,
        ];
        self.timings = report.timings;
        self.stats.total_ms += frame_ms;
        self.stats.all_ms.push(frame_ms);
        self.stats.frames += 1;
        let loop_ms = began.elapsed().as_secs_f64() * 1e3;
        if let Some(progress) = self.reload.as_mut() {
            progress.frames += 1;
            progress.longest_ms = progress.longest_ms.max(loop_ms);
        }
        if let Some((files, progress, prepare_ms)) = self.reloaded.take() {
            println!(
                "reloaded {files}: shown {:.1} ms after the change was taken \
                 (prepared off the frame loop in {prepare_ms:.1} ms; {} frames presented \
                 meanwhile, the longest {:.1} ms; this frame {loop_ms:.1} ms)",
                progress.taken.elapsed().as_secs_f64() * 1e3,
                progress.frames,
                progress.longest_ms,
            );
        }
        if let Some(pixels) = shown {
            self.save_screenshots(&pixels, on_exit)?;
        }
        self.update_title(false);
        if let (Some(limit), Some(to)) = (self.frame_limit, self.resize_to) {
            if self.frames == limit / 2 {
                if let Some(window) = &self.window {
                    let _ = window.request_inner_size(PhysicalSize::new(to.width, to.height));
                }
            }
        }
        if last {
            event_loop.exit();
        }
        Ok(())
    }
}

impl ApplicationHandler for Viewer<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            if let Err(err) = self.open(event_loop) {
                self.fail(event_loop, err);
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if self.panel_took(&event) {
            return;
        }
        match event {
            WindowEvent::CloseRequested => self.stop.store(true, Ordering::SeqCst),
            WindowEvent::Resized(size) => self.pending_size = Some([size.width, size.height]),
            WindowEvent::ModifiersChanged(modifiers) => {
                self.shift = modifiers.state().shift_key();
            }
            WindowEvent::KeyboardInput { event, .. } => self.key(&event),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                let on_panel = self.ui.panel.visible
                    && self
                        .overlay
                        .as_ref()
                        .is_some_and(EguiOverlay::wants_pointer);
                self.dragging = state == ElementState::Pressed && !on_panel;
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some((x, y))) = (self.dragging, self.cursor) {
                    self.drag += Vec2::new((position.x - x) as f32, (y - position.y) as f32);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / PIXELS_PER_NOTCH) as f32,
                };
                self.camera.scroll(notches, self.start.speed);
            }
            WindowEvent::RedrawRequested => {
                if let Err(err) = self.frame(event_loop) {
                    self.fail(event_loop, err);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let drawable = self
            .window
            .as_ref()
            .is_some_and(|w| w.inner_size().width > 0 && w.inner_size().height > 0);
        match &self.window {
            Some(window) if drawable => window.request_redraw(),
            _ if self.stop.load(Ordering::SeqCst) => event_loop.exit(),
            _ => {}
        }
    }
}
