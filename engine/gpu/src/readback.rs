//! The output image copied back to the CPU, converted to 8-bit RGBA or linear
//! float RGBA, and saved as PNG.

use std::path::Path;

/// Pixels read back from the device, row-major, top row first, RGBA.
#[derive(Debug, Clone, PartialEq)]
pub enum Pixels {
    /// 8-bit channels as stored (sRGB-encoded for `_SRGB` formats).
    Rgba8(Vec<u8>),
    /// Linear floats (from 16- or 32-bit float formats).
    RgbaF32(Vec<f32>),
    /// One unsigned integer per pixel (`R32_UINT`: counts).
    CountU32(Vec<u32>),
    /// One float per pixel (`R32_SFLOAT`: measures).
    ValueF32(Vec<f32>),
}

impl Pixels {
    /// One value per pixel, as f64, for single-channel images (counts and
    /// measures); `None` for colour images.
    pub fn values(&self) -> Option<Vec<f64>> {
        match self {
            Pixels::CountU32(v) => Some(v.iter().map(|&c| f64::from(c)).collect()),
            Pixels::ValueF32(v) => Some(v.iter().map(|&c| f64::from(c)).collect()),
            Pixels::Rgba8(_) | Pixels::RgbaF32(_) => None,
        }
    }

    /// RGBA floats, a single channel replicated into red, green and blue.
    fn rgba_f32(&self) -> Option<Vec<f32>> {
        let grey = |v: f32| [v, v, v, 1.0];
        match self {
            Pixels::RgbaF32(v) => Some(v.clone()),
            Pixels::CountU32(v) => Some(v.iter().flat_map(|&c| grey(c as f32)).collect()),
            Pixels::ValueF32(v) => Some(v.iter().flat_map(|&c| grey(c)).collect()),
            Pixels::Rgba8(_) => None,
        }
    }
}

/// An image read back from the device.
#[derive(Debug, Clone, PartialEq)]
pub struct Readback {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The Vulkan format name it came from.
    pub format: String,
    /// The pixel values.
    pub pixels: Pixels,
}

/// Why a readback could not be converted or saved.
#[derive(Debug, thiserror::Error)]
pub enum ReadbackError {
    /// The output format has no conversion.
    #[error("cannot read back images of format {0}")]
    Format(String),
    /// The file name ends in neither `.png` nor `.exr`.
    #[error("cannot save {0}: use a .png or .exr file name")]
    Extension(String),
    /// Writing the file failed.
    #[error("cannot write {path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// Bytes per texel of the formats that can be read back.
pub fn texel_bytes(format: &str) -> Option<u32> {
    match format {
        "R8G8B8A8_UNORM" | "R8G8B8A8_SRGB" | "B8G8R8A8_UNORM" | "B8G8R8A8_SRGB" => Some(4),
        "R16G16B16A16_SFLOAT" => Some(8),
        "R32G32B32A32_SFLOAT" => Some(16),
        "R32_UINT" | "R32_SFLOAT" => Some(4),
        _ => None,
    }
}

/// Converts raw texels (tightly packed) of `format` into `Pixels`.
pub fn decode(format: &str, bytes: &[u8]) -> Result<Pixels, ReadbackError> {
    match format {
        "R8G8B8A8_UNORM" | "R8G8B8A8_SRGB" => Ok(Pixels::Rgba8(bytes.to_vec())),
        "B8G8R8A8_UNORM" | "B8G8R8A8_SRGB" => Ok(Pixels::Rgba8(
            bytes
                .chunks_exact(4)
                .flat_map(|p| [p[2], p[1], p[0], p[3]])
                .collect(),
        )),
        "R16G16B16A16_SFLOAT" => Ok(Pixels::RgbaF32(
            bytes
                .chunks_exact(2)
                .map(|h| half_to_f32(u16::from_le_bytes([h[0], h[1]])))
                .collect(),
        )),
        "R32G32B32A32_SFLOAT" => Ok(Pixels::RgbaF32(
            bytes
                .chunks_exact(4)
                .map(|f| f32::from_le_bytes([f[0], f[1], f[2], f[3]]))
                .collect(),
        )),
        "R32_UINT" => Ok(Pixels::CountU32(
            bytes
                .chunks_exact(4)
                .map(|f| u32::from_le_bytes([f[0], f[1], f[2], f[3]]))
                .collect(),
        )),
        "R32_SFLOAT" => Ok(Pixels::ValueF32(
            bytes
                .chunks_exact(4)
                .map(|f| f32::from_le_bytes([f[0], f[1], f[2], f[3]]))
                .collect(),
        )),
        other => Err(ReadbackError::Format(other.to_string())),
    }
}

/// IEEE 754 half to single precision.
pub fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        e => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// The sRGB transfer function's inverse.
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

impl Readback {
    /// 8-bit RGBA: stored bytes, or floats clamped to [0, 1] and rounded.
    pub fn to_rgba8(&self) -> image::RgbaImage {
        let data = match (&self.pixels, self.pixels.rgba_f32()) {
            (Pixels::Rgba8(v), _) => v.clone(),
            (_, Some(v)) => v
                .iter()
                .map(|&f| (f.clamp(0.0, 1.0) * 255.0).round() as u8)
                .collect(),
            (_, None) => Vec::new(),
        };
        image::RgbaImage::from_raw(self.width, self.height, data)
            .unwrap_or_else(|| image::RgbaImage::new(self.width, self.height))
    }

