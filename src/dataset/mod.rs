//! Datasets: randomisation specs, the `generate` pipeline (parallel, resumable,
//! sharded), `merge`, `preview` and the built-in `replicate` datasets.
//!
//! One idea per file: `rng` (counter-based draws), `spec` (the TOML spec and its
//! validation), `renderer` (the trait a frame renderer implements), `bounds` (a
//! debugging renderer of object bounds), `layout` (the output folder and atomic
//! writes), `generate` (the frame loop), `finalize` (COCO, YOLO, frames.jsonl; `merge`),
//! `preview` (contact sheet), `replicate` (built-in scenes and specs).

pub mod bounds;
pub mod finalize;
pub mod generate;
pub mod layout;
pub mod preview;
pub mod renderer;
pub mod replicate;
pub mod rng;
pub mod spec;

pub use finalize::{finalize, merge};
pub use generate::{generate, GenerateOptions, Summary};
pub use renderer::{FrameRenderer, RenderedFrame};
pub use spec::{Spec, SpecError};
