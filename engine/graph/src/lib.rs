//! weft render graphs as data. A graph is a RON file of resources and passes; this
//! crate loads it with its includes, validates it with located diagnostics, and
//! compiles it into a [`Plan`]: pass order, culling, transient memory aliasing,
//! synchronization2 barriers and render-pass descriptions. No Vulkan calls.

pub mod check;
pub mod compile;
pub mod condition;
pub mod diagnostic;
pub mod dot;
pub mod expr;
pub mod id;
pub mod load;
pub mod plan;
pub mod provider;
pub mod resolve;
pub mod schema;
pub mod spans;
pub mod text;
pub mod vk;
pub mod vocabulary;

pub use check::check;
pub use compile::conditions_hold;
pub use compile::memory::{estimate_requirements, MemoryRequirements};
pub use compile::{compile, CompileOptions, Prepared};
pub use diagnostic::{Diagnostic, Severity};
pub use load::{load, load_with, load_with_params, LoadedGraph};
pub use plan::{Extent, Plan};
pub use resolve::feature_names;
pub use vocabulary::{check_vocabulary, SceneValue, SceneVocabulary};
