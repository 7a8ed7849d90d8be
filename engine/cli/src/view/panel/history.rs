//! What the panel plots: the last frames' times (frame and per pass) and,
//! for a progressive graph, samples per pixel against time since it restarted.

use std::collections::VecDeque;
use std::time::Instant;
use weft_gpu::PassTiming;

/// Frames kept for the plots.
pub const FRAMES_KEPT: usize = 240;

/// One presented frame.
#[derive(Debug, Clone)]
struct Frame {
    /// Wall milliseconds, render and present.
    ms: f64,
    /// Per pass.
    passes: Vec<(String, f64)>,
}

/// Rolling history of frames and the progressive image's convergence.
#[derive(Debug)]
pub struct History {
    frames: VecDeque<Frame>,
    /// Since the progressive image last started: (seconds, samples per pixel).
    convergence: Vec<(f64, u64)>,
    restarted_at: Option<Instant>,
}

impl Default for History {
    fn default() -> Self {
        Self {
            frames: VecDeque::with_capacity(FRAMES_KEPT),
            convergence: Vec::new(),
            restarted_at: None,
        }
    }
}

impl History {
    /// Adds a frame, dropping the oldest past [`FRAMES_KEPT`]; `samples` is
    /// the progressive image's samples per pixel after it (a drop means it
    /// restarted).
    pub fn push(&mut self, ms: f64, timings: &[PassTiming], samples: Option<u64>, now: Instant) {
        if self.frames.len() == FRAMES_KEPT {
            self.frames.pop_front();
        }
        self.frames.push_back(Frame {
            ms,
            passes: timings.iter().map(|t| (t.pass.clone(), t.ms)).collect(),
        });
        match samples {
            Some(spp) => {
                let restarted = self.convergence.last().is_none_or(|&(_, last)| spp < last);
                if restarted {
                    self.convergence.clear();
                    self.restarted_at = Some(now);
                }
                let since = self
                    .restarted_at
                    .map_or(0.0, |t| now.duration_since(t).as_secs_f64());
                self.convergence.push((since, spp));
            }
            None => {
                self.convergence.clear();
                self.restarted_at = None;
            }
        }
    }

    /// Frame times, oldest first, as (frame index in the window, ms).
    pub fn frame_ms(&self) -> Vec<[f64; 2]> {
        self.frames
            .iter()
            .enumerate()
            .map(|(i, f)| [i as f64, f.ms])
            .collect()
    }

    /// One pass's times over the kept frames (frames without it are skipped).
    pub fn pass_ms(&self, pass: &str) -> Vec<[f64; 2]> {
        self.frames
            .iter()
            .enumerate()
            .filter_map(|(i, f)| {
                f.passes
                    .iter()
                    .find(|(p, _)| p == pass)
                    .map(|&(_, ms)| [i as f64, ms])
            })
            .collect()
    }

    /// Samples per pixel against seconds since the progressive image restarted.
    pub fn convergence(&self) -> Vec<[f64; 2]> {
        self.convergence
            .iter()
            .map(|&(t, spp)| [t, spp as f64])
            .collect()
    }

    /// Samples per pixel added per second since the restart, once a second
    /// sample point exists.
    pub fn samples_per_second(&self) -> Option<f64> {
        let (&(t0, s0), &(t1, s1)) = (self.convergence.first()?, self.convergence.last()?);
        (t1 > t0).then(|| (s1 - s0) as f64 / (t1 - t0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;
    use weft_gpu::TimingSource;
    use weft_graph::schema::PassKind;

    fn timing(pass: &str, ms: f64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            kind: PassKind::Compute,
            source: TimingSource::CpuWall,
            ms,
        }
    }

    #[test]
    fn keeps_the_last_frames_and_each_pass_series() {
        let mut h = History::default();
        let t0 = Instant::now();
        for i in 0..FRAMES_KEPT + 10 {
            h.push(i as f64, &[timing("a", 1.0 + i as f64)], None, t0);
        }
        let frames = h.frame_ms();
        assert_eq!(frames.len(), FRAMES_KEPT);
        assert_eq!(frames[0], [0.0, 10.0]);
        assert_eq!(h.pass_ms("a")[0], [0.0, 11.0]);
        assert!(h.pass_ms("b").is_empty());
    }

    #[test]
    fn convergence_restarts_when_samples_drop() {
        let mut h = History::default();
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_millis(s * 100);
        for (i, spp) in [1u64, 2, 3, 4].into_iter().enumerate() {
            h.push(1.0, &[], Some(spp), at(i as u64));
        }
        assert_eq!(h.convergence().len(), 4);
        let rate = h.samples_per_second().unwrap();
        assert!((rate - 10.0).abs() < 1e-9, "{rate}");
        h.push(1.0, &[], Some(1), at(10));
        assert_eq!(h.convergence(), vec![[0.0, 1.0]]);
        assert_eq!(h.samples_per_second(), None);
        h.push(1.0, &[], None, at(11));
        assert!(h.convergence().is_empty());
    }
}
