//! Comments and documents cite the repository's own documents, never files outside it.
//!
//! Walks `crates/`, `python/`, `bench/`, `fuzz/`, `docs/` and `README.md` and fails, listing
//! `file:line`, on
//! * any mention of the external specification (its folder under `../shared`, its two file
//!   names, or a section number of it), except in `docs/validation.md`, which says where
//!   the acceptance numbers came from;
//! * any cited `docs/<page>.md` that does not exist, and any `docs/<page>.md §"<section>"`
//!   whose quoted section text does not occur in that page (a heading or a bold lead-in).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::fs;
use std::path::{Path, PathBuf};

/// Files allowed to name the external specification (where acceptance numbers came from).
const ALLOWED: &[&str] = &["docs/validation.md"];

/// Folders never scanned (build output, caches, VCS).
const SKIP_DIRS: &[&str] = &[
    "target",
    ".git",
    "__pycache__",
    ".venv",
    "node_modules",
    "corpus",
];

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The forbidden fragments, lower case; built from pieces so that this file does not match.
fn forbidden() -> Vec<String> {
    let s = "spec";
    vec![
        format!("{s} §"),
        format!("{s}(§"),
        format!("{s} (§"),
        format!("shared/{s}"),
        format!("mechanization{}", ".md"),
        format!("alignment_and_{}", "errors"),
    ]
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().to_string();
        if p.is_dir() {
            if !SKIP_DIRS.contains(&name.as_str()) {
                walk(&p, out);
            }
        } else if p.metadata().map(|m| m.len() < 4_000_000).unwrap_or(false) {
            out.push(p);
        }
    }
}

/// `(path, section)` of every `docs/….md` citation in `text`, with the 1-based line. A section
/// is the quoted text after `§` following the path, possibly on the next comment line.
fn citations(text: &str) -> Vec<(usize, String, Option<String>)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(k) = text[i..].find("docs/") {
        let start = i + k;
        i = start + 5;
        // a path that merely ends in "docs/" (e.g. "python/docs/") is still a docs path only
        // when it starts the citation: require a non-path character before it
        if start > 0 && (b[start - 1].is_ascii_alphanumeric() || b[start - 1] == b'_') {
            continue;
        }
        let mut j = i;
        while j < b.len() && (b[j].is_ascii_alphanumeric() || b"_-./".contains(&b[j])) {
            j += 1;
        }
        let path = text[start..j].trim_end_matches('.');
        if !path.ends_with(".md") {
            continue;
        }
        let line = text[..start].matches('\n').count() + 1;
        // optional section: whitespace / comment markers, then §"…"
        let rest = &text[start + path.len()..];
        let skipped = rest.trim_start_matches(|c: char| c.is_whitespace() || "/!#,".contains(c));
        let section = skipped.strip_prefix("§\"").and_then(|r| {
            r.find('"')
                .map(|e| r[..e].trim_end_matches('\\').to_string())
        });
        out.push((line, path.to_string(), section));
    }
    out
}

/// Problems of one file's text: forbidden fragments and unresolved citations.
fn problems(rel: &str, text: &str, root: &Path) -> Vec<String> {
    let mut bad = Vec::new();
    if !ALLOWED.contains(&rel) {
        let pats = forbidden();
        for (n, line) in text.lines().enumerate() {
            let low = line.to_lowercase();
            for p in &pats {
                if low.contains(p.as_str()) {
                    bad.push(format!(
                        "{rel}:{}: names the external specification ({p:?}): {}",
                        n + 1,
                        line.trim()
                    ));
                }
            }
        }
    }
    for (line, path, section) in citations(text) {
        let page = root.join(&path);
        match fs::read_to_string(&page) {
            Err(_) => bad.push(format!("{rel}:{line}: cites {path}, which does not exist")),
            Ok(body) => {
                if let Some(s) = section {
                    if !body.contains(s.as_str()) {
                        bad.push(format!(
                            "{rel}:{line}: cites {path} §\"{s}\", not found in that page"
                        ));
                    }
                }
            }
        }
    }
    bad
}

#[test]
fn comments_and_docs_cite_only_the_repository() {
    let root = repo_root();
    let mut files = Vec::new();
    for d in ["crates", "python", "bench", "fuzz", "docs"] {
        walk(&root.join(d), &mut files);
    }
    files.push(root.join("README.md"));
    assert!(
        files.len() > 50,
        "found only {} files under {}",
        files.len(),
        root.display()
    );
    let mut bad = Vec::new();
    let mut cited = 0;
    for f in &files {
        let Ok(text) = fs::read_to_string(f) else {
            continue; // not UTF-8: binary data
        };
        let rel = f
            .strip_prefix(&root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        cited += citations(&text).len();
        bad.extend(problems(&rel, &text, &root));
    }
    assert!(
        cited > 200,
        "only {cited} docs/ citations found: is the walk broken?"
    );
    assert!(
        bad.is_empty(),
        "{} problem(s):\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn the_check_catches_each_kind_of_problem() {
    let root = repo_root();
    let s = "spec";
    let text = format!(
        "/// good (docs/theory/alignment.md §\"Fine alignment\")\n\
         /// missing page (docs/theory/{missing}.md)\n\
         /// bad section (docs/theory/alignment.md\n/// §\"No such section\")\n\
         /// old form ({s} §2.4), ../shared/{s}/x\n",
        missing = "nowhere"
    );
    let bad = problems("x.rs", &text, &root);
    assert_eq!(bad.len(), 4, "{bad:#?}");
    assert!(
        bad[0].starts_with("x.rs:5:") && bad[1].starts_with("x.rs:5:"),
        "{bad:#?}"
    );
    assert!(
        bad[2].starts_with("x.rs:2:") && bad[2].contains("does not exist"),
        "{bad:#?}"
    );
    assert!(
        bad[3].starts_with("x.rs:3:") && bad[3].contains("No such section"),
        "{bad:#?}"
    );
    // the allow-listed page may name the specification
    assert!(problems("docs/validation.md", &format!("{s} §7.0"), &root).is_empty());
}
