//! Located errors and warnings: every problem in a graph names a file, line and
//! column, says what is wrong in one line, and where possible how to fix it.
//! The type is weft's one diagnostic (`weft-diagnostic`), shared with scene,
//! shader and reload errors and printed the same way.

pub use weft_diagnostic::{nearest, render, to_json, Diagnostic, Severity};
