//! The viewer's in-window panel (F1): graph picker, features, parameters,
//! per-pass times with their history, memory and draw counts, the compiled
//! plan, progressive convergence, reload status, camera and bookmarks, and
//! the live error against the reference. It only shows and asks: what a
//! click wants done comes back as [`PanelAction`]s, which the viewer applies
//! at the next frame boundary like a hot reload.

mod environment;
mod history;
mod params;

pub use history::History;
use params::param_widget;
pub use params::{graph_params, ParamEntry};

use super::bookmarks::Bookmark;
use egui::{Color32, RichText, Ui};
use egui_plot::{Line, Plot};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use weft_gpu::PassTiming;
use weft_graph::plan::{Plan, Residency};
use weft_graph::schema::{ParamRange, ParamValue};
use weft_render::ViewCulling;

/// What the user asked for through the panel.
#[derive(Debug, Clone, PartialEq)]
pub enum PanelAction {
    /// Render with another graph.
    Graph(PathBuf),
    /// Turn a feature on or off.
    Feature(String, bool),
    /// Set a graph parameter (`--param KEY=VALUE`).
    Param(String, ParamValue),
    /// Stop or resume scene time.
    Pause,
    /// Print the camera as a `.scene` block (it is also copied).
    PrintCamera,
    /// Save the camera as the next bookmark.
    SaveBookmark,
    /// Fly to a bookmark.
    GoToBookmark(usize),
    /// Start or stop the live error against the reference.
    LiveError(bool),
    /// Turn the environment map to this many degrees about +y.
    TurnEnvironment(f32),
    /// Light the scene with this environment map instead.
    PickEnvironment(PathBuf),
}

/// What the live error shows now.
#[derive(Debug, Clone)]
pub struct LiveErrorStatus {
    /// HDR-FLIP of the last measured frame against the reference.
    pub flip: Option<f64>,
    /// The reference's samples per pixel at that measure, and now.
    pub measured_spp: Option<u64>,
    /// Samples per pixel the reference holds now.
    pub reference_spp: u64,
    /// Why it cannot run, when it cannot.
    pub problem: Option<String>,
}

/// Everything the panel shows, gathered by the viewer each frame.
pub struct PanelView<'a> {
    /// The graph rendering now.
    pub graph: &'a Path,
    /// The graphs beside it.
    pub graphs: &'a [PathBuf],
    /// The features a user can switch (the graph's own, then the scene's).
    pub features: &'a [String],
    /// The live plan.
    pub plan: &'a Plan,
    /// Its settable parameters.
    pub params: &'a [ParamEntry],
    /// The last frame's pass times.
    pub timings: &'a [PassTiming],
    /// Mean wall milliseconds per frame, render and present.
    pub frame_ms: f64,
    /// Transient, dedicated and all allocated device bytes.
    pub memory: [u64; 3],
    /// Draw calls of the last frame.
    pub draws: u64,
    /// Meshes drawn and culled per view.
    pub culling: &'a [ViewCulling],
    /// Progressive graphs: samples per pixel now.
    pub samples: Option<u64>,
    /// Whether the progressive image restarts every frame (the scene animates).
    pub animating: bool,
    /// Whether scene time is stopped.
    pub paused: bool,
    /// The last refused reload, file:line first.
    pub error: Option<&'a str>,
    /// The last reload that went live.
    pub reloaded: Option<&'a str>,
    /// The camera as a `.scene` block.
    pub camera_block: &'a str,
    /// Saved bookmarks, and the file they live in.
    pub bookmarks: (&'a [Bookmark], &'a Path),
    /// The live error, when on.
    pub live_error: Option<&'a LiveErrorStatus>,
    /// For a debug view: the value under the cursor.
    pub under_cursor: Option<&'a str>,
    /// The scene's environment map and its turn now, in degrees.
    pub environment: Option<(&'a Path, f32)>,
}

/// The panel's own state between frames.
#[derive(Default)]
pub struct Panel {
    /// Shown (F1).
    pub visible: bool,
    /// Plotted history.
    pub history: History,
    /// Values being edited, by parameter key, until committed.
    /// Per parameter key: the live value last seen, and the value being
    /// edited (it follows the live value whenever a reload changes that).
    edits: HashMap<String, (ParamValue, ParamValue)>,
    /// Where each named widget was last drawn, for scripted clicks (`--ui`).
    targets: HashMap<String, egui::Rect>,
    /// A widget to scroll into view (a scripted click's target).
    reveal: Option<String>,
    /// Widgets drawn out of view in the last frame.
    hidden: std::collections::HashSet<String>,
    /// The width it took in the last frame it showed, in points.
    width: f32,
}

