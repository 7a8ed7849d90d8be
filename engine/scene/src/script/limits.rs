//! The limits every call into a script runs under, and how a script that
//! breaks one, or fails, is reported: located at file:line:column.

use super::*;

/// The sandbox's limits, per call into the script (the load, `init`, each `update`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Rhai operations (roughly one per expression node evaluated).
    pub operations: u64,
    /// Nested function calls.
    pub call_depth: usize,
    /// Nested expressions, at global level and in functions.
    pub expression_depth: usize,
    /// Bytes in one string.
    pub string_bytes: usize,
    /// Elements in one array.
    pub array_len: usize,
    /// Entries in one map.
    pub map_len: usize,
    /// Objects (lights, models, cameras) the load may add: each is read by
    /// the `.scene` reader, about 0.1 ms apiece.
    pub objects: usize,
    /// Wall-clock seconds one call may run: the load, `init` or one `update`
    /// step. It bounds what the operation count cannot: Rhai re-measures an
    /// array after every push, so growing one is quadratic in its length.
    pub call_seconds: f64,
    /// Wall-clock seconds the `update` steps of one frame may run together:
    /// a frame asking for time T runs every step up to T.
    pub frame_seconds: f64,
    /// Wall-clock seconds every `update` step of one runtime may run in all:
    /// a render's frames together. Infinite for the live viewer and
    /// `--watch`, which run until they are closed.
    pub render_seconds: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            operations: 50_000_000,
            call_depth: 64,
            expression_depth: 64,
            string_bytes: 1 << 20,
            array_len: 1 << 20,
            map_len: 1 << 16,
            objects: 100_000,
            call_seconds: 30.0,
            frame_seconds: 10.0,
            render_seconds: 120.0,
        }
    }
}

/// Starts the clock of one call ([`Limits::call_seconds`]), or of one
/// `update` step that must also end by `frame_end` (the earlier of the
/// frame's and the render's deadlines, with what the script is told then).
pub(super) fn start_call(state: &Shared, limits_seconds: f64, frame_end: Option<Deadline>) {
    let call = after(std::time::Instant::now(), limits_seconds.max(0.0)).map(|at| {
        (
            at,
            format!("the script ran past its limit of {limits_seconds} s for one call (the load, init or one update step)"),
        )
    });
    lock(state).deadline = earlier(call, frame_end);
}

/// When a script must stop, and what it is told then.
pub(super) type Deadline = (std::time::Instant, String);

/// The earlier of two deadlines, either of which may be none.
pub(super) fn earlier(a: Option<Deadline>, b: Option<Deadline>) -> Option<Deadline> {
    match (a, b) {
        (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
        (a, b) => a.or(b),
    }
}

/// `seconds` from `start`, or `None` when that is beyond any clock.
pub(super) fn after(start: std::time::Instant, seconds: f64) -> Option<std::time::Instant> {
    if !(0.0..1e9).contains(&seconds) {
        return None;
    }
    start.checked_add(std::time::Duration::from_secs_f64(seconds))
}

/// `value` checked against the string, array and map size limits. The
/// state kept between `update` calls is checked after each call, so indexing
/// cannot grow it past a limit frame by frame.
pub(super) fn within_limits(
    engine: &Engine,
    script: &Path,
    value: &Dynamic,
    (what, declared_by): (&str, &str),
) -> Result<(), SceneError> {
    engine
        .ensure_data_size_within_limits(value)
        .map_err(|e| SceneError::Syntax {
            at: first_mention(script, declared_by),
            message: format!("{what}: {e}"),
        })
}

/// Where `words` (`fn update`, `let x`) first appear in the script as weft
/// read it: a value that outgrew a limit is located where it was declared.
pub(super) fn first_mention(script: &Path, words: &str) -> Location {
    let text = weft_io::sources::text_of(script);
    let found = text.as_deref().and_then(|text| {
        text.lines().enumerate().find_map(|(i, line)| {
            let column = line.find(words)?;
            let end = line[column + words.len()..].chars().next();
            end.is_none_or(|c| !(c.is_alphanumeric() || c == '_'))
                .then(|| Location::column(script, i + 1, line[..column].chars().count() + 1))
        })
    });
    found.unwrap_or_else(|| Location::file(script))
}

/// The script error as a scene error at the script's file, line and column.
/// [`located`] for an error raised inside function `name` (`init`,
/// `update`): one Rhai reports without a position (a time limit, say) is
/// located at the function's definition.
pub(super) fn located_in(script: &Path, error: &EvalAltResult, name: &str) -> SceneError {
    let mut located = located(script, error);
    if let SceneError::Syntax { at, .. } = &mut located {
        if at.line.is_none() {
            *at = first_mention(script, &format!("fn {name}"));
        }
    }
    located
}

pub(super) fn located(script: &Path, error: &EvalAltResult) -> SceneError {
    let at = position_at(script, error.position());
    let message = match error {
        EvalAltResult::ErrorRuntime(value, _) | EvalAltResult::ErrorTerminated(value, _) => {
            value.to_string()
        }
        other => other.to_string(),
    };
    let message = message
        .split(" (line ")
        .next()
        .unwrap_or_default()
        .to_string();
    SceneError::Syntax { at, message }
}

pub(super) fn position_at(script: &Path, position: Position) -> Location {
    match (position.line(), position.position()) {
        (Some(line), Some(column)) => Location::column(script, line, column),
        (Some(line), None) => Location::line(script, line),
        _ => Location::file(script),
    }
}
