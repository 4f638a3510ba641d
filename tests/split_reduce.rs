//! `cablemap reduce --shard I --shards N` then `--merge`, and the memory
//! bound, as a user (or a cluster array) runs them: the merged map equals
//! the single-process one for any N; missing, mixed or foreign parts are
//! refused with the command that fixes them; a part killed and run again,
//! or run twice at once, leaves the same map.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const QUICK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");

fn cablemap() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
        c.env_remove(v);
    }
    c
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = cablemap().args(args).output().expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The tables of a map, byte for byte (summary.json without its run_dir).
fn tables(map: &Path) -> Vec<Vec<u8>> {
    let mut out: Vec<Vec<u8>> = ["cells.parquet", "modes.parquet", "designs.parquet"]
        .iter()
        .map(|f| std::fs::read(map.join(f)).unwrap_or_else(|e| panic!("{}: {e}", map.join(f).display())))
        .collect();
    let mut summary: serde_json::Value = serde_json::from_slice(&std::fs::read(map.join("summary.json")).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("run_dir");
    out.push(summary.to_string().into_bytes());
    out
}

/// A quick run (8 chunk files) and its single-process map.
fn quick_run(tmp: &Path) -> (PathBuf, Vec<Vec<u8>>) {
    let dir = tmp.join("run");
    let (ok, _, stderr) = run(&["sweep", QUICK, "--out", s(&dir)]);
    assert!(ok, "{stderr}");
    let single = tmp.join("single");
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&single)]);
    assert!(ok, "{stderr}");
    (dir.clone(), tables(&single))
}

fn parts(run_dir: &Path, map: &Path, n: u64) {
    for i in 0..n {
        let (ok, stdout, stderr) = run(&[
            "reduce",
            s(run_dir),
            "--out",
            s(map),
            "--shard",
            &i.to_string(),
            "--shards",
            &n.to_string(),
        ]);
        assert!(ok && stdout.contains(&format!("part {i} of {n}")), "{stdout}{stderr}");
    }
}

fn merge(run_dir: &Path, map: &Path) -> (bool, String, String) {
    run(&["reduce", s(run_dir), "--out", s(map), "--merge"])
}

#[test]
fn n_parts_merged_equal_the_single_reduce_for_any_n_and_any_memory_bound() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, single) = quick_run(tmp.path());
    // More parts than chunk files (8) leaves some parts empty.
    for n in [1u64, 2, 3, 8, 13] {
        let map = tmp.path().join(format!("map{n}"));
        parts(&dir, &map, n);
        let (ok, _, stderr) = merge(&dir, &map);
        assert!(ok, "{n} parts: {stderr}");
        assert_eq!(tables(&map), single, "{n} parts");
    }
    // The memory bound changes how the cells are partitioned, not the map:
    // one sample at a time puts every cell in its own partition.
    for memory in ["1", "40", "1000"] {
        let map = tmp.path().join(format!("mem{memory}"));
        let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--memory-samples", memory]);
        assert!(ok, "{stderr}");
        assert_eq!(tables(&map), single, "--memory-samples {memory}");
    }
    let map = tmp.path().join("map3");
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--merge", "--memory-samples", "7"]);
    assert!(ok, "{stderr}");
    assert_eq!(tables(&map), single);
    // SLURM's array index picks the part when --shard is not given.
    let map = tmp.path().join("slurm");
    for i in 0..2 {
        let out = cablemap()
            .args(["reduce", s(&dir), "--out", s(&map), "--shards", "2"])
            .env("SLURM_ARRAY_TASK_ID", i.to_string())
            .output()
            .unwrap();
        assert!(out.status.success() && String::from_utf8_lossy(&out.stdout).contains("SLURM_ARRAY_TASK_ID"));
    }
    assert!(merge(&dir, &map).0);
    assert_eq!(tables(&map), single);
}

