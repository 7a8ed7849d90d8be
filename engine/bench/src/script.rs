//! `weft bench script`: what a scene script costs per frame. For 100, 1,000
//! and 10,000 point lights that a script moves every frame (each on its own
//! circle, the common case of scripted light animation), the time of the
//! script's `update` step (with the lights copied out), and of the whole
//! per-frame scene update that uploads them (`GpuScene::update`: the
//! script's step, packing the lights and writing the light buffer), and of
//! that update for the same lights without a script (the upload alone:
//! packing and writing), and the scene update when the script declares the
//! same circles at load as `.scene` motions instead of moving the lights
//! itself. Then the same for 100 and 1,000 model placements
//! (a 12-triangle cube each) that a script moves every frame: the script's
//! step, the whole scene update (draw records rewritten in place), and the
//! rewrite alone (placing the records and writing the changed range).

use anyhow::{Context, Result};
use clap::Args;
use std::process::ExitCode;
use std::time::Instant;
use weft_gpu::{Gpu, GpuOptions};
use weft_render::GpuScene;
use weft_scene::script::{Limits, ScriptFrame, ScriptRuntime, STEP};

/// Arguments of `weft bench script`.
#[derive(Args)]
pub struct ScriptArgs {
    /// Light counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "100,1000,10000", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    lights: Vec<u32>,
    /// Placement counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "100,1000", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    placements: Vec<u32>,
    /// Frames measured per count (one update step each), after 10 warm-up frames.
    #[arg(long, default_value_t = 120, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
    /// Vulkan device to use (name substring); the first suitable one by default.
    #[arg(long)]
    device: Option<String>,
}

