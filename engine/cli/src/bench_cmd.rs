//! `weft bench`: benchmarks that render generated scenes, write their figures
//! (CSV and a PNG plot, see `plot.rs`) and print a table. Each benchmark is one
//! variant of [`BenchCommand`] in a module of its own.

use anyhow::Result;
use clap::Subcommand;
use std::process::ExitCode;

/// The benchmarks.
#[derive(Subcommand)]
pub enum BenchCommand {
    /// Frame time against the number of point lights, one line per graph.
    Lights(crate::bench_lights::LightsArgs),
    /// Bloom blur time and error: paired linear-filtered taps against one fetch per texel.
    Bloom(crate::bench_bloom::BloomArgs),
    /// Shadow-map resolution and PCF radius against error (vs ray-traced visibility) and time.
    Shadows(crate::bench_shadows::ShadowsArgs),
}

/// Runs `weft bench ...`.
pub fn run(cmd: BenchCommand) -> Result<ExitCode> {
    match cmd {
        BenchCommand::Lights(args) => crate::bench_lights::run(args),
        BenchCommand::Bloom(args) => crate::bench_bloom::run(args),
        BenchCommand::Shadows(args) => crate::bench_shadows::run(args),
    }
}
