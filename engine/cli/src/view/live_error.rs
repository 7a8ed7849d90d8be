//! Live error (L): a path-traced reference of the viewer's current view,
//! accumulated one frame per viewer frame, and the HDR-FLIP map of the frame
//! on screen against it — the same measure `weft compare` reports, computed
//! off the frame loop and shown over the image with its number and legend,
//! updating as the reference converges. Moving the camera restarts the
//! reference (the path tracer's own accumulation does).

use super::panel::LiveErrorStatus;
use anyhow::{anyhow, Context, Result};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};
use weft_compare::{hdr_flip, FlipResult, LinearImage};
use weft_gpu::{FrameReport, Gpu};
use weft_graph::plan::Extent;
use weft_render::{LiveRender, RenderSettings};
use weft_scene::Camera;

/// The shortest time between two measures while the reference converges.
const MEASURE_EVERY: Duration = Duration::from_millis(750);

/// A measure: the reference's samples per pixel, and the map.
pub struct Measure {
    /// Samples per pixel of the reference measured against.
    pub spp: u64,
    /// The HDR-FLIP map and mean.
    pub flip: FlipResult,
}

/// The reference and the measures against it.
pub struct LiveError<'g> {
    reference: LiveRender<'g>,
    /// Stop adding samples here (`--reference-spp`).
    max_spp: Option<u64>,
    frame: u32,
    /// A measure being computed off the frame loop, and the spp it is against.
    pending: Option<(u64, Receiver<FlipResult>)>,
    /// The latest measure finished.
    latest: Option<Measure>,
    /// When a measure last started.
    started: Option<Instant>,
    /// The reference's last image read back, and its samples per pixel.
    image: Option<(u64, LinearImage)>,
    /// The viewer's image last measured.
    test: Option<LinearImage>,
    /// Why the live image cannot be measured (no linear image read back).
    problem: Option<String>,
}

impl<'g> LiveError<'g> {
    /// Loads the reference graph for `scene` at the viewer's size, with the
    /// viewer's feature toggles the reference knows.
    pub fn start(
        gpu: &'g Gpu,
        scene: &Path,
        reference: &Path,
        viewer: &RenderSettings,
        max_spp: Option<u64>,
    ) -> Result<Self> {
        let settings = reference_settings(reference, viewer)?;
        let reference = LiveRender::new(gpu, scene, settings).map_err(|e| anyhow!("{e}"))?;
        Ok(Self {
            reference,
            max_spp,
            frame: 0,
            pending: None,
            latest: None,
            started: None,
            image: None,
            test: None,
            problem: None,
        })
    }

    /// The reference graph file.
    pub fn graph(&self) -> &Path {
        &self.reference.settings().graph
    }

    /// Whether the viewer should read its next frame back for a measure:
    /// no measure is in flight, the last began long enough ago, and the
    /// reference will hold samples the last measure did not see.
    pub fn due(&self) -> bool {
        let spp = self.reference.samples().unwrap_or(0);
        let full = self.max_spp.is_some_and(|max| spp >= max);
        let unseen = !full || self.latest.as_ref().is_none_or(|m| m.spp < spp);
        // The last frame before `--reference-spp` and the full reference are
        // measured however soon after the previous measure.
        let rested = self.started.is_none_or(|t| t.elapsed() >= MEASURE_EVERY)
            || self.reaches_max(spp)
            || full;
        self.pending.is_none() && self.problem.is_none() && unseen && rested
    }

    /// Whether one more frame takes the reference to `--reference-spp`.
    fn reaches_max(&self, spp: u64) -> bool {
        let per_frame = u64::from(self.reference.plan().samples_per_frame.unwrap_or(1));
        self.max_spp
            .is_some_and(|max| spp < max && spp + per_frame >= max)
    }

    /// Adds one frame of samples seen from `camera` at `time` (none once
    /// `--reference-spp` is reached); `extent` follows the window. With the
    /// viewer's frame (read back, its linear image first, because
    /// [`LiveError::due`] said so), starts measuring it against the
    /// reference off the frame loop.
    pub fn step(
        &mut self,
        (camera, time, extent): (&Camera, f64, Extent),
        viewer: Option<(&FrameReport, &Path)>,
    ) -> Result<()> {
        if self.reference.settings().extent != extent {
            let settings = RenderSettings {
                extent,
                ..self.reference.settings().clone()
            };
            self.reference
                .reconfigure(settings)
                .map_err(|e| anyhow!("{e}"))?;
            self.latest = None;
            self.image = None;
        }
        let before = self.reference.samples().unwrap_or(0);
        if self.max_spp.is_none_or(|max| before < max) {
            let read = viewer.is_some() || self.reaches_max(before);
            let report = self.reference.draw(camera, time, self.frame, read)?;
            self.frame += 1;
            let spp = self.reference.samples().unwrap_or(0);
            if spp < before || self.latest.as_ref().is_some_and(|m| spp < m.spp) {
                // A moved camera restarted the reference: earlier images are stale.
                self.latest = None;
                self.image = None;
            }
            if read {
                let (_, image) = report.readbacks.first().with_context(|| {
                    format!("{} reads back no linear image", self.graph().display())
                })?;
                self.image = Some((spp, crate::compare_cmd::linear(image)));
            }
        }
        self.collect();
        if let Some((report, graph)) = viewer {
            self.measure(report, graph)?;
        }
        Ok(())
    }

