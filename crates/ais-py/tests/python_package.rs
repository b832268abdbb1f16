//! The Python package's tests: builds a fresh virtual environment under Cargo's target
//! folder, installs the package into it with `pip install .[test]` (maturin compiles the
//! bindings in release mode, sharing `target/release` with the renderer), and runs pytest
//! on `python/tests`.
//!
//! Without Python 3 the test fails under CI (the `CI` variable is set) and otherwise
//! prints SKIPPED with the reason; so do the tests of AIS inside Mitsuba without the LLVM
//! library that Mitsuba's llvm variant needs. `AIS_PYTHON` picks the interpreter.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `command`, panicking with `what` and its status if it fails.
fn run(what: &str, command: &mut Command) {
    match command.status() {
        Ok(status) if status.success() => {}
        Ok(status) => panic!("{what} failed ({status}); its output is above"),
        Err(e) => panic!("{what} could not start: {e}"),
    }
}

/// The Python to build the environment with, or None (after saying so) to skip.
fn python() -> Option<String> {
    let python = std::env::var("AIS_PYTHON").unwrap_or_else(|_| "python3".into());
    match Command::new(&python).arg("--version").output() {
        Ok(output) if output.status.success() => Some(python),
        _ if std::env::var_os("CI").is_some() => {
            panic!("the Python package's tests need Python 3: {python} could not be run")
        }
        _ => {
            eprintln!("SKIPPED the Python package's tests: {python} could not be run");
            None
        }
    }
}

#[test]
fn the_python_package_passes_its_tests() {
    let Some(python) = python() else {
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let venv = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("python-venv");
    if venv.exists() {
        std::fs::remove_dir_all(&venv).expect("the old virtual environment can be removed");
    }
    run(
        "creating the virtual environment",
        Command::new(&python).arg("-m").arg("venv").arg(&venv),
    );
    let venv_python = venv.join("bin/python");
    let package = format!("{}[test]", root.display());
    run(
        "pip install .[test]",
        Command::new(&venv_python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
            ])
            .arg(&package),
    );
    run(
        "pytest python/tests",
        Command::new(&venv_python)
            .args(["-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider"])
            .arg(root.join("python/tests"))
            .current_dir(&root),
    );
}
