//! The library's layering (README "Layout"): the command line lives only in
//! the binary, data flows one way (model → solver → sweep → reduce → design,
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
/// `src/`, with its test code cut off (tests may use anything): items under
/// `#[cfg(test)]` anywhere in a file, and whole files that are test modules.
fn all_sources() -> Vec<(String, String)> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let test_files: Vec<PathBuf> = files.iter().flat_map(|p| test_module_files(p)).collect();
    files
        .into_iter()
        .filter(|p| !test_files.contains(p))
        .map(|p| (p.strip_prefix(&src).unwrap().display().to_string(), without_tests(&std::fs::read_to_string(&p).unwrap())))
        .collect()
}

/// Library source files with their text, test code cut off.
fn library_sources() -> Vec<(String, String)> {
    all_sources().into_iter().filter(|(file, _)| !file.starts_with("cli/") && file != "main.rs").collect()
}

/// The end of the item that starts at `at` (after its attributes): past its
/// `;`, or past the brace group that closes it.
fn item_end(text: &str, at: usize) -> usize {
    let mut i = at;
    loop {
        let rest = &text[i..];
        i += rest.len() - rest.trim_start().len();
        if text[i..].starts_with("#[") {
            i = group_end(text, i + 1).unwrap_or(text.len());
        } else {
            break;
        }
    }
    // The first `;` or `{` outside the signature's brackets (`[f64; 3]`).
    let mut depth = 0usize;
    for (k, c) in text[i..].char_indices() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth = depth.saturating_sub(1),
            ';' if depth == 0 => return i + k + 1,
            '{' if depth == 0 => return group_end(text, i + k).unwrap_or(text.len()),
            _ => {}
        }
    }
    text.len()
}

/// `text` with every item under `#[cfg(test)]` removed.
fn without_tests(text: &str) -> String {
    let mut kept = String::new();
    let mut from = 0;
    while let Some(k) = text[from..].find("#[cfg(test)]") {
        let at = from + k;
        kept.push_str(&text[from..at]);
        from = item_end(text, at + "#[cfg(test)]".len());
    }
    kept.push_str(&text[from..]);
    kept
}

/// The files that `path` declares as test modules (`#[cfg(test)] mod name;`,
/// with or without `#[path = "…"]`).
fn test_module_files(path: &Path) -> Vec<PathBuf> {
    let text = std::fs::read_to_string(path).unwrap();
    let dir = path.parent().unwrap();
    // A module's own folder: `a.rs` declares `a/b.rs`, `a/mod.rs` declares `a/b.rs`.
    let stem = path.file_stem().unwrap().to_str().unwrap();
    let child_dir = if stem == "mod" || stem == "lib" || stem == "main" { dir.to_path_buf() } else { dir.join(stem) };
    let mut found = Vec::new();
    for (at, _) in text.match_indices("#[cfg(test)]") {
        let end = item_end(&text, at + "#[cfg(test)]".len());
        let item = &text[at..end];
        if !item.trim_end().ends_with(';') {
            continue;
        }
        if let Some(p) = item.find("#[path = \"") {
            let rest = &item[p + "#[path = \"".len()..];
            if let Some(q) = rest.find('"') {
                found.push(dir.join(&rest[..q]));
            }
        } else if let Some(name) = item.trim_end().trim_end_matches(';').split_whitespace().last() {
            found.push(child_dir.join(format!("{name}.rs")));
            found.push(child_dir.join(name).join("mod.rs"));
        }
    }
    found
}

