//! `weft bench tiles`: how tight tiled light lists are and what each culling
//! test costs. For every combination of the tiled graph's culling features
//! (`tile_box`, `tile_depth_mask`) it reports the time of the culling and
//! shading passes and the lights listed per covered pixel, against the lights
//! that really reach each pixel's surface point, found by casting the camera's
//! rays on the CPU (`raytrace::Bvh`) and testing every light's reach.

use anyhow::{bail, Context, Result};
use clap::Args;
use glam::{Vec2, Vec3, Vec4};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_gpu::{Gpu, GpuOptions, TimingMode};
use weft_graph::plan::Extent;
use weft_render::{pack_lights, LightSet};
use weft_render::{render, RenderSettings};
use weft_scene::Scene;
use weft_testkit::light_scene;
use weft_testkit::raytrace;

/// Arguments of `weft bench tiles`.
#[derive(Args)]
pub struct TilesArgs {
    /// A scene; by default the generated floor with boxes under `--lights` point lights.
    scene: Option<PathBuf>,
    /// Point lights of the generated scene.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    lights: u32,
    /// The tiled graph.
    #[arg(long, default_value = "graphs/tiled.ron")]
    graph: PathBuf,
    /// Output size.
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames timed per variant; the first (pipeline builds) is left out of the mean.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=10_000))]
    frames: u32,
    /// The culling pass.
    #[arg(long, default_value = "cull_lights")]
    cull_pass: String,
    /// The pass that shades from the lists.
    #[arg(long, default_value = "shade")]
    shade_pass: String,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
}

/// The culling tests measured, as feature toggles of the tiled graph.
const VARIANTS: [(&str, &str); 4] = [
    ("frustum slab", "!tile_box,!tile_depth_mask"),
    ("slab + 2.5D depth mask", "!tile_box,tile_depth_mask"),
    ("surface box", "tile_box,!tile_depth_mask"),
    ("surface box + 2.5D depth mask", "tile_box,tile_depth_mask"),
];

/// Whether light record `light` reaches `point`: inside its cutoff range and,
/// for a spot, inside its cone.
fn reaches(set: &LightSet, light: usize, point: Vec3) -> bool {
    let record = &set.records[light];
    let (centre, range) = (record.position_range.truncate(), record.position_range.w);
    let offset = point - centre;
    if offset.length_squared() > range * range {
        return false;
    }
    let is_spot = light as u32 >= set.first_spot_cone() && (light as u32) < set.first_area();
    !is_spot
        || offset
            .normalize_or_zero()
            .dot(record.direction_type.truncate())
            >= record.attenuation_cos.w
}

/// Per pixel (row-major, top row first): the number of point and spot lights
/// reaching the surface the camera sees, or `None` for background.
fn reaching_per_pixel(scene: &Scene, size: Extent) -> Result<Vec<Option<u32>>> {
    let camera = scene.cameras.first().context("the scene has no camera")?;
    let (w, h) = (size.width, size.height);
    let view_proj = camera.view_projection(0.0, w as f32 / h as f32);
    let inv = view_proj.inverse();
    let eye = camera.pose_at(0.0).0;
    let set = pack_lights(
        &weft_scene::animation::lights_at(&scene.lights, 0.0, 0),
        &scene.effective_bounds(),
    );
    let first = set.first_point() as usize;
    let end = set.first_area() as usize;
    let bvh = raytrace::Bvh::from_scene(scene, |_, _| true);
    let viewport = Vec2::new(w as f32, h as f32);
    let mut counts = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let pixel = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let ndc = pixel / viewport * 2.0 - Vec2::ONE;
            let far = inv * Vec4::new(ndc.x, ndc.y, 0.5, 1.0);
            let dir = (far.truncate() / far.w - eye).normalize();
            counts.push(bvh.closest(eye, dir, f32::INFINITY).map(|hit| {
                let point = eye + dir * hit.t;
                (first..end).filter(|&i| reaches(&set, i, point)).count() as u32
            }));
        }
    }
    Ok(counts)
}

