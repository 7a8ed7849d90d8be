//! The flown camera written as a `.scene` `camera` block (key C in `weft
//! view`), so a view found by flying can be pasted into the scene file.

use glam::{DVec3, Quat, Vec3};
use weft_scene::Camera;

/// `camera "NAME" { ... }` with `lens`'s field of view and clip distances, at
/// `position` and `orientation`, in
/// world coordinates (the scene's `origin` added back: the viewer flies in
/// coordinates relative to it). The orientation is written as a `target` one
/// unit ahead, up +Y: the fly camera never rolls, so that is exact. Numbers
/// are written to 6 decimals, trailing zeros dropped (a micron at metre
/// scale, far finer than placing a camera needs).
pub fn camera_block(
    name: &str,
    lens: &Camera,
    origin: DVec3,
    position: Vec3,
    orientation: Quat,
) -> String {
    let world = origin + position.as_dvec3();
    let target = world + (orientation * Vec3::NEG_Z).as_dvec3();
    let triple = |v: DVec3| format!("{} {} {}", number(v.x), number(v.y), number(v.z));
    format!(
        "camera \"{}\"\n{{\n\tposition {}\n\ttarget {}\n\tfov_deg {}\n\tnear {}\n\tfar {}\n}}\n",
        name,
        triple(world),
        triple(target),
        number(f64::from(lens.fov_y.to_degrees())),
        number(f64::from(lens.near)),
        number(f64::from(lens.far))
    )
}

/// `x` to 6 decimals without trailing zeros (and without `-0`).
fn number(x: f64) -> String {
    let text = format!("{x:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use weft_scene::{scene_desc_from_str, Diagnostics};

    fn read_back(block: &str) -> (Camera, DVec3) {
        let mut diag = Diagnostics::default();
        let desc = scene_desc_from_str(block, Path::new("pasted.scene"), &mut diag)
            .unwrap_or_else(|e| panic!("{e}\n{block}"));
        assert!(diag.warnings.is_empty(), "{:?}\n{block}", diag.warnings);
        (desc.cameras[0].clone(), desc.origin)
    }

    fn lens() -> Camera {
        Camera {
            fov_y: 0.7,
            near: 0.05,
            far: 300.0,
            ..weft_scene::camera::default_camera(&weft_scene::Aabb::EMPTY)
        }
    }

    #[test]
    fn the_printed_block_reads_back_as_the_flown_camera() {
        let orientation = Quat::from_rotation_y(0.8) * Quat::from_rotation_x(-0.3);
        let position = Vec3::new(1.25, 2.5, -3.0);
        let block = camera_block("fly", &lens(), DVec3::ZERO, position, orientation);
        assert!(
            block.starts_with("camera \"fly\"\n{\n\tposition 1.25 2.5 -3\n"),
            "{block}"
        );
        let (read, origin) = read_back(&block);
        assert_eq!(origin, DVec3::ZERO);
        assert!((read.position - position).length() < 1e-6, "{block}");
        let (a, b) = (read.orientation * Vec3::NEG_Z, orientation * Vec3::NEG_Z);
        assert!(a.dot(b) > 1.0 - 1e-6, "{a} vs {b}");
        let (up_read, up) = (read.orientation * Vec3::Y, orientation * Vec3::Y);
        assert!(up_read.dot(up) > 1.0 - 1e-6, "no roll: {up_read} vs {up}");
        assert!((read.fov_y - 0.7).abs() < 1e-6);
        assert_eq!((read.near, read.far), (0.05, 300.0));
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(number(3.9000000953674316), "3.9");
        assert_eq!(number(-3.0), "-3");
        assert_eq!(number(-1e-9), "0");
        assert_eq!(number(10000003.25), "10000003.25");
    }

    #[test]
    fn far_from_the_origin_the_block_holds_world_coordinates() {
        let origin = DVec3::new(1e7, 0.0, -2048.0);
        let position = Vec3::new(3.0, 1.0, 2.0);
        let block = camera_block("far", &lens(), origin, position, Quat::IDENTITY);
        assert!(block.contains("\tposition 10000003 1 -2046\n"), "{block}");
        let (read, read_origin) = read_back(&block);
        let world = read_origin + read.position.as_dvec3();
        assert!(
            (world - (origin + position.as_dvec3())).length() < 1e-6,
            "{block}"
        );
    }
}
