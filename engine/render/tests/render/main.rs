//! Every integration test of weft-render in one binary (one link instead of one per
//! file), a module per subject. `cargo test -p weft-render --test render -- MODULE::` runs one.

mod octahedral;
mod reload;
mod watch;
