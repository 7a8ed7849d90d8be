//! Times a first (importing) and a second (cached) load of a scene or model:
//! `cargo run --release -p weft-scene --example cache_timing -- FILE CACHE_DIR`.
//! CACHE_DIR is emptied first so the first load is a true miss.

use std::path::PathBuf;
use std::time::Instant;
use weft_scene::{load_scene_with, LoadOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(file), Some(cache)) = (args.next(), args.next()) else {
        return Err("usage: cache_timing FILE CACHE_DIR".into());
    };
    let cache = PathBuf::from(cache);
    if cache.exists() {
        std::fs::remove_dir_all(&cache)?;
    }
    let options = LoadOptions {
        cache_dir: Some(cache),
        ..LoadOptions::default()
    };
    let start = Instant::now();
    let first = load_scene_with(file.as_ref(), &options)?;
    let first_time = start.elapsed();
    let start = Instant::now();
    let second = load_scene_with(file.as_ref(), &options)?;
    let second_time = start.elapsed();
    if first != second {
        return Err("the cached load differs from the first load".into());
    }
    println!(
        "{file}: {} triangles, {} materials; first load {:.1} ms, cached load {:.1} ms",
        first.triangle_count(),
        first
            .models
            .iter()
            .map(|m| m.materials.len())
            .sum::<usize>(),
        first_time.as_secs_f64() * 1e3,
        second_time.as_secs_f64() * 1e3
    );
    Ok(())
}
