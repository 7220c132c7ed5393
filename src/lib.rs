//! blendsynth: renders Blender scenes without Blender, to make labelled synthetic
//! training datasets.
//!
//! Data flows one way: a .blend is exported by Blender (`blender`) into the exchange
//! format, read by `scene`, evaluated by `nodes` (shader and Geometry Nodes graphs),
//! and reported on by `inspect`. See ARCHITECTURE.md.

pub mod anim;
pub mod api;
pub mod blender;
pub mod color;
pub mod dataset;
pub mod denoise;
pub mod foundation;
pub mod geometry;
pub mod inspect;
pub mod label;
pub mod nodes;
pub mod render;
pub mod scene;
pub mod shader;

/// Python bindings (the `blendsynth` wheel, built by maturin with `--features python`).
#[cfg(feature = "python")]
mod python;
