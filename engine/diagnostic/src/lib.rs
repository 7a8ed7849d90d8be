//! weft's one diagnostic type. Graph, scene, shader and reload problems are all
//! a [`Diagnostic`]: a file, a position, a one-line message, an optional hint
//! and notes. [`render`] prints them with the offending source line and a
//! caret under the position, as rustc does; [`to_json`] gives tools the same data.

use serde::Serialize;
use std::fmt;
use std::path::PathBuf;

/// A 1-based line and column; column 0 means the line as a whole, line 0 the
/// whole file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Default)]
pub struct Pos {
    pub line: u32,
    pub col: u32,
}

impl fmt::Display for Pos {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self.col {
            0 => write!(f, "{}", self.line),
            col => write!(f, "{}:{col}", self.line),
        }
    }
}

/// How bad a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// One located problem.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    pub severity: Severity,
    pub file: PathBuf,
    pub pos: Pos,
    /// What is wrong, on one line.
    pub message: String,
    /// How to fix it, when known.
    pub hint: Option<String>,
    /// Further context (where something was declared, what else was tried).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl Diagnostic {
    /// An error at a position.
    pub fn error(file: impl Into<PathBuf>, pos: Pos, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            file: file.into(),
            pos,
            message: message.into(),
            hint: None,
            notes: Vec::new(),
        }
    }

    /// A warning at a position.
    pub fn warning(file: impl Into<PathBuf>, pos: Pos, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(file, pos, message)
        }
    }

    /// An error about a whole file, or about a line when one is known.
    pub fn in_file(
        file: impl Into<PathBuf>,
        line: Option<u32>,
        message: impl Into<String>,
    ) -> Self {
        let pos = Pos {
            line: line.unwrap_or(0),
            col: 0,
        };
        Diagnostic::error(file, pos, message)
    }

    /// Adds a hint.
    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }

    /// Adds a note.
    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Adds a "did you mean" hint when a candidate is close to `wrong`.
    pub fn suggest<'a>(self, wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> Self {
        match nearest(wrong, candidates) {
            Some(best) => self.with_hint(format!("did you mean \"{best}\"?")),
            None => self,
        }
    }

    /// Whether this is an error (as opposed to a warning).
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// The 1-based line, when the problem has one.
    pub fn line(&self) -> Option<u32> {
        (self.pos.line > 0).then_some(self.pos.line)
    }
}

impl fmt::Display for Diagnostic {
    /// `file:line:col: error: message`, then `  hint: ...` and `  note: ...` lines.
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        match self.line() {
            Some(_) => write!(
                f,
                "{}:{}: {kind}: {}",
                self.file.display(),
                self.pos,
                self.message
            )?,
            None => write!(f, "{}: {kind}: {}", self.file.display(), self.message)?,
        }
        if let Some(hint) = &self.hint {
            write!(f, "\n  hint: {hint}")?;
        }
        for note in &self.notes {
            write!(f, "\n  note: {note}")?;
        }
        Ok(())
    }
}

/// The candidate closest to `wrong` by edit distance, if it is close enough to be a likely typo.
pub fn nearest<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let wrong_lower = wrong.to_ascii_lowercase();
    candidates
        .into_iter()
        .map(|c| {
            (
                strsim::levenshtein(&wrong_lower, &c.to_ascii_lowercase()),
                c,
            )
        })
        .filter(|(d, c)| *d <= (c.len().max(wrong.len()) / 3).max(2))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// The diagnostics for people: each one's header (`file:line:col: error:
/// message`, the grep-friendly form editors jump to), its hint and notes, then
/// the offending source line with a caret under the position, as rustc shows
/// it. The line comes from the text weft read ([`weft_io::sources`]); the
/// file is never read again, so a file weft did not read as text (or whose
/// content must not be echoed), or a position past its end, prints the header
/// alone.
pub fn render(diagnostics: &[Diagnostic]) -> String {
    let mut out = String::new();
    for d in diagnostics {
        out.push_str(&d.to_string());
        out.push('\n');
        if let Some(snippet) = source_snippet(d) {
            out.push_str(&snippet);
        }
    }
    out
}

/// The source line a diagnostic points at, with its caret line (see [`render`]),
/// for callers that print the header themselves; `None` when weft did not
/// read the file as text or the diagnostic has no line.
pub fn source_snippet(d: &Diagnostic) -> Option<String> {
    let text = weft_io::sources::text_of(&d.file)?;
    snippet(&text, d.pos)
}

