//! A generated scene for light-count benchmarks and tests: a floor with a grid
//! of boxes (so screen tiles span both flat and broken depth) under N seeded
//! point lights. The same N and seed give the same scene on every machine.

use std::io;
use std::path::{Path, PathBuf};

/// Half the floor's side in metres; lights are drawn over the whole floor.
pub const FLOOR_HALF: f32 = 20.0;

/// Boxes per side of the grid standing on the floor.
const BOXES: i32 = 5;

/// The floor and boxes as OBJ text: one quad for the floor, five faces per box
/// (their bottoms are never seen), counter-clockwise seen from outside.
pub fn floor_obj() -> String {
    let mut obj = String::from("# weft generated light-test floor\n");
    let mut vertices = 0;
    let mut quad = |obj: &mut String, corners: [[f32; 3]; 4]| {
        for c in corners {
            obj.push_str(&format!("v {} {} {}\n", c[0], c[1], c[2]));
        }
        obj.push_str(&format!(
            "f {} {} {} {}\n",
            vertices + 1,
            vertices + 2,
            vertices + 3,
            vertices + 4
        ));
        vertices += 4;
    };
    let h = FLOOR_HALF;
    quad(
        &mut obj,
        [[-h, 0.0, h], [h, 0.0, h], [h, 0.0, -h], [-h, 0.0, -h]],
    );
    let spacing = 2.0 * FLOOR_HALF / BOXES as f32;
    for i in 0..BOXES {
        for j in 0..BOXES {
            let cx = -FLOOR_HALF + spacing * (i as f32 + 0.5);
            let cz = -FLOOR_HALF + spacing * (j as f32 + 0.5);
            let height = 1.0 + ((i * 3 + j * 7) % 5) as f32;
            let (x0, x1, z0, z1) = (cx - 1.0, cx + 1.0, cz - 1.0, cz + 1.0);
            quad(
                &mut obj,
                [
                    [x0, height, z1],
                    [x1, height, z1],
                    [x1, height, z0],
                    [x0, height, z0],
                ],
            );
            quad(
                &mut obj,
                [
                    [x0, 0.0, z1],
                    [x1, 0.0, z1],
                    [x1, height, z1],
                    [x0, height, z1],
                ],
            );
            quad(
                &mut obj,
                [
                    [x1, 0.0, z0],
                    [x0, 0.0, z0],
                    [x0, height, z0],
                    [x1, height, z0],
                ],
            );
            quad(
                &mut obj,
                [
                    [x1, 0.0, z1],
                    [x1, 0.0, z0],
                    [x1, height, z0],
                    [x1, height, z1],
                ],
            );
            quad(
                &mut obj,
                [
                    [x0, 0.0, z0],
                    [x0, 0.0, z1],
                    [x0, height, z1],
                    [x0, height, z0],
                ],
            );
        }
    }
    obj
}

/// Colour scale for `lights` lights: about as bright overall whatever the
/// count (each pixel sees a number of lights proportional to it), capped at 1.
pub fn colour_scale(lights: u32) -> f32 {
    (64.0 / lights.max(1) as f32).sqrt().min(1.0)
}

/// `.scene` text placing `floor` (an OBJ path as written in the file) under
/// `lights` point lights of radius 1.5 to 3 m drawn with `seed`.
pub fn scene_text(floor: &str, lights: u32, seed: u32) -> String {
    let k = colour_scale(lights);
    let h = FLOOR_HALF;
    format!(
        "# weft generated: {lights} point lights (seed {seed}) over a floor with boxes\n\
         model\n{{\n\tfile \"{floor}\"\n}}\n\n\
         pointlights\n{{\n\tcount {lights}\n\tseed {seed}\n\tmin {lo} 0.2 {lo}\n\tmax {h} 3 {h}\n\
         \tcolor_min {c0} {c0} {c0}\n\tcolor_max {k} {k} {k}\n\tradius 1.5 3\n\tattenuation 1 0 1\n}}\n\n\
         camera \"view\"\n{{\n\tposition 0 18 26\n\ttarget 0 0 2\n\tfov_deg 55\n}}\n",
        lo = -h,
        c0 = 0.2 * k,
    )
}

/// Writes `floor.obj` and `lights_<N>.scene` into `dir` (created if missing) and
/// returns the scene's path.
pub fn write_light_scene(dir: &Path, lights: u32, seed: u32) -> io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("floor.obj"), floor_obj())?;
    let path = dir.join(format!("lights_{lights}.scene"));
    std::fs::write(&path, scene_text("floor.obj", lights, seed))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_loads_with_the_requested_lights_the_floor_and_the_boxes() {
        let dir = std::env::temp_dir().join(format!("weft-light-scene-{}", std::process::id()));
        let path = write_light_scene(&dir, 300, 7).unwrap();
        let scene = weft_scene::load_scene(&path).unwrap();
        assert_eq!(scene.lights.len(), 300);
        let triangles: usize = scene
            .models
            .iter()
            .flat_map(|m| m.meshes.iter())
            .map(|m| m.indices.len() / 3)
            .sum();
        // Floor quad + 25 boxes of 5 quads, 2 triangles per quad.
        assert_eq!(triangles, 2 + 25 * 5 * 2);
        let again = weft_scene::load_scene(&write_light_scene(&dir, 300, 7).unwrap()).unwrap();
        assert_eq!(format!("{:?}", scene.lights), format!("{:?}", again.lights));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn colours_dim_with_the_square_root_of_the_count_above_64_lights() {
        assert_eq!(colour_scale(1), 1.0);
        assert_eq!(colour_scale(64), 1.0);
        assert_eq!(colour_scale(256), 0.5);
        assert_eq!(colour_scale(0), 1.0);
    }
}