impl Panel {
    /// A panel, shown or hidden.
    pub fn new(visible: bool) -> Self {
        Self {
            visible,
            ..Self::default()
        }
    }

    /// Where the widget `name` (`feature:normals`, `param:exposure`, ...)
    /// was drawn wholly in view in the last frame, in points.
    pub fn target(&self, name: &str) -> Option<egui::Rect> {
        self.targets.get(name).copied()
    }

    /// Scrolls the widget `name` into view in the next frame.
    pub fn reveal(&mut self, name: &str) {
        self.reveal = Some(name.to_string());
    }

    /// Every widget a script can name, sorted (for error messages).
    pub fn target_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.targets.keys().chain(&self.hidden).cloned().collect();
        names.sort();
        names
    }

    /// The width the panel docks beside the 3D view with, in points: 0
    /// while hidden.
    pub fn width(&self) -> f32 {
        if self.visible {
            self.width
        } else {
            0.0
        }
    }

    /// Draws the panel docked on the right of the window, at most three
    /// quarters of it (the 3D view renders in the rest); returns what was
    /// asked.
    pub fn show(&mut self, ui: &mut Ui, view: &PanelView<'_>) -> Vec<PanelAction> {
        self.targets.clear();
        self.hidden.clear();
        let mut actions = Vec::new();
        let most = ui.ctx().content_rect().width() * 0.75;
        let shown = egui::Panel::right("weft panel")
            .resizable(true)
            .default_size(380.0_f32.min(most))
            .max_size(most)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.status(ui, view, &mut actions);
                    self.graph_section(ui, view, &mut actions);
                    self.params_section(ui, view, &mut actions);
                    self.environment_section(ui, view, &mut actions);
                    self.timing_section(ui, view);
                    plan_section(ui, view.plan);
                    self.camera_section(ui, view, &mut actions);
                });
            });
        self.width = shown.response.rect.width();
        actions
    }

    fn remember(&mut self, name: String, response: &egui::Response) {
        if self.reveal.as_ref() == Some(&name) {
            response.scroll_to_me_animation(
                Some(egui::Align::Center),
                egui::style::ScrollAnimation::none(),
            );
            self.reveal = None;
        }
        // A widget can be clicked where it shows: the middle of its part in
        // view, once its middle is in view.
        let shown = response.interact_rect;
        if shown.contains(response.rect.center())
            && response.ctx.content_rect().contains_rect(shown)
        {
            self.targets.insert(name, shown);
        } else {
            self.targets.remove(&name);
            self.hidden.insert(name);
        }
    }

    /// Reload status, the last error (click to copy), progressive state and
    /// the live error.
    fn status(&mut self, ui: &mut Ui, view: &PanelView<'_>, actions: &mut Vec<PanelAction>) {
        ui.heading(view.plan.name.as_str());
        match view.error {
            Some(error) => {
                let label = ui
                    .add(
                        egui::Label::new(RichText::new(error).color(Color32::LIGHT_RED))
                            .sense(egui::Sense::click()),
                    )
                    .on_hover_text(
                        "refused reload; the last good version keeps running. Click to copy",
                    );
                if label.clicked() {
                    ui.ctx().copy_text(error.to_string());
                }
                self.remember("error".into(), &label);
            }
            None => {
                let text = match view.reloaded {
                    Some(files) => format!("reloaded {files}"),
                    None => "watching the graph, its shaders and the scene".into(),
                };
                ui.label(RichText::new(text).color(Color32::LIGHT_GREEN));
            }
        }
        if let Some(spp) = view.samples {
            let rate = self
                .history
                .samples_per_second()
                .map_or_else(String::new, |r| format!(", {r:.1} spp/s"));
            ui.label(format!("{spp} samples per pixel{rate}"));
            if view.animating {
                ui.label(RichText::new(super::controls::ANIMATING).color(Color32::YELLOW));
            }
            let points = self.history.convergence();
            if points.len() > 1 {
                Plot::new("convergence")
                    .height(80.0)
                    .x_axis_label("s since restart")
                    .y_axis_label("spp")
                    .show(ui, |plot| plot.line(Line::new("spp", points)));
            }
        }
        let pause = ui.button(if view.paused {
            "resume time (Space)"
        } else {
            "pause time (Space)"
        });
        if pause.clicked() {
            actions.push(PanelAction::Pause);
        }
        self.remember("pause".into(), &pause);
        ui.horizontal(|ui| {
            let on = view.live_error.is_some();
            let button = ui.button(if on {
                "stop live error (L)"
            } else {
                "live error (L)"
            });
            if button.clicked() {
                actions.push(PanelAction::LiveError(!on));
            }
            self.remember("live_error".into(), &button);
            if let Some(status) = view.live_error {
                let text = match (&status.problem, status.flip, status.measured_spp) {
                    (Some(problem), ..) => problem.clone(),
                    (None, Some(flip), Some(spp)) => format!(
                        "HDR-FLIP {flip:.4} against {spp} spp (reference now {} spp)",
                        status.reference_spp
                    ),
                    _ => format!("reference at {} spp, measuring…", status.reference_spp),
                };
                ui.label(text).on_hover_text(
                    "scene time is held while the live error measures; L lets it run",
                );
            }
        });
        if let Some(value) = view.under_cursor {
            ui.label(format!("under the cursor: {value}"));
        }
    }

    fn graph_section(&mut self, ui: &mut Ui, view: &PanelView<'_>, actions: &mut Vec<PanelAction>) {
        egui::CollapsingHeader::new("graph and features")
            .default_open(true)
            .show(ui, |ui| {
                let name = |p: &Path| {
                    p.file_name().map_or_else(
                        || p.display().to_string(),
                        |n| n.to_string_lossy().into_owned(),
                    )
                };
                let combo = egui::ComboBox::from_id_salt("graph")
                    .selected_text(name(view.graph))
                    .show_ui(ui, |ui| {
                        for g in view.graphs {
                            let selected = super::controls::same_file(g, view.graph);
                            let item = ui.selectable_label(selected, name(g));
                            if item.clicked() && !selected {
                                actions.push(PanelAction::Graph(g.clone()));
                            }
                            self.remember(format!("graph:{}", name(g)), &item);
                        }
                    });
                self.remember("graph".into(), &combo.response);
                let on = |f: &str| view.plan.features.iter().any(|x| x == f);
                let (scene, own): (Vec<&String>, Vec<&String>) = view
                    .features
                    .iter()
                    .partition(|f| weft_render::scene_feature_reason(f).is_some());
                for feature in own {
                    let mut state = on(feature);
                    let check = ui.checkbox(&mut state, feature.as_str());
                    if check.changed() {
                        actions.push(PanelAction::Feature(feature.clone(), state));
                    }
                    self.remember(format!("feature:{feature}"), &check);
                }
                let lit = scene.iter().filter(|f| on(f)).count();
                egui::CollapsingHeader::new(format!("set by the scene ({lit} of {} on)", scene.len()))
                    .show(ui, |ui| {
                        for feature in scene {
                            let reason = weft_render::scene_feature_reason(feature).unwrap_or("");
                            let mut state = on(feature);
                            let text = if state {
                                format!("{feature}: on, {reason}")
                            } else {
                                format!("{feature}: off")
                            };
                            ui.add_enabled(false, egui::Checkbox::new(&mut state, text))
                                .on_disabled_hover_text(
                                    "set from what the scene holds (keys 1-9 and Shift+1-9 still toggle it)",
                                );
                        }
                    });
            });
    }

    fn params_section(
        &mut self,
        ui: &mut Ui,
        view: &PanelView<'_>,
        actions: &mut Vec<PanelAction>,
    ) {
        egui::CollapsingHeader::new("parameters")
            .default_open(true)
            .show(ui, |ui| {
                if view.params.is_empty() {
                    ui.label("this graph declares none");
                }
                for entry in view.params {
                    let (seen, value) = self
                        .edits
                        .entry(entry.key.clone())
                        .or_insert_with(|| (entry.value.clone(), entry.value.clone()));
                    if *seen != entry.value {
                        *seen = entry.value.clone();
                        *value = entry.value.clone();
                    }
                    let (response, commit) = ui
                        .horizontal(|ui| {
                            ui.label(entry.key.as_str())
                                .on_hover_text(range_text(&entry.range));
                            param_widget(ui, &entry.key, value, &entry.range)
                        })
                        .inner;
                    if commit && *value != entry.value {
                        actions.push(PanelAction::Param(entry.key.clone(), value.clone()));
                    }
                    self.remember(format!("param:{}", entry.key), &response);
                }
            });
    }

    fn timing_section(&mut self, ui: &mut Ui, view: &PanelView<'_>) {
        egui::CollapsingHeader::new("time and memory")
            .default_open(true)
            .show(ui, |ui| {
                let timer = view
                    .timings
                    .first()
                    .map_or("no per-pass timer on this device", |t| t.source.label());
                ui.label(format!(
                    "frame {:.2} ms (wall, render and present); passes by {timer}",
                    view.frame_ms
                ));
                let longest = view.timings.iter().map(|t| t.ms).fold(0.0, f64::max);
                for t in view.timings {
                    ui.horizontal(|ui| {
                        let share = if longest > 0.0 {
                            (t.ms / longest) as f32
                        } else {
                            0.0
                        };
                        ui.add(
                            egui::ProgressBar::new(share)
                                .desired_width(120.0)
                                .text(format!("{:.3} ms", t.ms)),
                        );
                        ui.label(t.pass.as_str());
                    });
                }
                let frames = self.history.frame_ms();
                if frames.len() > 1 {
                    Plot::new("frame times")
                        .height(100.0)
                        .y_axis_label("ms")
                        .legend(egui_plot::Legend::default())
                        .show(ui, |plot| {
                            plot.line(Line::new("frame", frames));
                            for t in view.timings {
                                plot.line(Line::new(t.pass.clone(), self.history.pass_ms(&t.pass)));
                            }
                        });
                }
                let [transient, dedicated, allocated] = view.memory;
                ui.label(format!(
                    "memory: transient {} (aliased), own allocations {}, device in use {}",
                    mib(transient),
                    mib(dedicated),
                    mib(allocated)
                ));
                let (drawn, culled) = view
                    .culling
                    .iter()
                    .fold((0, 0), |(d, c), v| (d + v.drawn, c + v.culled));
                ui.label(format!(
                    "{} draw calls; meshes drawn {drawn}, culled {culled} over {} views",
                    view.draws,
                    view.culling.len()
                ));
            });
    }

    fn camera_section(
        &mut self,
        ui: &mut Ui,
        view: &PanelView<'_>,
        actions: &mut Vec<PanelAction>,
    ) {
        // Opened when a scripted click reveals one of its widgets.
        let revealed = self.reveal.as_deref().is_some_and(|r| {
            r == "copy_camera" || r == "save_bookmark" || r.starts_with("bookmark:")
        });
        egui::CollapsingHeader::new("camera and bookmarks")
            .open(revealed.then_some(true))
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    let copy = ui.button("copy as .scene block (C)");
                    if copy.clicked() {
                        ui.ctx().copy_text(view.camera_block.to_string());
                        actions.push(PanelAction::PrintCamera);
                    }
                    self.remember("copy_camera".into(), &copy);
                    let save = ui.button("save bookmark (B)");
                    if save.clicked() {
                        actions.push(PanelAction::SaveBookmark);
                    }
                    self.remember("save_bookmark".into(), &save);
                });
                let (marks, file) = view.bookmarks;
                ui.label(format!("saved in {}", file.display()));
                for (i, mark) in marks.iter().enumerate() {
                    let go = ui.button(format!("go to {}", mark.name));
                    if go.clicked() {
                        actions.push(PanelAction::GoToBookmark(i));
                    }
                    self.remember(format!("bookmark:{}", i + 1), &go);
                }
            });
    }
}

