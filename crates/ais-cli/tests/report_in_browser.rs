//! `ais compare` writes a report that works in a real browser: headless Chromium opens it,
//! the page's self-test (run with `#selftest`) checks that every image, canvas and plot is
//! drawn and that the split, exposure, flip and image selection controls change what they
//! should, and a screenshot is saved to `target/tmp/report-screenshot.png`.
//!
//! `.ci/run` installs Debian's `chromium` when it is missing (`AIS_CHROMIUM` names another
//! binary). Without a browser the test fails under CI and prints SKIPPED elsewhere.

use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("AIS_CHROMIUM") {
        return Some(PathBuf::from(path));
    }
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|name| {
            Command::new(name)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
        .map(PathBuf::from)
}

fn headless(browser: &Path) -> Command {
    let mut command = Command::new(browser);
    command.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--allow-file-access-from-files",
        "--hide-scrollbars",
        "--virtual-time-budget=20000",
    ]);
    command
}

/// Runs `ais compare` on a small scene into `report`; returns the page's file URL.
fn write_report(report: &Path) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let _ = std::fs::remove_dir_all(report);
    let compare = Command::new(env!("CARGO_BIN_EXE_ais"))
        .arg("compare")
        .arg(root.join("scenes/crosscheck/sphere_light.xml"))
        .args([
            "--resolution",
            "48x27",
            "--time-budget",
            "0.15",
            "--seeds",
            "2",
        ])
        .args(["--reference-spp", "32", "--quiet", "-o"])
        .arg(report)
        .output()
        .expect("ais runs");
    assert!(
        compare.status.success(),
        "ais compare failed: {}",
        String::from_utf8_lossy(&compare.stderr)
    );
    let page = report.join("index.html").canonicalize().unwrap();
    format!("file://{}", page.display())
}

/// Takes a screenshot of `url` into `screenshot` and checks that it holds a page.
fn screenshot(browser: &Path, url: &str, screenshot: &Path) {
    let _ = std::fs::remove_file(screenshot);
    let shot = headless(browser)
        .arg(format!("--screenshot={}", screenshot.display()))
        .arg("--window-size=1200,2400")
        .arg(url)
        .output()
        .expect("chromium runs");
    assert!(
        shot.status.success(),
        "{}",
        String::from_utf8_lossy(&shot.stderr)
    );
    let size = std::fs::metadata(screenshot).map_or(0, |m| m.len());
    assert!(size > 20_000, "the screenshot is {size} bytes");
}

#[test]
fn the_compare_report_renders_and_its_controls_work_in_chromium() {
    let Some(browser) = chromium() else {
        assert!(
            std::env::var_os("CI").is_none(),
            "no Chromium found: .ci/run installs Debian's chromium (or set AIS_CHROMIUM)"
        );
        eprintln!("SKIPPED the browser test: no chromium, chromium-browser or google-chrome");
        return;
    };
    let scratch = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let url = write_report(&scratch.join("browser-report"));
    let dom = headless(&browser)
        .arg("--dump-dom")
        .arg(format!("{url}#selftest"))
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&dom.stdout);
    let result = dom
        .split("SELFTEST ")
        .nth(1)
        .and_then(|rest| rest.split("</pre>").next())
        .unwrap_or_else(|| panic!("the page's self-test did not run; DOM starts: {:.400}", dom));
    eprintln!("report self-test in {}: {result}", browser.display());
    assert!(result.contains("\"ok\":true"), "self-test failed: {result}");
    assert!(result.contains("\"plots\":2"), "{result}");
    assert!(!result.contains("\"maps\":0"), "{result}");
    screenshot(&browser, &url, &scratch.join("report-screenshot.png"));
}
