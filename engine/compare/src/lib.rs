//! What `weft compare` measures and writes: image error against a reference
//! (HDR-FLIP and LDR-FLIP through NVIDIA's FLIP, RMSE and relative MSE in
//! linear HDR, PSNR on the tonemapped output), the on-disk cache of
//! reference renders, and the report files (docs/compare.md).

pub mod cache;
pub mod flip;
pub mod image_io;
pub mod metrics;
pub mod pareto;
pub mod report;
pub mod sweep;

pub use flip::{hdr_flip, ldr_flip, FlipResult};
pub use image_io::{LinearImage, SrgbImage};
pub use metrics::{luminance_ratio, psnr, rel_mse, rmse};
