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

/// Temporary files being written now, so that an interrupt can remove them
/// ([`remove_temporaries`]).
static PENDING: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    PENDING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes every temporary output file being written: for a SIGINT or SIGTERM handler, so
/// that an interrupted write leaves nothing behind.
pub fn remove_temporaries() {
    for path in pending().drain(..) {
        let _ = std::fs::remove_file(path);
    }
}

/// Outputs written as a unit: each is written to a temporary file beside its target, and
/// only when every one has been written are they all renamed over their targets. Dropped
/// without [`OutputSet::commit`], it removes its temporary files and leaves the targets as
/// they were.
#[derive(Debug, Default)]
pub struct OutputSet {
    /// (temporary, target) of every staged output.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl OutputSet {
    /// Writes `target`'s content to its temporary file with `write`.
    pub fn stage<E>(
        &mut self,
        target: &Path,
        write: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<(), E> {
        let temporary = temporary_path(target);
        pending().push(temporary.clone());
        self.staged.push((temporary.clone(), target.to_path_buf()));
        write(&temporary)
    }

    /// Renames every staged output over its target. The targets' folder is locked while
    /// they are renamed, so that two renders to the same outputs leave one render's set,
    /// not a mix.
    pub fn commit(mut self) -> io::Result<()> {
        let folder = self.staged.first().and_then(|(_, target)| target.parent());
        let folder = match folder {
            Some(f) if !f.as_os_str().is_empty() => f.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let lock = std::fs::File::open(&folder)?;
        lock.lock()?;
        for (temporary, target) in std::mem::take(&mut self.staged) {
            pending().retain(|p| p != &temporary);
            std::fs::rename(&temporary, &target).map_err(|e| {
                let _ = std::fs::remove_file(&temporary);
                io::Error::new(e.kind(), format!("{}: cannot write: {e}", target.display()))
            })?;
        }
        Ok(())
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        let mut pending = pending();
        for (temporary, _) in &self.staged {
            pending.retain(|p| p != temporary);
            let _ = std::fs::remove_file(temporary);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_replaced_together_or_not_at_all() {
        let dir = std::env::temp_dir().join(format!("ais-output-set-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        let mut set = OutputSet::default();
        set.stage::<io::Error>(&a, |tmp| std::fs::write(tmp, "new a"))
            .unwrap();
        let failed: Result<(), io::Error> = set.stage(&b, |_| Err(io::Error::other("no space")));
        assert!(failed.is_err());
        drop(set);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            2,
            "no temporary left"
        );
        let mut set = OutputSet::default();
        set.stage::<io::Error>(&a, |tmp| std::fs::write(tmp, "new a"))
            .unwrap();
        set.stage::<io::Error>(&b, |tmp| std::fs::write(tmp, "new b"))
            .unwrap();
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
