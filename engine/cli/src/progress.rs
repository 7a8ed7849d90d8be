//! Progress of long work on stderr. On a terminal, indicatif's bar; where
//! stderr is a log or a pipe (a batch job, `weft sweep ... 2> log`), where a
//! bar would draw nothing, a line every 10 s or every tenth of the work with
//! the count, the message (samples per pixel and their rate), the rate and
//! the time left, so long work is never silent.

use std::cell::RefCell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// How often a log line is printed at the least, while work goes on.
const LINE_EVERY: Duration = Duration::from_secs(10);
/// Work that ends sooner than this prints no lines: a log is for long work.
const QUIET_START: Duration = Duration::from_secs(2);

/// A progress display: a bar, log lines, or nothing.
pub(crate) struct Progress {
    bar: indicatif::ProgressBar,
    lines: Option<RefCell<Lines>>,
}

/// The state of the log-line display.
struct Lines {
    label: String,
    unit: String,
    started: Instant,
    last_line: Option<Instant>,
    last_tenth: u64,
    length: u64,
    position: u64,
    message: String,
}

impl Progress {
    /// Progress labelled `label` counting `unit`s (`frame`, `point`); on a
    /// terminal a bar drawn with the indicatif `template`, elsewhere lines.
    pub(crate) fn new(label: &str, unit: &str, template: &str) -> Self {
        if std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(0);
            bar.set_style(
                indicatif::ProgressStyle::with_template(template)
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            return Self { bar, lines: None };
        }
        let now = Instant::now();
        Self {
            bar: indicatif::ProgressBar::hidden(),
            lines: Some(RefCell::new(Lines {
                label: label.to_string(),
                unit: unit.to_string(),
                started: now,
                last_line: None,
                last_tenth: 0,
                length: 0,
                position: 0,
                message: String::new(),
            })),
        }
    }

    /// No display at all (`--json`, work too short to report).
    pub(crate) fn hidden() -> Self {
        Self {
            bar: indicatif::ProgressBar::hidden(),
            lines: None,
        }
    }

    /// The amount of work in all.
    pub(crate) fn set_length(&self, length: u64) {
        self.bar.set_length(length);
        if let Some(lines) = &self.lines {
            lines.borrow_mut().length = length;
        }
    }

    /// The work done so far.
    pub(crate) fn set_position(&self, position: u64) {
        self.bar.set_position(position);
        if let Some(lines) = &self.lines {
            let mut lines = lines.borrow_mut();
            lines.position = position;
            lines.maybe_print(Instant::now());
        }
    }

    /// One more step done.
    pub(crate) fn inc(&self, steps: u64) {
        let position = self.bar.position() + steps;
        self.set_position(position);
    }

    /// What the work is at (shown after the count).
    pub(crate) fn set_message(&self, message: String) {
        if let Some(lines) = &self.lines {
            lines.borrow_mut().message.clone_from(&message);
        }
        self.bar.set_message(message);
    }

    /// The work is over: the bar is cleared; a log gets a closing line.
    pub(crate) fn finish_and_clear(&self) {
        self.bar.finish_and_clear();
        if let Some(lines) = &self.lines {
            let lines = lines.borrow();
            if lines.last_line.is_some() {
                eprintln!(
                    "{}: done, {} {}s in {}",
                    lines.label,
                    lines.position,
                    lines.unit,
                    seconds(lines.started.elapsed())
                );
            }
        }
    }
}

impl Lines {
    /// Prints a line when 10 s have passed since the last, or the work
    /// crossed into a new tenth (none in the first 2 s).
    fn maybe_print(&mut self, now: Instant) {
        if now.duration_since(self.started) < QUIET_START {
            return;
        }
        let tenth = (self.position * 10)
            .checked_div(self.length)
            .unwrap_or(0)
            .min(10);
        let due = self
            .last_line
            .is_none_or(|last| now.duration_since(last) >= LINE_EVERY);
        if tenth <= self.last_tenth && !due {
            return;
        }
        self.last_tenth = self.last_tenth.max(tenth);
        self.last_line = Some(now);
        eprintln!("{}", self.line(now));
    }

    /// `label: frame 12/64 (18%), MESSAGE, 0.9 frame/s, 13 s elapsed, ETA 58 s`.
    fn line(&self, now: Instant) -> String {
        let elapsed = now.duration_since(self.started);
        let rate = self.position as f64 / elapsed.as_secs_f64().max(1e-9);
        let mut text = format!("{}: {} {}", self.label, self.unit, self.position);
        if self.length > 0 {
            text += &format!(
                "/{} ({}%)",
                self.length,
                self.position * 100 / self.length.max(1)
            );
        }
        if !self.message.is_empty() {
            text += &format!(", {}", self.message);
        }
        text += &format!(", {rate:.2} {}/s, {} elapsed", self.unit, seconds(elapsed));
        if self.length > self.position && self.position > 0 {
            let left = (self.length - self.position) as f64 / rate;
            text += &format!(", ETA {}", seconds(Duration::from_secs_f64(left)));
        }
        text
    }
}

/// A duration as a person reads it: `4.2 s`, `3 min 5 s`.
fn seconds(duration: Duration) -> String {
    let s = duration.as_secs_f64();
    if s < 60.0 {
        format!("{s:.1} s")
    } else {
        format!("{} min {} s", (s / 60.0).floor(), (s % 60.0).floor())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(length: u64) -> Lines {
        let now = Instant::now();
        Lines {
            label: "reference".into(),
            unit: "frame".into(),
            started: now,
            last_line: None,
            last_tenth: 0,
            length,
            position: 0,
            message: String::new(),
        }
    }

    #[test]
    fn a_line_names_the_count_the_rate_and_the_time_left() {
        let mut l = lines(64);
        l.position = 16;
        l.message = "16 spp".into();
        let text = l.line(l.started + Duration::from_secs(8));
        assert_eq!(
            text,
            "reference: frame 16/64 (25%), 16 spp, 2.00 frame/s, 8.0 s elapsed, ETA 24.0 s"
        );
        l.position = 64;
        assert_eq!(
            l.line(l.started + Duration::from_secs(125)),
            "reference: frame 64/64 (100%), 16 spp, 0.51 frame/s, 2 min 5 s elapsed"
        );
    }

    #[test]
    fn lines_come_every_tenth_or_every_ten_seconds() {
        let mut l = lines(100);
        let t0 = l.started;
        let mut printed = Vec::new();
        for (position, after) in [
            (1, 1),
            (5, 2),
            (10, 3),
            (12, 4),
            (12, 15),
            (13, 16),
            (35, 17),
        ] {
            l.position = position;
            let before = l.last_line;
            l.maybe_print(t0 + Duration::from_secs(after));
            if l.last_line != before {
                printed.push(position);
            }
        }
        // Nothing in the first 2 s, then the first update, each new tenth
        // (10, 35), and 10 s or more after a line (12 at 15 s).
        assert_eq!(printed, [5, 10, 12, 35]);
    }
}