    /// Measures the viewer's frame against the reference image kept last.
    fn measure(&mut self, viewer: &FrameReport, graph: &Path) -> Result<()> {
        let Some((_, image)) = viewer.readbacks.first() else {
            self.problem = Some(format!(
                "{} reads back no linear image (`readback: [\"hdr\"]`), so it cannot be measured",
                graph.display()
            ));
            return Ok(());
        };
        let Some((spp, reference)) = self.image.clone() else {
            return Ok(());
        };
        let test = crate::compare_cmd::linear(image);
        if (test.width, test.height) != (reference.width, reference.height) {
            return Ok(());
        }
        self.test = Some(test.clone());
        let (send, receive) = mpsc::channel();
        std::thread::Builder::new()
            .name("live error".into())
            .spawn(move || {
                let _ = send.send(hdr_flip(&reference, &test));
            })
            .context("starting the live error's thread")?;
        self.pending = Some((spp, receive));
        self.started = Some(Instant::now());
        Ok(())
    }

    /// Takes a finished measure.
    fn collect(&mut self) {
        if let Some((spp, receive)) = &self.pending {
            match receive.try_recv() {
                Ok(flip) => {
                    self.latest = Some(Measure { spp: *spp, flip });
                    self.pending = None;
                }
                Err(mpsc::TryRecvError::Empty) => {}
                Err(mpsc::TryRecvError::Disconnected) => self.pending = None,
            }
        }
    }

    /// At exit: waits for the measure in flight, then measures the frame
    /// last measured against the reference's newest image if that holds more
    /// samples, so the last measure reported is against all of them.
    pub fn finish(&mut self) {
        if let Some((spp, receive)) = self.pending.take() {
            if let Ok(flip) = receive.recv() {
                self.latest = Some(Measure { spp, flip });
            }
        }
        let newer = match (&self.image, &self.latest) {
            (Some((spp, _)), Some(m)) => *spp > m.spp,
            (Some(_), None) => true,
            _ => false,
        };
        if let (true, Some((spp, reference)), Some(test)) = (newer, &self.image, &self.test) {
            self.latest = Some(Measure {
                spp: *spp,
                flip: hdr_flip(reference, test),
            });
        }
    }

    /// Says why the live image cannot be measured (`None`: it can).
    pub fn set_problem(&mut self, problem: Option<String>) {
        self.problem = problem;
    }

    /// The latest measure.
    pub fn latest(&self) -> Option<&Measure> {
        self.latest.as_ref()
    }

    /// What the panel says.
    pub fn status(&self) -> LiveErrorStatus {
        LiveErrorStatus {
            flip: self.latest.as_ref().map(|m| m.flip.mean),
            measured_spp: self.latest.as_ref().map(|m| m.spp),
            reference_spp: self.reference.samples().unwrap_or(0),
            problem: self.problem.clone(),
        }
    }
}

/// The reference's settings: its graph at the viewer's size, seen through
/// the viewer's camera (given each frame), with the viewer's toggles it knows.
fn reference_settings(reference: &Path, viewer: &RenderSettings) -> Result<RenderSettings> {
    let settings = RenderSettings {
        graph: reference.to_path_buf(),
        extent: viewer.extent,
        cache_dir: viewer.cache_dir.clone(),
        ..RenderSettings::default()
    };
    let graph = weft_render::load_graph(&settings)?;
    if graph.graph().progressive.is_none() {
        return Err(anyhow!(
            "{} is not progressive: the live error's reference must converge over frames (graphs/pathtrace.ron)",
            reference.display()
        ));
    }
    Ok(RenderSettings {
        features: graph.known_toggles(&viewer.features),
        extra_readback: graph.graph().readback_names(),
        ..settings
    })
}

/// The reference graph beside the viewer's graphs: `pathtrace.ron` in the
/// same folder when there is one, else the repository's.
pub fn default_reference(graph: &Path) -> PathBuf {
    let beside = graph.with_file_name("pathtrace.ron");
    if beside.exists() {
        beside
    } else {
        PathBuf::from("graphs/pathtrace.ron")
    }
}

/// Draws a measure's map (`texture`) over the whole window, behind the panel, with its
/// number and a magma legend at the bottom left.
pub fn show_map(ctx: &egui::Context, texture: &egui::TextureHandle, mean: f64, spp: u64) {
    let screen = ctx.content_rect();
    let painter = ctx.layer_painter(egui::LayerId::background());
    painter.image(
        texture.id(),
        screen,
        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
        egui::Color32::WHITE,
    );
    egui::Area::new(egui::Id::new("live error legend"))
        .anchor(egui::Align2::LEFT_BOTTOM, egui::vec2(8.0, -8.0))
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.label(format!("HDR-FLIP {mean:.4} vs reference, {spp} spp"));
                let (rect, _) =
                    ui.allocate_exact_size(egui::vec2(256.0, 12.0), egui::Sense::hover());
                for step in 0..256 {
                    let c = colorous::MAGMA.eval_rational(step, 256);
                    let x = rect.left() + step as f32;
                    ui.painter().rect_filled(
                        egui::Rect::from_min_max(
                            egui::pos2(x, rect.top()),
                            egui::pos2(x + 1.0, rect.bottom()),
                        ),
                        0.0,
                        egui::Color32::from_rgb(c.r, c.g, c.b),
                    );
                }
                ui.horizontal(|ui| {
                    ui.label("0");
                    ui.add_space(220.0);
                    ui.label("1");
                });
            });
        });
}

/// The map as an egui image (magma, as `weft compare` writes it).
pub fn map_image(flip: &FlipResult) -> egui::ColorImage {
    let magma = flip.magma();
    egui::ColorImage::from_rgb([magma.width as usize, magma.height as usize], &magma.bytes)
}
