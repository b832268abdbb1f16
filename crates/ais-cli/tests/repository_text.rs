//! The repository speaks of the project, not of how its work was organised: no text names a
//! numbered work period or a tracker number, and no link points outside the repository to a
//! folder a user who clones it does not have. History belongs in CHANGELOG.md, told by what
//! changed.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The phrases that give work history away, lower case. Built from pieces so that this
/// file does not match itself.
fn forbidden() -> Vec<(String, bool)> {
    // (phrase, whether a digit or '#' must follow it)
    vec![
        (format!("{} ", "session"), true),
        (format!("{} ", "sessions"), true),
        (format!("{} {}", "this", "session"), false),
        (format!("{} ", "issue"), true),
        (format!("{}{}", "../", "shared"), false),
    ]
}

/// The offending phrases in `text`, with their line numbers.
fn offences(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let lower = line.to_lowercase();
        for (phrase, needs_number) in forbidden() {
            let hits = lower.match_indices(&phrase).any(|(at, _)| {
                let next = lower[at + phrase.len()..].chars().next();
                !needs_number || next.is_some_and(|c| c.is_ascii_digit() || c == '#')
            });
            if hits {
                found.push((number + 1, line.trim().to_string()));
            }
        }
    }
    found
}

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every file git tracks, as text where it is text.
fn tracked_texts(root: &Path) -> Vec<(PathBuf, String)> {
    let listing = Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(root)
        .output()
        .expect("git runs in the repository");
    assert!(listing.status.success(), "git ls-files failed");
    String::from_utf8_lossy(&listing.stdout)
        .split('\0')
        .filter(|name| !name.is_empty() && !name.ends_with("Cargo.lock"))
        .filter_map(|name| {
            let path = root.join(name);
            let text = std::fs::read_to_string(&path).ok()?;
            Some((PathBuf::from(name), text))
        })
        .collect()
}

#[test]
fn no_text_refers_to_work_history() {
    let root = repository();
    let texts = tracked_texts(&root);
    assert!(
        texts.iter().any(|(name, _)| name.ends_with("README.md")),
        "the scan must see the README"
    );
    let mut report = String::new();
    for (name, text) in &texts {
        for (line, content) in offences(text) {
            report += &format!("{}:{line}: {content}\n", name.display());
        }
    }
    assert!(report.is_empty(), "work-history references:\n{report}");
}

#[test]
fn the_scan_finds_what_it_looks_for() {
    let sample = format!(
        "fine\nmeasured in {} 3\nsee ({} 7)\nlinks to {}{}\nissue tracker\n",
        "session", "issue", "../", "shared"
    );
    let lines: Vec<usize> = offences(&sample).into_iter().map(|(l, _)| l).collect();
    assert_eq!(lines, vec![2, 3, 4]);
}
