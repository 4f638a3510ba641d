//! One test binary for most integration test files. Each file stays where it
//! is and becomes a module here, so the suite links one binary instead of
//! fifteen (each link is the whole library with arrow and parquet), and the
//! harness runs all their tests from one pool: a long test overlaps the
//! others instead of ending a binary of its own with one core idle.
//!
//! `tests/bad_input.rs`, `cli.rs`, `design.rs` and `reliability.rs` stay
//! binaries of their own; Cargo.toml lists every test binary
//! (`autotests = false`), and [`every_test_file_is_run`] fails on a file in
//! `tests/` that neither lists. One file's tests:
//! `cargo test --release --test suite -- map::`.

#[path = "backends.rs"]
mod backends;
#[path = "bodies.rs"]
mod bodies;
#[path = "calibrate.rs"]
mod calibrate;
#[path = "captures.rs"]
mod captures;
#[path = "design_cables.rs"]
mod design_cables;
#[path = "effects.rs"]
mod effects;
#[path = "feasible.rs"]
mod feasible;
#[path = "heavy_rod.rs"]
mod heavy_rod;
#[path = "layering.rs"]
mod layering;
#[path = "map.rs"]
mod map;
#[path = "mould.rs"]
mod mould;
#[path = "reference.rs"]
mod reference;
#[path = "spatial.rs"]
mod spatial;
#[path = "spatial_cli.rs"]
mod spatial_cli;
#[path = "split_reduce.rs"]
mod split_reduce;
#[path = "study.rs"]
mod study;
#[path = "sweep.rs"]
mod sweep;
#[path = "sweep_cables.rs"]
mod sweep_cables;
#[path = "tentacle.rs"]
mod tentacle;
#[path = "test_script.rs"]
mod test_script;

/// With `autotests = false` cargo no longer finds test files by itself: a
/// new `tests/NAME.rs` must be a module above or a `[[test]]` of Cargo.toml,
/// or it would silently never run.
#[test]
fn every_test_file_is_run() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let suite = include_str!("suite.rs");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if !name.ends_with(".rs") || name == "suite.rs" {
            continue;
        }
        let module = suite.contains(&format!("#[path = \"{name}\"]"));
        let binary = manifest.contains(&format!("path = \"tests/{name}\""));
        if !(module || binary) {
            missing.push(name);
        }
    }
    let missing: Vec<String> = missing.iter().map(|n| format!("tests/{n}")).collect();
    assert!(
        missing.is_empty(),
        "{} would never run: add each as a module of tests/suite.rs (#[path = \"NAME.rs\"] mod NAME;) or as a [[test]] in Cargo.toml",
        missing.join(", ")
    );
}
