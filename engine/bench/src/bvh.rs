//! `weft bench bvh`: how long the ray tracer's BVH takes to build over a
//! scene's world-space triangles (the ones the `RayTracing` provider uploads),
//! its shape (nodes, leaves, depth) and quality (surface area heuristic cost)
//! as built and in the 4-wide form shaders walk, and the memory of the path
//! tracer's texture arrays for the scene's materials; on a device with ray
//! queries, the hardware backend's acceleration structures beside it: the
//! bottom levels' and top level's build, a top-level refit (what a frame
//! that moves a placement pays) and the memory of each, against the BVH's
//! (docs/hardware_rt.md).

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use weft_render::SceneGeometry;
use weft_render::{Bvh, WideBvh};

/// Options of `weft bench bvh`.
#[derive(Args)]
pub struct BvhArgs {
    /// Scenes to build a BVH for.
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Builds per scene; the median time is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub runs: u32,
}

/// One scene's figures.
struct Row {
    scene: String,
    triangles: usize,
    build_ms: f64,
    nodes: usize,
    leaves: usize,
    depth: usize,
    sah: f32,
    /// The 4-wide form: collapse time (median), nodes, depth, SAH cost.
    wide_ms: f64,
    wide_nodes: usize,
    wide_depth: usize,
    wide_sah: f32,
    /// Reading the BVH back from the cache (`weft_render::load_or_build_bvh`), median.
    cached_ms: f64,
    texture_bytes: u64,
    /// Bytes of the 4-wide BVH the walk reads (nodes and leaf triangles).
    bvh_bytes: u64,
}

/// One scene's acceleration structures (hardware backend), medians of the
/// runs.
struct StructureRow {
    scene: String,
    bottom_ms: f64,
    top_ms: f64,
    refit_ms: f64,
    bottom_bytes: u64,
    top_bytes: u64,
    /// The builds' scratch: transient memory of the plan in a frame.
    scratch_bytes: u64,
}