    /// The pixel at (x, y) as RGBA bytes.
    pub fn rgba8_at(&self, x: u32, y: u32) -> [u8; 4] {
        self.to_rgba8().get_pixel(x, y).0
    }

    /// Linear float RGBA: floats as read, 8-bit values divided by 255 and,
    /// for `_SRGB` formats, decoded to linear.
    pub fn to_rgba_f32(&self) -> image::Rgba32FImage {
        let srgb = self.format.ends_with("_SRGB");
        let data = match &self.pixels {
            Pixels::RgbaF32(_) | Pixels::CountU32(_) | Pixels::ValueF32(_) => {
                self.pixels.rgba_f32().unwrap_or_default()
            }
            Pixels::Rgba8(v) => v
                .iter()
                .enumerate()
                .map(|(i, &b)| {
                    let x = f32::from(b) / 255.0;
                    if srgb && i % 4 != 3 {
                        srgb_to_linear(x)
                    } else {
                        x
                    }
                })
                .collect(),
        };
        image::Rgba32FImage::from_raw(self.width, self.height, data)
            .unwrap_or_else(|| image::Rgba32FImage::new(self.width, self.height))
    }

    /// Saves as PNG (8-bit, as stored) or OpenEXR (linear floats), by extension.
    pub fn save(&self, path: &Path) -> Result<(), ReadbackError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => self.save_png(path),
            Some("exr") => self.save_exr(path),
            _ => Err(ReadbackError::Extension(path.display().to_string())),
        }
    }

    /// Saves linear floats as an RGBA OpenEXR file (`weft_io::exr`:
    /// scanlines, float channels).
    pub fn save_exr(&self, path: &Path) -> Result<(), ReadbackError> {
        let write = |message: String| ReadbackError::Write {
            path: path.display().to_string(),
            message,
        };
        let rgba: Vec<[f32; 4]> = self.to_rgba_f32().pixels().map(|p| p.0).collect();
        let bytes = weft_io::exr::encode_rgba(self.width, self.height, &rgba)
            .map_err(|e| write(e.to_string()))?;
        weft_io::write_output(path, &bytes).map_err(|e| write(e.reason()))
    }

    /// Saves the 8-bit image as PNG.
    pub fn save_png(&self, path: &Path) -> Result<(), ReadbackError> {
        let write = |message: String| ReadbackError::Write {
            path: path.display().to_string(),
            message,
        };
        let mut bytes = std::io::Cursor::new(Vec::new());
        self.to_rgba8()
            .write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| write(e.to_string()))?;
        weft_io::write_output(path, bytes.get_ref()).map_err(|e| write(e.reason()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_halves_exactly() {
        assert_eq!(half_to_f32(0x3c00), 1.0);
        assert_eq!(half_to_f32(0xc000), -2.0);
        assert_eq!(half_to_f32(0x3800), 0.5);
        assert_eq!(half_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(half_to_f32(0x7c00), f32::INFINITY);
    }

    #[test]
    fn saves_png_and_exr_by_extension() {
        let image = Readback {
            width: 2,
            height: 1,
            format: "R16G16B16A16_SFLOAT".into(),
            pixels: Pixels::RgbaF32(vec![0.25, 2.0, 0.0, 1.0, 1.0, 0.5, 0.0, 1.0]),
        };
        let dir = std::env::temp_dir().join(format!("weft-readback-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        image.save(&dir.join("a.exr")).expect("exr");
        let back = image::open(dir.join("a.exr"))
            .expect("reads exr")
            .to_rgba32f();
        assert_eq!(back.get_pixel(0, 0).0, [0.25, 2.0, 0.0, 1.0]);
        image.save(&dir.join("a.png")).expect("png");
        let png = image::open(dir.join("a.png"))
            .expect("reads png")
            .to_rgba8();
        assert_eq!(png.get_pixel(0, 0).0, [64, 255, 0, 255]);
        assert!(matches!(
            image.save(&dir.join("a.bmp")),
            Err(ReadbackError::Extension(_))
        ));
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn decodes_srgb_bytes_to_linear() {
        let image = Readback {
            width: 1,
            height: 1,
            format: "R8G8B8A8_SRGB".into(),
            pixels: Pixels::Rgba8(vec![255, 0, 188, 128]),
        };
        let p = image.to_rgba_f32().get_pixel(0, 0).0;
        assert_eq!(p[0], 1.0);
        assert_eq!(p[1], 0.0);
        assert!((p[2] - 0.503).abs() < 0.001, "{}", p[2]);
        assert_eq!(p[3], 128.0 / 255.0);
    }

    #[test]
    fn swizzles_bgra() {
        let p = decode("B8G8R8A8_UNORM", &[1, 2, 3, 4]).expect("decodes");
        assert_eq!(p, Pixels::Rgba8(vec![3, 2, 1, 4]));
        assert!(matches!(
            decode("D32_SFLOAT", &[0; 4]),
            Err(ReadbackError::Format(_))
        ));
    }
}