#[test]
fn test_code_is_cut_wherever_it_sits() {
    let code = "fn a() {}\n#[cfg(test)]\n#[path = \"t.rs\"]\nmod tests;\nfn b() {}\n#[cfg(test)]\nfn helper(v: [f64; 3]) { if x { y } }\nfn c() {}\n#[cfg(test)]\nmod tests { fn d() {} }\n";
    let kept = without_tests(code);
    assert!(kept.contains("fn a()") && kept.contains("fn b()") && kept.contains("fn c()"), "{kept}");
    assert!(!kept.contains("helper") && !kept.contains("fn d()") && !kept.contains("t.rs"), "{kept}");
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
    let above: [(&str, &[&str]); 11] = [
        ("io/", &["model", "solver", "shape", "sweep", "reduce", "study", "map", "job", "design", "calibrate", "mould", "bench", "plot"]),
        ("shape", &["model", "solver", "sweep", "reduce", "design", "calibrate", "mould"]),
        ("model/", &["solver", "sweep", "reduce", "design", "calibrate", "mould", "bench", "plot", "study"]),
        ("solver/", &["sweep", "reduce", "design", "calibrate", "mould", "study", "plot", "bench"]),
        ("sweep/", &["reduce", "study", "map", "job", "design", "calibrate", "mould", "bench", "plot"]),
        ("reduce/", &["study", "map", "job", "design", "calibrate", "mould", "bench"]),
        // A study runs sweeps and maps them; a job file names a sweep or a
        // study; `map` reduces the run a job made. None of them designs or
        // calibrates.
        ("study/", &["map", "design", "calibrate", "mould", "bench"]),
        ("job.rs", &["reduce", "map", "design", "calibrate", "mould", "bench", "plot"]),
        ("map.rs", &["design", "calibrate", "mould", "bench"]),
        ("mould/", &["design", "calibrate", "reduce", "sweep", "study", "map", "job", "bench"]),
        // Pictures draw what the stages computed; no workflow runs from them.
        ("plot/", &["sweep", "study", "map", "job", "bench"]),
    ];
    for (file, code) in library_sources() {
        for (layer, upper) in above {
            if !file.starts_with(layer) {
                continue;
            }
            for u in upper {
                for needle in [format!("crate::{u}::"), format!("crate::{u};")] {
                    assert!(!code.contains(&needle), "src/{file} (layer {layer}) uses {needle}: lower layers never import upward");
                }
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

/// The names the code defines: identifiers after `fn`, `struct`, `enum`,
/// `type`, `trait`, `const`, `static` and `mod`.
fn defined_names(code: &str) -> Vec<String> {
    let words: Vec<&str> = code.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
    words
        .windows(2)
        .filter(|w| ["fn", "struct", "enum", "type", "trait", "const", "static", "mod"].contains(&w[0]))
        .map(|w| w[1].to_string())
        .collect()
}

/// The words of an identifier, lowercase: `Lu6Factors` → lu, 6, factors;
/// `lu_solve` → lu, solve.
fn name_words(name: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut previous: Option<char> = None;
    for c in name.chars() {
        let boundary = c == '_'
            || previous.is_some_and(|p| (p.is_lowercase() && c.is_uppercase()) || (p.is_ascii_digit() != c.is_ascii_digit()));
        if boundary && !word.is_empty() {
            words.push(std::mem::take(&mut word));
        }
        if c != '_' {
            word.extend(c.to_lowercase());
        }
        previous = Some(c);
    }
    if !word.is_empty() {
        words.push(word);
    }
    words
}

/// The code with all whitespace removed, so that a pattern matches however
/// it is formatted.
fn squeezed(code: &str) -> String {
    code.chars().filter(|c| !c.is_whitespace()).collect()
}

/// `count` or more non-overlapping occurrences of `needle` in
/// `text[at..at + window]` (clamped to char boundaries).
fn occurs_near(text: &str, at: usize, window: usize, needle: &str, count: usize) -> bool {
    let mut end = (at + window).min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    text[at..end].matches(needle).count() >= count
}

#[test]
fn the_rk4_step_is_written_once() {
    // Owner: src/numerics/rk4.rs. The tableau's combination of the stages,
    // h/6 (k1 + 2 k2 + 2 k3 + k4) or with weights 1/6, 1/3, in any layout.
    let mut problems = Vec::new();
    for (file, code) in all_code() {
        if file == "numerics/rk4.rs" {
            continue;
        }
        let text = squeezed(&code);
        for (at, _) in text.match_indices("/6.0") {
            let mut from = at.saturating_sub(80);
            while !text.is_char_boundary(from) {
                from -= 1;
            }
            let weights = occurs_near(&text, from, 160, "+2.0*", 2) || occurs_near(&text, from, 160, "+2.0*(", 1);
            let thirds = occurs_near(&text, from, 160, "1.0/3.0", 1) && occurs_near(&text, from, 160, "1.0/6.0", 1);
            let mut to = (at + 80).min(text.len());
            while !text.is_char_boundary(to) {
                to -= 1;
            }
            if weights || thirds {
                problems.push(format!(
                    "src/{file} combines RK4 stages itself (near `{}`): step with crate::numerics::rk4_step",
                    &text[from..to]
                ));
            }
        }
        for name in defined_names(&code) {
            let words = name_words(&name);
            let stepper = words.iter().any(|w| w == "runge" || w == "kutta")
                || (words.iter().any(|w| w == "rk4" || w == "rk") && words.iter().any(|w| w == "step" || w == "stage" || w == "stages"));
            if stepper {
                problems.push(format!("src/{file} defines `{name}`: RK4 steps belong to crate::numerics (rk4_step)"));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn linear_systems_use_nalgebra_not_a_hand_written_lu() {
    // Owner: nalgebra (`Matrix::lu`, `full_piv_lu`, `cholesky`, ...).
    let mut problems = Vec::new();
    for (file, code) in all_code() {
        for name in defined_names(&code) {
            let words = name_words(&name);
            let lu = words.iter().any(|w| ["lu", "lup", "plu", "gauss", "gaussian", "pivot", "pivots", "pivoting", "elimination", "eliminate"].contains(&w.as_str()));
            if lu {
                problems.push(format!("src/{file} defines `{name}`: factor matrices with nalgebra (`.lu()`, `.full_piv_lu()`), not by hand"));
            }
        }
        let words: Vec<&str> = code.split(|c: char| !(c.is_alphanumeric() || c == '_')).collect();
        for pivot in ["piv", "pivot", "pivots", "pivot_row", "ipiv"] {
            if words.contains(&pivot) {
                problems.push(format!(
                    "src/{file} uses `{pivot}`: row pivoting means a hand-written LU; factor with nalgebra (`.lu()`) instead"
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn legendre_polynomials_are_written_once() {
    // Owner: src/shape.rs (legendre, shifted_legendre_powers, ...).
    let mut problems = Vec::new();
    for (file, code) in all_code() {
        if file == "shape.rs" {
            continue;
        }
        for name in defined_names(&code) {
            if name.to_lowercase().contains("legendre") {
                problems.push(format!(
                    "src/{file} defines `{name}`: Legendre polynomials belong to src/shape.rs (legendre, shifted_legendre_powers)"
                ));
            }
        }
        // Bonnet's recurrence ((2k + 1) t P_k − k P_{k−1}) / (k + 1), in
        // f64 or integer spelling.
        let text = squeezed(&code);
        for (at, _) in text.match_indices("(2.0*").chain(text.match_indices("(2*")) {
            let rest = &text[at..];
            let var: String = rest.split('*').nth(1).unwrap_or("").chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if var.is_empty() {
                continue;
            }
            let division = [format!("/({var}+1.0)"), format!("/({var}+1)asf64"), format!("/(({var}+1)asf64)")];
            let window: String = rest.chars().take(160).collect();
            if division.iter().any(|d| window.contains(d.as_str())) {
                problems.push(format!(
                    "src/{file} has a three-term recurrence in `{var}` (near `{}`): Legendre polynomials belong to src/shape.rs",
                    window.chars().take(80).collect::<String>()
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
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
        // The registry, and the struct whose fields the keys name.
        if file == "model/effects.rs" || file == "model/effect_parameters.rs" {
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

/// A file's module path: `model/cable.rs` → [model, cable], `model/mod.rs`
/// → [model], `lib.rs` → [].
fn module_of(file: &str) -> Vec<String> {
    let mut parts: Vec<String> = file.trim_end_matches(".rs").split('/').map(String::from).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The library's files by module path.
struct Modules {
    files: Vec<(String, String)>,
}

impl Modules {
    /// The file of module `path`, if there is one.
    fn file(&self, path: &[String]) -> Option<&(String, String)> {
        let joined = path.join("/");
        let candidates = if path.is_empty() { vec!["lib.rs".to_string()] } else { vec![format!("{joined}.rs"), format!("{joined}/mod.rs")] };
        self.files.iter().find(|(f, _)| candidates.contains(f))
    }

    /// The file defining what `rest` names from module `module`: a
    /// submodule's file, or the module's own; an item the module re-exports
    /// (`pub use child::…Item`) is followed to where it comes from.
    fn resolve(&self, module: &[String], rest: &[String], depth: usize) -> Option<String> {
        let (file, code) = self.file(module)?;
        let Some(next) = rest.first() else { return Some(file.clone()) };
        let mut child = module.to_vec();
        child.push(next.clone());
        if self.file(&child).is_some() {
            return self.resolve(&child, &rest[1..], depth);
        }
        if depth < 8 {
            for statement in code.split(';').map(str::trim).filter_map(|s| s.strip_prefix("pub use ")) {
                let words: Vec<&str> = statement.split(|c: char| !(c.is_alphanumeric() || c == '_')).collect();
                if !words.contains(&next.as_str()) {
                    continue;
                }
                let prefix: Vec<String> =
                    statement.split('{').next().unwrap_or("").split("::").map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
                let prefix = if statement.contains('{') { prefix } else { prefix[..prefix.len().saturating_sub(1)].to_vec() };
                let (start, path) = match prefix.first().map(String::as_str) {
                    Some("crate") => (Vec::new(), prefix[1..].to_vec()),
                    Some("super") => (module[..module.len().saturating_sub(1)].to_vec(), prefix[1..].to_vec()),
                    Some("self") => (module.to_vec(), prefix[1..].to_vec()),
                    Some(_) => (module.to_vec(), prefix),
                    None => continue,
                };
                let mut target = path;
                target.push(next.clone());
                if let Some(found) = self.resolve(&start, &target, depth + 1) {
                    return Some(found);
                }
            }
        }
        Some(file.clone())
    }

    /// The files `file` uses through `crate::…` and `super::…` paths (one
    /// level of braces expanded), itself left out.
    fn uses(&self, file: &str, code: &str) -> Vec<String> {
        let module = module_of(file);
        // A file's `super` is its module's parent (a mod.rs is its folder's module).
        let parent = module[..module.len().saturating_sub(1)].to_vec();
        let ident = |c: char| c.is_alphanumeric() || c == '_';
        let mut out = Vec::new();
        for (root, start) in [("crate::", Vec::new()), ("super::", parent)] {
            for (at, _) in code.match_indices(root) {
                if code[..at].chars().next_back().is_some_and(|c| ident(c) || c == ':') {
                    continue;
                }
                let rest = &code[at + root.len()..];
                let mut segments = Vec::new();
                let mut tail = rest;
                loop {
                    let name: String = tail.chars().take_while(|c| ident(*c)).collect();
                    if name.is_empty() {
                        break;
                    }
                    tail = &tail[name.len()..];
                    segments.push(name);
                    match tail.strip_prefix("::") {
                        Some(t) => tail = t,
                        None => break,
                    }
                }
                let mut paths = Vec::new();
                if let Some(group) = tail.strip_prefix('{').and_then(|t| t.split('}').next()) {
                    for item in group.split(',') {
                        let mut path = segments.clone();
                        path.extend(item.split("::").map(|s| s.trim().split(' ').next().unwrap_or("").to_string()).filter(|s| !s.is_empty() && s != "self"));
                        paths.push(path);
                    }
                } else {
                    paths.push(segments);
                }
                for path in paths {
                    if let Some(target) = self.resolve(&start, &path, 0) {
                        if target != file {
                            out.push(target);
                        }
                    }
                }
            }
        }
        out.sort();
        out.dedup();
        out
    }
}

#[test]
fn no_files_use_each_other_in_a_circle() {
    // Following `use crate::…` paths and `super::…` through re-exports: a
    // circle of any length (effects.rs → a backend → the registry) hides a
    // layer that depends on itself.
    let library: Vec<String> = library_sources().into_iter().map(|(f, _)| f).collect();
    let modules = Modules { files: all_code().into_iter().filter(|(f, _)| library.contains(f)).collect() };
    let graph: Vec<(String, Vec<String>)> = modules.files.iter().map(|(f, code)| (f.clone(), modules.uses(f, code))).collect();
    let edges = |f: &str| graph.iter().find(|(g, _)| g == f).map(|(_, e)| e.clone()).unwrap_or_default();
    // Each file's circle back to itself, if any (breadth first: the shortest).
    let mut circles: Vec<Vec<String>> = Vec::new();
    for (start, _) in &graph {
        let mut previous: std::collections::BTreeMap<String, String> = Default::default();
        let mut queue = std::collections::VecDeque::from([start.clone()]);
        let mut found = None;
        while let Some(f) = queue.pop_front() {
            for g in edges(&f) {
                if g == *start {
                    found = Some(f.clone());
                    break;
                }
                if !previous.contains_key(&g) {
                    previous.insert(g.clone(), f.clone());
                    queue.push_back(g);
                }
            }
            if found.is_some() {
                break;
            }
        }
        if let Some(mut last) = found {
            let mut circle = vec![last.clone()];
            while last != *start {
                last = previous[&last].clone();
                circle.push(last.clone());
            }
            circle.reverse();
            let mut key = circle.clone();
            key.sort();
            if !circles.iter().any(|c| {
                let mut k = c.clone();
                k.sort();
                k == key
            }) {
                circles.push(circle);
            }
        }
    }
    // Circles still to be untangled by their layers' owners: inside these
    // folders, and between these files; nothing may be added.
    let known_folders = ["reduce/", "sweep/", "mould/"];
    let known_files = ["map.rs", "study/run.rs"];
    circles.retain(|c| {
        let inside = known_folders.iter().any(|d| c.iter().all(|f| f.starts_with(d)));
        let between = c.iter().all(|f| known_files.contains(&f.as_str()));
        !(inside || between)
    });
    let text: Vec<String> = circles.iter().map(|c| format!("{} → back", c.iter().map(|f| format!("src/{f}")).collect::<Vec<_>>().join(" → "))).collect();
    assert!(text.is_empty(), "files use each other in a circle: move what they share into one of them (or a file below both):\n{}", text.join("\n"));
}

#[test]
fn the_library_returns_no_string_errors_but_where_listed() {
    // Still to be typed by their layers' owners; nothing may be added.
    let remaining: [&str; 0] = [];
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
    assert_eq!(matched, ["map.rs"], "a run directory's kind picks its code in map::reduce only");
}

/// Files outside `src/solver/` that still build a backend by name, each
/// with the reason; shrink only. The captures' chains read body points at
/// the markers' s and hold each static capture from a virgin rod, which only
/// the spatial collocation offers.
const NAMING_A_BACKEND: &[&str] = &["calibrate/observations/captures/simulate.rs"];

#[test]
fn one_place_picks_the_backend() {
    // Owner: src/solver/simulator.rs (Simulator::serving, Simulator::for_rod
    // over Backend::serving's capability table). A workflow that builds a
    // backend by name decides what the picker decides, and the two drift apart.
    let named = ["SpatialCollocation::new", "SpatialRk4::new", "PlanarSolver::new", "PlanarCollocation::new", "PlanarRk4::new", "Backend::planar(", "Backend::spatial("];
    let mut problems = Vec::new();
    for (file, code) in all_sources() {
        if file.starts_with("solver/") {
            continue;
        }
        let code = squeezed(&code);
        let names = named.iter().any(|n| code.contains(&squeezed(n)));
        match (names, NAMING_A_BACKEND.contains(&file.as_str())) {
            (true, false) => problems.push(format!("src/{file} builds a backend by name: ask crate::solver::Simulator (serving, for_rod) or Backend::serving")),
            (false, true) => problems.push(format!("src/{file} no longer names a backend: remove it from NAMING_A_BACKEND")),
            _ => {}
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn every_backend_returns_the_one_result_type() {
    // Owner: src/solver/result.rs (TipPose, CentrelinePoint,
    // Simulation); a second pose, centreline node or simulation type (or an
    // alias) would be a twin the backends' outputs must be converted between.
    let mut problems = Vec::new();
    for (file, code) in all_code() {
        if file == "solver/result.rs" {
            continue;
        }
        let words: Vec<&str> = code.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
        for w in words.windows(2).filter(|w| w[0] == "struct" || w[0] == "type") {
            let last = name_words(w[1]).last().cloned().unwrap_or_default();
            if ["pose", "simulation", "node"].contains(&last.as_str()) {
                problems.push(format!("src/{file} defines `{}`: every backend returns cablemap::solver::result's TipPose, CentrelinePoint and Simulation", w[1]));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The end of the bracketed group opening at `open` (`(`, `[` or `{`):
/// the index just past its closing bracket.
fn group_end(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, c) in text[open..].char_indices() {
        match c {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(open + i + 1);
                }
            }
            _ => {}
        }
    }
    None
}

/// The error variants (and error structs) of `code` that carry a
/// pre-formatted sentence: a lone `String` tuple field, or a `String` field
/// named as a sentence (`message`, `reason`, `why`, `detail`, `list`,
/// `text`). Their `Display` prints a text made elsewhere, so the problem is
/// not a value a caller can match on. `code` has its comments removed.
fn string_sentence_variants(code: &str) -> Vec<String> {
    let mut found = Vec::new();
    for (at, _) in code.match_indices("#[error(") {
        let Some(mut i) = group_end(code, at + 1) else { continue };
        // Further attributes between `#[error(..)]` and the declaration.
        loop {
            let rest = &code[i..];
            let skipped = rest.len() - rest.trim_start().len();
            i += skipped;
            if code[i..].starts_with("#[") {
                match group_end(code, i + 1) {
                    Some(end) => i = end,
                    None => break,
                }
            } else {
                break;
            }
        }
        let rest = &code[i..];
        let Some(open) = rest.find(['(', '{', ',', ';']) else { continue };
        let name: String = rest[..open].split_whitespace().last().unwrap_or("").to_string();
        let fields = match rest[open..].chars().next() {
            Some('(') | Some('{') => group_end(rest, open).map_or("", |end| &rest[open..end]),
            _ => "",
        };
        let fields = squeezed(fields);
        let lone = fields == "(String)" || fields == "(pubString)";
        let sentence = ["message", "reason", "why", "detail", "list", "text"].iter().any(|f| {
            ["{", ","].iter().any(|before| {
                fields.contains(&format!("{before}{f}:String")) || fields.contains(&format!("{before}pub{f}:String"))
            })
        });
        if lone || sentence {
            found.push(name);
        }
    }
    found
}

/// Library files under `dirs` (or named so), with their comments removed.
fn library_code_under(dirs: &[&str]) -> Vec<(String, String)> {
    library_sources()
        .into_iter()
        .filter(|(file, _)| dirs.iter().any(|d| file.starts_with(d)))
        .map(|(file, text)| {
            let code: Vec<&str> = text.lines().map(|l| l.find("//").map_or(l, |i| &l[..i])).collect();
            (file, code.join("\n"))
        })
        .collect()
}

#[test]
fn errors_carry_typed_fields_not_sentences() {
    // The sweep, reduce, study, mould and io layers (and the job and map
    // workflows) hold none; library-wide the count may only fall.
    let typed = ["sweep/", "reduce/", "study/", "mould/", "io/", "job.rs", "map.rs"];
    let mut listed = Vec::new();
    let mut total = 0;
    for (file, code) in library_code_under(&[""]) {
        let names = string_sentence_variants(&code);
        total += names.len();
        if typed.iter().any(|d| file.starts_with(d)) {
            listed.extend(names.iter().map(|n| format!("src/{file}: {n}")));
        }
        if !names.is_empty() {
            eprintln!("src/{file}: {}", names.join(", "));
        }
    }
    assert!(listed.is_empty(), "error variants carrying a pre-formatted String (give them typed fields; Display makes the sentence):\n{}", listed.join("\n"));
    assert!(total <= LIBRARY_STRING_SENTENCES, "{total} error variants carry a pre-formatted String, more than the {LIBRARY_STRING_SENTENCES} left to type");
}

/// Error variants in the library still carrying a pre-formatted `String`
/// ([`errors_carry_typed_fields_not_sentences`]); lowered as they are typed.
/// `plot::PlotError` is one of them: plotters' errors are generic over the
/// backend, so a drawing's failure is kept as its text.
const LIBRARY_STRING_SENTENCES: usize = 3;

#[test]
fn the_detector_of_sentence_errors_sees_each_form() {
    let code = r#"
        #[derive(Debug, thiserror::Error)]
        pub enum E {
            #[error("{0}")]
            Lone(String),
            #[error("[{section}] {message}")]
            Setting { section: &'static str, message: String },
            #[error("cannot read {}", path.display())]
            #[non_exhaustive]
            Read { path: PathBuf, name: String },
            #[error("{context}: {source}")]
            Parquet { context: String, source: ParquetError },
            #[error("{why}")]
            Why { origin: String, pub why: String },
            #[error("{count} rows")]
            Rows { count: u64 },
        }
        #[derive(Debug, thiserror::Error)]
        #[error("{0}")]
        pub struct Invalid(pub String);
    "#;
    assert_eq!(string_sentence_variants(code), ["Lone", "Setting", "Why", "Invalid"]);
}

#[test]
fn no_source_file_is_over_1200_lines() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut long = Vec::new();
    for path in files {
        let lines = std::fs::read_to_string(&path).unwrap().lines().count();
        if lines > 1200 {
            long.push(format!("{}: {lines} lines", path.strip_prefix(&src).unwrap().display()));
        }
    }
    assert!(long.is_empty(), "split these by job (at most 1,200 lines a file):\n{}", long.join("\n"));
}

/// The types of the library (structs, enums, traits, aliases) by name.
fn type_names() -> Vec<String> {
    let mut names = Vec::new();
    for (_, code) in library_sources() {
        for line in code.lines() {
            let words: Vec<&str> = line.split_whitespace().collect();
            let Some(k) = words.iter().position(|w| ["struct", "enum", "trait", "type"].contains(w)) else { continue };
            if !words[..k].iter().all(|w| w.starts_with("pub")) {
                continue;
            }
            if let Some(name) = words.get(k + 1) {
                let name: String = name.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if name.starts_with(|c: char| c.is_ascii_uppercase()) {
                    names.push(name);
                }
            }
        }
    }
    names
}

/// Types still twinned with a `3` beside their planar name; this list only
/// shrinks (one concept, one type).
const TWINNED_BY_A_3: [&str; 0] = [];

#[test]
fn no_type_is_a_twin_named_with_a_3() {
    let names = type_names();
    let twins: Vec<&String> = names.iter().filter(|n| n.contains('3') && names.contains(&n.replacen('3', "", 1))).collect();
    let new: Vec<&&String> = twins.iter().filter(|n| !TWINNED_BY_A_3.contains(&n.as_str())).collect();
    assert!(new.is_empty(), "one type per concept: {new:?} beside the same name without the 3 (generalise the one type)");
    let gone: Vec<&&str> = TWINNED_BY_A_3.iter().filter(|t| !twins.iter().any(|n| n == *t)).collect();
    assert!(gone.is_empty(), "{gone:?} no longer twinned: remove them from TWINNED_BY_A_3");
}

/// `python/src` converts Python's arguments and wraps the library's
/// reports: every request it runs is the library's, deserialised, so the
/// checks and defaults are written once.
#[test]
fn python_declares_no_request_of_its_own() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("python/src");
    let mut files = Vec::new();
    rust_files(&dir, &mut files);
    assert!(!files.is_empty(), "no sources in {}", dir.display());
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let words: Vec<&str> = text.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
        for w in words.windows(2).filter(|w| w[0] == "struct") {
            assert!(!w[1].ends_with("Request"), "{} declares struct {}: fill the library's request instead", path.display(), w[1]);
        }
    }
}
