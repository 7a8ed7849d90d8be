//! What `weft scene check FILE [--json]` prints, runnable before the CLI wires it in:
//! `cargo run -p weft-scene --example scene_check -- FILE [--json]`.

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let json = args.iter().any(|a| a == "--json");
    let Some(file) = args.iter().find(|a| *a != "--json") else {
        eprintln!("usage: scene_check FILE [--json]");
        return ExitCode::from(2);
    };
    match weft_scene::check_report(std::path::Path::new(file)) {
        Ok(report) if json => match serde_json::to_string_pretty(&report) {
            Ok(text) => {
                println!("{text}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
        Ok(report) => {
            print!("{report}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
