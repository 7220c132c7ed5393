//! Errors from evaluating a scene at a frame. Each names what was being evaluated (an
//! object, a constraint, an F-curve's ID and data path) so a user can find it in Blender.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub struct AnimError {
    /// Where, as a Blender-style path: `objects["Camera"].constraints["Follow Path"]`,
    /// `curves["Path"] fcurve eval_time[0]`, ...
    pub context: String,
    pub message: String,
}

impl AnimError {
    pub fn new(context: impl Into<String>, message: impl Into<String>) -> Self {
        AnimError {
            context: context.into(),
            message: message.into(),
        }
    }

    /// Prefixes an outer context (`objects["A"]` + `constraints["B"]`).
    pub fn within(mut self, outer: &str) -> Self {
        self.context = if self.context.is_empty() {
            outer.to_string()
        } else {
            format!("{outer}.{}", self.context)
        };
        self
    }
}

impl fmt::Display for AnimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.context.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.context, self.message)
        }
    }
}

impl std::error::Error for AnimError {}