/// The source line of `pos` in a gutter, and a caret line under the word there:
///
/// ```text
///    |
///  2 |     output: "hdx",
///    |             ^^^^^
/// ```
fn snippet(text: &str, pos: Pos) -> Option<String> {
    let line_text = text.lines().nth(pos.line.checked_sub(1)? as usize)?;
    let number = pos.line.to_string();
    let gutter = " ".repeat(number.len());
    // Column 0 underlines the whole line, leading white space aside; otherwise
    // the word (or the one character) at the column.
    let (col, width) = if pos.col == 0 {
        let trimmed = line_text.trim_start();
        let col = line_text.chars().count() - trimmed.chars().count();
        (col, trimmed.trim_end().chars().count())
    } else {
        let col = pos.col as usize - 1;
        let rest: String = line_text.chars().skip(col).collect();
        let width = rest
            .find(|c: char| c.is_whitespace() || matches!(c, ',' | ')' | ']' | '}' | ':'))
            .map_or(rest.chars().count(), |end| rest[..end].chars().count());
        (col, width)
    };
    // Tabs stay tabs under the line so the caret keeps its place.
    let indent: String = line_text
        .chars()
        .take(col)
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    Some(format!(
        " {gutter} |\n {number} | {line_text}\n {gutter} | {indent}{}\n",
        "^".repeat(width.max(1))
    ))
}

/// The diagnostics as JSON, an array of objects with `severity`, `file`, `pos`
/// (`line`, `col`), `message`, `hint` and, when there are any, `notes`.
pub fn to_json(diagnostics: &[Diagnostic]) -> String {
    serde_json::to_string_pretty(diagnostics)
        .unwrap_or_else(|e| format!("[] (not serialisable: {e})"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_finds_typos_and_rejects_unrelated_names() {
        let names = ["albedo", "normal", "depth", "hdr"];
        assert_eq!(nearest("albdo", names), Some("albedo"));
        assert_eq!(nearest("Depht", names), Some("depth"));
        assert_eq!(nearest("shadow_map", names), None);
    }

    #[test]
    fn display_has_location_message_hint_and_notes() {
        let d = Diagnostic::error(
            "g.ron",
            Pos { line: 4, col: 9 },
            "unknown resource \"albdo\"",
        )
        .suggest("albdo", ["albedo"])
        .with_note("resources are shared with included fragments");
        assert_eq!(
            d.to_string(),
            "g.ron:4:9: error: unknown resource \"albdo\"\n  hint: did you mean \"albedo\"?\n  note: resources are shared with included fragments"
        );
        let whole = Diagnostic::in_file("m.obj", None, "not a text file");
        assert_eq!(whole.to_string(), "m.obj: error: not a text file");
        let line = Diagnostic::in_file("s.scene", Some(7), "unknown block");
        assert_eq!(line.to_string(), "s.scene:7: error: unknown block");
    }

    #[test]
    fn render_shows_the_source_line_and_a_caret_under_the_position() {
        let dir = std::env::temp_dir().join(format!("weft-diag-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let file = dir.join("g.ron");
        std::fs::write(&file, "Graph(\n    output: \"hdx\",\n)\n").expect("write");
        weft_io::read_text(&file, 1 << 20).expect("read as weft reads it");
        let d = Diagnostic::error(&file, Pos { line: 2, col: 13 }, "unknown resource \"hdx\"")
            .with_hint("did you mean \"hdr\"?");
        let text = render(&[d, Diagnostic::in_file(&file, None, "whole file")]);
        let _ = std::fs::remove_dir_all(&dir);
        let name = file.display();
        assert_eq!(
            text,
            format!(
                "{name}:2:13: error: unknown resource \"hdx\"\n  hint: did you mean \"hdr\"?\n   |\n 2 |     output: \"hdx\",\n   |             ^^^^^\n{name}: error: whole file\n"
            )
        );
    }

    #[test]
    fn render_never_reads_a_file_weft_did_not_read() {
        let dir = std::env::temp_dir().join(format!("weft-diag-unread-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let file = dir.join("g.ron");
        std::fs::write(&file, "Graph(\n)\n").expect("write");
        let d = Diagnostic::error(&file, Pos { line: 1, col: 1 }, "broken");
        let text = render(&[d]);
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(text, format!("{}:1:1: error: broken\n", file.display()));
    }

    #[test]
    fn render_without_the_file_prints_the_header_alone() {
        let d = Diagnostic::error("/nonexistent/g.ron", Pos { line: 3, col: 1 }, "broken");
        assert_eq!(render(&[d]), "/nonexistent/g.ron:3:1: error: broken\n");
    }

    #[test]
    fn json_carries_every_field() {
        let d =
            Diagnostic::warning("g.ron", Pos { line: 1, col: 2 }, "unused").with_hint("remove it");
        let v: serde_json::Value = serde_json::from_str(&to_json(&[d])).expect("json");
        assert_eq!(v[0]["severity"], "warning");
        assert_eq!(v[0]["pos"]["col"], 2);
        assert_eq!(v[0]["hint"], "remove it");
        assert!(v[0].get("notes").is_none());
    }
}
