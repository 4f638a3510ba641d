//! The library's layering (README "Layout"): the command line lives only in
//! the binary, data flows one way (model → shape → sweep → reduce → design,
//! calibrate), and no layer below the top returns the top-level error.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Library source files with their text, test modules cut off (tests may
/// use anything).
fn library_sources() -> Vec<(String, String)> {
    all_sources().into_iter().filter(|(f, _)| !f.starts_with("cli/") && f != "main.rs").collect()
}

#[test]
fn the_library_knows_nothing_of_the_command_line() {
    for (file, code) in library_sources() {
        for needle in ["clap::", "anyhow", "crate::cli", "mod cli"] {
            assert!(!code.contains(needle), "src/{file} uses {needle}: the command line belongs to the binary (src/main.rs, src/cli)");
        }
    }
}

#[test]
fn lower_layers_never_import_upward() {
    // Each layer and the layers above it, which it must not use.
    let above: [(&str, &[&str]); 5] = [
        ("shape", &["model", "sweep", "reduce", "design", "calibrate", "mould"]),
        ("model/", &["sweep", "reduce", "design", "calibrate", "mould", "bench", "plot"]),
        ("sweep/", &["reduce", "design", "calibrate", "mould", "bench", "plot"]),
        ("reduce/", &["design", "calibrate", "mould", "bench"]),
        ("mould/", &["design", "calibrate", "reduce", "sweep", "bench"]),
    ];
    for (file, code) in library_sources() {
        for (layer, upper) in above {
            if !file.starts_with(layer) {
                continue;
            }
            for u in upper {
                let needle = format!("crate::{u}::");
                assert!(!code.contains(&needle), "src/{file} (layer {layer}) uses {needle}: lower layers never import upward");
            }
        }
    }
}

#[test]
fn only_the_top_returns_the_top_level_error() {
    for (file, code) in library_sources() {
        if file == "lib.rs" || file == "bench.rs" {
            continue;
        }
        assert!(!code.contains("crate::Error"), "src/{file} uses the top-level crate::Error: return the layer's own error enum");
    }
}

/// Every source file under src/ (the binary's too) with its text, test
/// modules cut off.
fn all_sources() -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            let code = match text.find("#[cfg(test)]") {
                Some(i) => text[..i].to_string(),
                None => text,
            };
            (p.strip_prefix(&src).unwrap().display().to_string(), code)
        })
        .collect()
}

#[test]
fn no_two_files_of_a_folder_use_each_other() {
    // A file's siblings are the files beside it; `super::NAME` names one.
    let files = all_sources();
    let sibling = |file: &str, name: &str| -> Option<String> {
        let dir = Path::new(file).parent().map(|d| d.display().to_string()).unwrap_or_default();
        let candidate = if dir.is_empty() { format!("{name}.rs") } else { format!("{dir}/{name}.rs") };
        (Path::new(file).file_name().is_some_and(|n| n != "mod.rs") && files.iter().any(|(f, _)| *f == candidate)).then_some(candidate)
    };
    let uses = |file: &str, code: &str| -> Vec<String> {
        let mut out: Vec<String> = code
            .split("super::")
            .skip(1)
            .filter_map(|rest| {
                let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                sibling(file, &name)
            })
            .collect();
        out.sort();
        out.dedup();
        out
    };
    // Still to be untangled by their layer's owners; nothing may be added.
    let known = [("model/body.rs", "model/rod.rs")];
    let mut circles = Vec::new();
    for (a, code_a) in &files {
        for b in uses(a, code_a) {
            let code_b = &files.iter().find(|(f, _)| *f == b).unwrap().1;
            if a < &b && uses(&b, code_b).contains(a) && !known.contains(&(a.as_str(), b.as_str())) {
                circles.push(format!("src/{a} and src/{b}"));
            }
        }
    }
    assert!(circles.is_empty(), "{} use each other: move what both need into one of them (or a third file)", circles.join("; "));
}

#[test]
fn the_library_returns_no_string_errors_but_where_listed() {
    // Still to be typed by their layers' owners; nothing may be added.
    // (study.rs: the axis parser, beside the effects' patches being moved to the registry.)
    let remaining =
        ["model/body.rs", "model/resolution.rs", "model/rod.rs", "io.rs", "sweep/cables.rs", "reduce/cables.rs", "calibrate/data.rs", "study.rs"];
    let re = |code: &str| code.lines().filter(|l| l.contains("Result<") && l.contains(", String>")).count();
    for (file, code) in library_sources() {
        if remaining.contains(&file.as_str()) {
            continue;
        }
        assert_eq!(re(&code), 0, "src/{file} returns Result<_, String>: give it a thiserror enum naming the problem");
    }
}

#[test]
fn a_run_kind_picks_its_code_in_one_place() {
    let matched: Vec<String> = all_sources()
        .into_iter()
        .filter(|(f, code)| f != "sweep/kind.rs" && code.contains("RunKind::Planar =>"))
        .map(|(f, _)| f)
        .collect();
    assert_eq!(matched, ["map.rs"], "a run directory's kind picks its code in map::on_kind only");
}
