//! Errors from reading an exported scene: each names the file and, where it applies,
//! the JSON path (or mesh accessor) that was wrong.

use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Debug)]
pub struct SceneError {
    /// The file that was being read.
    pub file: PathBuf,
    /// Where in the file: a JSON path such as `node_groups[2].links[5].to_node`,
    /// `line 3 column 7`, or a glb accessor name. Empty when the whole file is meant.
    pub location: String,
    pub message: String,
}

impl SceneError {
    pub fn new(file: &Path, location: impl Into<String>, message: impl Into<String>) -> Self {
        SceneError {
            file: file.to_path_buf(),
            location: location.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.location.is_empty() {
            write!(f, "{}: {}", self.file.display(), self.message)
        } else {
            write!(
                f,
                "{}: at {}: {}",
                self.file.display(),
                self.location,
                self.message
            )
        }
    }
}

impl std::error::Error for SceneError {}
