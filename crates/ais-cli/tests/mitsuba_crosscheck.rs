//! The Mitsuba 3 cross-check suite: every scene in `scenes/` and `scenes/crosscheck/` is
//! rendered by Mitsuba's `direct` integrator and by `ais render` (AIS off and per-batch), and
//! must agree within the thresholds of `tools/crosscheck.py` (channel means within 1%,
//! relMSE within 1e-3 of its noise floor, no 8×8 block beyond 5 standard errors).
//!
//! The script installs Mitsuba into a virtual environment under Cargo's target folder the
//! first time (about a minute; `AIS_PYTHON` picks the Python). When Mitsuba cannot be
//! installed the test fails under CI (the `CI` variable is set) and otherwise prints
//! SKIPPED with the reason.

use std::path::Path;
use std::process::Command;

/// The script's exit status when Mitsuba cannot be installed or imported.
const NO_MITSUBA: i32 = 3;

#[test]
fn ais_agrees_with_mitsuba_on_every_scene() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scratch = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let python = std::env::var("AIS_PYTHON").unwrap_or_else(|_| "python3".into());
    let status = Command::new(&python)
        .arg(root.join("tools/crosscheck.py"))
        .arg("--setup")
        .arg("--venv")
        .arg(scratch.join("mitsuba-venv"))
        .arg("--suite")
        .arg("--ais")
        .arg(env!("CARGO_BIN_EXE_ais"))
        .arg("--out")
        .arg(scratch.join("crosscheck"))
        .status();
    let in_ci = std::env::var_os("CI").is_some();
    match status {
        Ok(status) if status.success() => {}
        Ok(status) if status.code() == Some(NO_MITSUBA) && !in_ci => {
            eprintln!(
                "SKIPPED the Mitsuba cross-check: Mitsuba could not be installed (see above)"
            );
        }
        Ok(status) => panic!(
            "the Mitsuba cross-check failed ({status}); the table above names the scene and the \
             threshold, and {} holds the images",
            scratch.join("crosscheck").display()
        ),
        Err(e) if !in_ci => {
            eprintln!("SKIPPED the Mitsuba cross-check: {python} could not be run ({e})");
        }
        Err(e) => panic!("the Mitsuba cross-check needs Python: {python} could not be run ({e})"),
    }
}
