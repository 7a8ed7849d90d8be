//! The camera's sub-pixel jitter for graphs that accumulate pixels over
//! frames (`jitter` in a graph file; `graphs/taa.ron`): frame n of a plan
//! moves the projection by the (n mod 256) + 1-th point of the Halton
//! sequence in bases 2 and 3, centred on the pixel. Any run of frames from
//! a plan's first covers the pixel evenly (the first 16 put one offset in
//! each sixteenth of x and spread y as evenly in thirds and ninths), so a
//! still camera's running mean converges to the box-filtered pixel.

use glam::{Mat4, Vec2, Vec3};

/// Frames after which the sequence starts again.
const PERIOD: u32 = 256;

/// The radical inverse of `index` in `base`: its digits mirrored about the
/// radix point (Halton's sequence, one base per dimension).
fn radical_inverse(mut index: u32, base: u32) -> f32 {
    let mut inverse = 0.0f64;
    let mut scale = 1.0f64 / f64::from(base);
    while index > 0 {
        inverse += f64::from(index % base) * scale;
        index /= base;
        scale /= f64::from(base);
    }
    inverse as f32
}

/// The jitter of a plan's frame `frame`, in pixels, each coordinate in
/// [-0.5, 0.5).
pub fn camera_jitter(frame: u32) -> Vec2 {
    let index = frame % PERIOD + 1;
    Vec2::new(radical_inverse(index, 2), radical_inverse(index, 3)) - Vec2::splat(0.5)
}

/// `view_proj` moved by `jitter` pixels on a target of `extent` pixels:
/// the point a pixel centre sees is `jitter` pixels from where the
/// unjittered matrix puts it (Vulkan's clip space: x right, y down).
pub fn jittered(view_proj: Mat4, jitter: Vec2, extent: Vec2) -> Mat4 {
    let ndc = 2.0 * jitter / extent;
    Mat4::from_translation(Vec3::new(ndc.x, ndc.y, 0.0)) * view_proj
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sequence_is_halton_2_3_centred_on_the_pixel() {
        assert_eq!(camera_jitter(0), Vec2::new(0.0, 1.0 / 3.0 - 0.5));
        assert_eq!(camera_jitter(1), Vec2::new(-0.25, 2.0 / 3.0 - 0.5));
        assert_eq!(camera_jitter(2), Vec2::new(0.25, 1.0 / 9.0 - 0.5));
        assert_eq!(camera_jitter(3), Vec2::new(-0.375, 4.0 / 9.0 - 0.5));
        assert_eq!(camera_jitter(PERIOD), camera_jitter(0), "it repeats");
    }

    /// Sixteen frames put one offset in each sixteenth of the pixel's width
    /// and, in height, the first nine one in each ninth.
    #[test]
    fn sixteen_frames_stratify_the_pixel() {
        let mut columns: Vec<u32> = (0..16)
            .map(|f| ((camera_jitter(f).x + 0.5) * 16.0 + 1e-4) as u32)
            .collect();
        columns.sort_unstable();
        assert_eq!(columns, (0..16).collect::<Vec<_>>());
        let mut rows: Vec<u32> = (0..9)
            .map(|f| ((camera_jitter(f).y + 0.5) * 9.0 + 1e-4) as u32)
            .collect();
        rows.sort_unstable();
        assert_eq!(rows, (0..9).collect::<Vec<_>>());
        for f in 0..PERIOD {
            let j = camera_jitter(f);
            assert!((-0.5..0.5).contains(&j.x) && (-0.5..0.5).contains(&j.y));
        }
    }

    /// A point the unjittered matrix puts at pixel centre c is, under the
    /// jittered one, at c + jitter.
    #[test]
    fn jittering_moves_points_by_the_jitter_in_pixels() {
        let view_proj = weft_scene::reverse_z_projection(1.0, 1.5, 0.1, 100.0)
            * Mat4::look_at_rh(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y);
        let extent = Vec2::new(120.0, 80.0);
        let jitter = Vec2::new(0.3, -0.2);
        let pixel = |m: Mat4| {
            let clip = m * glam::Vec4::new(0.4, -0.3, 0.2, 1.0);
            (Vec2::new(clip.x, clip.y) / clip.w * 0.5 + 0.5) * extent
        };
        let moved = pixel(jittered(view_proj, jitter, extent)) - pixel(view_proj);
        assert!((moved - jitter).abs().max_element() < 1e-4, "{moved}");
    }
}
