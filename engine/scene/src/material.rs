//! Materials: Blinn-Phong parameters from MTL and metallic-roughness from glTF in one type,
//! with texture references resolved to absolute paths or embedded bytes.

use glam::{Vec3, Vec4};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::Arc;

/// Which parameter set the source defined, so a renderer picks the matching shading.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShadingModel {
    /// MTL: diffuse, specular, shininess.
    BlinnPhong,
    /// glTF: base colour, metallic, roughness.
    MetallicRoughness,
}

/// How light leaves or passes a surface in the path tracer, as the importer
/// read the file (docs: `scenes/FORMAT.md`, "Materials in the path tracer").
/// Raster graphs shade every kind by its [`ShadingModel`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub enum Optics {
    /// The shading model's BSDF.
    #[default]
    Opaque,
    /// A perfect mirror reflecting `Ks` over a Lambert `Kd` (MTL `illum 3`).
    Mirror,
    /// A Lambert `Kd` base under a smooth dielectric coat whose reflectance at
    /// normal incidence is `Ks` (MTL `illum 5`, "Fresnel on").
    Coated,
    /// A smooth dielectric of index `ior` over `fraction` of the surface (the
    /// rest is opaque): MTL glass, glTF transmission.
    Dielectric {
        /// The share of the surface that is glass: 1 for MTL `illum 4/6/7`,
        /// `1 - d` for the dissolve rule, glTF's transmission factor.
        fraction: f32,
        /// A thin shell: refracts in and straight back out (glTF transmission
        /// without a volume, or with thickness 0).
        thin: bool,
    },
}

/// How alpha is used, as glTF defines it (MTL dissolve < 1 maps to `Blend`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Alpha below the cutoff is discarded.
    Mask(f32),
    /// Alpha blends.
    Blend,
}

/// Where a texture's pixels are.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum TextureSource {
    /// An image file, as an absolute path.
    File(PathBuf),
    /// Image bytes embedded in a glTF buffer or data URI.
    Embedded {
        /// Identifies the image for sharing: `FILE#imageN`.
        id: String,
        /// The MIME type the glTF file gives (`image/png`, `image/jpeg`).
        mime_type: String,
        /// The encoded image, shared by every material that uses it.
        bytes: Arc<[u8]>,
    },
}

/// A texture used by a material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TextureRef {
    /// The image.
    pub source: TextureSource,
    /// Which UV set it reads (glTF `texCoord`; 0 for OBJ).
    pub tex_coord: u32,
}

impl TextureRef {
    /// A texture read from a file with the first UV set.
    pub fn file(path: PathBuf) -> Self {
        Self {
            source: TextureSource::File(path),
            tex_coord: 0,
        }
    }
}

/// The textures of a material, each optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MaterialTextures {
    /// `map_Kd` or `baseColorTexture`.
    pub base_color: Option<TextureRef>,
    /// `map_Ks`.
    pub specular: Option<TextureRef>,
    /// MTL `norm` or glTF `normalTexture`: a tangent-space normal map.
    pub normal: Option<TextureRef>,
    /// MTL `map_bump`/`bump`: a height map (most OBJ exporters write these).
    pub bump: Option<TextureRef>,
    /// `map_d`.
    pub opacity: Option<TextureRef>,
    /// `metallicRoughnessTexture`.
    pub metallic_roughness: Option<TextureRef>,
    /// `map_Ke` or `emissiveTexture`.
    pub emissive: Option<TextureRef>,
    /// `occlusionTexture`.
    pub occlusion: Option<TextureRef>,
    /// KHR_materials_transmission `transmissionTexture`.
    pub transmission: Option<TextureRef>,
    /// KHR_materials_volume `thicknessTexture`.
    pub thickness: Option<TextureRef>,
}

impl MaterialTextures {
    /// Whether a tangent frame is needed (a normal or bump map).
    pub fn needs_tangents(&self) -> bool {
        self.normal.is_some() || self.bump.is_some()
    }

    /// Every texture that is set, for counting and listing.
    pub fn iter(&self) -> impl Iterator<Item = &TextureRef> {
        [
            &self.base_color,
            &self.specular,
            &self.normal,
            &self.bump,
            &self.opacity,
            &self.metallic_roughness,
            &self.emissive,
            &self.occlusion,
            &self.transmission,
            &self.thickness,
        ]
        .into_iter()
        .flatten()
    }
}