fn range_text(range: &ParamRange) -> String {
    let mut parts = Vec::new();
    if !range.one_of.is_empty() {
        parts.push(format!("one of {:?}", range.one_of));
    }
    if range.integer {
        parts.push("whole number".into());
    }
    if let Some(min) = range.min {
        parts.push(format!("at least {min}"));
    }
    if let Some(max) = range.max {
        parts.push(format!("at most {max}"));
    }
    if parts.is_empty() {
        "any value".into()
    } else {
        parts.join(", ")
    }
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0))
}

/// The compiled plan: passes in order, culled ones greyed with why, and
/// resources with their lifetimes and where aliased ones live.
fn plan_section(ui: &mut Ui, plan: &Plan) {
    egui::CollapsingHeader::new(format!(
        "plan: {} passes, {} culled",
        plan.passes.len(),
        plan.culled.len()
    ))
    .show(ui, |ui| {
        for (i, pass) in plan.passes.iter().enumerate() {
            ui.label(format!("{i:>2} {} ({:?})", pass.name, pass.kind));
        }
        for culled in &plan.culled {
            ui.label(RichText::new(format!("   {}: {}", culled.name, culled.reason)).weak());
        }
        ui.separator();
        let pass_name = |id| {
            plan.passes
                .get(id)
                .map_or("?", |p: &weft_graph::plan::PlanPass| p.name.as_str())
        };
        for resource in plan.resources.iter() {
            let (first, last) = resource.lifetime;
            let place = match (&resource.residency, &resource.placement) {
                (Residency::Transient, Some(p)) => {
                    format!("block {} at {} ({})", p.block, mib(p.offset), mib(p.size))
                }
                (residency, _) => format!("{residency:?}"),
            };
            ui.label(format!(
                "{}: {} → {}, {place}",
                resource.name,
                pass_name(first),
                pass_name(last)
            ));
        }
        ui.label(format!(
            "transient memory {} aliased, {} if each resource had its own",
            mib(plan.memory.transient_bytes),
            mib(plan.memory.transient_bytes_unaliased)
        ));
    });
}