/// Runs `weft bench bvh`.
pub fn run(args: BvhArgs) -> Result<ExitCode> {
    let mut rows = Vec::new();
    for path in &args.scenes {
        let scene = weft_scene::load_scene(path)
            .with_context(|| format!("loading scene {}", path.display()))?;
        let geometry = SceneGeometry::new(&scene);
        let triangles = geometry.trace_mesh().corners;
        let textures = weft_render::gather_trace_textures(&geometry.materials);
        for w in &textures.warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        eprintln!(
            "{}: texture layers per class {:?} colour, {:?} data",
            path.display(),
            textures.colour.each_ref().map(Vec::len),
            textures.data.each_ref().map(Vec::len)
        );
        let texture_bytes = textures.bytes();
        let mut times = Vec::new();
        let mut bvh = None;
        for _ in 0..args.runs {
            let started = Instant::now();
            bvh = Some(Bvh::build(&triangles));
            times.push(started.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        let bvh = bvh.context("at least one build")?;
        let cache = std::env::temp_dir().join(format!("weft-bench-bvh-{}", std::process::id()));
        weft_render::load_or_build_bvh(&triangles, Some(&cache));
        let mut cached = Vec::new();
        for _ in 0..args.runs {
            let started = Instant::now();
            let (read, _) = weft_render::load_or_build_bvh(&triangles, Some(&cache));
            cached.push(started.elapsed().as_secs_f64() * 1e3);
            anyhow::ensure!(read == bvh, "the cached BVH differs from the built one");
        }
        let _ = std::fs::remove_dir_all(&cache);
        let mut collapses = Vec::new();
        let mut wide = None;
        for _ in 0..args.runs {
            let started = Instant::now();
            wide = Some(WideBvh::collapse(&bvh, &triangles));
            collapses.push(started.elapsed().as_secs_f64() * 1e3);
        }
        collapses.sort_by(f64::total_cmp);
        let wide = wide.context("at least one collapse")?;
        cached.sort_by(f64::total_cmp);
        let bvh_bytes = (std::mem::size_of_val(wide.nodes.as_slice())
            + std::mem::size_of_val(wide.triangles.as_slice())) as u64;
        rows.push(Row {
            scene: path.display().to_string(),
            triangles: triangles.len(),
            build_ms: times[times.len() / 2],
            nodes: bvh.nodes.len(),
            leaves: bvh.leaf_count(),
            depth: bvh.depth(),
            sah: bvh.sah_cost(),
            wide_ms: collapses[collapses.len() / 2],
            wide_nodes: wide.nodes.len(),
            wide_depth: wide.depth(),
            wide_sah: wide.sah_cost(),
            cached_ms: cached[cached.len() / 2],
            texture_bytes,
            bvh_bytes,
        });
    }
    print!("{}", table(&rows));
    let gpu = weft_gpu::Gpu::new(&weft_gpu::GpuOptions::default())?;
    if !gpu.info().shaders.ray_query {
        println!(
            "\n{} offers no ray queries: no acceleration structures to build",
            gpu.info().name
        );
        return Ok(ExitCode::SUCCESS);
    }
    let mut structures = Vec::new();
    for path in &args.scenes {
        let scene = weft_scene::load_scene(path)
            .with_context(|| format!("loading scene {}", path.display()))?;
        structures.push(structure_row(&gpu, &scene, path, args.runs)?);
    }
    println!("\nAcceleration structures on {}:\n", gpu.info().name);
    print!("{}", structure_table(&structures, &rows));
    Ok(ExitCode::SUCCESS)
}

/// Builds `scene`'s acceleration structures `runs` times (each on a scene
/// uploaded afresh) and refits the top level `runs` times.
fn structure_row(
    gpu: &weft_gpu::Gpu,
    scene: &weft_scene::Scene,
    path: &std::path::Path,
    runs: u32,
) -> Result<StructureRow> {
    let (mut bottom, mut top, mut refit) = (Vec::new(), Vec::new(), Vec::new());
    let mut bytes = (0, 0, 0);
    for _ in 0..runs {
        let mut uploaded = weft_render::GpuScene::new(gpu, scene, false)?;
        uploaded.trace_in_hardware(true)?;
        let built = uploaded.build_structures_now()?;
        bottom.push(built.bottom_build.as_secs_f64() * 1e3);
        top.push(built.top_build.as_secs_f64() * 1e3);
        bytes = (built.bottom_bytes, built.top_bytes, built.scratch_bytes);
        uploaded.refit_structures()?;
        let refitted = uploaded.build_structures_now()?;
        refit.push(refitted.top_build.as_secs_f64() * 1e3);
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    Ok(StructureRow {
        scene: path.display().to_string(),
        bottom_ms: median(bottom),
        top_ms: median(top),
        refit_ms: median(refit),
        bottom_bytes: bytes.0,
        top_bytes: bytes.1,
        scratch_bytes: bytes.2,
    })
}

fn structure_table(structures: &[StructureRow], rows: &[Row]) -> String {
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    let mut out = String::from("| scene | bottom levels: build (ms, median) | top level: build (ms) | top level: refit (ms) | bottom levels (MiB) | top level (MiB) | scratch, transient (MiB) | BVH: build + collapse (ms) | BVH (MiB) |\n|---|---|---|---|---|---|---|---|---|\n");
    for (s, r) in structures.iter().zip(rows) {
        out.push_str(&format!(
            "| {} | {:.1} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {:.2} |\n",
            s.scene,
            s.bottom_ms,
            s.top_ms,
            s.refit_ms,
            mib(s.bottom_bytes),
            mib(s.top_bytes),
            mib(s.scratch_bytes),
            r.build_ms + r.wide_ms,
            mib(r.bvh_bytes)
        ));
    }
    out
}

fn table(rows: &[Row]) -> String {
    let mut out = String::from("| scene | triangles | build (ms, median) | from the cache (ms, median) | nodes | leaves | depth | SAH cost | 4-wide: collapse (ms, median) | nodes | depth | SAH cost | texture arrays (MiB) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {:.1} | {:.1} | {} | {} | {} | {:.1} | {:.1} | {} | {} | {:.1} | {:.1} |\n",
            r.scene,
            r.triangles,
            r.build_ms,
            r.cached_ms,
            r.nodes,
            r.leaves,
            r.depth,
            r.sah,
            r.wide_ms,
            r.wide_nodes,
            r.wide_depth,
            r.wide_sah,
            r.texture_bytes as f64 / (1024.0 * 1024.0)
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_lists_every_scene() {
        let rows = [Row {
            scene: "a.scene".into(),
            triangles: 12,
            build_ms: 0.25,
            nodes: 7,
            leaves: 4,
            depth: 3,
            sah: 9.5,
            wide_ms: 0.05,
            wide_nodes: 2,
            wide_depth: 2,
            wide_sah: 7.25,
            cached_ms: 0.125,
            texture_bytes: 3 * 1024 * 1024,
            bvh_bytes: 1024 * 1024,
        }];
        assert_eq!(
            table(&rows),
            "| scene | triangles | build (ms, median) | from the cache (ms, median) | nodes | leaves | depth | SAH cost | 4-wide: collapse (ms, median) | nodes | depth | SAH cost | texture arrays (MiB) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n| a.scene | 12 | 0.2 | 0.1 | 7 | 4 | 3 | 9.5 | 0.1 | 2 | 2 | 7.2 | 3.0 |\n"
        );
        let structures = [StructureRow {
            scene: "a.scene".into(),
            bottom_ms: 1.25,
            top_ms: 0.5,
            refit_ms: 0.25,
            bottom_bytes: 2 * 1024 * 1024,
            top_bytes: 512 * 1024,
            scratch_bytes: 256 * 1024,
        }];
        assert_eq!(
            structure_table(&structures, &rows),
            "| scene | bottom levels: build (ms, median) | top level: build (ms) | top level: refit (ms) | bottom levels (MiB) | top level (MiB) | scratch, transient (MiB) | BVH: build + collapse (ms) | BVH (MiB) |\n|---|---|---|---|---|---|---|---|---|\n| a.scene | 1.2 | 0.50 | 0.25 | 2.00 | 0.50 | 0.25 | 0.3 | 1.00 |\n"
        );
    }
}
