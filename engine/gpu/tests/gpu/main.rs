//! Every integration test of weft-gpu in one binary (one link instead of one per
//! file), a module per subject. `cargo test -p weft-gpu --test gpu -- MODULE::` runs one.

mod common;

mod check;
mod context;
mod execute;
mod golden;
mod layouts;
mod readback;
mod shaders;
