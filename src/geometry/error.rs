//! Errors of Geometry Nodes evaluation. Messages name the object, node tree and node
//! (as `node tree "T", node "Group > Math": ...`) so a user can find what failed.

use std::fmt;

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GeometryError {
    pub message: String,
}

impl GeometryError {
    pub fn new(message: impl Into<String>) -> Self {
        GeometryError {
            message: message.into(),
        }
    }
    /// Prefixes the message with where it happened.
    pub fn within(self, outer: impl fmt::Display) -> Self {
        GeometryError {
            message: format!("{outer}: {}", self.message),
        }
    }
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for GeometryError {}

impl From<crate::scene::SceneError> for GeometryError {
    fn from(e: crate::scene::SceneError) -> Self {
        GeometryError::new(e.to_string())
    }
}

impl From<crate::anim::AnimError> for GeometryError {
    fn from(e: crate::anim::AnimError) -> Self {
        GeometryError::new(e.to_string())
    }
}
