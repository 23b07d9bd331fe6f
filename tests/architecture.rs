//! The one-direction rules of `ARCHITECTURE.md`, checked on the source: every `crate::MODULE`
//! path in `src/` (in `use` lines and inline, comments left out) is matched against the rules, so
//! a change cannot break them silently.
//!
//! - only the walks (`pipeline/`, `cli/`) and `config/` itself read the config: no other module
//!   names `crate::config`;
//! - nothing names `crate::pipeline` except `cli/` (the walks are called, never called back);
//! - `program/` (the model) names no stage;
//! - `emit/` (the writers) names only `program` and `geom` (and format crates, which are not
//!   `crate::` paths).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::support::root;

/// The stage modules: what `program/` must not name.
const STAGES: [&str; 13] = [
    "slice",
    "region",
    "circuit",
    "route",
    "curved",
    "conform",
    "robot",
    "jet",
    "emit",
    "check",
    "pipeline",
    "postprocess",
    "view",
];

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("source folder").flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The code of a file without its comments (line comments, doc comments and block comments).
fn code_of(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_block = 0usize;
    for line in text.lines() {
        let mut rest = line;
        let mut kept = String::new();
        loop {
            if in_block > 0 {
                match rest.find("*/") {
                    Some(i) => {
                        in_block -= 1;
                        rest = &rest[i + 2..];
                    }
                    None => break,
                }
            } else {
                let line_comment = rest.find("//");
                let block = rest.find("/*");
                match (line_comment, block) {
                    (Some(l), b) if b.is_none_or(|b| l < b) => {
                        kept.push_str(&rest[..l]);
                        break;
                    }
                    (_, Some(b)) => {
                        kept.push_str(&rest[..b]);
                        in_block += 1;
                        rest = &rest[b + 2..];
                    }
                    _ => {
                        kept.push_str(rest);
                        break;
                    }
                }
            }
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// The top-level modules a piece of code names as `crate::name` or `crate::{name, ...}`.
fn crate_modules(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        let before = rest[..i].chars().next_back();
        rest = &rest[i + "crate::".len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue; // `conduit_crate::` or the like, not this crate
        }
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level items of the group, up to its closing brace.
            let mut depth = 0usize;
            let mut item_start = true;
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if item_start && !c.is_whitespace() => {
                        out.insert(ident(&group[k..]));
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    out.retain(|m| !m.is_empty());
    out
}

/// Every breach of the rules in `src/`, as `file -> crate::module` (file relative to `src/`).
fn breaches() -> BTreeSet<String> {
    let src = root().join("src");
    let mut out = BTreeSet::new();
    for file in rust_files(&src) {
        let rel = file
            .strip_prefix(&src)
            .expect("under src")
            .to_string_lossy()
            .replace('\\', "/");
        let top = rel
            .split('/')
            .next()
            .unwrap_or_default()
            .trim_end_matches(".rs");
        let text = std::fs::read_to_string(&file).expect("source file");
        for module in crate_modules(&code_of(&text)) {
            let breach = match module.as_str() {
                "config" => !matches!(top, "config" | "pipeline" | "cli"),
                "pipeline" => !matches!(top, "pipeline" | "cli"),
                _ => false,
            } || (top == "program" && STAGES.contains(&module.as_str()))
                || (top == "emit" && !matches!(module.as_str(), "emit" | "program" | "geom"));
            if breach {
                out.insert(format!("{rel} -> crate::{module}"));
            }
        }
    }
    out
}

#[test]
fn the_scanner_sees_grouped_inline_and_commented_paths() {
    let code = code_of(
        "use crate::{config::Config, geom::{Point2, scaled}};\n\
         // use crate::jet;\n\
         /// [`crate::route`]\n\
         let x = crate::emit::gcode::write(); /* crate::check */ let y = 1;\n\
         use conduit_crate::thing;\n",
    );
    let found: Vec<String> = crate_modules(&code).into_iter().collect();
    assert_eq!(found, ["config", "emit", "geom"]);
}

#[test]
fn modules_depend_one_way_config_to_stages_to_walks() {
    let found = breaches();
    assert!(
        found.is_empty(),
        "breaches of the module rules (ARCHITECTURE.md):\n{}",
        found
            .iter()
            .map(|s| format!("  {s}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}
