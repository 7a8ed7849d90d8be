//! The viewer's side of the panel: what it needs between frames, running it
//! each frame (with scripted input), applying what it asks for at the frame
//! boundary, the live error's reference, bookmarks, and the debug-view value
//! under the cursor.

use super::super::bookmarks::{self, Bookmark};
use super::super::controls;
use super::super::live_error::{self, LiveError};
use super::super::panel::{graph_params, Panel, PanelAction, PanelView};
use super::super::script::{self, UiStep};
use super::super::ViewArgs;
use super::Viewer;
use anyhow::{bail, Result};
use std::path::PathBuf;
use weft_gpu::readback::Pixels;
use weft_gpu::FrameReport;
use weft_render::{LiveRender, RenderSettings};
use weft_scene::Camera;
use winit::event::{ElementState, WindowEvent};

/// Frames a scripted click waits for its widget to scroll into view.
const CLICK_WAIT_FRAMES: u32 = 10;

/// What the panel needs between frames.
pub(super) struct UiState<'g> {
    /// The panel itself.
    pub panel: Panel,
    /// Screenshots include the overlay (`--screenshot-panel`).
    pub screenshot_panel: bool,
    /// The last frame's transient, dedicated and allocated device bytes.
    pub memory: [u64; 3],
    /// `--ui` steps not yet taken, by frame.
    script: Vec<(u32, UiStep)>,
    /// Scripted clicks waiting for their widget to be scrolled into view:
    /// the widget, and the last frame to wait for.
    presses: Vec<(String, u32)>,
    /// Scripted typing waiting for a field to have the keyboard, with the
    /// last frame to wait for.
    typing: Vec<(UiStep, u32)>,
    live_error: Option<LiveError<'g>>,
    reference: PathBuf,
    reference_spp: Option<u64>,
    live_error_out: Option<PathBuf>,
    /// The live error map on screen: the samples and mean it shows, and its texture.
    map: Option<(u64, f64, egui::TextureHandle)>,
    bookmarks: Vec<Bookmark>,
    /// Where bookmarks are saved.
    bookmarks_path: PathBuf,
    /// Whether that file could be read (it is never overwritten unread).
    bookmarks_readable: bool,
    /// A debug view's value under the cursor.
    under_cursor: Option<String>,
    /// Whether the overlay draws this frame.
    drawn: bool,
    /// What the panel costs per frame.
    pub cost: PanelCost,
    scene: PathBuf,
}

impl<'g> UiState<'g> {
    /// The panel's state for a viewer started with `args` on `graph`.
    pub fn new(args: &ViewArgs, graph: &std::path::Path) -> Result<Self> {
        let bookmarks_path = args
            .bookmarks
            .clone()
            .unwrap_or_else(|| bookmarks::file_for(&args.scene, dirs::data_dir()));
        let (bookmarks, bookmarks_readable) = match bookmarks::load(&bookmarks_path) {
            Ok(marks) => (marks, true),
            Err(err) => {
                eprintln!("warning: {err:#}; bookmarks will not be saved over it");
                (Vec::new(), false)
            }
        };
        Ok(Self {
            panel: Panel::new(args.panel),
            screenshot_panel: args.screenshot_panel,
            memory: [0; 3],
            script: args.ui.clone(),
            presses: Vec::new(),
            typing: Vec::new(),
            live_error: None,
            reference: args
                .reference
                .clone()
                .unwrap_or_else(|| live_error::default_reference(graph)),
            reference_spp: args.reference_spp,
            live_error_out: args.live_error_out.clone(),
            map: None,
            bookmarks,
            bookmarks_readable,
            bookmarks_path,
            under_cursor: None,
            drawn: false,
            cost: PanelCost::default(),
            scene: args.scene.clone(),
        })
    }

    /// Whether the overlay draws over this frame.
    pub fn overlay_drawn(&self) -> bool {
        self.drawn
    }

    /// Whether scene time stands still: while the live error measures, so
    /// its reference converges instead of restarting with every step.
    pub fn holds_time(&self) -> bool {
        self.live_error.is_some()
    }

