//! Watching files for hot reload with `notify`, debounced. Parent directories are
//! watched rather than files, so an editor that writes a temporary file and renames
//! it over the original is still seen; a batch is handed out only after no event
//! for a quiet period, so bursts (truncate, then several writes) come as one change
//! and the files are read after the editor stopped writing.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, TryRecvError};
use std::time::{Duration, Instant};

use notify::event::{AccessKind, AccessMode, EventKind};
use notify::{RecommendedWatcher, RecursiveMode, Watcher};

use crate::sources::normalize;

/// How long the watched files must stay untouched before a batch is handed out:
/// longer than the gaps inside one editor save, short enough to feel immediate.
pub const QUIET: Duration = Duration::from_millis(50);

/// Why watching failed.
#[derive(Debug, thiserror::Error)]
pub enum WatchError {
    /// The operating system's watcher refused (too many watches, missing folder).
    #[error("watching {}: {source}", path.display())]
    Notify {
        /// The folder being watched.
        path: PathBuf,
        /// What notify said.
        source: notify::Error,
    },
    /// The watcher stopped delivering events.
    #[error("the file watcher stopped")]
    Stopped,
}

/// Watches a set of files and hands out debounced batches of the ones that changed.
pub struct FileWatcher {
    watcher: RecommendedWatcher,
    events: Receiver<notify::Result<notify::Event>>,
    files: BTreeSet<PathBuf>,
    dirs: BTreeSet<PathBuf>,
    quiet: Duration,
    /// Files `poll_batch` has seen change, with when the last one did, until
    /// they have been quiet long enough to hand out.
    gathering: BTreeSet<PathBuf>,
    last_change: Option<Instant>,
}

/// Whether an event can mean new contents (opening or reading a file cannot).
fn changes_contents(kind: &EventKind) -> bool {
    match kind {
        EventKind::Access(AccessKind::Close(AccessMode::Write)) => true,
        EventKind::Access(_) => false,
        _ => true,
    }
}

impl FileWatcher {
    /// A watcher with nothing watched yet that waits `quiet` before handing out a batch.
    pub fn new(quiet: Duration) -> Result<Self, WatchError> {
        let (send, events) = channel();
        let watcher = notify::recommended_watcher(move |event| {
            let _ = send.send(event);
        })
        .map_err(|source| WatchError::Notify {
            path: PathBuf::new(),
            source,
        })?;
        Ok(Self {
            watcher,
            events,
            files: BTreeSet::new(),
            dirs: BTreeSet::new(),
            quiet,
            gathering: BTreeSet::new(),
            last_change: None,
        })
    }

    /// Watches exactly `files` (normalized paths) from now on: their folders are
    /// watched, folders no longer needed are let go; files in folders that do not
    /// exist are skipped (an include naming a missing folder is the loader's error).
    pub fn watch(&mut self, files: &BTreeSet<PathBuf>) -> Result<(), WatchError> {
        let dirs: BTreeSet<PathBuf> = files
            .iter()
            .filter_map(|f| f.parent())
            .filter(|d| d.is_dir())
            .map(Path::to_path_buf)
            .collect();
        for gone in self.dirs.difference(&dirs) {
            let _ = self.watcher.unwatch(gone);
        }
        for dir in dirs.difference(&self.dirs) {
            self.watcher
                .watch(dir, RecursiveMode::NonRecursive)
                .map_err(|source| WatchError::Notify {
                    path: dir.clone(),
                    source,
                })?;
        }
        self.dirs = dirs;
        self.files = files.clone();
        Ok(())
    }

    /// The watched files an event names.
    fn relevant(&self, event: notify::Result<notify::Event>) -> Vec<PathBuf> {
        match event {
            Ok(event) if changes_contents(&event.kind) => event
                .paths
                .iter()
                .map(|p| normalize(p))
                .filter(|p| self.files.contains(p))
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Waits up to `timeout` for a watched file to change, then until none has
    /// changed for the quiet period; returns the changed files, or an empty set
    /// when nothing changed in time.
    pub fn next_batch(&mut self, timeout: Duration) -> Result<BTreeSet<PathBuf>, WatchError> {
        let mut changed = std::mem::take(&mut self.gathering);
        self.last_change = None;
        let deadline = Instant::now() + timeout;
        while changed.is_empty() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.events.recv_timeout(left) {
                Ok(event) => changed.extend(self.relevant(event)),
                Err(RecvTimeoutError::Timeout) => return Ok(changed),
                Err(RecvTimeoutError::Disconnected) => return Err(WatchError::Stopped),
            }
        }
        let mut last = Instant::now();
        loop {
            let left = self.quiet.saturating_sub(last.elapsed());
            match self.events.recv_timeout(left) {
                Ok(event) => {
                    let paths = self.relevant(event);
                    if !paths.is_empty() {
                        last = Instant::now();
                        changed.extend(paths);
                    }
                }
                Err(RecvTimeoutError::Timeout) => return Ok(changed),
                Err(RecvTimeoutError::Disconnected) => return Err(WatchError::Stopped),
            }
        }
    }

    /// Never waits: gathers the changes reported so far and hands them out once
    /// none has come for the quiet period (an empty set before that), so a frame
    /// loop can poll it every frame without the debounce stalling a frame.
    pub fn poll_batch(&mut self) -> Result<BTreeSet<PathBuf>, WatchError> {
        loop {
            match self.events.try_recv() {
                Ok(event) => {
                    let paths = self.relevant(event);
                    if !paths.is_empty() {
                        self.last_change = Some(Instant::now());
                        self.gathering.extend(paths);
                    }
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return Err(WatchError::Stopped),
            }
        }
        match self.last_change {
            Some(at) if at.elapsed() >= self.quiet => {
                self.last_change = None;
                Ok(std::mem::take(&mut self.gathering))
            }
            _ => Ok(BTreeSet::new()),
        }
    }
}