/// Runs `weft bench tiles`.
pub fn run(args: TilesArgs) -> Result<ExitCode> {
    if !args.graph.is_file() {
        bail!(
            "graph {} not found (run from the repository root)",
            args.graph.display()
        );
    }
    let path = match &args.scene {
        Some(path) => path.clone(),
        None => {
            let dir = std::env::temp_dir().join(format!("weft-bench-tiles-{}", std::process::id()));
            light_scene::write_light_scene(&dir, args.lights, 1)
                .with_context(|| format!("writing a scene into {}", dir.display()))?
        }
    };
    let scene =
        weft_scene::load_scene(&path).with_context(|| format!("loading {}", path.display()))?;
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    let reaching = reaching_per_pixel(&scene, args.size)?;
    let covered: Vec<usize> = (0..reaching.len())
        .filter(|&i| reaching[i].is_some())
        .collect();
    if covered.is_empty() {
        bail!("the camera sees no surface in {}", path.display());
    }
    let mean_reaching = covered
        .iter()
        .map(|&i| f64::from(reaching[i].unwrap_or(0)))
        .sum::<f64>()
        / covered.len() as f64;
    println!(
        "{} at {}x{} on {}: {:.2} lights reach a covered pixel's surface on average \
         (CPU ray casts); pass times are CPU wall time, mean of frames 2..{}\n",
        path.display(),
        args.size.width,
        args.size.height,
        gpu.info().name,
        mean_reaching,
        args.frames
    );
    println!(
        "| culling test | listed per covered pixel | listed / reaching | {} ms | {} ms | sum ms |",
        args.cull_pass, args.shade_pass
    );
    println!("|---|---|---|---|---|---|");
    for (label, toggles) in VARIANTS {
        let features: Vec<String> = ["!bloom"]
            .into_iter()
            .chain(toggles.split(','))
            .map(String::from)
            .collect();
        let timed = RenderSettings {
            graph: args.graph.clone(),
            extent: args.size,
            frames: args.frames,
            features: features.clone(),
            timing: TimingMode::CpuPerPass,
            readback: false,
            ..RenderSettings::default()
        };
        let rendered = render(&gpu, &scene, &timed)
            .with_context(|| format!("rendering {label} through {}", args.graph.display()))?;
        let mut ms: BTreeMap<&str, f64> = BTreeMap::new();
        let measured = &rendered.timings[1..];
        for frame in measured {
            for t in frame {
                *ms.entry(t.pass.as_str()).or_default() += t.ms / measured.len() as f64;
            }
        }
        let counted = RenderSettings {
            graph: args.graph.clone(),
            extent: args.size,
            features: features
                .into_iter()
                .chain(["light_heatmap".to_string()])
                .collect(),
            extra_readback: vec!["light_counts".into()],
            readback_asked: true,
            ..RenderSettings::default()
        };
        let counts = render(&gpu, &scene, &counted)
            .with_context(|| format!("counting {label} through {}", args.graph.display()))?;
        let image = counts
            .report
            .readbacks
            .first()
            .context("light_counts was not read back")?
            .1
            .to_rgba8();
        let listed = covered
            .iter()
            .map(|&i| {
                let (x, y) = (i as u32 % args.size.width, i as u32 / args.size.width);
                let [r, g, b, _] = image.get_pixel(x, y).0;
                f64::from(u32::from(r) + 256 * u32::from(g) + 65536 * u32::from(b))
            })
            .sum::<f64>()
            / covered.len() as f64;
        let cull = ms.get(args.cull_pass.as_str()).copied().unwrap_or(0.0);
        let shade = ms.get(args.shade_pass.as_str()).copied().unwrap_or(0.0);
        println!(
            "| {label} | {listed:.2} | {:.2} | {cull:.1} | {shade:.1} | {:.1} |",
            listed / mean_reaching.max(1e-9),
            cull + shade
        );
    }
    Ok(ExitCode::SUCCESS)
}
