//! What `weft scene check FILE [--json]` prints, runnable before the CLI wires it in:
//! `cargo run -p weft-scene --example scene_check -- FILE [--json]`.
//! Exit status 0 when the scene loads (warnings or not), 1 when it does not. With `--json`,
//! stdout is the report, or `{"error": {"at": {"file", "line"}, "message"}}`.

use serde::Serialize;
use std::process::ExitCode;

/// The JSON shape of a failed check.
#[derive(Serialize)]
struct Failure<'a> {
    error: &'a weft_scene::SceneError,
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let Some(file) = args.iter().find(|a| *a != "--json") else {
        eprintln!("usage: scene_check FILE [--json]");
        return ExitCode::from(2);
    };
    let result = weft_scene::check_report(std::path::Path::new(file));
    let text = match (&result, json) {
        (Ok(report), false) => Ok(report.to_string()),
        (Err(e), false) => {
            eprintln!("error: {e}");
            Ok(String::new())
        }
        (Ok(report), true) => serde_json::to_string_pretty(report).map(|s| s + "\n"),
        (Err(e), true) => serde_json::to_string_pretty(&Failure { error: e }).map(|s| s + "\n"),
    };
    match text {
        Ok(text) => print!("{text}"),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    }
    if result.is_ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
