//! What `weft compare` writes: `report.json` (for scripts), `report.md` and
//! the stdout table (for people), each FLIP error map with its legend, and a
//! contact sheet of every image beside its error map.

use crate::flip::FlipResult;
use crate::image_io::{ImageError, SrgbImage};
use crate::metrics::Spread;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The reference every configuration is measured against.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceInfo {
    /// The graph that rendered it, or `None` for a given image.
    pub graph: Option<PathBuf>,
    /// Its samples per pixel, when rendered.
    pub spp: Option<u64>,
    /// Its seed, when rendered.
    pub seed: Option<u32>,
    /// Its graph parameters (`--reference-param`).
    pub params: BTreeMap<String, String>,
    /// Whether it came from the reference cache.
    pub cached: bool,
    /// The linear image (the cache entry or the given file).
    pub image: PathBuf,
    /// Seconds it took to render (0 when cached or given).
    pub seconds: f64,
    /// Its own noise, when asked for (`--noise-floor`).
    pub noise_floor: Option<NoiseFloor>,
}

/// The reference's noise: HDR-FLIP between it and the same render with
/// another seed. Differences between configurations below it are noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NoiseFloor {
    /// The other render's seed.
    pub seed: u32,
    /// HDR-FLIP between the two renders.
    pub flip: f64,
    /// The other render (linear EXR).
    pub image: PathBuf,
}

/// One pass's time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassTime {
    /// The pass.
    pub name: String,
    /// Median milliseconds over the measured frames.
    pub ms: f64,
    /// How those milliseconds spread.
    pub spread: Spread,
    /// How it was measured: `gpu` timestamps, or `cpu` wall time of the pass
    /// submitted alone (where timestamps are meaningless, e.g. compute on
    /// lavapipe).
    pub timer: String,
    /// For a pass that traces rays, the median over the measured frames of
    /// the rays it traced per output pixel (BVH walks, closest-hit and
    /// shadow rays alike): where the time went.
    pub rays_per_pixel: Option<f64>,
}

/// One configuration's measurements.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Configuration {
    /// A short name: the graph's file stem, with a number when repeated.
    pub name: String,
    /// The graph file.
    pub graph: PathBuf,
    /// The scene features the plan ran with.
    pub features: Vec<String>,
    /// Parameters given on the command line.
    pub params: BTreeMap<String, String>,
    /// HDR-FLIP of the linear image against the reference.
    pub flip: f64,
    /// LDR-FLIP of the tonemapped output against the tonemapped reference.
    pub flip_ldr: f64,
    /// RMSE in linear HDR.
    pub rmse: f64,
    /// Relative MSE in linear HDR.
    pub rel_mse: f64,
    /// PSNR of the tonemapped output in dB.
    pub psnr: f64,
    /// Mean luminance over the reference's (1: the same light overall).
    pub luminance_ratio: f64,
    /// Median wall milliseconds per frame after warm-up.
    pub frame_ms: f64,
    /// How the measured frames' wall times spread (every round's frames).
    pub frame_spread: Spread,
    /// Per-pass times.
    pub passes: Vec<PassTime>,
    /// Bytes of transient (graph) images and buffers.
    pub transient_bytes: u64,
    /// Bytes of device memory allocated in all.
    pub device_bytes: u64,
    /// Where its graph differs from the reference by design (the graph's
    /// `caveats` whose features held): error there is a modelling gap, not
    /// the technique's.
    pub caveats: Vec<String>,
    /// The graph's debug views whose features held (`views` in the file,
    /// e.g. `history_length`: the frames each pixel's temporal history
    /// holds), summarised over the last measured frame, by name.
    pub views: Vec<(String, ViewNumbers)>,
    /// The files written for it.
    pub files: Vec<PathBuf>,
}

/// A debug view's per-pixel numbers over one frame, as `weft render --json`
/// gives them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ViewNumbers {
    /// The mean over the pixels summarised.
    pub mean: f64,
    /// The nearest-rank median.
    pub median: f64,
    /// The nearest-rank 95th percentile.
    pub p95: f64,
    /// The largest value.
    pub max: f64,
}

