//! Helpers shared by the renderer's integration tests.
#![allow(dead_code)]

use std::io::Write;
use std::path::PathBuf;
use std::process::Command;

/// A fresh scratch folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ais-render-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Prints why a test is skipped, where the test harness does not swallow it.
pub fn skip(test: &str, reason: &str) {
    let _ = writeln!(std::io::stderr(), "SKIPPED {test}: {reason}");
}

/// Fetches an npm package tarball (`name@version`) with `npm pack` and unpacks it; returns
/// the package folder, or `None` (after printing why) when npm cannot provide it.
pub fn npm_package(test: &str, spec: &str) -> Option<PathBuf> {
    let dir = scratch(&format!("npm-{}", spec.replace(['/', '@'], "_")));
    let pack = Command::new("npm")
        .args(["pack", spec, "--silent", "--pack-destination"])
        .arg(&dir)
        .output();
    let tarball = match pack {
        Err(e) => {
            skip(test, &format!("npm could not be run ({e})"));
            return None;
        }
        Ok(out) if !out.status.success() => {
            skip(
                test,
                &format!(
                    "`npm pack {spec}` failed: {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                ),
            );
            return None;
        }
        Ok(out) => String::from_utf8_lossy(&out.stdout)
            .trim()
            .lines()
            .last()
            .unwrap_or("")
            .to_string(),
    };
    let untar = Command::new("tar")
        .args(["xzf", &tarball])
        .current_dir(&dir)
        .status()
        .expect("tar runs");
    assert!(untar.success(), "the npm tarball {tarball} must unpack");
    Some(dir.join("package"))
}

/// The repository's `scenes/` folder, with its generated assets made (by
/// `scenes/make_assets.py`) if they are missing; `Err` says why they could not be.
pub fn shipped_scenes() -> Result<PathBuf, String> {
    let folder = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    if !folder.join("assets/sky.hdr").exists() {
        let made = Command::new("python3")
            .arg(folder.join("make_assets.py"))
            .status();
        match made {
            Ok(status) if status.success() => {}
            Ok(status) => panic!("scenes/make_assets.py failed: {status}"),
            Err(e) => return Err(format!("python3 could not be run ({e})")),
        }
    }
    Ok(folder)
}