/// A surface description that either importer fills; fields the source lacks keep defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// The name in the source file.
    pub name: String,
    /// Which parameter set is authoritative.
    pub shading: ShadingModel,
    /// Diffuse (`Kd`) or base colour, with opacity (`d`, `1 - Tr`, or glTF alpha) in `w`.
    pub base_color: Vec4,
    /// `Ka`.
    pub ambient: Vec3,
    /// `Ks`.
    pub specular: Vec3,
    /// `Ns`.
    pub shininess: f32,
    /// `Ke`, or glTF emissive factor times KHR_materials_emissive_strength.
    pub emissive: Vec3,
    /// `Ni` or KHR_materials_ior.
    pub ior: f32,
    /// MTL `Tf`, the transmission filter: what a refraction lets through.
    pub transmission_filter: Vec3,
    /// Beer–Lambert coefficient σ per world unit inside a dielectric (the
    /// `.scene` model's `absorption`); zero for clear glass.
    pub absorption: Vec3,
    /// MTL `illum` model, when given.
    pub illum: Option<u8>,
    /// What the path tracer does at the surface.
    pub optics: Optics,
    /// glTF metallic factor (0 for MTL).
    pub metallic: f32,
    /// glTF roughness factor (for MTL, derived from `Ns` as `sqrt(2 / (Ns + 2))`).
    pub roughness: f32,
    /// KHR_materials_transmission factor.
    pub transmission: f32,
    /// KHR_materials_volume thickness factor.
    pub thickness: f32,
    /// KHR_materials_volume attenuation distance (`None` = infinite).
    pub attenuation_distance: Option<f32>,
    /// KHR_materials_volume attenuation colour.
    pub attenuation_color: Vec3,
    /// How alpha is used.
    pub alpha_mode: AlphaMode,
    /// Whether back faces are shaded.
    pub double_sided: bool,
    /// Normal map strength (glTF `normalTexture.scale`, MTL `-bm`).
    pub normal_scale: f32,
    /// The textures.
    pub textures: MaterialTextures,
}

/// A `model` block's replacements for the factors of every material of that
/// placement (scenes/FORMAT.md, "Material overrides"); textures stay and are
/// multiplied by the new factors as before. Placements of one file share its
/// geometry whatever their overrides.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MaterialOverride {
    /// `color r g b`: the diffuse or base colour (alpha kept).
    pub color: Option<Vec3>,
    /// `emission r g b`: the emitted radiance.
    pub emission: Option<Vec3>,
    /// `roughness r` in [0, 1]; makes the material metallic-roughness.
    pub roughness: Option<f32>,
    /// `metallic m` in [0, 1]; makes the material metallic-roughness.
    pub metallic: Option<f32>,
}

impl MaterialOverride {
    /// Whether it replaces nothing.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// `material` with the factors replaced. Setting roughness or metallic on
    /// a Blinn-Phong (MTL) material turns it metallic-roughness: its diffuse
    /// colour becomes the base colour, roughness defaults to the one derived
    /// from `Ns`, and metallic to 0.
    pub fn apply(&self, material: &Material) -> Material {
        let mut m = material.clone();
        if let Some(c) = self.color {
            m.base_color = c.extend(m.base_color.w);
        }
        if let Some(e) = self.emission {
            m.emissive = e;
        }
        if self.roughness.is_some() || self.metallic.is_some() {
            m.shading = ShadingModel::MetallicRoughness;
            m.roughness = self.roughness.unwrap_or(m.roughness);
            m.metallic = self.metallic.unwrap_or(m.metallic);
        }
        m
    }

    /// The override's exact bits, to tell overrides apart as map keys.
    pub fn key(&self) -> [u32; 8] {
        let bits = |v: Option<Vec3>| v.map_or([u32::MAX; 3], |v| v.to_array().map(f32::to_bits));
        let [r, g, b] = bits(self.color);
        let [er, eg, eb] = bits(self.emission);
        [
            r,
            g,
            b,
            er,
            eg,
            eb,
            self.roughness.map_or(u32::MAX, f32::to_bits),
            self.metallic.map_or(u32::MAX, f32::to_bits),
        ]
    }
}

impl Default for Material {
    /// The material for meshes without one: mid grey, rough, opaque.
    fn default() -> Self {
        Self {
            name: "default".to_string(),
            shading: ShadingModel::BlinnPhong,
            base_color: Vec4::new(0.8, 0.8, 0.8, 1.0),
            ambient: Vec3::ZERO,
            specular: Vec3::ZERO,
            shininess: 0.0,
            emissive: Vec3::ZERO,
            ior: 1.5,
            transmission_filter: Vec3::ONE,
            absorption: Vec3::ZERO,
            illum: None,
            optics: Optics::Opaque,
            metallic: 0.0,
            roughness: 1.0,
            transmission: 0.0,
            thickness: 0.0,
            attenuation_distance: None,
            attenuation_color: Vec3::ONE,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            normal_scale: 1.0,
            textures: MaterialTextures::default(),
        }
    }
}

