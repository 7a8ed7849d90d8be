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
        /// Import every model again instead of reading the model cache (in
        /// $WEFT_CACHE_DIR/models, else $XDG_CACHE_HOME/weft/models or
        /// ~/.cache/weft/models), and write no entry.
        #[arg(long)]
        no_cache: bool,
    },
}

/// Runs a scene subcommand.
pub fn run(cmd: SceneCommand) -> Result<ExitCode> {
    match cmd {
        SceneCommand::Check {
            file,
            json,
            no_cache,
        } => {
            let options = weft_scene::LoadOptions {
                cache_dir: weft_scene::cache::user_cache_dir()
                    .filter(|_| !no_cache)
                    .map(|d| d.join("models")),
                environment: None,
            };
            match weft_scene::check_report_with(&file, &options) {
                Ok(report) => {
                    // The scene loaded once already, so this read is from the cache.
                    let scene = weft_scene::load_scene_with(&file, &options)?;
                    let geometry = weft_render::SceneGeometry::new(&scene);
                    let vertices = geometry.vertices.len() as u64;
                    let emitters = weft_render::emitter_lights(&geometry);
                    let vertex_bytes = u64::from(weft_render::VERTEX_BYTES);
                    if json {
                        let mut value = serde_json::to_value(&report)?;
                        value["vertex_bytes"] = vertex_bytes.into();
                        value["vertex_buffer_bytes"] = (vertices * vertex_bytes).into();
                        value["emitter_lights"] = serde_json::json!({
                            "triangles": emitters.triangles,
                            "polygons": emitters.polygons.len(),
                            "quads": emitters.quads,
                            "clusters": emitters.clusters,
                            "clustered": emitters.clustered,
                            "cluster_angle_degrees": emitters.cluster_angle,
                            "cluster_power_lost": emitters.cluster_loss,
                            "dropped": emitters.dropped,
                            "dropped_power": emitters.dropped_power,
                            "textured": emitters.textured,
                        });
                        println!("{}", serde_json::to_string_pretty(&value)?);
                    } else {
                        print!("{report}");
                        if let Some(line) = emitters.summary() {
                            println!("  {line}");
                        }
                        println!(
                            "  vertex buffer: {vertices} vertices x {vertex_bytes} bytes = {:.2} MiB (light volumes included)",
                            (vertices * vertex_bytes) as f64 / (1024.0 * 1024.0)
                        );
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
            }
        }
    }
}
