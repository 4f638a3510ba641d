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

/// Every source file of `src/` (the binary's too), by its path below
/// `src/`, with its text, test modules cut off (tests may use anything).
fn all_sources() -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.into_iter().map(|p| (p.strip_prefix(&src).unwrap().display().to_string(), without_tests(&p))).collect()
}

/// Library source files with their text, test modules cut off.
fn library_sources() -> Vec<(String, String)> {
    all_sources().into_iter().filter(|(file, _)| !file.starts_with("cli/") && file != "main.rs").collect()
}

/// A source file's text with its test module cut off.
fn without_tests(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    match text.find("#[cfg(test)]") {
        Some(i) => text[..i].to_string(),
        None => text,
    }
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

/// [`all_sources`] with `//` comments removed (a comment may name anything).
fn all_code() -> Vec<(String, String)> {
    all_sources()
        .into_iter()
        .map(|(file, text)| {
            let code: Vec<&str> = text.lines().map(|l| l.find("//").map_or(l, |i| &l[..i])).collect();
            (file, code.join("\n"))
        })
        .collect()
}

/// Where `word` occurs in `code` as a whole word other than as a field
/// access (`.word`, checked by the compiler): line numbers.
fn spelled(code: &str, word: &str) -> Vec<usize> {
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut lines = Vec::new();
    for (n, line) in code.lines().enumerate() {
        let mut from = 0;
        while let Some(i) = line[from..].find(word).map(|i| i + from) {
            let before = line[..i].chars().next_back();
            let after = line[i + word.len()..].chars().next();
            let whole = !before.is_some_and(ident) && !after.is_some_and(ident) && !before.is_some_and(|c| c == '-');
            if whole && before != Some('.') {
                lines.push(n + 1);
            }
            from = i + word.len();
        }
    }
    lines
}

#[test]
fn an_effects_spec_key_is_spelled_only_in_the_registry() {
    // The `[effects]` keys (gravity's `scale` is too common a word to
    // search for). Tests may use them; field accesses are the compiler's
    // to check. The flag's kebab form counts as a spelling too.
    let keys: Vec<&str> = cablemap::model::REGISTRY
        .iter()
        .filter(|e| e.section == cablemap::model::effects::Section::Effects)
        .map(|e| e.key)
        .collect();
    assert!(keys.contains(&"friction_mu") && keys.contains(&"stiffening_alpha"), "{keys:?}");
    let mut found = Vec::new();
    for (file, code) in all_code() {
        if file == "model/effects.rs" {
            continue;
        }
        for key in &keys {
            for word in [key.to_string(), key.replace('_', "-")] {
                for line in spelled(&code, &word) {
                    found.push(format!("src/{file}:{line} spells {word}"));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "effect keys are spelled outside the registry (src/model/effects.rs); take them from its entry (e.g. FRICTION.key, .flag, .path):\n{}",
        found.join("\n")
    );
}
