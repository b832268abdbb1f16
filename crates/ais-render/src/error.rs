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

/// The largest mesh or image file a scene may refer to, in bytes.
pub const LARGEST_INPUT_FILE: u64 = 4 << 30;

/// Checks that `path` names a regular file of at most [`LARGEST_INPUT_FILE`] bytes (`what`
/// says what it should hold, for the error): a device such as `/dev/zero` or a folder would
/// be read until memory runs out, or fail with a bare system error.
pub fn check_input_file(path: &Path, what: &str) -> Result<(), InputError> {
    let metadata = match std::fs::metadata(path) {
        Ok(metadata) => metadata,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(InputError::new(path, format!("{what} not found")))
        }
        Err(e) => {
            return Err(InputError::new(
                path,
                format!("cannot read the {what}: {e}"),
            ))
        }
    };
    if !metadata.is_file() {
        return Err(InputError::new(
            path,
            format!("the {what} is not a regular file"),
        ));
    }
    if metadata.len() > LARGEST_INPUT_FILE {
        return Err(InputError::new(
            path,
            format!(
                "the {what} has {} bytes, more than the {LARGEST_INPUT_FILE} ais reads",
                metadata.len()
            ),
        ));
    }
    Ok(())
}

thread_local! {
    /// Whether a panic on this thread is being caught by [`catch_panic`].
    static CATCHING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f`, turning a panic inside it into `Err` with the panic's message, without the
/// panic being printed: for third-party readers that panic on malformed input instead of
/// returning an error. Panics elsewhere are reported as before.
pub fn catch_panic<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CATCHING.with(|c| c.get()) {
                previous(info);
            }
        }));
    });
    let was = CATCHING.with(|c| c.replace(true));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    CATCHING.with(|c| c.set(was));
    outcome.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown failure".into())
    })
}
