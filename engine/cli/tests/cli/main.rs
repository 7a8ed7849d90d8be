//! Every test of the `weft` command line in one binary (one link instead of one
//! per file), a module per command. `cargo test -p weft-cli --test cli -- MODULE::`
//! runs one.

mod harness;
mod watch_support;

mod bench;
mod check_interfaces;
mod compare;
mod graph;
mod render;
mod robustness;
mod scene;
mod view;
mod watch;
