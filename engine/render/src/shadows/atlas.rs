//! The shadow map as an atlas of square tiles, one per view.

use glam::{Mat4, Vec4};

/// Square tiles of the shadow-map atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Atlas {
    /// Texels per side of the whole map.
    pub size: u32,
    /// Tiles per side.
    pub grid: u32,
    /// Texels per side of one tile.
    pub tile: u32,
}

impl Atlas {
    /// The layout for `views` tiles in a `size` squared map.
    pub fn new(size: u32, views: u32) -> Self {
        let mut grid = 1;
        while grid * grid < views.max(1) {
            grid += 1;
        }
        Self {
            size,
            grid,
            tile: (size / grid).max(1),
        }
    }

    /// Texel x, y of tile `i`'s corner and its side, for the viewport.
    pub fn viewport(&self, i: u32) -> [u32; 3] {
        [
            (i % self.grid) * self.tile,
            (i / self.grid) * self.tile,
            self.tile,
        ]
    }

    /// Clip space of tile `i`'s view to atlas texture coordinates (xy), keeping z and w,
    /// so `lookup = clip_to_uv * clip` and `textureProj` divides by w.
    pub fn clip_to_uv(&self, i: u32) -> Mat4 {
        let [x, y, side] = self.viewport(i);
        let scale = side as f32 / self.size as f32;
        let (ox, oy) = (x as f32 / self.size as f32, y as f32 / self.size as f32);
        Mat4::from_cols(
            Vec4::new(0.5 * scale, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 0.5 * scale, 0.0, 0.0),
            Vec4::new(0.0, 0.0, 1.0, 0.0),
            Vec4::new(ox + 0.5 * scale, oy + 0.5 * scale, 0.0, 1.0),
        )
    }

    /// Tile `i`'s texture-coordinate bounds (min xy, max xy) shrunk by `margin`
    /// texels: a lookup inside them reads only this tile.
    pub fn inner_rect(&self, i: u32, margin: f32) -> Vec4 {
        let [x, y, side] = self.viewport(i);
        let s = self.size as f32;
        Vec4::new(
            (x as f32 + margin) / s,
            (y as f32 + margin) / s,
            ((x + side) as f32 - margin) / s,
            ((y + side) as f32 - margin) / s,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atlas_tiles_cover_the_map_without_overlap() {
        let a = Atlas::new(2048, 3);
        assert_eq!((a.grid, a.tile), (2, 1024));
        assert_eq!(a.viewport(0), [0, 0, 1024]);
        assert_eq!(a.viewport(1), [1024, 0, 1024]);
        assert_eq!(a.viewport(2), [0, 1024, 1024]);
        assert_eq!(
            Atlas::new(512, 1),
            Atlas {
                size: 512,
                grid: 1,
                tile: 512
            }
        );
        // Clip corners land on the tile's corners in texture coordinates.
        let m = a.clip_to_uv(1);
        assert_eq!(
            m * Vec4::new(-1.0, -1.0, 0.3, 1.0),
            Vec4::new(0.5, 0.0, 0.3, 1.0)
        );
        assert_eq!(
            m * Vec4::new(1.0, 1.0, 0.3, 1.0),
            Vec4::new(1.0, 0.5, 0.3, 1.0)
        );
        let r = a.inner_rect(2, 4.0);
        assert_eq!(
            r,
            Vec4::new(
                4.0 / 2048.0,
                0.5 + 4.0 / 2048.0,
                0.5 - 4.0 / 2048.0,
                1.0 - 4.0 / 2048.0
            )
        );
    }
}
