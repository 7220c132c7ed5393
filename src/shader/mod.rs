//! Materials compiled into flat programs that run per shading point (`program`), from a
//! node tree flattened by `nodes::graph` (`compile`), and evaluated over a mesh's UV
//! map the way Cycles' EMIT bake does (`bake`).

pub mod attributes;
pub mod bump;
pub mod bump_graph;
pub mod compile;
pub mod derived;
pub mod images;
pub mod inputs;
pub mod point;
pub mod program;
pub mod tangent;
pub mod trace;
pub mod view;

pub use compile::{compile_material, CompileError};
pub use point::{HairPoint, ShadingPoint};
pub use program::Program;