    /// An error naming every `--ui` step that never ran in the `frames`
    /// presented (a step for a later frame, a click or typing still
    /// waiting): a script that did not run is not a success.
    pub fn no_steps_left(&self, frames: u32) -> Result<()> {
        let mut left: Vec<String> = self
            .script
            .iter()
            .map(|(f, step)| format!("{f}:{step}"))
            .collect();
        left.extend(
            self.presses
                .iter()
                .map(|(name, _)| format!("click:{name} (waiting for its widget)")),
        );
        left.extend(
            self.typing
                .iter()
                .map(|(step, _)| format!("{step} (waiting for a field with the keyboard)")),
        );
        if left.is_empty() {
            return Ok(());
        }
        bail!(
            "--ui: {} step(s) never ran in the {frames} frames shown: {}; give more --frames",
            left.len(),
            left.join(", ")
        )
    }

    /// `settings` with the live image read back when the live error needs it
    /// (the graph's `readback` list), and nothing read back otherwise.
    pub fn with_readback(&mut self, settings: RenderSettings) -> RenderSettings {
        let extra_readback = match &mut self.live_error {
            Some(live_error) => {
                let names = weft_graph::load(&settings.graph).readback_names();
                live_error.set_problem(names.is_empty().then(|| {
                    format!(
                        "{} reads back no linear image (`readback: [\"hdr\"]`), so it cannot be measured",
                        settings.graph.display()
                    )
                }));
                names
            }
            None => Vec::new(),
        };
        RenderSettings {
            extra_readback,
            ..settings
        }
    }

    /// Whether this frame is read back to be measured by the live error.
    pub fn live_error_due(&self, live: &LiveRender<'_>) -> bool {
        !live.settings().extra_readback.is_empty()
            && self.live_error.as_ref().is_some_and(LiveError::due)
    }

    /// Adds the reference's samples for this frame, and measures `report`
    /// (read back because [`UiState::live_error_due`] said so).
    pub fn step_live_error(
        &mut self,
        camera: &Camera,
        time: f64,
        live: &LiveRender<'_>,
        report: Option<&FrameReport>,
    ) -> Result<()> {
        if let Some(live_error) = &mut self.live_error {
            let graph = live.settings().graph.as_path();
            live_error.step(
                (camera, time, live.settings().extent),
                report.map(|r| (r, graph)),
            )?;
        }
        Ok(())
    }

    /// Reads the first debug view's value at `cursor` (window pixels) from
    /// `report`, when the panel shows and the frame was read back.
    pub fn read_under_cursor(
        &mut self,
        live: &LiveRender<'_>,
        report: &FrameReport,
        cursor: Option<(f64, f64)>,
    ) {
        self.under_cursor = None;
        let plan = live.plan();
        let (Some(view), Some((x, y)), true) = (plan.views.first(), cursor, self.panel.visible)
        else {
            return;
        };
        let name = &plan.resources[view.image].name;
        let Some((_, image)) = report.readbacks.iter().find(|(n, _)| n == name) else {
            return;
        };
        let (px, py) = (x.max(0.0) as usize, y.max(0.0) as usize);
        let value = value_at(image, px, py);
        self.under_cursor = value.map(|v| format!("{} {v} at ({px}, {py})", view.name));
    }

    /// At exit: the live error's last measure of `graph`, printed, and its
    /// map written where `--live-error-out` says.
    pub fn report_live_error(&mut self, graph: &std::path::Path) -> Result<()> {
        let Some(live_error) = &mut self.live_error else {
            if let Some(out) = &self.live_error_out {
                bail!(
                    "--live-error-out {}: the live error was never on (press L or `--press FRAME:l`)",
                    out.display()
                );
            }
            return Ok(());
        };
        live_error.finish();
        let Some(measure) = live_error.latest() else {
            if let Some(out) = &self.live_error_out {
                bail!(
                    "--live-error-out {}: no measure finished before the viewer quit (give more --frames)",
                    out.display()
                );
            }
            return Ok(());
        };
        println!(
            "live error: HDR-FLIP {:.6} against {} at {} spp",
            measure.flip.mean,
            live_error.graph().display(),
            measure.spp
        );
        if let Some(out) = &self.live_error_out {
            // As `weft compare` writes it, labelled by the graph's name as there.
            let name = graph
                .file_stem()
                .map_or_else(|| "graph".into(), |s| s.to_string_lossy().into_owned());
            weft_compare::report::write_flip_map(&measure.flip, &format!("{name} HDR-FLIP"), out)?;
            println!("wrote {}", out.display());
        }
        Ok(())
    }
}

