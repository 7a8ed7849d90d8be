//! Material textures from files or embedded bytes, decoded to RGBA8 for
//! upload (`weft_gpu::texture::Texture`).

use crate::error::RenderError;
use weft_gpu::texture::Rgba8Image;
use weft_scene::material::TextureSource;

/// Decodes a texture's image file or embedded bytes.
pub fn decode(source: &TextureSource) -> Result<Rgba8Image, RenderError> {
    let (path, result) = match source {
        TextureSource::File(path) => (path.clone(), image::open(path)),
        TextureSource::Embedded { id, bytes, .. } => (id.into(), image::load_from_memory(bytes)),
    };
    let img = result
        .map_err(|e| RenderError::Texture {
            path,
            message: e.to_string(),
        })?
        .to_rgba8();
    Ok(Rgba8Image {
        width: img.width(),
        height: img.height(),
        rgba: img.into_raw(),
    })
}
