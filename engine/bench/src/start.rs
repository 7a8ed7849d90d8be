//! `weft bench start`: the whole `weft render` process, cold (every cache
//! bypassed with `--no-cache`: models imported, shaders compiled, BVH
//! built) against warm (a user cache primed by one run: models, SPIR-V and
//! BVH read back), as wall time from spawn to exit.

use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::{Command, ExitCode};
use std::time::Instant;
use weft_compare::metrics::median;

/// Arguments of `weft bench start`.
#[derive(Args)]
pub struct StartArgs {
    /// The scene rendered.
    scene: PathBuf,
    /// The graph.
    #[arg(long, default_value = "graphs/forward.ron")]
    graph: PathBuf,
    /// Image size.
    #[arg(long, default_value = "64x64")]
    size: String,
    /// Runs measured per case (the median is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeats: u32,
}

/// Runs `weft bench start`.
pub fn run(args: StartArgs) -> Result<ExitCode> {
    let exe = std::env::current_exe().context("finding the weft binary")?;
    let cache = std::env::temp_dir().join(format!("weft-bench-start-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    let out = cache.join("out.png");
    let render = |no_cache: bool| -> Result<f64> {
        let mut command = Command::new(&exe);
        command
            .arg("render")
            .arg(&args.scene)
            .arg("--graph")
            .arg(&args.graph)
            .args(["--size", &args.size, "--out"])
            .arg(&out)
            .env("WEFT_CACHE_DIR", &cache);
        if no_cache {
            command.arg("--no-cache");
        }
        let started = Instant::now();
        let result = command.output().context("running weft render")?;
        let seconds = started.elapsed().as_secs_f64();
        if !result.status.success() {
            bail!(
                "weft render failed: {}",
                String::from_utf8_lossy(&result.stderr)
            );
        }
        Ok(seconds * 1e3)
    };
    let mut cold: Vec<f64> = (0..args.repeats)
        .map(|_| render(true))
        .collect::<Result<_>>()?;
    render(false)?;
    let mut warm: Vec<f64> = (0..args.repeats)
        .map(|_| render(false))
        .collect::<Result<_>>()?;
    let _ = std::fs::remove_dir_all(&cache);
    let (cold, warm) = (median(&mut cold), median(&mut warm));
    println!(
        "{} through {} at {}, median of {} runs each (whole process)\n",
        args.scene.display(),
        args.graph.display(),
        args.size,
        args.repeats
    );
    println!("| start | ms |\n|---|---|");
    println!("| cold (`--no-cache`) | {cold:.0} |");
    println!("| warm (models, SPIR-V, BVH cached) | {warm:.0} |");
    println!("\nwarm is {:.2}x faster", cold / warm.max(1e-9));
    Ok(ExitCode::SUCCESS)
}