/// The largest side, in texels, of a texture weft uploads when no device says
/// otherwise: `maxImageDimension2D` of lavapipe and of desktop GPUs. A larger
/// image is downscaled to fit ([`fit_within`]); `weft scene check` reports it.
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// The size of a `width`×`height` image scaled down, keeping its aspect, so
/// neither side exceeds `max_side` (each side at least 1); the size itself
/// when it fits.
pub fn fit_within(width: u32, height: u32, max_side: u32) -> (u32, u32) {
    let longest = width.max(height);
    if longest <= max_side || max_side == 0 {
        return (width, height);
    }
    let scale = |side: u32| {
        ((u64::from(side) * u64::from(max_side) + u64::from(longest) / 2) / u64::from(longest))
            .clamp(1, u64::from(max_side)) as u32
    };
    (scale(width), scale(height))
}

/// The most bytes one texture's decoded pixels may take (a 16384x16384
/// texture of 16-bit RGBA channels is 2 GiB): `weft scene check` reports a
/// texture over it as dropped, and the renderer decodes up to it and no
/// further, so the two agree.
pub const MAX_TEXTURE_DECODE_BYTES: u64 = 4 << 30;

/// The limits an image decoder runs under for a texture: at most
/// [`MAX_TEXTURE_DECODE_BYTES`] allocated.
pub fn texture_decode_limits() -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_alloc = Some(MAX_TEXTURE_DECODE_BYTES);
    limits
}

/// Why a texture of `width`×`height` whose decoder needs `decoded` bytes
/// cannot be decoded, if it cannot: its pixels, or the RGBA8 copy uploaded,
/// are over [`MAX_TEXTURE_DECODE_BYTES`].
pub fn decode_refusal(width: u32, height: u32, decoded: u64) -> Option<String> {
    let rgba8 = u64::from(width) * u64::from(height) * 4;
    let needed = decoded.max(rgba8);
    (needed > MAX_TEXTURE_DECODE_BYTES).then(|| {
        format!(
            "texture is {width}x{height}: decoding it needs {:.2} GiB, over the {} GiB weft decodes; it is dropped (the material keeps its factors)",
            needed as f64 / f64::from(1u32 << 30),
            MAX_TEXTURE_DECODE_BYTES >> 30
        )
    })
}

/// The width and height an image file or embedded image declares, and the
/// bytes its decoded pixels take, read from its header alone (a file is opened through weft's one reader's checks, so
/// a FIFO is refused); `None` when it cannot be read or decoded.
pub fn declared_size(source: &TextureSource) -> Option<(u32, u32, u64)> {
    fn header<R: std::io::BufRead + std::io::Seek>(reader: R) -> Option<(u32, u32, u64)> {
        use image::ImageDecoder;
        let decoder = image::ImageReader::new(reader)
            .with_guessed_format()
            .ok()?
            .into_decoder()
            .ok()?;
        let (width, height) = decoder.dimensions();
        Some((width, height, decoder.total_bytes()))
    }
    match source {
        TextureSource::File(path) => {
            header(std::io::BufReader::new(weft_io::open_regular(path).ok()?))
        }
        TextureSource::Embedded { bytes, .. } => header(std::io::Cursor::new(&bytes[..])),
    }
}

#[cfg(test)]
mod fit_tests {
    use super::{decode_refusal, fit_within};

    #[test]
    fn textures_decode_up_to_four_gibibytes() {
        // 16384 a side in 16-bit RGBA: 2 GiB decoded, 1 GiB as RGBA8.
        assert_eq!(decode_refusal(16384, 16384, 2 << 30), None);
        assert_eq!(
            decode_refusal(32768, 32768, 8 << 30).as_deref(),
            Some("texture is 32768x32768: decoding it needs 8.00 GiB, over the 4 GiB weft decodes; it is dropped (the material keeps its factors)")
        );
        // The RGBA8 copy counts even when the decoder's pixels are smaller.
        assert!(decode_refusal(40000, 40000, 1 << 30).is_some());
    }

    #[test]
    fn oversized_images_fit_keeping_their_aspect() {
        assert_eq!(fit_within(65536, 1, 16384), (16384, 1));
        assert_eq!(fit_within(1, 32768, 16384), (1, 16384));
        assert_eq!(fit_within(20000, 10000, 16384), (16384, 8192));
        assert_eq!(fit_within(4096, 4096, 16384), (4096, 4096));
        assert_eq!(fit_within(16384, 3, 16384), (16384, 3));
    }
}
