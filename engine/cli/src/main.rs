//! The `weft` command.

mod bench_bloom;
mod bench_cmd;
mod bench_lights;
mod bench_shadows;
mod graph_cmd;
mod plot;
mod render_cmd;
mod scene_cmd;
mod view;
mod watch_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// weft: a data-driven render-graph engine on Vulkan.
#[derive(Parser)]
#[command(name = "weft", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check, plan and draw render graphs.
    #[command(subcommand)]
    Graph(graph_cmd::GraphCommand),
    /// Check scenes.
    #[command(subcommand)]
    Scene(scene_cmd::SceneCommand),
    /// Render a scene through a graph to an image.
    Render(render_cmd::RenderArgs),
    /// Benchmarks that write figures and plots (into docs/ by default).
    #[command(subcommand)]
    Bench(bench_cmd::BenchCommand),
    /// Show a scene in a window: fly around, switch graphs and features, hot reload.
    View(view::ViewArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Graph(cmd) => graph_cmd::run(cmd),
        Command::Scene(cmd) => scene_cmd::run(cmd),
        Command::Render(args) => render_cmd::run(args),
        Command::Bench(cmd) => bench_cmd::run(cmd),
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