/// A script with `n` point lights that its `update` moves on circles.
fn script_text(n: u32) -> String {
    format!(
        r#"fn lights() {{ {n} }}
for i in 0..lights() {{
    point_light(#{{ position: [i % 100, 1, i / 100], color: [1, 1, 1], radius: 2 }});
}}
fn update(t, dt) {{
    for i in 0..lights() {{
        let a = t + i * 0.1;
        set_light_position(i, i % 100 + 0.5 * a.cos(), 1, i / 100 + 0.5 * a.sin());
    }}
}}
"#
    )
}

/// The same circles as [`script_text`] declared at load as `.scene` motions
/// (`velocity`, `amplitude`), with an `update` that changes no light: the
/// renderer moves them, the script runs no per-light code.
fn declared_text(n: u32) -> String {
    format!(
        r#"fn lights() {{ {n} }}
for i in 0..lights() {{
    point_light(#{{ position: [i % 100, 1, i / 100], color: [1, 1, 1], radius: 2, velocity: 1, amplitude: 0.5 }});
}}
fn update(t, dt) {{ }}
"#
    )
}

/// A unit cube (12 triangles).
const CUBE: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
    v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
    f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 5 8\nf 1 8 4\n\
    f 2 3 7\nf 2 7 6\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n";

/// A script with `n` cubes that its `update` moves up and down and turns.
fn placements_text(n: u32) -> String {
    format!(
        r#"fn cubes() {{ {n} }}
point_light(#{{ position: [50, 10, 50], color: [1, 1, 1], radius: 200 }});
for i in 0..cubes() {{
    model("cube.obj", #{{ position: [i % 100, 0, i / 100], scale: 0.4 }});
}}
fn update(t, dt) {{
    for i in 0..cubes() {{
        set_model_transform(i, #{{
            position: [i % 100, 0.5 * (t + i * 0.1).sin(), i / 100],
            orientation: [0, 40 * t, 0],
            scale: 0.4,
        }});
    }}
}}
"#
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The scene's update per frame for `scene` (`SceneUpdater::at`, which runs
/// the script, then `GpuScene::update`, which uploads), one 1/60 s step each,
/// after 10 warm-up frames.
fn scene_update_ms(gpu: &Gpu, scene: &weft_scene::Scene, frames: u32) -> Result<Vec<f64>> {
    let mut updater = weft_scene::SceneUpdater::new(scene)?;
    let mut gpu_scene = GpuScene::new(gpu, scene, updater.animates())?;
    let camera = scene.cameras[0].clone();
    let mut ms = Vec::new();
    for frame in 0..frames + 10 {
        let t = f64::from(frame + 1) * STEP;
        let started = Instant::now();
        let at = updater.at(t);
        gpu_scene.update(&at, &camera, t, ([1280, 720], glam::Vec2::ZERO))?;
        if frame >= 10 {
            ms.push(started.elapsed().as_secs_f64() * 1e3);
        }
        if let Some(e) = updater.take_error() {
            return Err(e.into());
        }
    }
    Ok(ms)
}

/// Placing the instances at each frame's transforms
/// (`SceneGeometry::place_instances`, as `GpuScene::update` calls it) and
/// writing the draw records' range to a host-visible buffer, timed per frame.
fn rewrite_ms(
    gpu: &Gpu,
    scene: &weft_scene::Scene,
    frames: &[Vec<glam::Mat4>],
) -> Result<Vec<f64>> {
    let mut geometry = weft_render::SceneGeometry::new(scene);
    let bytes = bytemuck::cast_slice::<_, u8>(&geometry.draw_records).to_vec();
    let mut buffer = weft_gpu::buffer::Buffer::host(
        gpu,
        "draw records",
        bytes.len() as u64,
        ash::vk::BufferUsageFlags::STORAGE_BUFFER,
    )?;
    buffer.write(&bytes)?;
    let mut placed: Vec<glam::Mat4> = scene.instances.iter().map(|i| i.transform).collect();
    let mut moved = Vec::new();
    let mut ms = Vec::with_capacity(frames.len());
    for transforms in frames {
        let started = Instant::now();
        moved.clear();
        if let Some(ids) = geometry.place_instances(transforms, &mut placed, &mut moved) {
            let records = &geometry.draw_records[ids.start as usize..ids.end as usize];
            buffer.write_at(
                ids.start as usize * std::mem::size_of::<weft_render::GpuDraw>(),
                bytemuck::cast_slice(records),
            )?;
        }
        ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(ms)
}

/// The scene of the script `text`, written to `path`.
fn scene_from(path: &std::path::Path, text: &str) -> Result<weft_scene::Scene> {
    std::fs::write(path, text)?;
    weft_scene::load_scene(path).with_context(|| format!("loading {}", path.display()))
}

/// The script's step per frame, one 1/60 s step each, after 10 warm-up
/// frames: the times, and what each measured step left.
fn script_steps(scene: &weft_scene::Scene, frames: u32) -> Result<(Vec<f64>, Vec<ScriptFrame>)> {
    let script = scene.script.as_ref().context("the scene has its script")?;
    let mut runtime = ScriptRuntime::new(script, scene, &Limits::default())?;
    let (mut ms, mut left) = (Vec::new(), Vec::new());
    for frame in 0..frames + 10 {
        let t = f64::from(frame + 1) * STEP;
        let started = Instant::now();
        let stepped = runtime.frame_at(t)?;
        if frame >= 10 {
            ms.push(started.elapsed().as_secs_f64() * 1e3);
            left.push(stepped);
        }
    }
    Ok((ms, left))
}

/// Runs the benchmark and prints a table.
pub fn run(args: ScriptArgs) -> Result<ExitCode> {
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    println!(
        "device: {}; median over {} frames of one 1/60 s step each",
        gpu.info().name,
        args.frames
    );
    println!("| lights | script update (ms) | scene update with upload (ms) | upload alone (ms) | declared motions: scene update (ms) | light buffer (KiB) |");
    println!("|---:|---:|---:|---:|---:|---:|");
    let dir = std::env::temp_dir().join(format!("weft-bench-script-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    for &n in &args.lights {
        let scene = scene_from(&dir.join(format!("lights{n}.rhai")), &script_text(n))?;
        let (script_ms, _) = script_steps(&scene, args.frames)?;
        let update_ms = scene_update_ms(&gpu, &scene, args.frames)?;
        let still = weft_scene::Scene {
            script: None,
            ..scene.clone()
        };
        let upload_ms = scene_update_ms(&gpu, &still, args.frames)?;
        let declared = scene_from(&dir.join(format!("declared{n}.rhai")), &declared_text(n))?;
        let declared_ms = scene_update_ms(&gpu, &declared, args.frames)?;
        println!(
            "| {n} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1} |",
            median(script_ms),
            median(update_ms),
            median(upload_ms),
            median(declared_ms),
            f64::from(n) * 64.0 / 1024.0
        );
    }
    println!();
    println!("| placements | script update (ms) | scene update with rewrite (ms) | rewrite alone (ms) | draw records (KiB) |");
    println!("|---:|---:|---:|---:|---:|");
    std::fs::write(dir.join("cube.obj"), CUBE)?;
    for &n in &args.placements {
        let scene = scene_from(
            &dir.join(format!("placements{n}.rhai")),
            &placements_text(n),
        )?;
        let (script_ms, frames) = script_steps(&scene, args.frames)?;
        let frames: Vec<Vec<glam::Mat4>> = frames.into_iter().map(|f| f.transforms).collect();
        let update_ms = scene_update_ms(&gpu, &scene, args.frames)?;
        let rewrite_ms = rewrite_ms(&gpu, &scene, &frames)?;
        println!(
            "| {n} | {:.3} | {:.3} | {:.3} | {:.1} |",
            median(script_ms),
            median(update_ms),
            median(rewrite_ms),
            f64::from(n) * 160.0 / 1024.0
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(ExitCode::SUCCESS)
}
