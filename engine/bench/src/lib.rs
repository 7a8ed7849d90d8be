//! `weft bench`: benchmarks that render generated scenes, write their figures
//! (CSV and a PNG plot, see `plot.rs`) and print a table. Each benchmark is one
//! variant of [`BenchCommand`] in a module of its own.

use anyhow::Result;
use clap::Subcommand;
use std::process::ExitCode;

mod bloom;
mod bvh;
mod floors;
mod lights;
mod output;
mod pathtrace;
mod plot;
mod script;
mod shadow_reference;
mod shadows;
mod start;
mod tangents;
mod tiles;

/// The benchmarks.
#[derive(Subcommand)]
pub enum BenchCommand {
    /// Frame time against the number of point lights, one line per graph.
    Lights(crate::lights::LightsArgs),
    /// Bloom blur time and error: paired linear-filtered taps against one fetch per texel.
    Bloom(crate::bloom::BloomArgs),
    /// Shadow-map resolution and PCF radius against error (vs ray-traced visibility) and time.
    Shadows(crate::shadows::ShadowsArgs),
    /// Build time and shape of the ray tracer's BVH over each scene's triangles.
    Bvh(crate::bvh::BvhArgs),
    /// Path tracer samples per second, and convergence against a reference image.
    Pathtrace(crate::pathtrace::PathtraceArgs),
    /// Whole-process `weft render` time, cold (`--no-cache`) against warm.
    Start(crate::start::StartArgs),
    /// Each pass against its floor in the same frame (constant shading, a G-buffer read).
    Floors(crate::floors::FloorsArgs),
    /// Tiled light lists: lights listed per pixel and culling cost of each culling test.
    Tiles(crate::tiles::TilesArgs),
    /// Packed vertex tangent frames of real models against their float frames.
    Tangents(crate::tangents::TangentsArgs),
    /// Scene scripts: the per-frame cost of `update` and of uploading what it changed.
    Script(crate::script::ScriptArgs),
}

/// Runs `weft bench ...`.
pub fn run(cmd: BenchCommand) -> Result<ExitCode> {
    match cmd {
        BenchCommand::Lights(args) => crate::lights::run(args),
        BenchCommand::Bloom(args) => crate::bloom::run(args),
        BenchCommand::Shadows(args) => crate::shadows::run(args),
        BenchCommand::Bvh(args) => crate::bvh::run(args),
        BenchCommand::Pathtrace(args) => crate::pathtrace::run(args),
        BenchCommand::Start(args) => crate::start::run(args),
        BenchCommand::Floors(args) => crate::floors::run(args),
        BenchCommand::Tiles(args) => crate::tiles::run(args),
        BenchCommand::Tangents(args) => crate::tangents::run(args),
        BenchCommand::Script(args) => crate::script::run(args),
    }
}