/// Everything a compare run measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// The scene file.
    pub scene: PathBuf,
    /// The camera.
    pub camera: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The Vulkan device.
    pub device: String,
    /// Frames measured per configuration (after one warm-up frame) in each
    /// round.
    pub frames: u32,
    /// Rounds of measurement: the configurations take turns, A B C A B C.
    pub rounds: u32,
    /// The frame-time budget asked for (`--budget-ms`).
    pub budget_ms: Option<f64>,
    /// Whether LDR-FLIP and PSNR measure each graph's own output, post
    /// effects such as bloom included (`--post`), rather than its HDR image
    /// through the reference's tonemap.
    pub post_effects: bool,
    /// The reference.
    pub reference: ReferenceInfo,
    /// The configurations in command-line order.
    pub configurations: Vec<Configuration>,
}

/// Of `candidates` (name, HDR-FLIP, median frame milliseconds), the most
/// accurate whose median is within `budget` ms (the faster of equals), as a
/// sentence with its margin; or that no `what` is within it.
pub fn within_budget<'a>(
    budget: f64,
    candidates: impl IntoIterator<Item = (&'a str, f64, f64)>,
    what: &str,
) -> String {
    let best = candidates
        .into_iter()
        .filter(|&(_, _, ms)| ms <= budget)
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)));
    match best {
        Some((name, flip, ms)) => format!(
            "Within {budget} ms a frame: **{name}**, the most accurate (HDR-FLIP {flip:.4}) at a median {ms:.2} ms, {:.2} ms to spare.",
            budget - ms
        ),
        None => format!("No {what}'s median frame time is within {budget} ms."),
    }
}

/// The most accurate HDR-FLIP among `candidates` (name, HDR-FLIP), and the
/// names of those within `floor` of it, that one included: what a reference
/// with that noise floor cannot rank by accuracy.
pub fn within_noise<'a>(
    floor: f64,
    candidates: impl IntoIterator<Item = (&'a str, f64)> + Clone,
) -> (f64, Vec<&'a str>) {
    let best = candidates
        .clone()
        .into_iter()
        .map(|(_, flip)| flip)
        .fold(f64::INFINITY, f64::min);
    let tied = candidates
        .into_iter()
        .filter(|&(_, flip)| flip - best < floor)
        .map(|(name, _)| name)
        .collect();
    (best, tied)
}

impl Report {
    /// The table of results, as markdown (also what stdout shows), then the
    /// caveats the configurations' graphs declare, numbered in the table's
    /// last column.
    pub fn table(&self) -> String {
        let notes = self.caveat_notes();
        let mut out = String::from(
            "| configuration | HDR-FLIP | LDR-FLIP | RMSE | rel. MSE | PSNR (dB) | luminance ratio | frame ms: median (IQR) | fastest ms | transient (MiB) | device (MiB) | caveats |\n\
             |---|---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for c in &self.configurations {
            let numbers: Vec<String> = c
                .caveats
                .iter()
                .filter_map(|note| notes.iter().position(|n| n == note))
                .map(|i| (i + 1).to_string())
                .collect();
            out += &format!(
                "| {} | {:.4} | {:.4} | {:.4e} | {:.4e} | {:.2} | {:.3} | {:.2} ({:.2}–{:.2}) | {:.2} | {:.1} | {:.1} | {} |\n",
                c.name,
                c.flip,
                c.flip_ldr,
                c.rmse,
                c.rel_mse,
                c.psnr,
                c.luminance_ratio,
                c.frame_spread.median,
                c.frame_spread.p25,
                c.frame_spread.p75,
                c.frame_spread.min,
                mib(c.transient_bytes),
                mib(c.device_bytes),
                if numbers.is_empty() {
                    "none".to_string()
                } else {
                    numbers.join(", ")
                }
            );
        }
        out += &self.timing_note();
        out += &self.views_note();
        if !notes.is_empty() {
            out += "\nCaveats: where a configuration differs from the reference by design, so part of its error is a modelling gap, not the technique's:\n\n";
            for (i, note) in notes.iter().enumerate() {
                out += &format!("{}. {note}\n", i + 1);
            }
        }
        out
    }

