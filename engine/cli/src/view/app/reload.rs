//! The viewer's side of hot reload: switching settings all-or-nothing,
//! watching the live version's files, committing reloads the worker prepared,
//! and showing why an edit was refused.

use super::super::controls::{self};
use super::{ReloadProgress, Viewer};
use anyhow::Result;
use std::time::Instant;
use weft_render::{Committed, RenderSettings};

impl Viewer<'_> {
    /// Switches the live render to `settings`; a refusal keeps the last good version.
    pub(super) fn reconfigure(&mut self, settings: RenderSettings) -> bool {
        let settings = self.ui.with_readback(settings);
        let graph_changed = settings.graph != self.live.settings().graph;
        let features_changed = settings.features != self.live.settings().features;
        match self.live.reconfigure(settings) {
            Ok(()) => {
                if graph_changed {
                    self.features = controls::graph_features(self.live.graph());
                }
                if graph_changed || features_changed {
                    self.print_features();
                }
                self.watch();
                self.error = None;
                true
            }
            Err(err) => {
                self.report_error(err.to_string());
                false
            }
        }
    }

    pub(super) fn report_error(&mut self, error: String) {
        eprintln!("error: {error} (kept last good)");
        self.error = Some(error);
        self.update_title(true);
    }

    pub(super) fn watch(&mut self) {
        if let Err(err) = self.watcher.watch(&self.live.sources().all()) {
            eprintln!("error: {err} (still watching the other files)");
        }
    }

    /// Hands edited files, if any, to the worker (superseding a reload still
    /// being prepared), and commits the newest prepared reload, if one is ready.
    pub(super) fn hot_reload(&mut self) -> Result<()> {
        let changed = self.watcher.poll_batch()?;
        if !changed.is_empty() {
            self.reload.get_or_insert(ReloadProgress {
                taken: Instant::now(),
                frames: 0,
                longest_ms: 0.0,
            });
            let job = self.live.files_job(&changed);
            self.worker.submit(job);
        }
        let Some(prepared) = self.worker.poll() else {
            return Ok(());
        };
        let prepare_ms = prepared.elapsed.as_secs_f64() * 1e3;
        let committed = prepared.result.and_then(|reload| self.live.commit(reload));
        match committed {
            Ok(Committed::Applied(paths)) => {
                self.watch();
                self.error = None;
                let progress = self.reload.take();
                if let (false, Some(progress)) = (paths.is_empty(), progress) {
                    let files: Vec<String> =
                        paths.iter().map(|p| p.display().to_string()).collect();
                    self.last_reload = Some(files.join(", "));
                    self.reloaded = Some((files.join(", "), progress, prepare_ms));
                }
            }
            Ok(Committed::Stale) => {
                let job = self.live.files_job(&Default::default());
                self.worker.submit(job);
            }
            Err(err) => {
                self.reload = None;
                self.report_error(err.to_string());
            }
        }
        Ok(())
    }
}