/// The value of a count or measure image at pixel (`x`, `y`); `None` off
/// the image or for colour images.
fn value_at(image: &weft_gpu::Readback, x: usize, y: usize) -> Option<String> {
    if x >= image.width as usize || y >= image.height as usize {
        return None;
    }
    let at = y * image.width as usize + x;
    match &image.pixels {
        Pixels::CountU32(v) => v.get(at).map(|c| c.to_string()),
        Pixels::ValueF32(v) => v.get(at).map(|c| format!("{c:.4}")),
        _ => None,
    }
}

/// The panel's cost per frame, for the exit summary: CPU time to run it
/// (layout, tessellation, texture uploads), and presenting time (on a CPU
/// device such as lavapipe the overlay's drawing runs inside it) in frames
/// with and without the overlay.
#[derive(Debug, Default)]
pub(super) struct PanelCost {
    ui_ms: Vec<f64>,
    present_with_ms: Vec<f64>,
    present_without_ms: Vec<f64>,
}

impl PanelCost {
    /// Notes one frame: whether the overlay drew, the time to run the UI, to present.
    pub fn record(&mut self, drawn: bool, ui_ms: f64, present_ms: f64) {
        if drawn {
            self.ui_ms.push(ui_ms);
            self.present_with_ms.push(present_ms);
        } else {
            self.present_without_ms.push(present_ms);
        }
    }

    /// `panel: shown in N frames, UI median a ms (CPU), present median b ms
    /// with it, c ms without`; `None` when it never showed.
    pub fn summary(&self) -> Option<String> {
        let median = |v: &[f64]| {
            let mut v = v.to_vec();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied()
        };
        let ui = median(&self.ui_ms)?;
        let with = median(&self.present_with_ms)?;
        let without = median(&self.present_without_ms)
            .map_or_else(|| "no frames".into(), |ms| format!("{ms:.2} ms"));
        Some(format!(
            "panel: shown in {} frames, UI median {ui:.2} ms (CPU: layout, tessellation, uploads); \
             present median {with:.2} ms with it, {without} without",
            self.ui_ms.len()
        ))
    }
}

