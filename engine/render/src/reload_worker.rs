//! Prepares reloads on a worker thread so a frame loop keeps presenting while
//! edits are loaded and checked. Each request gets a generation; a newer edit
//! supersedes an older one (queued jobs are skipped, finished stale results
//! dropped), so only the newest request's result reaches the frame thread,
//! which commits it at a frame boundary.

use crate::prepare::{PreparedReload, ReloadJob, ShaderChecker};
use crate::reload_error::ReloadError;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::thread::{Scope, ThreadId};
use std::time::{Duration, Instant};
use weft_gpu::Gpu;

/// Which result is worth committing: requests are numbered in order and only
/// the newest one's result is kept. Pure bookkeeping, apart from threads.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Generations {
    issued: u64,
    answered: bool,
}

impl Generations {
    /// Numbers a new request; it supersedes every earlier one.
    pub fn issue(&mut self) -> u64 {
        self.issued += 1;
        self.answered = false;
        self.issued
    }

    /// Takes a result of request `generation`: true when it is the newest
    /// request's (and it was not answered yet), false when it is stale.
    pub fn accept(&mut self, generation: u64) -> bool {
        let fresh = self.waiting() && generation == self.issued;
        self.answered |= fresh;
        fresh
    }

    /// Whether the newest request still waits for its result.
    pub fn waiting(&self) -> bool {
        self.issued > 0 && !self.answered
    }
}

/// A prepared reload (or why it was refused) as the worker hands it back.
#[derive(Debug)]
pub struct WorkerReply {
    /// The request it answers.
    pub generation: u64,
    /// The thread that prepared it.
    pub thread: ThreadId,
    /// How long preparing took on that thread.
    pub elapsed: Duration,
    /// The new version to commit, or the error at file:line.
    pub result: Result<PreparedReload, ReloadError>,
}

/// A thread that prepares [`ReloadJob`]s; it ends when the worker is dropped
/// (after the job in hand), and the scope it was spawned in waits for it.
pub struct ReloadWorker {
    jobs: Sender<(u64, ReloadJob)>,
    results: Receiver<WorkerReply>,
    generations: Generations,
}

impl ReloadWorker {
    /// Starts the thread in `scope`; it asks `gpu` only for image memory
    /// requirements. `delay` makes each prepare sleep first, standing in for a
    /// slow edit in tests and measurements; zero otherwise.
    pub fn spawn<'scope>(
        scope: &'scope Scope<'scope, '_>,
        gpu: &'scope Gpu,
        delay: Duration,
    ) -> Self {
        let (jobs, inbox) = channel::<(u64, ReloadJob)>();
        let (outbox, results) = channel();
        scope.spawn(move || {
            let mut checker = ShaderChecker::new();
            while let Ok(mut job) = inbox.recv() {
                while let Ok(newer) = inbox.try_recv() {
                    job = newer;
                }
                let (generation, job) = job;
                let started = Instant::now();
                std::thread::sleep(delay);
                let result = match &mut checker {
                    Ok(checker) => job.prepare(gpu, checker),
                    Err(err) => Err(ReloadError::new(
                        &job.base.settings.graph,
                        None,
                        &err.to_string(),
                    )),
                };
                let prepared = WorkerReply {
                    generation,
                    thread: std::thread::current().id(),
                    elapsed: started.elapsed(),
                    result,
                };
                if outbox.send(prepared).is_err() {
                    break;
                }
            }
        });
        Self {
            jobs,
            results,
            generations: Generations::default(),
        }
    }

    /// Hands `job` to the thread, superseding any request not answered yet;
    /// returns its generation.
    pub fn submit(&mut self, job: ReloadJob) -> u64 {
        let generation = self.generations.issue();
        // The thread only stops when this worker is dropped, so the send
        // cannot fail while `self` exists; a result that never comes keeps
        // `waiting` true, which is what a caller polling for it should see.
        let _ = self.jobs.send((generation, job));
        generation
    }

    /// The newest request's result, once it is ready; stale results are dropped.
    pub fn poll(&mut self) -> Option<WorkerReply> {
        let mut newest = None;
        while let Ok(prepared) = self.results.try_recv() {
            if self.generations.accept(prepared.generation) {
                newest = Some(prepared);
            }
        }
        newest
    }

    /// Whether the newest request is still being prepared.
    pub fn waiting(&self) -> bool {
        self.generations.waiting()
    }
}

#[cfg(test)]
mod tests {
    use super::Generations;

    #[test]
    fn only_the_newest_request_is_accepted_and_only_once() {
        let mut g = Generations::default();
        assert!(!g.waiting());
        let first = g.issue();
        let second = g.issue();
        assert_eq!((first, second), (1, 2));
        assert!(g.waiting());
        assert!(!g.accept(first), "superseded by the second");
        assert!(g.waiting());
        assert!(g.accept(second));
        assert!(!g.waiting());
        assert!(!g.accept(second), "answered already");
    }

    #[test]
    fn a_result_arriving_after_a_newer_request_is_dropped() {
        let mut g = Generations::default();
        let first = g.issue();
        assert!(g.accept(first));
        let second = g.issue();
        assert!(!g.accept(first));
        assert!(g.waiting());
        let third = g.issue();
        assert!(!g.accept(second));
        assert!(g.accept(third));
        assert!(!g.waiting());
    }

    #[test]
    fn nothing_is_accepted_before_a_request() {
        let mut g = Generations::default();
        assert!(!g.accept(0));
        assert!(!g.accept(1));
        assert!(!g.waiting());
    }
}
