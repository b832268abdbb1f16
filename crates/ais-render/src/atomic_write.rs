//! Writing outputs atomically: a temporary file beside the target, renamed over it only once
//! it is complete, so a failed or interrupted write never destroys a good output.

use std::io;
use std::path::{Path, PathBuf};

/// The temporary path used while writing `target`.
fn temporary_path(target: &Path) -> PathBuf {
    let mut name = target
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".{}.tmp", std::process::id()));
    target.with_file_name(name)
}

/// Calls `write` with a temporary path next to `target`, then renames it over `target`. On
/// failure the temporary file is removed and `target` is left as it was.
pub fn write_atomically<E: From<io::Error>>(
    target: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let temporary = temporary_path(target);
    match write(&temporary) {
        Ok(()) => std::fs::rename(&temporary, target).map_err(|e| {
            let _ = std::fs::remove_file(&temporary);
            E::from(e)
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&temporary);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_keeps_the_old_file() {
        let dir = std::env::temp_dir().join(format!("ais-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("out.txt");
        std::fs::write(&target, "good").unwrap();
        let result: Result<(), io::Error> = write_atomically(&target, |tmp| {
            std::fs::write(tmp, "half")?;
            Err(io::Error::other("interrupted"))
        });
        assert!(result.is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "good");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            1,
            "temporary file removed"
        );
        write_atomically::<io::Error>(&target, |tmp| std::fs::write(tmp, "new")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
