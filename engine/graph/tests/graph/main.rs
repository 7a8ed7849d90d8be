//! Every integration test of weft-graph in one binary (one link instead of one per
//! file), a module per subject. `cargo test -p weft-graph --test graph -- MODULE::` runs one.

mod support;

mod define_sets;
mod errors;
mod fuzz;
mod includes;
mod jitter;
mod params;
mod plans;
mod random;
mod scratch;
