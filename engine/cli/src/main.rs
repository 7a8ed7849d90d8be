//! The `weft` command.

mod compare_cmd;
mod graph_cmd;
mod graphs;
mod progress;
mod render_cmd;
mod scene_cmd;
mod sweep_cmd;
mod view;
mod watch_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// weft: a data-driven render-graph engine on Vulkan.
#[derive(Parser)]
#[command(name = "weft", version, about)]
struct Cli {
    /// Let scenes name scripts, and glTF files name buffers and images,
    /// outside their own folder tree (refused by default).
    #[arg(long, global = true)]
    allow_outside: bool,
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
    /// Configurations of a scene against a path-traced (or given) reference:
    /// FLIP, RMSE, PSNR beside time and memory.
    Compare(compare_cmd::CompareArgs),
    /// One graph over every combination of parameter values and feature sets
    /// against one reference: CSV, Pareto plot and frontier table.
    Sweep(sweep_cmd::SweepArgs),
    /// Benchmarks that write figures and plots (into --out-dir, by default
    /// the user cache's bench/ folder, e.g. ~/.cache/weft/bench/NAME).
    #[command(subcommand)]
    Bench(weft_bench::BenchCommand),
    /// Show a scene in a window: fly around, switch graphs and features, hot reload.
    View(view::ViewArgs),
}

/// Lets a closed pipe (`weft scene check --json F | head`) end the process
/// quietly, as it ends other Unix tools, instead of a panic in `println!`
/// (Rust ignores SIGPIPE by default, turning it into a write error).
fn die_quietly_on_closed_pipes() {
    // SAFETY: called first thing in `main`, before any thread exists; restoring
    // a signal's default disposition has no other effect on the process.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Turns off backtraces of library errors unless the user chose otherwise:
/// spirq (shader reflection) builds an `anyhow` error on every successful
/// lookup, and with `RUST_BACKTRACE` set each captured a backtrace, which
/// made reflecting a shader about five times slower. Panics still follow
/// `RUST_BACKTRACE`. Runs first, before any thread exists.
fn quiet_library_backtraces() {
    if std::env::var_os("RUST_LIB_BACKTRACE").is_none() {
        std::env::set_var("RUST_LIB_BACKTRACE", "0");
    }
}

fn main() -> ExitCode {
    quiet_library_backtraces();
    die_quietly_on_closed_pipes();
    let cli = Cli::parse();
    weft_scene::outside::allow_outside(cli.allow_outside);
    // Compiled shaders are kept in the user cache; commands with --no-cache
    // turn it off.
    weft_gpu::spirv_cache::set_dir(weft_scene::cache::user_cache_dir().map(|d| d.join("spirv")));
    let result = match cli.command {
        Command::Graph(cmd) => graph_cmd::run(cmd),
        Command::Scene(cmd) => scene_cmd::run(cmd),
        Command::Render(args) => render_cmd::run(args),
        Command::Compare(args) => compare_cmd::run(args),
        Command::Sweep(args) => sweep_cmd::run(args),
        Command::Bench(cmd) => weft_bench::run(cmd),
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
