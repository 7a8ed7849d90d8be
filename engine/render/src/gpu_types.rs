//! Every struct the shaders read from weft-render's buffers, as `#[repr(C)]`
//! plain-old-data (`bytemuck`), field for field with the GLSL declarations in
//! `shaders/include/scene.glsl` and `shadows.glsl`. The compiler lays the
//! bytes out, so no offset is kept by hand; each struct's size is asserted
//! against the std430/std140 size its GLSL twin has. Every member is a vec4,
//! mat4 or uvec4 (or, for the vertex, tightly packed attributes), so the two
//! layouts agree and there is no padding.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec4, Vec4};

/// One vertex of the shared vertex buffer (`layout(location = 0..2)` inputs,
/// `crate::geometry::VERTEX_ATTRIBUTES`): 20 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuVertex {
    /// Model-space position.
    pub position: [f32; 3],
    /// The tangent frame (normal, tangent, handedness) packed by
    /// `weft_scene::tangent_frame::pack`, decoded in the vertex shader.
    pub frame: u32,
    /// Texture coordinates as 16-bit fractions of the mesh's UV box (the
    /// draw record's `uv_box` maps them back).
    pub uv: [u16; 2],
}

/// `struct Draw`: one placed mesh.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuDraw {
    /// Model to world.
    pub model: Mat4,
    /// Inverse transpose of `model`.
    pub normal: Mat4,
    /// x: index into the materials.
    pub material: UVec4,
    /// The mesh's UV box: xy its smallest UV, zw its size; a vertex's UV is
    /// `xy + zw * uv` with `uv` its 16-bit fractions.
    pub uv_box: Vec4,
    /// World now to world at the frame before: where a point of this mesh
    /// was then, for reprojecting history (identity while it stays put).
    pub previous: Mat4,
}

/// `struct Light`. Area lights reuse the fields (see `scene.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// xyz world position, w cutoff range.
    pub position_range: Vec4,
    /// xyz unit direction the light travels, w type.
    pub direction_type: Vec4,
    /// rgb colour, w spot exponent.
    pub color_exponent: Vec4,
    /// Constant, linear, quadratic attenuation, cos(spot half-angle).
    pub attenuation_cos: Vec4,
}

/// `struct Material`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Kd or base colour, alpha.
    pub diffuse: Vec4,
    /// Ks, Ns (metallic-roughness: metallic, roughness, 0, 0).
    pub specular: Vec4,
    /// Ambient reflectance, normal-map scale (0: none).
    pub ambient: Vec4,
    /// Ke, shading model.
    pub emissive: Vec4,
    /// For the path tracer's smooth dielectrics: the transmission tint (MTL
    /// `Tf`), and the index of refraction in w; w = 0 for other materials.
    pub transmission: Vec4,
    /// The reflection tint of a dielectric (MTL `Ks`) or of a coat, 0.
    pub reflection: Vec4,
    /// A dielectric's Beer–Lambert coefficient σ per world unit, 0.
    pub absorption: Vec4,
    /// How the path tracer meets the surface: the share that is glass, 1 for
    /// a thin shell, and for a coated material (`SHADING_COATED`) the coat's
    /// index and internal diffuse reflectance.
    pub optics: Vec4,
}

/// The `Frame` uniform block.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuFrame {
    /// World to clip space, moved by `jitter` when the plan jitters the camera.
    pub view_proj: Mat4,
    /// Clip to world space (the inverse of `view_proj`, jitter included).
    pub inv_view_proj: Mat4,
    /// xyz the camera's world position, w 1.
    pub camera_position: Vec4,
    /// Sum of the suns' ambient terms.
    pub ambient: Vec4,
    /// Suns, point lights, spots, all lights but the emissive polygons.
    pub counts: UVec4,
    /// Width, height, 1/width, 1/height.
    pub viewport: Vec4,
    /// x: emissive polygon records after the others (`crate::emitter_lights`).
    pub emitter_lights: UVec4,
    /// World to clip space of the frame before (the same as `view_proj` on
    /// a scene's first frame), for passes that reproject last frame's images.
    pub prev_view_proj: Mat4,
    /// `view_proj` without this frame's jitter: where a point is on the
    /// pixel grid the history of accumulating passes lives on.
    pub unjittered_view_proj: Mat4,
    /// xy: this frame's sub-pixel jitter of `view_proj` in pixels (0 when
    /// the plan does not jitter), zw: 0.
    pub jitter: Vec4,
    /// x: how many of `moved_lo`/`moved_hi` hold boxes ([`moved_boxes`]).
    pub moved: UVec4,
    /// The smallest corners of the world boxes where what moved since the
    /// last frame was and is now, w 0.
    pub moved_lo: [Vec4; MAX_MOVED_BOXES],
    /// Their largest corners, w 0.
    pub moved_hi: [Vec4; MAX_MOVED_BOXES],
    /// The environment map: intensity, cos and sin of its turn about +y, 1
    /// when it can be sampled (`crate::scene_gpu::FrameEnvironment`).
    pub environment: Vec4,
    /// The map's width, height, 1 when the scene has one, 0.
    pub environment_size: UVec4,
    /// Its irradiance over π in nine spherical-harmonic coefficients (rgb,
    /// [`crate::environment::irradiance_sh`]).
    pub environment_sh: [Vec4; 9],
}

