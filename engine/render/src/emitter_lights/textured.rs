//! What an emissive texture adds to raster lighting: the texture's mean over
//! each emissive triangle, so a textured emitter lights raster passes with
//! the power the path tracer emits from it (factor × texture at each point,
//! summed over the triangle). The texture is decoded once per scene, its
//! sRGB texels made linear before they are averaged.

use crate::geometry::{DrawItem, SceneGeometry};
use glam::{Vec2, Vec3};
use std::collections::HashMap;
use std::sync::Arc;
use weft_gpu::readback::srgb_to_linear;
use weft_scene::material::MAX_TEXTURE_SIDE;

/// An emissive texture in linear RGB, rows from the top.
struct LinearTexture {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl LinearTexture {
    /// The texture `source` names, or `None` where it cannot be decoded (its
    /// mesh then emits its factor alone, as raster and tracer draw it).
    fn decode(source: &weft_scene::material::TextureSource) -> Option<Self> {
        let image = crate::texture::decode(source, MAX_TEXTURE_SIDE).ok()?.image;
        let table: Vec<f32> = (0..=255u8)
            .map(|v| srgb_to_linear(f32::from(v) / 255.0))
            .collect();
        let texels = image
            .rgba
            .chunks_exact(4)
            .map(|p| {
                Vec3::new(
                    table[p[0] as usize],
                    table[p[1] as usize],
                    table[p[2] as usize],
                )
            })
            .collect();
        Some(Self {
            width: image.width.max(1),
            height: image.height.max(1),
            texels,
        })
    }

    /// The texel at `uv`, repeating as the samplers do.
    fn at(&self, uv: Vec2) -> Vec3 {
        let x = ((uv.x * self.width as f32).floor() as i64).rem_euclid(i64::from(self.width));
        let y = ((uv.y * self.height as f32).floor() as i64).rem_euclid(i64::from(self.height));
        self.texels[(y * i64::from(self.width) + x) as usize]
    }

    /// The mean over the triangle with these UVs: the texel at the centroid
    /// of each of k² equal sub-triangles, k from the triangle's texel count
    /// (about one sample a texel, 4 to 1024 samples).
    fn triangle_mean(&self, [a, b, c]: [Vec2; 3]) -> Vec3 {
        let texels = 0.5 * (b - a).perp_dot(c - a).abs() * (self.width * self.height) as f32;
        let k = (2.0 * texels).sqrt().ceil().clamp(2.0, 32.0) as u32;
        let at = |s: f32, t: f32| self.at(a + (b - a) * (s / k as f32) + (c - a) * (t / k as f32));
        let mut sum = Vec3::ZERO;
        for i in 0..k {
            for j in 0..k - i {
                sum += at(i as f32 + 1.0 / 3.0, j as f32 + 1.0 / 3.0);
                if i + j + 1 < k {
                    sum += at(i as f32 + 2.0 / 3.0, j as f32 + 2.0 / 3.0);
                }
            }
        }
        sum / (k * k) as f32
    }
}

/// Per textured emissive mesh (its index range, vertex offset and material),
/// each triangle's emissive-texture mean, in index order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TextureMeans {
    by_mesh: HashMap<(u32, i32, u32), Arc<[Vec3]>>,
}

impl TextureMeans {
    /// The means of every placed mesh whose emission a texture modulates.
    pub fn gather(geometry: &SceneGeometry) -> Self {
        let mut decoded: HashMap<String, Option<LinearTexture>> = HashMap::new();
        let mut by_mesh = HashMap::new();
        for draw in &geometry.draws {
            let Some(material) = geometry.materials.get(draw.material as usize) else {
                continue;
            };
            let Some(texture) = &material.textures.emissive else {
                continue;
            };
            let key = mesh_key(draw);
            if material.emissive.max_element() <= 0.0 || by_mesh.contains_key(&key) {
                continue;
            }
            let source = &texture.source;
            let linear = decoded
                .entry(crate::texture::source_key(source))
                .or_insert_with(|| LinearTexture::decode(source));
            let means: Arc<[Vec3]> = geometry
                .triangle_uvs(draw)
                .map(|uvs| linear.as_ref().map_or(Vec3::ONE, |t| t.triangle_mean(uvs)))
                .collect();
            by_mesh.insert(key, means);
        }
        Self { by_mesh }
    }

    /// Each triangle's mean for `draw`, `None` where its material has no
    /// emissive texture.
    pub fn of(&self, draw: &DrawItem) -> Option<&[Vec3]> {
        self.by_mesh.get(&mesh_key(draw)).map(|m| &m[..])
    }
}

fn mesh_key(draw: &DrawItem) -> (u32, i32, u32) {
    (
        draw.range.first_index,
        draw.range.vertex_offset,
        draw.material,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(width: u32, height: u32, texel: impl Fn(u32, u32) -> Vec3) -> LinearTexture {
        LinearTexture {
            width,
            height,
            texels: (0..height)
                .flat_map(|y| (0..width).map(move |x| (x, y)))
                .map(|(x, y)| texel(x, y))
                .collect(),
        }
    }

    #[test]
    fn a_triangle_averages_the_texels_it_covers() {
        // Left half black, right half white.
        let t = texture(8, 8, |x, _| Vec3::splat(if x < 4 { 0.0 } else { 1.0 }));
        let whole = |uvs: [[f32; 2]; 3]| t.triangle_mean(uvs.map(Vec2::from));
        // A quarter of the lower-left half of the unit square lies at u ≥ ½.
        let mean = whole([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).x;
        assert!((mean - 0.25).abs() < 0.02, "{mean}");
        assert_eq!(whole([[0.6, 0.1], [0.9, 0.1], [0.6, 0.4]]), Vec3::ONE);
        assert_eq!(whole([[0.1, 0.1], [0.3, 0.1], [0.1, 0.4]]), Vec3::ZERO);
        // UVs a whole period away repeat.
        assert_eq!(whole([[1.6, 0.1], [1.9, 0.1], [1.6, 0.4]]), Vec3::ONE);
        assert_eq!(whole([[-0.9, 2.1], [-0.7, 2.1], [-0.9, 2.4]]), Vec3::ZERO);
    }
}
