//! glTF images and materials: every image as a texture source, decoded once;
//! metallic-roughness materials with the emissive-strength, transmission, IOR
//! and volume extensions.

use super::*;

/// Every image as a texture source, decoded once so materials share the bytes; `None`
/// (with a warning) for images that cannot be found.
pub(super) fn image_sources(
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    dir: &Path,
    path: &Path,
    diag: &mut Diagnostics,
    sources: &mut Vec<PathBuf>,
) -> Vec<Option<TextureSource>> {
    doc.images()
        .map(|image| {
            let id = format!("{}#image{}", path.display(), image.index());
            match image.source() {
                gltf::image::Source::View { view, mime_type } => {
                    let bytes = buffers
                        .get(view.buffer().index())
                        .and_then(|b| b.get(view.offset()..view.offset() + view.length()));
                    if bytes.is_none() {
                        diag.warn(
                            Location::file(path),
                            format!("image {} lies outside its buffer; left out", image.index()),
                        );
                    }
                    bytes.map(|bytes| TextureSource::Embedded {
                        id,
                        mime_type: mime_type.to_string(),
                        bytes: bytes.into(),
                    })
                }
                gltf::image::Source::Uri { uri, mime_type } => match decode_data_uri(uri) {
                    Some(Ok((mime, bytes))) => Some(TextureSource::Embedded {
                        id,
                        mime_type: mime_type.map_or(mime, str::to_string),
                        bytes: bytes.into(),
                    }),
                    Some(Err(e)) => {
                        diag.warn(
                            Location::file(path),
                            format!("image {}: {e}; left out", image.index()),
                        );
                        None
                    }
                    None => {
                        let file: PathBuf = dir.join(percent_decode(uri));
                        if let Some(message) = crate::outside::refusal(&file, dir, "image") {
                            diag.warn(
                                Location::file(path),
                                format!("image {}: {message}; left out", image.index()),
                            );
                            return None;
                        }
                        sources.push(file.clone());
                        if file.is_file() {
                            Some(TextureSource::File(
                                std::path::absolute(&file).unwrap_or(file),
                            ))
                        } else {
                            diag.warn(
                                Location::file(path),
                                format!("texture {} not found; left out", file.display()),
                            );
                            None
                        }
                    }
                },
            }
        })
        .collect()
}

/// A texture reference to an already-decoded image.
fn texture(
    texture: gltf::Texture<'_>,
    tex_coord: u32,
    images: &[Option<TextureSource>],
) -> Option<TextureRef> {
    let source = images.get(texture.source().index())?.clone()?;
    Some(TextureRef { source, tex_coord })
}

/// A glTF material.
pub(super) fn material(m: &gltf::Material<'_>, images: &[Option<TextureSource>]) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let tex = |t: Option<gltf::texture::Info<'_>>| {
        t.and_then(|info| texture(info.texture(), info.tex_coord(), images))
    };
    let mut out = Material {
        name: m.name().map_or_else(
            || format!("material{}", m.index().unwrap_or(0)),
            str::to_string,
        ),
        shading: ShadingModel::MetallicRoughness,
        base_color: Vec4::from_array(pbr.base_color_factor()),
        emissive: Vec3::from_array(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        ior: m.ior().unwrap_or(1.5),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
        ..Material::default()
    };
    out.textures.base_color = tex(pbr.base_color_texture());
    out.textures.metallic_roughness = tex(pbr.metallic_roughness_texture());
    out.textures.emissive = tex(m.emissive_texture());
    if let Some(n) = m.normal_texture() {
        out.normal_scale = n.scale();
        out.textures.normal = texture(n.texture(), n.tex_coord(), images);
    }
    if let Some(o) = m.occlusion_texture() {
        out.textures.occlusion = texture(o.texture(), o.tex_coord(), images);
    }
    if let Some(t) = m.transmission() {
        out.transmission = t.transmission_factor();
        out.textures.transmission = tex(t.transmission_texture());
    }
    if let Some(v) = m.volume() {
        out.thickness = v.thickness_factor();
        out.textures.thickness = tex(v.thickness_texture());
        let d = v.attenuation_distance();
        out.attenuation_distance = (d.is_finite() && d > 0.0).then_some(d);
        out.attenuation_color = Vec3::from_array(v.attenuation_color());
        out.absorption = absorption(out.attenuation_color, out.attenuation_distance);
    }
    if out.transmission > 0.0 {
        out.optics = Optics::Dielectric {
            fraction: out.transmission.min(1.0),
            thin: out.thickness <= 0.0,
        };
    }
    out
}

/// KHR_materials_volume's Beer–Lambert coefficient σ = −ln(c) / d per world
/// unit: light that travels `attenuation_distance` d keeps the fraction
/// `attenuation_color` c. A channel of 0 is taken as 1e-6 (σ finite); no
/// distance means no absorption.
fn absorption(color: Vec3, distance: Option<f32>) -> Vec3 {
    let Some(d) = distance else {
        return Vec3::ZERO;
    };
    let c = color.clamp(Vec3::splat(1e-6), Vec3::ONE);
    Vec3::new(-c.x.ln(), -c.y.ln(), -c.z.ln()) / d
}
