//! Scripted panel input (`--ui`): clicks on named panel widgets, typed text
//! and keys, fed to egui as if they came from the window, so tests drive the
//! panel through the same widgets a user clicks.

/// One scripted step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UiStep {
    /// Press and release the primary button on the widget with this name
    /// (`feature:normals`, `param:exposure`), in one frame's input.
    Click(String),
    /// Type text into the focused field.
    Text(String),
    /// Press and release Enter.
    Enter,
}

/// As `--ui` spells it: `click:NAME`, `text:TEXT`, `enter`.
impl std::fmt::Display for UiStep {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Click(name) => write!(f, "click:{name}"),
            Self::Text(text) => write!(f, "text:{text}"),
            Self::Enter => f.write_str("enter"),
        }
    }
}

/// Parses one `--ui` entry, `FRAME:click:NAME`, `FRAME:text:TEXT` or
/// `FRAME:enter`: the step happens before frame FRAME (counted from 0).
pub fn parse_ui(text: &str) -> Result<(u32, UiStep), String> {
    let (frame, step) = super::controls::split_frame(text, "STEP")?;
    let step = match step.split_once(':') {
        Some(("click", name)) if !name.is_empty() => UiStep::Click(name.to_string()),
        Some(("text", typed)) => UiStep::Text(typed.to_string()),
        None if step == "enter" => UiStep::Enter,
        _ => {
            return Err(format!(
                "unknown step \"{step}\" (use click:NAME, text:TEXT or enter)"
            ))
        }
    };
    Ok((frame, step))
}

/// The events a pointer press (`pressed`) or release at `at` makes.
pub fn pointer(at: egui::Pos2, pressed: bool) -> Vec<egui::Event> {
    vec![
        egui::Event::PointerMoved(at),
        egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        },
    ]
}

/// The events of pressing and releasing Enter.
pub fn enter() -> Vec<egui::Event> {
    [true, false]
        .into_iter()
        .map(|pressed| egui::Event::Key {
            key: egui::Key::Enter,
            physical_key: Some(egui::Key::Enter),
            pressed,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_parse_and_bad_ones_say_what_is_expected() {
        assert_eq!(
            parse_ui("3:click:feature:normals"),
            Ok((3, UiStep::Click("feature:normals".into())))
        );
        assert_eq!(parse_ui("4:text:2.5"), Ok((4, UiStep::Text("2.5".into()))));
        assert_eq!(parse_ui("5:enter"), Ok((5, UiStep::Enter)));
        assert!(parse_ui("x:enter")
            .unwrap_err()
            .contains("not a frame number"));
        assert!(parse_ui("1:hover:x").unwrap_err().contains("click:NAME"));
        assert!(parse_ui("1:click:").is_err());
        assert!(parse_ui("enter").is_err());
    }
}
