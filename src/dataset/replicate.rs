//! `blendsynth replicate --dataset doi-23843904`: the procedural colonoscopy and
//! laparoscopy datasets of Dowrick et al. (UCL, 2023; DOI 10.5522/04/23843904),
//! regenerated through the same `generate` pipeline.
//!
//! Built-in scenes live in `assets/doi-23843904/` (authored by `make_scenes.py` with
//! bpy, exported with the project's exporter), each with its spec (TOML) listing the
//! study's randomised parameters. `--assets DIR` takes a user's converted .blend
//! instead; for the published colon scene (`colon_nodes.blend`) the spec
//! `colon_nodes.toml` reproduces the authors' script (frames, ranges).

use std::path::{Path, PathBuf};

use super::spec::Spec;
use crate::scene::Scene;

pub const DATASET: &str = "doi-23843904";

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Part {
    Colonoscopy,
    Laparoscopy,
    All,
}

impl Part {
    pub fn parts(self) -> Vec<Part> {
        match self {
            Part::All => vec![Part::Colonoscopy, Part::Laparoscopy],
            p => vec![p],
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Part::Colonoscopy => "colonoscopy",
            Part::Laparoscopy => "laparoscopy",
            Part::All => "all",
        }
    }
}

/// The study's split: 45,000 / 5,000 of 50,000.
pub fn split() -> Vec<(String, f64)> {
    vec![("train".into(), 0.9), ("val".into(), 0.1)]
}

/// Where the built-in scenes and specs are.
pub fn assets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(DATASET)
}

/// The scene and spec of one part: built-in, or a converted scene given by `--assets`.
pub fn scene_and_spec(part: Part, assets: Option<&Path>) -> Result<(Scene, Spec), String> {
    let root = assets_dir();
    let scene_dir = match assets {
        Some(d) => d.to_path_buf(),
        None => root.join(part.name()),
    };
    let scene = Scene::load(&scene_dir).map_err(|e| e.to_string())?;
    let spec_name = if scene.file.source_file == "colon_nodes.blend" {
        "colon_nodes.toml".to_string()
    } else {
        format!("{}.toml", part.name())
    };
    let spec = Spec::load(&root.join(spec_name)).map_err(|e| e.to_string())?;
    Ok((scene, spec))
}
