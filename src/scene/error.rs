use std::fmt;

/// An error in the scene description: where it is (`file:line`, or the command-line flag that
/// set the value), which key, and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// `file:line`, or the flag that set the value.
    pub at: String,
    /// The key, dotted from the table (empty where the error is about no key).
    pub key: String,
    /// What is wrong, and where it helps, what would be right.
    pub message: String,
}

impl SceneError {
    /// An error at `at`, on `key`.
    pub fn new(at: impl Into<String>, key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            at: at.into(),
            key: key.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        if self.key.is_empty() {
            write!(f, "{}: {}", self.at, self.message)
        } else {
            write!(f, "{}: key `{}`: {}", self.at, self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}
