//! `weft scene check`.

use anyhow::Result;
use clap::Subcommand;
use std::path::PathBuf;
use std::process::ExitCode;

/// Scene subcommands.
#[derive(Subcommand)]
pub enum SceneCommand {
    /// Load a scene and summarise it: models, triangles, materials, textures, lights,
    /// bounds and warnings; exit 1 when it does not load.
    Check {
        file: PathBuf,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Runs a scene subcommand.
pub fn run(cmd: SceneCommand) -> Result<ExitCode> {
    match cmd {
        SceneCommand::Check { file, json } => match weft_scene::check_report(&file) {
            Ok(report) => {
                if json {
                    println!("{}", serde_json::to_string_pretty(&report)?);
                } else {
                    print!("{report}");
                }
                Ok(ExitCode::SUCCESS)
            }
            Err(err) => {
                if json {
                    let value = serde_json::json!({ "error": err });
                    println!("{}", serde_json::to_string_pretty(&value)?);
                } else {
                    eprintln!("error: {err}");
                    if let Some(snippet) = weft_diagnostic::source_snippet(&err.diagnostic()) {
                        eprint!("{snippet}");
                    }
                }
                Ok(ExitCode::FAILURE)
            }
        },
    }
}
