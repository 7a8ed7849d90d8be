//! The two images compare works on: linear HDR RGB (EXR) and tonemapped
//! 8-bit sRGB (PNG), with errors that say what was wrong with a file.

use std::path::{Path, PathBuf};

/// The largest EXR file read (a 16384×16384 RGBA float image is 4 GiB).
const MAX_EXR_BYTES: u64 = 4 << 30;

/// Why an image could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be decoded.
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
    /// The file could not be written.
    #[error("writing {path}: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What the encoder said.
        message: String,
    },
    /// An image that should hold radiance holds non-finite or negative values.
    #[error("{path}: {count} pixel(s) are not finite, non-negative radiance; the first is at ({x}, {y}): {value:?}")]
    Radiance {
        /// The file.
        path: PathBuf,
        /// How many pixels have a non-finite or negative channel.
        count: usize,
        /// The first such pixel's column.
        x: u32,
        /// The first such pixel's row.
        y: u32,
        /// Its value.
        value: [f32; 3],
    },
    /// Two images that must match in size do not.
    #[error("{what}: {found_width}x{found_height}, but the reference is {width}x{height} (images are not resampled)")]
    Size {
        /// Which image.
        what: String,
        /// The reference's size.
        width: u32,
        /// The reference's size.
        height: u32,
        /// This image's size.
        found_width: u32,
        /// This image's size.
        found_height: u32,
    },
}

/// Linear RGB floats, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// One RGB triple per pixel.
    pub pixels: Vec<[f32; 3]>,
}

/// 8-bit sRGB, row by row from the top.
#[derive(Debug, Clone, PartialEq)]
pub struct SrgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// R, G, B bytes per pixel.
    pub bytes: Vec<u8>,
}

impl LinearImage {
    /// Reads an OpenEXR file's RGB channels (alpha, if any, is dropped)
    /// through weft's one reader: a FIFO or device is refused, never waited on.
    pub fn read_exr(path: &Path) -> Result<Self, ImageError> {
        let bytes = weft_io::read_capped(path, MAX_EXR_BYTES).map_err(|e| ImageError::Read {
            path: path.to_path_buf(),
            message: e.reason(),
        })?;
        Self::decode_exr(&bytes, path)
    }

    /// Decodes OpenEXR bytes; `path` names them in errors.
    pub fn decode_exr(bytes: &[u8], path: &Path) -> Result<Self, ImageError> {
        let read = |message: String| ImageError::Read {
            path: path.to_path_buf(),
            message,
        };
        let mut decoded = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| read(e.to_string()))?;
        let named_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if decoded.format().is_none() && named_exr {
            // A file named .exr whose bytes are not: say why it does not decode.
            decoded.set_format(image::ImageFormat::OpenExr);
        }
        if decoded.format() != Some(image::ImageFormat::OpenExr) {
            return Err(read("not an OpenEXR file".into()));
        }
        let rgb = decoded
            .decode()
            .map_err(|e| read(format!("not a readable RGB(A) EXR: {e}")))?
            .into_rgb32f();
        Ok(Self {
            width: rgb.width(),
            height: rgb.height(),
            pixels: rgb.pixels().map(|p| p.0).collect(),
        })
    }

    /// The image as the bytes of an RGB OpenEXR file (`weft_io::exr`:
    /// scanlines, float channels); `path` names it in errors.
    pub fn encode_exr(&self, path: &Path) -> Result<Vec<u8>, ImageError> {
        weft_io::exr::encode_rgb(self.width, self.height, &self.pixels).map_err(|e| {
            ImageError::Write {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })
    }

    /// An error unless every channel of every pixel is finite and not
    /// negative, as radiance is: it names how many pixels are not, and the
    /// first (row by row from the top).
    pub fn check_radiance(&self, path: &Path) -> Result<(), ImageError> {
        let bad = |p: &[f32; 3]| p.iter().any(|c| !c.is_finite() || *c < 0.0);
        let count = self.pixels.iter().filter(|p| bad(p)).count();
        match self.pixels.iter().position(bad) {
            None => Ok(()),
            Some(first) => Err(ImageError::Radiance {
                path: path.to_path_buf(),
                count,
                x: first as u32 % self.width.max(1),
                y: first as u32 / self.width.max(1),
                value: self.pixels[first],
            }),
        }
    }

    /// Writes the image as an RGB OpenEXR file.
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        let bytes = self.encode_exr(path)?;
        weft_io::write_output(path, &bytes).map_err(|e| ImageError::Write {
            path: path.to_path_buf(),
            message: e.reason(),
        })
    }

    /// An error unless `other` has this image's size.
    pub fn check_size(
        &self,
        other_width: u32,
        other_height: u32,
        what: &str,
    ) -> Result<(), ImageError> {
        if (self.width, self.height) == (other_width, other_height) {
            return Ok(());
        }
        Err(ImageError::Size {
            what: what.to_string(),
            width: self.width,
            height: self.height,
            found_width: other_width,
            found_height: other_height,
        })
    }
}

impl SrgbImage {
    /// Writes the image as a PNG file.
    pub fn write_png(&self, path: &Path) -> Result<(), ImageError> {
        let write = |message: String| ImageError::Write {
            path: path.to_path_buf(),
            message,
        };
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::RgbImage::from_raw(self.width, self.height, self.bytes.clone())
            .ok_or_else(|| write("pixel count does not match the size".into()))?
            .write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| write(e.to_string()))?;
        weft_io::write_output(path, bytes.get_ref()).map_err(|e| write(e.reason()))
    }
}

/// The sRGB encoding of a linear value in [0, 1] (IEC 61966-2-1).
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// A value in [0, 1] as the nearest byte.
pub fn to_byte(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}