    /// Which configurations the frame times cannot tell from the fastest
    /// (their interquartile ranges overlap its).
    fn timing_note(&self) -> String {
        let Some(fastest) = self
            .configurations
            .iter()
            .min_by(|a, b| a.frame_spread.median.total_cmp(&b.frame_spread.median))
        else {
            return String::new();
        };
        let tied: Vec<&str> = self
            .configurations
            .iter()
            .filter(|c| c.name != fastest.name && c.frame_spread.overlaps(&fastest.frame_spread))
            .map(|c| c.name.as_str())
            .collect();
        if tied.is_empty() {
            return format!(
                "\nFrame times: {} is the fastest, outside every other configuration's interquartile range.\n",
                fastest.name
            );
        }
        format!(
            "\nFrame times: {} has the lowest median, but the interquartile range of {} overlaps its: the timings do not order them.\n",
            fastest.name,
            tied.join(" and ")
        )
    }

    /// The configurations' debug views, one line each, when any has one.
    fn views_note(&self) -> String {
        let lines: Vec<String> = self
            .configurations
            .iter()
            .flat_map(|c| {
                c.views.iter().map(move |(name, v)| {
                    format!(
                        "- {}: {name} mean {:.2}, median {}, p95 {}, max {}\n",
                        c.name, v.mean, v.median, v.p95, v.max
                    )
                })
            })
            .collect();
        if lines.is_empty() {
            return String::new();
        }
        format!(
            "\nDebug views, per pixel over the last frame:\n\n{}",
            lines.concat()
        )
    }

    /// The budget verdict ([`within_budget`]) over the configurations.
    pub fn budget_verdict(&self) -> Option<String> {
        let candidates = self
            .configurations
            .iter()
            .map(|c| (c.name.as_str(), c.flip, c.frame_spread.median));
        Some(within_budget(self.budget_ms?, candidates, "configuration"))
    }

    /// Every configuration's caveats, each once, in the order first met.
    pub fn caveat_notes(&self) -> Vec<&str> {
        let mut notes: Vec<&str> = Vec::new();
        for note in self.configurations.iter().flat_map(|c| &c.caveats) {
            if !notes.contains(&note.as_str()) {
                notes.push(note);
            }
        }
        notes
    }

