//! Material textures for the path tracer. Compute shaders on lavapipe can
//! index neither descriptor arrays at run time (no `runtimeDescriptorArray`)
//! nor sampled images by a non-uniform value, so every texture (base colour,
//! metallic-roughness, tangent-space normal map, emission) is resampled
//! to a square size class and becomes a layer of that class's `sampler2DArray`:
//! one array per class and colour space (sRGB base colours and emission, UNORM
//! metallic-roughness and normals), bound at set 1, bindings 12 to 17
//! (`shaders/include/trace.glsl`). A material's record says which class and
//! layer each of its textures is in. Sampling a coordinate of an array image
//! is uniform control flow, so this works on every Vulkan device.
//!
//! A texture goes to the smallest class at least as large as its larger
//! side; larger ones are downsampled to the largest class. Memory is
//! 4 bytes × side² per layer, without mips: the tracer samples level 0 and
//! its many jittered samples per pixel do the filtering.

use crate::texture::decode;
use std::collections::HashMap;
use weft_gpu::texture::Rgba8Image;
use weft_scene::material::TextureRef;
use weft_scene::Material;

/// Sides of the size classes, in texels.
pub const CLASSES: [u32; 3] = [256, 512, 1024];

/// A material record's slot for "no texture".
pub const NO_TEXTURE: u32 = u32::MAX;

/// The layers of every class, and each material's slots.
#[derive(Debug, Clone, Default)]
pub struct TraceTextures {
    /// Per class: sRGB colour layers (base colour, emission).
    pub colour: [Vec<Rgba8Image>; 3],
    /// Per class: UNORM data layers (metallic-roughness).
    pub data: [Vec<Rgba8Image>; 3],
    /// Per material: base colour slot, metallic-roughness slot, normal-map
    /// slot, emissive slot; a slot is `class << 16 | layer`, or [`NO_TEXTURE`].
    pub slots: Vec<[u32; 4]>,
    /// Textures that could not be decoded (their materials go untextured).
    pub warnings: Vec<String>,
}

impl TraceTextures {
    /// Device bytes of all layers.
    pub fn bytes(&self) -> u64 {
        self.colour
            .iter()
            .chain(&self.data)
            .flatten()
            .map(|l| l.rgba.len() as u64)
            .sum()
    }
}

/// The class a `width` x `height` texture goes to.
pub fn class_of(width: u32, height: u32) -> usize {
    let side = width.max(height);
    CLASSES
        .iter()
        .position(|&c| side <= c)
        .unwrap_or(CLASSES.len() - 1)
}

/// `image` resampled (bilinear, "triangle" filter) to `side` x `side`.
fn resample(image: Rgba8Image, side: u32) -> Rgba8Image {
    if image.width == side && image.height == side {
        return image;
    }
    let Some(buffer) = image::RgbaImage::from_raw(image.width, image.height, image.rgba) else {
        return Rgba8Image {
            width: side,
            height: side,
            rgba: vec![255; (side * side * 4) as usize],
        };
    };
    let resized =
        image::imageops::resize(&buffer, side, side, image::imageops::FilterType::Triangle);
    Rgba8Image {
        width: side,
        height: side,
        rgba: resized.into_raw(),
    }
}

/// Decodes and places the base colour, metallic-roughness, normal and emissive textures of
/// `materials`, each distinct source once per colour space.
pub fn gather(materials: &[Material]) -> TraceTextures {
    let mut out = TraceTextures::default();
    let mut placed: HashMap<(String, bool), u32> = HashMap::new();
    let mut slot = |t: Option<&TextureRef>, colour: bool, out: &mut TraceTextures| -> u32 {
        let Some(t) = t else { return NO_TEXTURE };
        let key = (crate::texture::source_key(&t.source), colour);
        if let Some(&s) = placed.get(&key) {
            return s;
        }
        // Every texture is resampled to one of the fixed classes below, so any
        // size decodes; the cap only bounds the memory of the decoded copy.
        let s = match decode(&t.source, weft_scene::material::MAX_TEXTURE_SIDE) {
            Ok(decoded) => {
                let image = decoded.image;
                let class = class_of(image.width, image.height);
                let layers = if colour {
                    &mut out.colour[class]
                } else {
                    &mut out.data[class]
                };
                layers.push(resample(image, CLASSES[class]));
                ((class as u32) << 16) | (layers.len() as u32 - 1)
            }
            Err(e) => {
                out.warnings
                    .push(format!("path tracer texture left white: {e}"));
                NO_TEXTURE
            }
        };
        placed.insert(key, s);
        s
    };
    for m in materials {
        let base = slot(m.textures.base_color.as_ref(), true, &mut out);
        let metal_rough = slot(m.textures.metallic_roughness.as_ref(), false, &mut out);
        let normal = slot(m.textures.normal.as_ref(), false, &mut out);
        let emissive = slot(m.textures.emissive.as_ref(), true, &mut out);
        out.slots.push([base, metal_rough, normal, emissive]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textures_go_to_the_smallest_class_that_holds_them() {
        assert_eq!(class_of(1, 1), 0);
        assert_eq!(class_of(256, 100), 0);
        assert_eq!(class_of(257, 2), 1);
        assert_eq!(class_of(512, 512), 1);
        assert_eq!(class_of(1024, 700), 2);
        assert_eq!(class_of(4096, 4096), 2, "larger ones are downsampled");
    }

    #[test]
    fn a_shared_texture_is_placed_once_and_slots_name_class_and_layer() {
        let dir = std::env::temp_dir().join(format!("weft-trace-textures-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let small = dir.join("small.png");
        let large = dir.join("large.png");
        image::RgbaImage::from_pixel(64, 32, image::Rgba([255, 0, 0, 255]))
            .save(&small)
            .expect("png");
        image::RgbaImage::from_pixel(600, 600, image::Rgba([0, 0, 255, 255]))
            .save(&large)
            .expect("png");
        let texture = |p: &std::path::Path| TextureRef::file(p.to_path_buf());
        let mut a = Material::default();
        a.textures.base_color = Some(texture(&small));
        let mut b = Material::default();
        b.textures.base_color = Some(texture(&large));
        b.textures.metallic_roughness = Some(texture(&small));
        let mut c = Material::default();
        c.textures.base_color = Some(texture(&small));
        c.textures.emissive = Some(texture(&small));
        let missing = dir.join("missing.png");
        c.textures.metallic_roughness = Some(texture(&missing));
        let t = gather(&[a, b, c, Material::default()]);
        assert_eq!(t.slots[0], [0, NO_TEXTURE, NO_TEXTURE, NO_TEXTURE]);
        assert_eq!(t.slots[1], [2 << 16, 0, NO_TEXTURE, NO_TEXTURE]);
        assert_eq!(
            t.slots[2],
            [0, NO_TEXTURE, NO_TEXTURE, 0],
            "the small colour texture again, as base colour and as emission"
        );
        assert_eq!(t.slots[3], [NO_TEXTURE, NO_TEXTURE, NO_TEXTURE, NO_TEXTURE]);
        assert_eq!(t.colour[0].len(), 1);
        assert_eq!(t.colour[2].len(), 1);
        assert_eq!(t.data[0].len(), 1, "data textures keep their own layers");
        assert_eq!((t.colour[0][0].width, t.colour[0][0].height), (256, 256));
        assert_eq!(&t.colour[0][0].rgba[..4], &[255, 0, 0, 255]);
        assert_eq!((t.colour[2][0].width, t.colour[2][0].height), (1024, 1024));
        assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
        assert_eq!(t.bytes(), 4 * (2 * 256 * 256 + 1024 * 1024));
    }
}
