//! The documentation against the code: `docs/features.md` is generated from the same
//! tables `inspect` and the evaluators read (regenerate it with
//! `BLENDSYNTH_UPDATE_DOCS=1 cargo test --release --test docs`), and every command the
//! README and docs/cli.md show uses a subcommand and flags the current CLI has.

mod common;
use common::*;

use std::collections::BTreeSet;

fn features_page() -> String {
    let mut shader: Vec<(&str, &str)> = blendsynth::shader::compile::NODES
        .iter()
        .map(|n| (n.bl_idname, n.notes))
        .collect();
    shader.sort_unstable();
    let mut geo: Vec<&str> = blendsynth::geometry::nodes::supported().collect();
    geo.sort_unstable();
    let mut o = String::new();
    o.push_str("# Supported Blender features\n\n");
    o.push_str(
        "Generated from the tables `blendsynth inspect` and the evaluators read \
         (`tests/docs.rs` fails when they differ; regenerate with\n\
         `BLENDSYNTH_UPDATE_DOCS=1 cargo test --release --test docs`). Anything not listed is \
         reported by `inspect` and refused by `render` with an error naming it.\n\n",
    );
    o.push_str("## Objects\n\n");
    o.push_str(
        "Where an object's geometry comes from is decided in one place \
         (`geometry::source`; details in [coverage.md](coverage.md)):\n\n",
    );
    o.push_str(&format!(
        "- no geometry (skipped, as Cycles does): {}\n",
        list(blendsynth::geometry::source::NO_GEOMETRY)
    ));
    o.push_str(&format!(
        "- modifiers evaluated by blendsynth (an option one does not evaluate keeps the \
         object frozen, named by `inspect`; see coverage.md): {}\n",
        list(&blendsynth::geometry::source::native_modifiers())
    ));
    o.push_str(
        "- every other renderable object (curves, surfaces, text, metaballs, meshes with \
         other modifiers or shape keys, instancers): Blender's evaluated mesh from the \
         export, only while nothing it reads changes (\"frozen\")\n\n",
    );
    o.push_str(&format!("## Shader nodes ({})\n\n", shader.len()));
    for (n, notes) in &shader {
        o.push_str(&format!("- `{n}`: {notes}\n"));
    }
    o.push_str(&format!("\n## Geometry Nodes ({})\n\n", geo.len()));
    for n in &geo {
        o.push_str(&format!("- `{n}`\n"));
    }
    o
}

fn list(items: &[&str]) -> String {
    items
        .iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[test]
fn features_page_matches_the_tables() {
    let path = repo().join("docs/features.md");
    let want = features_page();
    if std::env::var_os("BLENDSYNTH_UPDATE_DOCS").is_some() {
        std::fs::write(&path, &want).unwrap();
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        have == want,
        "docs/features.md differs from the support tables: regenerate it with \
         BLENDSYNTH_UPDATE_DOCS=1 cargo test --release --test docs"
    );
}

/// The commands shown in fenced blocks: `cargo run --release -- ARGS` and `blendsynth ARGS`
/// lines (synopsis lines keep their `[--flag ...]` parts).
fn shown_commands(text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut in_block = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if !in_block {
            continue;
        }
        let words = |rest: &str| -> Vec<String> {
            rest.split(|c: char| c.is_whitespace() || c == '[' || c == ']' || c == '|')
                .filter(|w| !w.is_empty())
                .map(|w| w.split('=').next().unwrap().to_string())
                .collect()
        };
        if let Some(r) = t
            .strip_prefix("cargo run --release -- ")
            .or_else(|| t.strip_prefix("blendsynth "))
        {
            out.push(words(r));
        } else if t.starts_with('[') || t.starts_with('-') {
            // A synopsis continued on the next line.
            if let Some(last) = out.last_mut() {
                last.extend(words(t));
            }
        }
    }
    out
}

#[test]
fn shown_commands_parse_with_the_cli() {
    let mut checked = 0;
    for doc in ["README.md", "docs/cli.md"] {
        let text = std::fs::read_to_string(repo().join(doc)).unwrap();
        for words in shown_commands(&text) {
            let sub = &words[0];
            if sub.starts_with('-') {
                continue; // `blendsynth --help | --version`
            }
            let o = run(&[sub.as_str(), "--help"], &[]);
            assert_eq!(
                o.status.code(),
                Some(0),
                "{doc}: `blendsynth {sub}` is not a subcommand"
            );
            let help = stdout(&o);
            let flags: BTreeSet<&String> = words.iter().filter(|w| w.starts_with("--")).collect();
            for f in flags {
                assert!(
                    help.contains(&format!("{f} "))
                        || help.contains(&format!("{f}\n"))
                        || help.contains(&format!("{f},")),
                    "{doc}: `blendsynth {sub}` has no flag {f}"
                );
            }
            checked += 1;
        }
    }
    assert!(
        checked >= 10,
        "only {checked} commands found in the README and docs/cli.md"
    );
}