    /// `report.md`: what was compared, the table, per-pass times, the images.
    pub fn markdown(&self) -> String {
        let reference = match (&self.reference.graph, self.reference.spp) {
            (Some(graph), Some(spp)) => format!(
                "{} at {spp} spp, seed {}{}{}",
                graph.display(),
                self.reference.seed.unwrap_or(0),
                self.reference
                    .params
                    .iter()
                    .map(|(k, v)| format!(", {k}={v}"))
                    .collect::<String>(),
                if self.reference.cached {
                    " (from the reference cache)".to_string()
                } else {
                    format!(", rendered in {:.1} s", self.reference.seconds)
                }
            ),
            _ => format!("the image {}", self.reference.image.display()),
        };
        let mut out = format!(
            "# weft compare: {}\n\nCamera \"{}\", {}x{}, on {}; reference: {reference}. Frame times: {} round(s), the configurations taking turns, each round one warm-up frame and {} measured; medians and interquartile ranges over all measured frames.\n\n",
            self.scene.display(),
            self.camera,
            self.width,
            self.height,
            self.device,
            self.rounds,
            self.frames
        );
        if let Some(floor) = &self.reference.noise_floor {
            let (best, tied) = within_noise(
                floor.flip,
                self.configurations
                    .iter()
                    .map(|c| (c.name.as_str(), c.flip)),
            );
            out += &format!(
                "Reference noise floor: HDR-FLIP {:.4} between this reference and the same render with seed {}; differences in HDR-FLIP smaller than that are the reference's noise. Within it of the most accurate ({best:.4}), so not ranked by accuracy: {}.\n\n",
                floor.flip,
                floor.seed,
                tied.join(", ")
            );
        }
        if let Some(verdict) = self.budget_verdict() {
            out += &verdict;
            out += "\n\n";
        }
        out += if self.post_effects {
            "LDR-FLIP and PSNR measure each configuration's own output, post effects such as bloom included (`--post`); the reference has none.\n\n"
        } else {
            "LDR-FLIP and PSNR measure each configuration's HDR image through the reference's tonemap, so post effects the reference does not model (bloom) are not counted as error (`--post` counts them).\n\n"
        };
        out += &self.table();
        out += "\n## Passes\n\nRays per pixel: the rays a pass traced per output pixel each frame (median), where it traces.\n\n| configuration | pass | ms: median (IQR) | rays per pixel | timer |\n|---|---|---|---|---|\n";
        for c in &self.configurations {
            for p in &c.passes {
                let rays = p
                    .rays_per_pixel
                    .map_or_else(|| "–".to_string(), |r| format!("{r:.3}"));
                out += &format!(
                    "| {} | {} | {:.3} ({:.3}–{:.3}) | {rays} | {} |\n",
                    c.name, p.name, p.ms, p.spread.p25, p.spread.p75, p.timer
                );
            }
        }
        out += "\n## Images\n\nEach configuration's output and its HDR-FLIP error map (magma: black 0, yellow 1).\n\n![contact sheet](contact_sheet.png)\n";
        out
    }
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

/// The family the embedded font is registered under.
pub(crate) const FAMILY: &str = "sans-serif";

/// Registers the embedded DejaVu Sans, once, so text does not depend on
/// system fonts.
pub(crate) fn ensure_font() -> Result<(), ImageError> {
    static FONT: OnceLock<Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| {
        register_font(FAMILY, FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| "the embedded DejaVu Sans is not a usable TrueType font".to_string())
    })
    .clone()
    .map_err(|message| ImageError::Write {
        path: PathBuf::from("(font)"),
        message,
    })
}

fn drawing_error(path: &Path, e: impl std::fmt::Display) -> ImageError {
    ImageError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Draws on a white `w` x `h` canvas with `draw` and writes it to `path` as PNG
/// (with the image crate the rest of weft uses, not plotters' own encoder).
pub(crate) fn draw_png(
    w: u32,
    h: u32,
    path: &Path,
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<(), ImageError>,
) -> Result<(), ImageError> {
    ensure_font()?;
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| drawing_error(path, e))?;
        draw(&root)?;
        root.present().map_err(|e| drawing_error(path, e))?;
    }
    SrgbImage {
        width: w,
        height: h,
        bytes: buffer,
    }
    .write_png(path)
}

/// Height of the legend strip under an error map.
const LEGEND: u32 = 44;

/// Writes `flip`'s error map in magma with a legend under it: the colour bar
/// from 0 to 1 and the mean.
pub fn write_flip_map(flip: &FlipResult, label: &str, path: &Path) -> Result<(), ImageError> {
    let magma = flip.magma();
    let bar = FlipResult {
        width: 256,
        height: 1,
        map: (0..256).map(|i| i as f32 / 255.0).collect(),
        mean: 0.0,
        exposures: None,
    }
    .magma();
    let (w, h) = (magma.width.max(240), magma.height + LEGEND);
    draw_png(w, h, path, |root| {
        blit(root, &magma, 0, 0).map_err(|e| drawing_error(path, e))?;
        let bar_width = w - 40;
        for x in 0..bar_width {
            let i = (x * 255 / (bar_width - 1).max(1)) as usize;
            let c = RGBColor(bar.bytes[3 * i], bar.bytes[3 * i + 1], bar.bytes[3 * i + 2]);
            for y in 0..10 {
                root.draw_pixel((20 + x as i32, (magma.height + 4 + y) as i32), &c)
                    .map_err(|e| drawing_error(path, e))?;
            }
        }
        let style = (FAMILY, 13).into_font().color(&BLACK);
        let text_y = (magma.height + 18) as i32;
        for (text, x) in [
            ("0".to_string(), 16),
            ("1".to_string(), w as i32 - 24),
            (format!("{label}: mean {:.4}", flip.mean), 40),
        ] {
            root.draw_text(&text, &style, (x, text_y))
                .map_err(|e| drawing_error(path, e))?;
        }
        Ok(())
    })
}

