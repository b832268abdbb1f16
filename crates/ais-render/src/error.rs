//! Errors that name the file, the line and what is wrong.

use std::fmt;
use std::path::{Path, PathBuf};

/// An input error: a scene, mesh or image that cannot be used, with where it went wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// The file at fault.
    pub file: PathBuf,
    /// The 1-based line, where known.
    pub line: Option<u32>,
    /// What is wrong.
    pub message: String,
}

impl InputError {
    /// An error in `file` (no line).
    pub fn new(file: impl AsRef<Path>, message: impl Into<String>) -> Self {
        InputError {
            file: file.as_ref().to_path_buf(),
            line: None,
            message: message.into(),
        }
    }

    /// An error at `line` of `file`.
    pub fn at(file: impl AsRef<Path>, line: u32, message: impl Into<String>) -> Self {
        InputError {
            line: Some(line),
            ..InputError::new(file, message)
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.file.display(), line, self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for InputError {}
