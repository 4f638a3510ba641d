//! The effect registry (`cablemap::model::effects`) against what is
//! generated from it or written beside it: the `Effects` struct's fields,
//! the command line's flags and docs/model.md's effects table.

mod process;

use cablemap::model::effects::{fittable, Section, REGISTRY};
use cablemap::solver::Backend;
use cablemap::model::{Effects, Rod};
use std::collections::BTreeSet;

/// Every numeric field of `Effects` (the serde form, as a spec writes it)
/// is a registry entry, and every registry entry of the `[effects]` table is
/// a field: a new field without an entry would have no flag, no bounds and
/// no capability check.
#[test]
fn every_effects_field_is_a_registry_entry_and_back() {
    let mut effects = Effects::default();
    // Fields not written at their default are written once set.
    for info in REGISTRY.iter().filter(|e| e.section == Section::Effects) {
        let v = if info.default == 0.0 { 0.25 } else if info.default.is_finite() { info.default * 0.5 } else { 40.0 };
        let mut rod = Rod { effects, ..Rod::default() };
        (info.set)(&mut rod, v);
        effects = rod.effects;
    }
    let json = serde_json::to_value(&effects).unwrap();
    // The load direction is the protocol's state, not an effect parameter.
    let fields: BTreeSet<&str> = json.as_object().unwrap().keys().map(String::as_str).filter(|k| *k != "load_direction").collect();
    let entries: BTreeSet<&str> = REGISTRY.iter().filter(|e| e.section == Section::Effects).map(|e| e.key).collect();
    assert_eq!(fields, entries);
    assert!(!json.as_object().unwrap().contains_key("hidden"), "the unmodelled effects are not part of the file format");
}

/// A spec's `[effects.hidden]` table is refused: the effects `synth`
/// plants outside the library are no effects but the body's (a rest
/// curvature, a stiff segment), read where the body is.
#[test]
fn synths_out_of_library_effects_are_the_bodys_not_effects() {
    let e = Rod::from_toml_str("[effects.hidden]\nrest_curvature_per_mm = 0.01\n").unwrap_err().to_string();
    assert!(e.contains("hidden"), "{e}");
    let curved = Rod::from_toml_str("rest_curvature_per_mm = 0.01\n").unwrap();
    assert_eq!(curved.rest_curvature_per_mm, 0.01);
    assert!(!toml::to_string(&Rod::default()).unwrap().contains("rest_curvature"), "not written when 0: files are unchanged");
}

/// `cablemap simulate --help` shows each registry flag with its value name
/// and default, and each flag (and its old alias) sets its parameter. (The
/// other way round, every effect field is an entry: the test above.)
#[test]
fn the_effect_flags_are_the_registrys() {
    let out = process::cablemap().args(["simulate", "--help"]).output().unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    for info in REGISTRY.iter() {
        let line = format!("{} <{}>", info.flag, info.value_name);
        assert!(help.contains(&line), "simulate --help lacks {line}");
        assert!(help.contains(&format!("[default: {}]", info.default_text)), "{}: default", info.flag);
    }
    // Each flag reaches its parameter: an out-of-bounds value is refused
    // naming the parameter's path.
    for info in REGISTRY.iter() {
        for flag in std::iter::once(info.flag).chain(info.flag_aliases.iter().copied()) {
            let out = process::cablemap().args(["simulate", "--routing", "1,1,1,1,1", "--tension-n", "1", flag, "-1e300"]).output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success() && err.contains(info.path), "{flag} -1e300: {err}");
        }
    }
}

/// docs/model.md's effects table lists exactly the registry's entries, in
/// its order, with their units, defaults, flags, fit names and solvers.
#[test]
fn the_docs_effects_table_is_the_registry() {
    let text = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/model.md")).unwrap();
    let section = &text[text.find("## Effects").expect("docs/model.md has an Effects section")..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let header = "| effect | parameter | unit | default | flag | fit as | solvers | term |";
    let start = section.find(header).unwrap_or_else(|| panic!("docs/model.md's effects table has the header {header}"));
    let rows: Vec<Vec<String>> = section[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.replace("\\|", "¦").split('|').map(|c| c.trim().to_string()).collect())
        .collect();
    assert_eq!(rows.len(), REGISTRY.len(), "one row per registry entry");
    for (row, info) in rows.iter().zip(REGISTRY.iter()) {
        let fit = info.fit.map_or("—".to_string(), |f| format!("`{}`", f.name));
        let solvers: Vec<&str> = Backend::ALL.iter().filter(|b| b.models(info)).map(|b| b.name()).collect();
        let expected = [
            info.effect.to_string(),
            format!("`{}` ({})", info.path, info.symbol),
            info.unit.to_string(),
            info.default_text.to_string(),
            format!("`{}`", info.flag),
            fit,
            solvers.join(", "),
        ];
        assert_eq!(&row[1..8], &expected[..], "docs/model.md's row of {} differs from the registry", info.path);
    }
    assert_eq!(fittable().count(), cablemap::calibrate::Effect::ALL.len());
}