impl Viewer<'_> {
    /// Passes `event` to the panel; true when the panel took it (a press or
    /// wheel over the panel, typing into a field), so the viewer ignores it.
    pub(super) fn panel_took(&mut self, event: &WindowEvent) -> bool {
        let (Some(overlay), Some(window)) = (self.overlay.as_mut(), self.window.as_ref()) else {
            return false;
        };
        let consumed = overlay.on_window_event(window, event);
        let press = match event {
            WindowEvent::KeyboardInput { event, .. } => event.state == ElementState::Pressed,
            WindowEvent::MouseInput { state, .. } => *state == ElementState::Pressed,
            WindowEvent::MouseWheel { .. } => true,
            _ => false,
        };
        self.ui.panel.visible && consumed && press
    }

    /// Runs the panel (and the live error map) for this frame with the
    /// frame's scripted input; returns what the panel asked for.
    pub(super) fn run_panel(&mut self) -> Result<Vec<PanelAction>> {
        let (Some(overlay), Some(_)) = (self.overlay.as_mut(), self.window.as_ref()) else {
            return Ok(Vec::new());
        };
        let mut events: Vec<egui::Event> = Vec::new();
        let frame = self.frames;
        let due: Vec<UiStep> = self
            .ui
            .script
            .iter()
            .filter(|(f, _)| *f == frame)
            .map(|(_, step)| step.clone())
            .collect();
        self.ui.script.retain(|(f, _)| *f != frame);
        for step in due {
            match step {
                // The widget is scrolled into view first, then pressed where
                // a frame drew it in view.
                UiStep::Click(name) => {
                    self.ui.panel.reveal(&name);
                    self.ui.presses.push((name, frame + CLICK_WAIT_FRAMES));
                }
                typed => self.ui.typing.push((typed, frame + CLICK_WAIT_FRAMES)),
            }
        }
        // Typing waits for a field to have the keyboard (a click gives it one
        // a frame or two after the press) and for earlier clicks.
        if self.ui.presses.is_empty() && overlay.wants_keyboard() {
            for (typed, _) in self.ui.typing.drain(..) {
                match typed {
                    UiStep::Text(text) => events.push(egui::Event::Text(text)),
                    UiStep::Enter => events.extend(script::enter()),
                    UiStep::Click(_) => {}
                }
            }
        } else if let Some((typed, _)) = self.ui.typing.iter().find(|(_, last)| frame >= *last) {
            bail!("--ui {typed:?}: no panel field had the keyboard by frame {frame} (click one first)");
        }
        let waiting = std::mem::take(&mut self.ui.presses);
        for (name, last) in waiting {
            // A click is its press and its release, delivered together as
            // the events they are: however long a frame takes, they are
            // never split across two frames.
            if let Some(rect) = self.ui.panel.target(&name) {
                events.extend(script::pointer(rect.center(), true));
                events.extend(script::pointer(rect.center(), false));
            } else if frame < last {
                self.ui.presses.push((name, last));
            } else {
                bail!(
                    "--ui click:{name}: the panel showed no widget \"{name}\" in view by frame {frame}{}",
                    if self.ui.panel.visible {
                        format!(" (it showed: {})", self.ui.panel.target_names().join(", "))
                    } else {
                        " (it is hidden: press F1 first, `--press FRAME:f1` or --panel)".into()
                    }
                );
            }
        }
        overlay.inject(events);
        if let Some(live_error) = &self.ui.live_error {
            match (live_error.latest(), &self.ui.map) {
                (Some(m), Some((spp, mean, _))) if m.spp == *spp && m.flip.mean == *mean => {}
                (Some(m), _) => {
                    let texture = overlay.context().load_texture(
                        "live error",
                        live_error::map_image(&m.flip),
                        egui::TextureOptions::NEAREST,
                    );
                    self.ui.map = Some((m.spp, m.flip.mean, texture));
                }
                (None, _) => self.ui.map = None,
            }
        }
        self.ui.drawn = self.ui.panel.visible || self.ui.map.is_some();
        if !self.ui.drawn {
            overlay.clear();
            return Ok(Vec::new());
        }
        let camera_block = self.camera_block();
        let (Some(overlay), Some(window)) = (self.overlay.as_mut(), self.window.as_ref()) else {
            return Ok(Vec::new());
        };
        let params = graph_params(self.live.graph().graph());
        let live_status = self.ui.live_error.as_ref().map(LiveError::status);
        let view = PanelView {
            graph: &self.live.settings().graph,
            graphs: &self.graphs,
            features: &self.features,
            plan: self.live.plan(),
            params: &params,
            timings: &self.timings,
            frame_ms: self.stats.mean_ms,
            memory: self.ui.memory,
            draws: self.live.draw_calls(),
            culling: self.live.culling(),
            samples: self.live.samples(),
            animating: self.restarts.animating(),
            paused: self.paused,
            error: self.error.as_deref(),
            reloaded: self.last_reload.as_deref(),
            camera_block: &camera_block,
            bookmarks: (&self.ui.bookmarks, &self.ui.bookmarks_path),
            live_error: live_status.as_ref(),
            under_cursor: self.ui.under_cursor.as_deref(),
            environment: super::environment::environment_view(&self.live, self.environment_turn),
        };
        let panel = &mut self.ui.panel;
        let map = &self.ui.map;
        overlay.run(window, |ui| {
            if let Some((spp, mean, texture)) = map {
                live_error::show_map(ui.ctx(), texture, *mean, *spp);
            }
            if panel.visible {
                panel.show(ui, &view)
            } else {
                Vec::new()
            }
        })
    }

    /// Applies what the panel asked for, at the frame boundary.
    pub(super) fn apply_panel(&mut self, action: PanelAction) {
        let settings = self.live.settings().clone();
        match action {
            PanelAction::Graph(graph) => {
                self.reconfigure(RenderSettings { graph, ..settings });
            }
            PanelAction::Feature(name, on) => {
                let features = controls::toggle(&settings.features, &name, !on);
                self.reconfigure(RenderSettings {
                    features,
                    ..settings
                });
            }
            PanelAction::Param(key, value) => {
                let mut params = settings.params.clone();
                params.insert(key.clone(), value.clone());
                if self.reconfigure(RenderSettings { params, ..settings }) {
                    println!(
                        "parameter {key} = {}",
                        crate::compare_cmd::param_text(&value)
                    );
                }
            }
            action @ (PanelAction::PickEnvironment(_) | PanelAction::TurnEnvironment(_)) => {
                self.apply_environment(action, settings)
            }
            PanelAction::Pause => self.paused = !self.paused,
            PanelAction::PrintCamera => print!("{}", self.camera_block()),
            PanelAction::SaveBookmark => self.save_bookmark(),
            PanelAction::GoToBookmark(index) => {
                if let Some(mark) = self.ui.bookmarks.get(index) {
                    self.camera.position = mark.position(self.live.scene().origin);
                    self.camera.orientation = mark.orientation;
                }
            }
            PanelAction::LiveError(on) => {
                if on != self.ui.live_error.is_some() {
                    self.toggle_live_error();
                }
            }
        }
    }

    /// Starts the live error (its reference at the viewer's view) or stops it.
    pub(super) fn toggle_live_error(&mut self) {
        if self.ui.live_error.take().is_some() {
            self.ui.map = None;
            println!("live error off");
        } else {
            let started = LiveError::start(
                self.gpu,
                &self.ui.scene,
                &self.ui.reference,
                self.live.settings(),
                self.ui.reference_spp,
            );
            match started {
                Ok(live_error) => {
                    println!(
                        "live error on: measuring against {}; scene time held at {:.3} s while it measures (L again lets it run)",
                        live_error.graph().display(),
                        self.time
                    );
                    self.ui.live_error = Some(live_error);
                }
                Err(err) => {
                    self.report_error(format!("live error: {err:#}"));
                    return;
                }
            }
        }
        // The live image is read back for measuring only while the live error is on.
        let settings = self.live.settings().clone();
        self.reconfigure(settings);
    }

    /// Saves the camera as the next bookmark in the bookmarks file.
    pub(super) fn save_bookmark(&mut self) {
        let file = self.ui.bookmarks_path.clone();
        if !self.ui.bookmarks_readable {
            self.report_error(format!(
                "{} could not be read, so bookmarks are not saved over it",
                file.display()
            ));
            return;
        }
        let number = self.ui.bookmarks.len() + 1;
        self.ui.bookmarks.push(Bookmark {
            name: format!("bookmark {number}"),
            world: self.live.scene().origin + self.camera.position.as_dvec3(),
            orientation: self.camera.orientation,
        });
        match bookmarks::save(&file, &self.ui.bookmarks, &self.lens) {
            Ok(()) => println!("saved bookmark {number} to {}", file.display()),
            Err(err) => {
                self.ui.bookmarks.pop();
                self.report_error(format!("{err:#}"));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_gpu::Readback;

    #[test]
    fn the_value_under_the_cursor_is_read_row_by_row() {
        let counts = Readback {
            width: 3,
            height: 2,
            format: "R32_UINT".into(),
            pixels: Pixels::CountU32(vec![0, 1, 2, 3, 4, 5]),
        };
        assert_eq!(value_at(&counts, 1, 1).as_deref(), Some("4"));
        assert_eq!(value_at(&counts, 3, 0), None);
        assert_eq!(value_at(&counts, 0, 2), None);
        let measures = Readback {
            pixels: Pixels::ValueF32(vec![0.5; 6]),
            ..counts
        };
        assert_eq!(value_at(&measures, 2, 1).as_deref(), Some("0.5000"));
    }

    #[test]
    fn the_cost_summary_compares_presenting_with_and_without_the_panel() {
        let mut cost = PanelCost::default();
        assert_eq!(cost.summary(), None);
        for ms in [10.0, 12.0, 11.0] {
            cost.record(false, 0.0, ms);
        }
        for (ui, ms) in [(1.0, 13.0), (3.0, 14.0), (2.0, 12.5)] {
            cost.record(true, ui, ms);
        }
        assert_eq!(
            cost.summary().as_deref(),
            Some(
                "panel: shown in 3 frames, UI median 2.00 ms (CPU: layout, tessellation, uploads); \
                 present median 13.00 ms with it, 11.00 ms without"
            )
        );
    }
}