/// The most boxes of moved placements and panels the `Frame` block holds;
/// more are merged into the last.
pub const MAX_MOVED_BOXES: usize = 8;

/// The `Frame` block's moved boxes (`moved`, `moved_lo`, `moved_hi`) for the
/// world boxes where placements and area-light panels that moved since the
/// last frame were and are now: the radiance cache's sweep empties the cells
/// that see one (shaders/cache/sweep.comp). Boxes past the
/// [`MAX_MOVED_BOXES`]th are merged into the last, which can only restart
/// more cells, never fewer.
pub fn moved_boxes(
    boxes: &[weft_scene::Aabb],
) -> (UVec4, [Vec4; MAX_MOVED_BOXES], [Vec4; MAX_MOVED_BOXES]) {
    let mut lo = [Vec4::ZERO; MAX_MOVED_BOXES];
    let mut hi = [Vec4::ZERO; MAX_MOVED_BOXES];
    let mut count = 0;
    for b in boxes.iter().filter(|b| !b.is_empty()) {
        let (at, b) = if count < MAX_MOVED_BOXES {
            count += 1;
            (count - 1, *b)
        } else {
            let last = weft_scene::Aabb {
                min: lo[count - 1].truncate(),
                max: hi[count - 1].truncate(),
            };
            (count - 1, last.union(b))
        };
        lo[at] = b.min.extend(0.0);
        hi[at] = b.max.extend(0.0);
    }
    (UVec4::new(count as u32, 0, 0, 0), lo, hi)
}

/// The head of the `Shadows` buffer, before the views.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuShadowsHeader {
    /// Cascades, spot views, light index of the first spot cone, PCF radius.
    pub counts: UVec4,
    /// Far view depth of each cascade.
    pub splits: Vec4,
    /// Camera view direction, w: normal offset in texels.
    pub forward: Vec4,
    /// First area-light view, light index of the first area light, area
    /// views, point lights with cube views (their six views follow the
    /// area views).
    pub areas: UVec4,
    /// The light index of each point light with cube views, in view order
    /// (unused slots `u32::MAX`).
    pub point_lights: UVec4,
}

/// `struct ShadowView`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuShadowView {
    /// World to the view's clip space.
    pub clip: Mat4,
    /// World to atlas coordinates.
    pub lookup: Mat4,
    /// Texture-coordinate bounds the kernel stays inside.
    pub rect: Vec4,
    /// x: world size of a texel, y: 1 for perspective views.
    pub texel: Vec4,
    /// Area-light views: the side of a square of the light's area, the
    /// view's near and far depth; zero for other views.
    pub light: Vec4,
}

const _: () = {
    use std::mem::size_of;
    assert!(size_of::<GpuVertex>() == 20);
    assert!(size_of::<GpuDraw>() == 224);
    assert!(size_of::<GpuLight>() == 64);
    assert!(size_of::<GpuMaterial>() == 128);
    assert!(size_of::<GpuFrame>() == 4 * 64 + (7 + 2 * MAX_MOVED_BOXES + 11) * 16);
    assert!(size_of::<GpuShadowsHeader>() == 80);
    assert!(size_of::<GpuShadowView>() == 176);
};

/// The bytes of a slice of records, for uploading.
pub fn bytes_of<T: Pod>(records: &[T]) -> &[u8] {
    bytemuck::cast_slice(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_lie_where_the_glsl_declares_them() {
        let light = GpuLight {
            position_range: Vec4::new(1.0, 2.0, 3.0, 4.0),
            direction_type: Vec4::new(0.0, -1.0, 0.0, 2.0),
            color_exponent: Vec4::splat(0.5),
            attenuation_cos: Vec4::new(1.0, 0.0, 0.0, 0.25),
        };
        let words: &[f32] = bytemuck::cast_slice(std::slice::from_ref(&light));
        assert_eq!(words[3], 4.0, "range is position_range.w");
        assert_eq!(words[7], 2.0, "type is direction_type.w");
        assert_eq!(words[15], 0.25, "cos cutoff is attenuation_cos.w");
        let draw = GpuDraw {
            model: Mat4::from_translation(glam::Vec3::new(9.0, 8.0, 7.0)),
            normal: Mat4::IDENTITY,
            material: UVec4::new(5, 0, 0, 0),
            uv_box: Vec4::new(0.25, 0.5, 2.0, 4.0),
            previous: Mat4::from_translation(glam::Vec3::new(-1.0, 0.0, 0.0)),
        };
        let words: &[u32] = bytemuck::cast_slice(std::slice::from_ref(&draw));
        assert_eq!(f32::from_bits(words[12]), 9.0, "column-major translation");
        assert_eq!(words[32], 5, "material index after two mat4s");
        assert_eq!(f32::from_bits(words[38]), 2.0, "uv_box after the material");
        assert_eq!(f32::from_bits(words[52]), -1.0, "previous after uv_box");
        let vertex = GpuVertex {
            position: [1.0, 2.0, 3.0],
            frame: 0xDEAD_BEEF,
            uv: [7, 65535],
        };
        let bytes = bytemuck::bytes_of(&vertex);
        assert_eq!(
            bytes[12..16],
            0xDEAD_BEEFu32.to_le_bytes(),
            "frame at offset 12"
        );
        assert_eq!(bytes[16..20], [7, 0, 255, 255], "UV at offset 16");
    }
}