fn blit<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    image: &SrgbImage,
    x0: u32,
    y0: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for y in 0..image.height {
        for x in 0..image.width {
            let i = 3 * (y * image.width + x) as usize;
            let c = RGBColor(image.bytes[i], image.bytes[i + 1], image.bytes[i + 2]);
            area.draw_pixel(((x0 + x) as i32, (y0 + y) as i32), &c)?;
        }
    }
    Ok(())
}

/// One column of the contact sheet: a label, the image, and its error map
/// (none for the reference).
pub struct SheetColumn<'a> {
    /// Shown above the image.
    pub label: String,
    /// The tonemapped image.
    pub image: &'a SrgbImage,
    /// Its error map and mean.
    pub flip: Option<&'a FlipResult>,
}

/// Writes every image side by side with its error map under it, labelled, as
/// one PNG (the images scaled down to at most 320 pixels wide).
pub fn write_contact_sheet(columns: &[SheetColumn<'_>], path: &Path) -> Result<(), ImageError> {
    let Some(first) = columns.first() else {
        return Ok(());
    };
    let step = first.image.width.div_ceil(320).max(1);
    let (cw, ch) = (first.image.width / step, first.image.height / step);
    let label_height = 22;
    let (w, h) = (
        columns.len() as u32 * (cw + 8) + 8,
        label_height * 2 + 2 * ch + 24,
    );
    draw_png(w, h, path, |root| {
        let style = (FAMILY, 14).into_font().color(&BLACK);
        for (i, column) in columns.iter().enumerate() {
            let x0 = 8 + i as u32 * (cw + 8);
            root.draw_text(&column.label, &style, (x0 as i32, 4))
                .map_err(|e| drawing_error(path, e))?;
            blit(root, &downscale(column.image, step), x0, label_height)
                .map_err(|e| drawing_error(path, e))?;
            if let Some(flip) = column.flip {
                let y = label_height + ch + 4;
                root.draw_text(
                    &format!("HDR-FLIP {:.4}", flip.mean),
                    &style,
                    (x0 as i32, y as i32),
                )
                .map_err(|e| drawing_error(path, e))?;
                blit(root, &downscale(&flip.magma(), step), x0, y + label_height)
                    .map_err(|e| drawing_error(path, e))?;
            }
        }
        Ok(())
    })
}

/// Every `step`-th pixel of `image` (nearest, no filtering: error maps stay sharp).
fn downscale(image: &SrgbImage, step: u32) -> SrgbImage {
    if step <= 1 {
        return image.clone();
    }
    let (w, h) = (image.width / step, image.height / step);
    let mut bytes = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let i = 3 * ((y * step) * image.width + x * step) as usize;
            bytes.extend_from_slice(&image.bytes[i..i + 3]);
        }
    }
    SrgbImage {
        width: w,
        height: h,
        bytes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within the floor of the best means a difference strictly below it.
    #[test]
    fn within_noise_names_the_best_and_those_less_than_the_floor_above_it() {
        let candidates = [("a", 0.20), ("b", 0.10), ("c", 0.149), ("d", 0.16)];
        let (best, tied) = within_noise(0.05, candidates);
        assert_eq!(best, 0.10);
        assert_eq!(tied, ["b", "c"]);
        assert_eq!(within_noise(0.0, candidates).1, Vec::<&str>::new());
    }
}
