//! What the viewer shows and keeps: the 3D view's size beside the docked
//! panel, the window's title, and screenshots.

use super::super::controls::{self, Status};
use super::Viewer;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use weft_gpu::Readback;
use weft_graph::plan::Extent;
use weft_render::RenderSettings;

/// How often the title's times are refreshed.
const TITLE_EVERY: Duration = Duration::from_millis(500);

impl Viewer<'_> {
    /// Prints the graph's features with their keys and whether each is on.
    pub(super) fn print_features(&self) {
        let on = &self.live.plan().features;
        let list: Vec<String> = self
            .features
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                let state = if on.contains(f) { "on" } else { "off" };
                controls::feature_key(i).map(|key| format!("{key} {f} [{state}]"))
            })
            .collect();
        println!(
            "graph {}: features {}",
            self.live.settings().graph.display(),
            if list.is_empty() {
                "none".to_string()
            } else {
                list.join(", ")
            }
        );
    }

    /// Rebuilds the swapchain and the plan for a window of `size` pixels.
    pub(super) fn resize(&mut self, size: [u32; 2]) -> Result<()> {
        if let Some(presenter) = self.presenter.as_mut() {
            let current = presenter.extent();
            if [current.width, current.height] != size {
                presenter.resize(size)?;
            }
        }
        let extent = self.view_extent(size);
        if self.live.settings().extent != extent {
            let settings = RenderSettings {
                extent,
                ..self.live.settings().clone()
            };
            self.reconfigure(settings);
        }
        Ok(())
    }

    /// The 3D view's size in a window of `size` pixels: the window less the
    /// panel docked on its right, at least one pixel wide.
    pub(super) fn view_extent(&self, size: [u32; 2]) -> Extent {
        let ppp = self.overlay.as_ref().map_or(1.0, |o| o.pixels_per_point());
        let docked = (self.ui.panel.width() * ppp).round() as u32;
        Extent {
            width: size[0].saturating_sub(docked).max(1),
            height: size[1],
        }
    }

    /// Saves an F12 screenshot when one was asked for (a failure is
    /// reported and the viewer goes on: a key press never closes it), and
    /// the `--screenshot-on-exit` one (whose failure fails the command).
    pub(super) fn save_screenshots(&mut self, pixels: &Readback, on_exit: bool) -> Result<()> {
        if self.screenshot_now {
            self.screenshot_now = false;
            self.screenshots += 1;
            let stamp = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            let saved = self
                .screenshot_dir
                .as_ref()
                .context(
                    "no folder for screenshots: give --screenshot-dir (there is no pictures folder, WEFT_CACHE_DIR or HOME)",
                )
                .and_then(|dir| {
                    save(pixels, &dir.join(format!("weft-{stamp}-{}.png", self.screenshots)))
                });
            if let Err(err) = saved {
                eprintln!("error: screenshot not saved: {err:#} (the viewer goes on)");
            }
        }
        if on_exit {
            if let Some(path) = self.screenshot_on_exit.clone() {
                save(pixels, &path)?;
            }
        }
        Ok(())
    }

    /// Shows the graph, features and times in the title, at most every
    /// [`TITLE_EVERY`] unless `now`.
    pub(super) fn update_title(&mut self, now: bool) {
        let since = *self.stats.since.get_or_insert_with(Instant::now);
        if !now && since.elapsed() < TITLE_EVERY {
            return;
        }
        if self.stats.frames > 0 {
            self.stats.mean_ms = self.stats.total_ms / f64::from(self.stats.frames);
        }
        self.stats.total_ms = 0.0;
        self.stats.frames = 0;
        self.stats.since = Some(Instant::now());
        let title = controls::title(&Status {
            graph: &self.live.settings().graph,
            features: &self.live.plan().features,
            frame_ms: self.stats.mean_ms,
            timings: &self.timings,
            error: self.error.as_deref(),
            samples: self.live.samples(),
            animating: self.restarts.animating(),
        });
        if let Some(window) = &self.window {
            window.set_title(&title);
        }
    }
}

/// The default screenshot folder: `weft` in the user's pictures folder when
/// there is one, else `screenshots` in the user cache.
pub(super) fn screenshot_folder(
    pictures: Option<PathBuf>,
    cache: Option<PathBuf>,
) -> Option<PathBuf> {
    pictures
        .map(|p| p.join("weft"))
        .or_else(|| cache.map(|c| c.join("screenshots")))
}

/// Writes a screenshot and says where.
fn save(pixels: &Readback, path: &Path) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    pixels.save(path)?;
    println!("wrote {}", path.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screenshots_go_to_the_pictures_folder_else_the_user_cache() {
        let pictures = Some(PathBuf::from("/home/u/Pictures"));
        let cache = Some(PathBuf::from("/home/u/.cache/weft"));
        assert_eq!(
            screenshot_folder(pictures, cache.clone()),
            Some(PathBuf::from("/home/u/Pictures/weft"))
        );
        assert_eq!(
            screenshot_folder(None, cache),
            Some(PathBuf::from("/home/u/.cache/weft/screenshots"))
        );
        assert_eq!(screenshot_folder(None, None), None);
    }
}
