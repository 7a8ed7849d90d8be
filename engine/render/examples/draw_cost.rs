//! Measures the engine's host cost per frame for many draws: a generated scene
//! of N cubes (default 500; forward draws each twice, shadow map and shading, so
//! 1,000 draws) rendered for some frames without validation; prints the mean
//! host recording time and wall frame time after the first frame.
//!
//! `cargo run --release -p weft-render --example draw_cost -- [CUBES] [FRAMES]`

use std::fmt::Write as _;
use std::path::Path;
use weft_gpu::{Gpu, GpuOptions};
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings, Rendered};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cubes: usize = args.next().map_or(Ok(500), |a| a.parse())?;
    let frames: u32 = args.next().map_or(Ok(20), |a| a.parse())?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cube = root
        .join("../shared/assets/462/scenes/models/cube.obj")
        .canonicalize()?;
    let side = (cubes as f32).sqrt().ceil() as usize;
    let mut text =
        String::from("sunlight\n{\n\tdirection -0.4 -1 -0.3\n\tcolor 1 1 1\n\tambient 0.1\n}\n");
    for i in 0..cubes {
        let (x, z) = ((i % side) as f32 * 3.0, (i / side) as f32 * 3.0);
        write!(
            text,
            "model\n{{\n\tfile \"{}\"\n\tposition {x} 0 {z}\n\tscale 0.5\n}}\n",
            cube.display()
        )?;
    }
    let dir = std::env::temp_dir().join(format!("weft-draw-cost-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("cubes.scene");
    std::fs::write(&path, text)?;
    let scene = weft_scene::load_scene(&path)?;
    let gpu = Gpu::new(&GpuOptions::default())?;
    let settings = RenderSettings {
        graph: root.join("graphs/forward.ron"),
        extent: Extent {
            width: 320,
            height: 180,
        },
        frames,
        readback: false,
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings)?;
    println!(
        "{} on {}: {} draws per frame; host recording {:.3} ms per frame; frame {:.3} ms wall (mean of frames 2..{frames})",
        path.display(),
        gpu.info().name,
        rendered.draw_calls,
        Rendered::steady_mean(&rendered.record_ms),
        Rendered::steady_mean(&rendered.frame_ms),
    );
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
