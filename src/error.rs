//! The crate's one error type: what went wrong and where, with the underlying cause as
//! `source()`. Every fallible public function returns [`Result`].

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

/// What went wrong.
#[derive(Clone, Debug)]
pub enum Error {
    /// The scene description: file and line (or the flag that set the value), key, what.
    Scene(SceneError),
    /// A command-line flag's value.
    Flag {
        /// The flag as typed, e.g. `--backend`.
        flag: String,
        /// What is wrong with its value.
        message: String,
    },
    /// A backend could not be had, built or used (an unknown name, Embree's own messages).
    Backend(String),
    /// Beyond a limit of the program: more primitives than a group numbers, more memory than
    /// the limit allows.
    Limit(String),
    /// A value handed to the library that it refuses (a viewer's request, an argument from
    /// code); the message names the value and says why.
    Invalid(String),
    /// An image file could not be written or read (the message names the file).
    Image {
        /// The file.
        path: PathBuf,
        /// What went wrong with it.
        message: String,
        /// The underlying error, if any.
        source: Option<Cause>,
    },
}

/// `std::result::Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An error of a flag's value.
    pub fn flag(flag: &str, message: impl fmt::Display) -> Error {
        Error::Flag {
            flag: flag.to_string(),
            message: message.to_string(),
        }
    }

    /// A backend's error.
    pub fn backend(message: impl Into<String>) -> Error {
        Error::Backend(message.into())
    }

    /// An image file's error, with its cause.
    pub fn image(
        path: impl Into<PathBuf>,
        message: impl Into<String>,
        source: Option<Cause>,
    ) -> Error {
        Error::Image {
            path: path.into(),
            message: message.into(),
            source,
        }
    }

    /// A value refused, the message naming it.
    pub fn invalid(message: impl Into<String>) -> Error {
        Error::Invalid(message.into())
    }

    /// The same error blamed on `flag` (a backend named on the command line, say).
    pub fn on_flag(self, flag: &str) -> Error {
        match self {
            Error::Scene(_) | Error::Flag { .. } => self,
            other => Error::flag(flag, other),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Error::Scene(e) => write!(f, "{e}"),
            Error::Flag { flag, message } => write!(f, "{flag}: {message}"),
            Error::Backend(m) | Error::Limit(m) | Error::Invalid(m) => write!(f, "{m}"),
            Error::Image { message, .. } => write!(f, "{message}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Scene(e) => Some(e),
            Error::Image {
                source: Some(s), ..
            } => Some(s.as_ref()),
            _ => None,
        }
    }
}

/// The cause of an error, shared so that [`Error`] can be cloned.
pub type Cause = Arc<dyn std::error::Error + Send + Sync>;

/// An error as the cause of another (a render's inside the writing of its file).
impl From<Error> for Cause {
    fn from(e: Error) -> Cause {
        Arc::new(e)
    }
}

impl Error {
    /// The error of this crate's that caused this one, if any (an image written as it was
    /// rendered fails with the render's error as its cause): the one to report.
    pub fn root(self) -> Error {
        let inner = match &self {
            Error::Image {
                source: Some(s), ..
            } => s.downcast_ref::<Error>().cloned(),
            _ => None,
        };
        inner.map_or(self, Error::root)
    }
}

impl From<SceneError> for Error {
    fn from(e: SceneError) -> Error {
        Error::Scene(e)
    }
}

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

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        if self.key.is_empty() {
            write!(f, "{}: {}", self.at, self.message)
        } else {
            write!(f, "{}: key `{}`: {}", self.at, self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// The scene's error is the cause of a scene error, the file system's of an image error; a
    /// backend's error blamed on a flag names the flag.
    #[test]
    fn errors_say_where_and_keep_their_cause() {
        let scene = Error::from(SceneError::new("a.toml:3", "camera.fov_y", "too wide"));
        assert_eq!(scene.to_string(), "a.toml:3: key `camera.fov_y`: too wide");
        assert!(scene.source().is_some());
        let io = std::io::Error::new(std::io::ErrorKind::PermissionDenied, "denied");
        let image = Error::image("x.png", "cannot write `x.png`: denied", Some(Arc::new(io)));
        assert_eq!(image.source().unwrap().to_string(), "denied");
        let flag = Error::backend("unknown backend 'x'").on_flag("--backend");
        assert_eq!(flag.to_string(), "--backend: unknown backend 'x'");
        assert!(flag.source().is_none());
    }
}
