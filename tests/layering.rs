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
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files
        .into_iter()
        .filter(|p| !p.starts_with(src.join("cli")) && p != &src.join("main.rs"))
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
