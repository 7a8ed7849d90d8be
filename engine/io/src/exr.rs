//! The one way weft writes OpenEXR: scanline blocks of 16 lines, ZIP
//! compressed (lossless), 32-bit float R, G, B (and A) channels, lines in
//! increasing order. Every OpenEXR reader reads that: the OpenEXR library,
//! tinyexr (which the FLIP reference tool uses, and which cannot read the
//! tiled files the `image` crate writes) and Python's `OpenEXR`.

use exr::prelude::{
    Blocks, Compression, Encoding, Image, Layer, LayerAttributes, LineOrder, SpecificChannels,
    Vec2, WritableImage,
};
use std::io::Cursor;

/// Why an image could not be encoded.
#[derive(Debug, thiserror::Error)]
pub enum ExrError {
    /// The pixel count is not width × height.
    #[error("{pixels} pixels do not fill a {width}x{height} image")]
    Size {
        /// Pixels given.
        pixels: usize,
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
    },
    /// The encoder failed.
    #[error("{0}")]
    Encode(String),
}

/// How weft's EXR files are laid out (see the module docs).
const ENCODING: Encoding = Encoding {
    compression: Compression::ZIP16,
    blocks: Blocks::ScanLines,
    line_order: LineOrder::Increasing,
};

/// Writes one layer of `channels` over `size` with weft's [`ENCODING`].
macro_rules! encode_layer {
    ($size:expr, $channels:expr) => {{
        let mut bytes = Cursor::new(Vec::new());
        Image::from_layer(Layer::new(
            $size,
            LayerAttributes::default(),
            ENCODING,
            $channels,
        ))
        .write()
        .to_buffered(&mut bytes)
        .map_err(encode_error)?;
        Ok(bytes.into_inner())
    }};
}

/// An RGB float image, rows from the top, as the bytes of an EXR file.
pub fn encode_rgb(width: u32, height: u32, pixels: &[[f32; 3]]) -> Result<Vec<u8>, ExrError> {
    let size = checked_size(width, height, pixels.len())?;
    encode_layer!(
        size,
        SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let [r, g, b] = pixels[y * size.0 + x];
            (r, g, b)
        })
    )
}

/// An RGBA float image, rows from the top, as the bytes of an EXR file.
pub fn encode_rgba(width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<Vec<u8>, ExrError> {
    let size = checked_size(width, height, pixels.len())?;
    encode_layer!(
        size,
        SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let [r, g, b, a] = pixels[y * size.0 + x];
            (r, g, b, a)
        })
    )
}

/// The image size as the encoder takes it, when `count` pixels fill it.
fn checked_size(width: u32, height: u32, count: usize) -> Result<(usize, usize), ExrError> {
    let size = (width as usize, height as usize);
    if size.0.checked_mul(size.1) != Some(count) || count == 0 {
        return Err(ExrError::Size {
            pixels: count,
            width,
            height,
        });
    }
    Ok(size)
}

fn encode_error(e: exr::error::Error) -> ExrError {
    ExrError::Encode(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use exr::prelude::{read, FlatSamples, ReadChannels, ReadLayers};

    /// Reads `bytes` back with the exr crate's generic reader: the layer's
    /// encoding and its channels by name.
    fn read_back(bytes: &[u8]) -> (Encoding, Vec<(String, Vec<f32>)>) {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .expect("reads back");
        let layer = &image.layer_data;
        let channels = layer
            .channel_data
            .list
            .iter()
            .map(|c| match &c.sample_data {
                FlatSamples::F32(values) => (c.name.to_string(), values.clone()),
                other => panic!("channel {} is not f32: {other:?}", c.name),
            })
            .collect();
        (layer.encoding, channels)
    }

    #[test]
    fn writes_float_scanlines_any_reader_reads_with_every_value_kept() {
        let pixels = [[0.25, 2.0, 1e30], [0.0, 5e-39, 7.5]];
        let (encoding, channels) = read_back(&encode_rgb(2, 1, &pixels).expect("encodes"));
        assert_eq!(encoding.blocks, Blocks::ScanLines);
        assert_eq!(encoding.compression, Compression::ZIP16);
        assert_eq!(encoding.line_order, LineOrder::Increasing);
        // Channels are stored in name order.
        assert_eq!(
            channels,
            [
                ("B".to_string(), vec![1e30, 7.5]),
                ("G".to_string(), vec![2.0, 5e-39]),
                ("R".to_string(), vec![0.25, 0.0]),
            ]
        );
        let rgba = [
            [0.5, 0.25, 0.125, 1.0],
            [1.0, 2.0, 3.0, 0.0],
            [4.0, 5.0, 6.0, 0.5],
            [7.0, 8.0, 9.0, 1.0],
        ];
        let (encoding, channels) = read_back(&encode_rgba(2, 2, &rgba).expect("encodes"));
        assert_eq!(encoding.blocks, Blocks::ScanLines);
        let names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["A", "B", "G", "R"]);
        assert_eq!(channels[0].1, [1.0, 0.0, 0.5, 1.0]);
        assert_eq!(channels[3].1, [0.5, 1.0, 4.0, 7.0]);
    }

    #[test]
    fn refuses_pixels_that_do_not_fill_the_image() {
        let error = encode_rgb(3, 2, &[[0.0; 3]; 5]).expect_err("5 pixels for 6");
        assert_eq!(error.to_string(), "5 pixels do not fill a 3x2 image");
        assert!(encode_rgba(0, 0, &[]).is_err());
    }
}