#[test]
fn missing_mixed_foreign_and_damaged_parts_are_refused_with_the_fix() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, single) = quick_run(tmp.path());
    let map = tmp.path().join("map");
    // No parts at all.
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("no reduce parts found") && stderr.contains("--shard I --shards N"),
        "{stderr}"
    );
    // One missing: named, with its command.
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "0", "--shards", "3"]);
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "2", "--shards", "3"]);
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("1 of 3 parts missing (part 1)") && stderr.contains("--shard 1 --shards 3"),
        "{stderr}"
    );
    assert!(!map.exists(), "no map is written from incomplete parts");
    // Parts of another split mixed in.
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "1", "--shards", "2"]);
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(!ok && stderr.contains("different splits (of 2, 3)"), "{stderr}");
    // A bad part number.
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--shard", "3", "--shards", "3"]);
    assert!(!ok && stderr.contains("not below --shards 3"), "{stderr}");
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--shard", "1"]);
    assert!(!ok && stderr.contains("--shards"), "{stderr}");
    // A part of another run (its spec differs).
    let parts_dir = tmp.path().join("map.parts");
    std::fs::remove_dir_all(&parts_dir).unwrap();
    parts(&dir, &map, 2);
    let record = parts_dir.join("part-1-of-2.json");
    let text = std::fs::read_to_string(&record).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let hash = v["spec_sha256"].as_str().unwrap();
    std::fs::write(&record, text.replace(hash, &"0".repeat(hash.len()))).unwrap();
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("part-1-of-2.json") && stderr.contains("another run"),
        "{stderr}"
    );
    // A cut-short samples file.
    std::fs::write(&record, &text).unwrap();
    let samples = parts_dir.join("part-0-of-2.samples");
    let bytes = std::fs::read(&samples).unwrap();
    std::fs::write(&samples, &bytes[..bytes.len() - 48]).unwrap();
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("part-0-of-2.samples") && stderr.contains("run this part again"),
        "{stderr}"
    );
    // Running that part again fixes it.
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "0", "--shards", "2"]);
    assert!(merge(&dir, &map).0);
    assert_eq!(tables(&map), single);
    // Three flipped bytes in a samples file (same length): its checksum names it.
    let mut bytes = std::fs::read(&samples).unwrap();
    for at in [100, bytes.len() / 2, bytes.len() - 3] {
        bytes[at] ^= 0x5a;
    }
    std::fs::write(&samples, &bytes).unwrap();
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("part-0-of-2.samples") && stderr.contains("SHA-256") && stderr.contains("--shard 0 --shards 2`"),
        "{stderr}"
    );
    assert_eq!(tables(&map), single, "the refused merge left the earlier map");
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "0", "--shards", "2"]);
    // An edited count and extent in a record (valid JSON, plausible numbers).
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    let rows = v["pass1"]["tally"]["rows_total"].as_u64().unwrap();
    v["pass1"]["tally"]["rows_total"] = (rows + 10).into();
    let x_max = v["pass1"]["extent"]["x_mm"][1].as_f64().unwrap();
    v["pass1"]["extent"]["x_mm"][1] = (x_max + 40.0).into();
    std::fs::write(&record, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(
        !ok && stderr.contains("part-1-of-2.json") && stderr.contains("record_sha256") && stderr.contains("--shard 1 --shards 2`"),
        "{stderr}"
    );
    run(&["reduce", s(&dir), "--out", s(&map), "--shard", "1", "--shards", "2"]);
    assert!(merge(&dir, &map).0);
    assert_eq!(tables(&map), single);
}

#[test]
fn a_part_killed_and_run_again_or_run_twice_at_once_gives_the_same_map() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, single) = quick_run(tmp.path());
    let map = tmp.path().join("map");
    let args = |i: &str| {
        vec![
            "reduce".to_string(),
            s(&dir).into(),
            "--out".into(),
            s(&map).into(),
            "--shard".into(),
            i.into(),
            "--shards".into(),
            "2".into(),
        ]
    };
    let started = Instant::now();
    assert!(cablemap().args(args("0")).stdout(Stdio::null()).status().unwrap().success());
    let full_us = started.elapsed().as_micros().max(1000) as u64;
    let mut seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64
        | 1;
    eprintln!("part kill test seed {seed}, one part {full_us} µs");
    for _ in 0..6 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let mut child = cablemap()
            .args(args("1"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_micros(seed % full_us));
        let _ = child.kill();
        child.wait().unwrap();
        // Whatever the kill left, the merge either refuses (part 1 missing)
        // or, if the part had finished, gives the single map.
        let (ok, _, stderr) = merge(&dir, &map);
        if ok {
            assert_eq!(tables(&map), single);
        } else {
            assert!(stderr.contains("(part 1)"), "{stderr}");
        }
    }
    // Two copies of part 1 at once, after the kills.
    let mut a = cablemap().args(args("1")).stdout(Stdio::null()).spawn().unwrap();
    let mut b = cablemap().args(args("1")).stdout(Stdio::null()).spawn().unwrap();
    assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
    let (ok, _, stderr) = merge(&dir, &map);
    assert!(ok, "{stderr}");
    assert_eq!(tables(&map), single);
    // The kills' temporaries are gone (the next writer of the part removed
    // them), and the scratch of every reduce too.
    let leftovers: Vec<String> = std::fs::read_dir(tmp.path().join("map.parts"))
        .unwrap()
        .chain(std::fs::read_dir(tmp.path()).unwrap())
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-") || n.starts_with(".cablemap-reduce-"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
