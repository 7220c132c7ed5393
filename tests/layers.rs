//! The layer order of ARCHITECTURE.md, checked on the `crate::` paths of every file in
//! `src/`: a module may use only modules of a lower layer (data flows one way). A new
//! top-level module must be placed in `LAYERS` before it builds.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Lowest first. Modules in one row are siblings and do not use each other.
const LAYERS: &[&[&str]] = &[
    &["foundation"],
    &["scene"],
    &["nodes", "anim", "color"],
    &["shader"],
    &["geometry"],
    &["render"],
    &["denoise"],
    &["label"],
    &["dataset", "inspect", "blender"],
    &["api"],
    &["python"],
];

/// Uses that point up today, each with the move that removes it. The list may only
/// shrink: an entry that no longer occurs fails the test too, so it is taken out.
const KNOWN: &[(&str, &str, &str)] = &[];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|row| row.contains(&module))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level modules a file names as `crate::NAME`, comments left out.
fn uses(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            let after = &rest[i + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                found.insert(name);
            }
            rest = after;
        }
    }
    found
}

#[test]
fn no_module_uses_a_layer_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut wrong = Vec::new();
    let mut seen_known = BTreeSet::new();
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let module = first.trim_end_matches(".rs").to_string();
        if module == "lib" || module == "main" {
            continue;
        }
        let Some(own) = layer_of(&module) else {
            wrong.push(format!(
                "{}: module {module:?} has no layer in LAYERS",
                rel.display()
            ));
            continue;
        };
        let text = std::fs::read_to_string(f).unwrap();
        for dep in uses(&text) {
            if dep == module {
                continue;
            }
            let Some(theirs) = layer_of(&dep) else {
                continue; // not a top-level module (e.g. a macro path)
            };
            if theirs < own {
                continue;
            }
            if KNOWN.iter().any(|k| k.0 == module && k.1 == dep) {
                seen_known.insert((module.clone(), dep.clone()));
                continue;
            }
            wrong.push(format!("{}: {module} uses {dep}", rel.display()));
        }
    }
    for k in KNOWN {
        if !seen_known.contains(&(k.0.to_string(), k.1.to_string())) {
            wrong.push(format!(
                "KNOWN lists {} -> {}, which no longer occurs: take it out",
                k.0, k.1
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "layer order broken:\n{}",
        wrong.join("\n")
    );
}
/// No function in `src/` runs past 150 lines unless a comment just above it says why.
#[test]
fn long_functions_say_why() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let mut i = 0;
        while i < lines.len() {
            let t = lines[i].trim_start();
            let is_fn = (t.starts_with("fn ")
                || t.starts_with("pub fn ")
                || t.starts_with("pub(crate) fn "))
                && !t.ends_with(';');
            if !is_fn {
                i += 1;
                continue;
            }
            let indent = lines[i].len() - t.len();
            let close = format!("{}}}", " ".repeat(indent));
            let end = (i + 1..lines.len()).find(|&j| lines[j] == close);
            let Some(end) = end else {
                i += 1;
                continue;
            };
            let len = end - i + 1;
            if len > 150 {
                // The doc comment or attributes above may carry the reason.
                let mut j = i;
                let mut why = false;
                while j > 0 {
                    j -= 1;
                    let above = lines[j].trim_start();
                    if above.starts_with("///")
                        || above.starts_with("//")
                        || above.starts_with("#[")
                    {
                        why |= above.contains("Long because") || above.contains("long because");
                    } else {
                        break;
                    }
                }
                if !why {
                    long.push(format!(
                        "{}:{}: {} lines",
                        f.strip_prefix(&src).unwrap().display(),
                        i + 1,
                        len
                    ));
                }
            }
            i = end + 1;
        }
    }
    assert!(
        long.is_empty(),
        "functions over 150 lines without a comment saying why (\"Long because ...\"):\n{}",
        long.join("\n")
    );
}
