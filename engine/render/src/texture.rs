//! Material textures from files or embedded bytes, decoded to RGBA8 for
//! upload (`weft_gpu::texture::Texture`). Files are read through weft's one
//! reader; an image with a side over the device's `maxImageDimension2D` is
//! downscaled here, with a warning, and never reaches the driver.

use crate::error::RenderError;
use weft_gpu::texture::Rgba8Image;
use weft_scene::material::TextureSource;

/// The largest texture file read.
const MAX_TEXTURE_FILE_BYTES: u64 = 1 << 30;

/// A decoded texture and, when it had to be downscaled, why.
pub struct Decoded {
    /// The pixels, at most the asked side.
    pub image: Rgba8Image,
    /// Why the image was downscaled, when it was.
    pub warning: Option<String>,
}

/// What names a texture's source for sharing one decoded copy: a file's
/// path, an embedded image's id.
pub fn source_key(source: &TextureSource) -> String {
    match source {
        TextureSource::File(p) => p.display().to_string(),
        TextureSource::Embedded { id, .. } => id.clone(),
    }
}

/// Decodes a texture's image file or embedded bytes, downscaled (keeping its
/// aspect, each side at least 1) so neither side exceeds `max_side`.
pub fn decode(source: &TextureSource, max_side: u32) -> Result<Decoded, RenderError> {
    let (name, bytes) = match source {
        TextureSource::File(path) => (
            path.clone(),
            weft_io::read_capped(path, MAX_TEXTURE_FILE_BYTES)
                .map_err(|e| RenderError::Texture {
                    path: path.clone(),
                    message: e.reason(),
                })?
                .into(),
        ),
        TextureSource::Embedded { id, bytes, .. } => {
            (id.into(), std::borrow::Cow::from(&bytes[..]))
        }
    };
    let failed = |message: String| RenderError::Texture {
        path: name.clone(),
        message,
    };
    let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
        .with_guessed_format()
        .map_err(|e| failed(e.to_string()))?;
    // Up to the bytes `weft scene check` accepts, so the two agree.
    reader.limits(weft_scene::material::texture_decode_limits());
    let decoded = reader.decode().map_err(|e| failed(e.to_string()))?;
    let (width, height) = (decoded.width(), decoded.height());
    if let Some(refusal) = weft_scene::material::decode_refusal(width, height, 0) {
        return Err(failed(refusal));
    }
    let img = decoded.to_rgba8();
    let (width, height) = img.dimensions();
    let (fit_width, fit_height) = weft_scene::material::fit_within(width, height, max_side);
    let (img, warning) = if (fit_width, fit_height) == (width, height) {
        (img, None)
    } else {
        let smaller = image::imageops::resize(
            &img,
            fit_width,
            fit_height,
            image::imageops::FilterType::Triangle,
        );
        let warning = format!(
            "texture {} is {width}x{height}, over the device's maxImageDimension2D of {max_side}: downscaled to {fit_width}x{fit_height}",
            name.display()
        );
        (smaller, Some(warning))
    };
    Ok(Decoded {
        image: Rgba8Image {
            width: img.width(),
            height: img.height(),
            rgba: img.into_raw(),
        },
        warning,
    })
}
