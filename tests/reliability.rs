//! Faults a cluster or a disk can inflict, run as a user would meet them:
//! two copies of one shard at once (each as pid 1 in its own pid
//! namespace, as in containers), flipped bits in committed chunks, an
//! edited manifest, leftovers of killed writers, a reduce killed while it
//! replaces a map, and outputs aimed into a run directory
//! (docs/reliability.md).

use cablemap::sweep::{open_run, Completeness};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod process;
use process::{cablemap, snapshot};

const QUICK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");
/// Many small chunks, a few seconds of work: long enough for two copies to overlap.
const OVERLAP_SPEC: &str = "[grid]\nlevels = 5\n[tension]\ncount = 4\n[output]\nchunk_routings = 10\n";


fn run(args: &[&str]) -> (bool, String, String) {
    let out = cablemap().args(args).output().expect("runs");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), String::from_utf8_lossy(&out.stderr).into())
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn sweep(spec: &Path, dir: &Path) -> (bool, String, String) {
    run(&["sweep", s(spec), "--out", s(dir), "--quiet"])
}


/// The chunk files of a run, by name, with their bytes.
fn chunks(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir.join("shards"))
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())
        })
        .collect()
}

fn unshare_works() -> bool {
    Command::new("unshare")
        .args(["--pid", "--fork", "--kill-child", "true"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn two_copies_of_one_shard_as_pid_1_in_separate_namespaces_both_finish_the_same_run() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("overlap.toml");
    std::fs::write(&spec, OVERLAP_SPEC).unwrap();
    let reference = tmp.path().join("reference");
    assert!(sweep(&spec, &reference).0);
    let expected = chunks(&reference);
    let namespaces = unshare_works();
    if !namespaces {
        eprintln!(
            "WARNING: `unshare --pid --fork` is not available here (needs root or user namespaces): the two copies run as \
             ordinary processes with different pids, so the pid-1 collision of containers is NOT exercised"
        );
    }
    for trial in 0..3 {
        let dir = tmp.path().join(format!("run{trial}"));
        let start = || {
            let mut c = if namespaces {
                let mut c = Command::new("unshare");
                c.args(["--pid", "--fork", "--kill-child", env!("CARGO_BIN_EXE_cablemap")]);
                c
            } else {
                cablemap()
            };
            for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
                c.env_remove(v);
            }
            c.args(["sweep", s(&spec), "--out", s(&dir), "--threads", "1", "--quiet"])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (start(), start());
        for child in [a, b] {
            let out = child.wait_with_output().unwrap();
            assert!(
                out.status.success(),
                "trial {trial}: a copy failed: {}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        assert_eq!(chunks(&dir), expected, "trial {trial}: the chunks differ from a single run's (or temporaries were left)");
        let (ok, stdout, _) = run(&["status", s(&dir)]);
        assert!(ok && stdout.contains("state      complete"), "{stdout}");
    }
}

#[test]
fn a_flipped_bit_anywhere_in_a_chunk_is_named_refused_by_reduce_and_redone_by_resume() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    let good = chunks(&dir);
    let victim = dir.join("shards/chunk-000001.parquet");
    let len = good["chunk-000001.parquet"].len();
    // Header, data pages, footer metadata, last byte.
    for (k, at) in [4, len / 3, len / 2, len - 40, len - 1].into_iter().enumerate() {
        let mut bytes = good["chunk-000001.parquet"].clone();
        bytes[at] ^= 1 << (k % 8);
        std::fs::write(&victim, &bytes).unwrap();
        let (ok, stdout, _) = run(&["status", s(&dir)]);
        assert!(ok && stdout.contains("damaged") && stdout.contains("chunk-000001.parquet") && stdout.contains("partial"), "byte {at}: {stdout}");
        let map = tmp.path().join(format!("map{k}"));
        let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
        assert!(!ok && stderr.contains("chunk-000001.parquet") && stderr.contains("damaged"), "byte {at}: {stderr}");
        assert!(!map.exists(), "a map was written from a damaged run");
        let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--partial"]);
        assert!(!ok && stderr.contains("damaged"), "byte {at}: {stderr}");
        let (ok, stdout, stderr) = sweep(Path::new(QUICK), &dir);
        assert!(ok && stdout.contains("1 damaged chunks redone"), "byte {at}: {stdout}{stderr}");
        assert_eq!(chunks(&dir), good, "byte {at}: the redone chunk differs");
    }
    assert_eq!(std::fs::read_dir(dir.join("damaged")).unwrap().count(), 5, "each damaged file is kept aside");
    // A chunk whose checksum record is missing is not trusted either.
    std::fs::remove_file(dir.join("checksums/chunk-000002.parquet.sha256")).unwrap();
    let (ok, stdout, _) = run(&["status", s(&dir)]);
    assert!(ok && stdout.contains("no checksum recorded"), "{stdout}");
    assert!(sweep(Path::new(QUICK), &dir).0);
    assert_eq!(chunks(&dir), good);
    assert!(open_run(&dir, Completeness::Complete).is_ok());
}

#[test]
fn an_edited_manifest_field_is_refused_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    let manifest = dir.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    for (from, to) in [("\"max_n\": 2.0", "\"max_n\": 2.5"), ("\"total_rows\": 610", "\"total_rows\": 600")] {
        assert!(text.contains(from), "{text}");
        std::fs::write(&manifest, text.replace(from, to)).unwrap();
        for args in [vec!["status", s(&dir)], vec!["reduce", s(&dir), "--out", s(&tmp.path().join("m"))]] {
            let (ok, _, stderr) = run(&args);
            assert!(!ok && stderr.contains("manifest") && stderr.contains("edited or damaged"), "{from}: {stderr}");
        }
        let (ok, _, stderr) = sweep(Path::new(QUICK), &dir);
        assert!(!ok && stderr.contains("edited or damaged"), "{stderr}");
    }
    std::fs::write(&manifest, &text).unwrap();
    assert!(run(&["status", s(&dir)]).0);
}

#[test]
fn an_abandoned_temporary_is_removed_but_a_live_writers_is_left_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    std::fs::remove_file(dir.join("shards/chunk-000003.parquet")).unwrap();
    let abandoned = dir.join("shards/.chunk-000003.parquet.tmp-1");
    std::fs::write(&abandoned, b"half a chunk").unwrap();
    // A live writer (this test) holds the lock on its temporary.
    let live = dir.join("shards/.chunk-000003.parquet.tmp-1-0123456789abcdef-0");
    let held = std::fs::File::create(&live).unwrap();
    held.try_lock().unwrap();
    let (ok, stdout, stderr) = sweep(Path::new(QUICK), &dir);
    assert!(ok && stdout.contains("1 abandoned partial chunks removed"), "{stdout}{stderr}");
    assert!(!abandoned.exists());
    assert!(live.exists(), "a live writer's temporary was deleted");
    drop(held);
    let (ok, stdout, _) = sweep(Path::new(QUICK), &dir);
    assert!(ok && stdout.contains("1 abandoned partial chunks removed"), "{stdout}");
    assert!(!live.exists());
}

fn summary_cell_mm(map: &Path) -> f64 {
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(map.join("summary.json")).unwrap()).unwrap();
    v["cell_mm"].as_f64().unwrap()
}

/// A map directory is whole: every table and picture of one reduction.
fn assert_whole_map(map: &Path, context: &str) -> f64 {
    let cell = summary_cell_mm(map);
    for f in ["cells.parquet", "modes.parquet", "designs.parquet", "reach.png", "modes.png", "index.html"] {
        assert!(map.join(f).is_file(), "{context}: {f} missing");
    }
    let reach_of = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(reach_of(&map.join("cells.parquet")) > 0);
    cell
}

#[test]
fn a_reduce_killed_while_replacing_a_map_leaves_the_old_map_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("overlap.toml");
    std::fs::write(&spec, OVERLAP_SPEC).unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(&spec, &dir).0);
    let map = tmp.path().join("map");
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
    assert!(ok, "{stderr}");
    let one_mm_cells = std::fs::read(map.join("cells.parquet")).unwrap();
    let started = Instant::now();
    assert!(run(&["reduce", s(&dir), "--out", s(&tmp.path().join("timing")), "--cell-mm", "5"]).0);
    let full_us = started.elapsed().as_micros().max(1000) as u64;
    let mut seed = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64 | 1;
    eprintln!("reduce kill test seed {seed}, full reduce {full_us} µs");
    let (mut old, mut new) = (0, 0);
    for round in 0..8 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let cell = if round % 2 == 0 { "5" } else { "1" };
        let mut child = cablemap()
            .args(["reduce", s(&dir), "--out", s(&map), "--cell-mm", cell])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_micros(seed % (full_us + full_us / 4)));
        let _ = child.kill();
        child.wait().unwrap();
        let found = assert_whole_map(&map, &format!("round {round}"));
        if found == cell.parse::<f64>().unwrap() {
            new += 1;
        } else {
            old += 1;
        }
        // The map on disk is consistent with itself: feasible agrees with its tables.
        let (ok, stdout, stderr) = run(&["feasible", "--map", s(&map), "--target", "x=50,y=5"]);
        assert!(ok && stdout.starts_with("verdict   feasible\n"), "round {round}: {stdout}{stderr}");
    }
    eprintln!("kills: {old} left the previous map, {new} the new one");
    // The next reduce clears what killed ones left beside the map.
    assert!(run(&["reduce", s(&dir), "--out", s(&map)]).0);
    assert_eq!(std::fs::read(map.join("cells.parquet")).unwrap(), one_mm_cells);
    let leftovers: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".map."))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_map_directory_is_only_replaced_when_it_is_a_map() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    let notes = tmp.path().join("notes");
    std::fs::create_dir(&notes).unwrap();
    std::fs::write(notes.join("thesis.pdf"), b"pdf").unwrap();
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&notes)]);
    assert!(!ok && stderr.contains("not a cablemap map"), "{stderr}");
    assert_eq!(std::fs::read(notes.join("thesis.pdf")).unwrap(), b"pdf");
    // A file named summary.json does not make a folder a map: only the
    // format marker a reduce writes does (replacing deletes everything).
    let lookalike = tmp.path().join("lookalike");
    std::fs::create_dir_all(lookalike.join("sub")).unwrap();
    std::fs::write(lookalike.join("summary.json"), "{}\n").unwrap();
    std::fs::write(lookalike.join("thesis.tex"), "keep\n").unwrap();
    let before = snapshot(&lookalike);
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&lookalike)]);
    assert!(!ok && stderr.contains("not a cablemap map") && stderr.contains("cablemap-map/"), "{stderr}");
    assert_eq!(snapshot(&lookalike), before);
    assert!(lookalike.join("sub").is_dir());
    // A map cablemap wrote is replaced, and an empty directory is taken.
    let map = tmp.path().join("map");
    std::fs::create_dir(&map).unwrap();
    for _ in 0..2 {
        let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
        assert!(ok, "{stderr}");
    }
    // A map written before the marker existed (no `format`) is still
    // replaced, as long as it holds only what maps are made of.
    let summary_path = map.join("summary.json");
    let mut summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&summary_path).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("format");
    std::fs::write(&summary_path, serde_json::to_string(&summary).unwrap()).unwrap();
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
    assert!(ok, "an unmarked old map must be replaceable: {stderr}");
    std::fs::write(&summary_path, serde_json::to_string(&summary).unwrap()).unwrap();
    std::fs::write(map.join("my-notes.txt"), "keep\n").unwrap();
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
    assert!(!ok && stderr.contains("not a cablemap map"), "{stderr}");
    assert_eq!(std::fs::read_to_string(map.join("my-notes.txt")).unwrap(), "keep\n");
}

#[test]
fn outputs_aimed_into_a_run_directory_are_refused_and_the_run_stays_usable() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    let before = snapshot(&dir);
    let inside = dir.join("maps");
    // At any depth, through `..`, and for output files as well as directories.
    let deep = dir.join("shards/new/deeper/map");
    let roundabout = dir.join("shards/../checksums/map");
    let manifest = dir.join("manifest.json");
    let csv = dir.join("shards/centreline.csv");
    let nested = dir.join("shards/run");
    let simulate = |csv: &Path| {
        vec!["simulate".to_string(), "--routing".into(), "0,1,0,1,0".into(), "--tension".into(), "1".into(), "--csv".into(), s(csv).into()]
    };
    let mut picture = simulate(&manifest);
    picture[5] = "--png".into();
    picture[6] = s(&dir.join("shards/picture.png")).into();
    let simulations = [simulate(&manifest), simulate(&csv), picture];
    for args in [
        vec!["reduce", s(&dir), "--out", s(&dir)],
        vec!["reduce", s(&dir), "--out", s(&inside)],
        vec!["reduce", s(&dir), "--out", s(&dir.join("shards/map"))],
        vec!["reduce", s(&dir), "--out", s(&deep)],
        vec!["reduce", s(&dir), "--out", s(&roundabout)],
        vec!["reduce", s(&dir), "--out", s(&deep), "--shard", "0", "--shards", "2"],
        vec!["design", "--target", "x=50,y=5", "--out", s(&dir)],
        vec!["diagnose", "no-such.csv", "--out", s(&dir)],
        vec!["diagnose", "no-such.csv", "--out", s(&inside)],
        vec!["sweep", QUICK, "--out", s(&nested), "--quiet"],
    ]
    .into_iter()
    .chain(simulations.iter().map(|a| a.iter().map(String::as_str).collect()))
    {
        let (ok, _, stderr) = run(&args);
        assert!(!ok && stderr.contains("sweep run directory") && stderr.contains("outside the run"), "{args:?}: {stderr}");
    }
    assert_eq!(snapshot(&dir), before);
    assert!(run(&["status", s(&dir)]).0);
}

/// A cable sweep of two routings and two tensions: a few milliseconds.
const TINY_CABLE_SPEC: &str = "[rod.gravity]\nenabled = false\n[output]\nchunk_routings = 1\n[[cable]]\ny_mm = [2, 2, 2, 2, 2]\n\
    tension_n = { min = 0.5, max = 1.0, count = 2 }\n[[cable.sweep]]\naxis = \"y\"\npoints = [2]\nlevels_mm = [1.0, 3.0]\n";

#[test]
fn a_cable_run_is_guarded_like_a_planar_run() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("cables.toml");
    std::fs::write(&spec, TINY_CABLE_SPEC).unwrap();
    let dir = tmp.path().join("cabrun");
    let (ok, _, stderr) = sweep(&spec, &dir);
    assert!(ok, "{stderr}");
    let before = snapshot(&dir);
    for args in [
        vec!["reduce", s(&dir), "--out", s(&dir.join("mymap"))],
        vec!["design", "--target", "x=50,y=5", "--out", s(&dir.join("d"))],
        vec!["simulate", "--routing", "0,1,0,1,0", "--tension", "1", "--csv", s(&dir.join("shards/c.csv"))],
    ] {
        let (ok, _, stderr) = run(&args);
        assert!(!ok && stderr.contains("sweep run directory") && stderr.contains("outside the run"), "{args:?}: {stderr}");
    }
    assert_eq!(snapshot(&dir), before);
    let (ok, _, stderr) = run(&["status", s(&dir)]);
    assert!(ok, "{stderr}");
}

#[test]
fn a_one_routing_run_is_refused_at_reduce_time_with_the_fix_and_the_fix_works() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("one.toml");
    std::fs::write(&spec, "[grid]\nlevels = 1\n[tension]\ncount = 5\n").unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(&spec, &dir).0);
    let map = tmp.path().join("map");
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map)]);
    assert!(!ok && stderr.contains("--a0-bounds") && stderr.contains("--a1-bounds"), "{stderr}");
    assert!(!map.exists());
    let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&map), "--a0-bounds", "0.001,0.002,0.003", "--a1-bounds", "-0.001,0.001"]);
    assert!(ok, "{stderr}");
    let (ok, stdout, stderr) = run(&["feasible", "--map", s(&map), "--target", "x=60,y=0"]);
    assert!(ok && stdout.contains("verdict"), "{stdout}{stderr}");
}

#[test]
fn cell_indices_never_wrap() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(sweep(Path::new(QUICK), &dir).0);
    let map = tmp.path().join("map");
    assert!(run(&["reduce", s(&dir), "--out", s(&map)]).0);
    // 2³² + 50 mm would land on x = 50 mm if the index wrapped through i32.
    for target in ["x=4294967346,y=5", "x=-4294967246,y=5", "x=50,y=4294967301", "x=1e300,y=-1e300"] {
        let (ok, stdout, stderr) = run(&["feasible", "--map", s(&map), "--target", target]);
        assert!(ok && stdout.starts_with("verdict   not reached by any of the map's designs"), "{target}: {stdout}{stderr}");
    }
    let (ok, stdout, _) = run(&["feasible", "--map", s(&map), "--target", "x=50,y=5"]);
    assert!(ok && !stdout.contains("not reached"), "{stdout}");
    for cell in ["1e-9", "5e-324"] {
        let (ok, _, stderr) = run(&["reduce", s(&dir), "--out", s(&tmp.path().join("tiny")), "--cell-mm", cell]);
        assert!(!ok && stderr.contains("too small") && stderr.contains("use --cell-mm ≥"), "{cell}: {stderr}");
        assert!(!stderr.contains("000000000000"), "{stderr}");
    }
}

/// A small tmpfs mounted for one test, unmounted when dropped.
struct TinyDisk {
    path: PathBuf,
    _dir: tempfile::TempDir,
}

impl TinyDisk {
    /// A `size_kib` tmpfs, or None (with a loud warning) where mounting is not allowed.
    fn mount(size_kib: u32) -> Option<Self> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("disk");
        std::fs::create_dir(&path).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size_kib}k"), "tmpfs", s(&path)])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|st| st.success());
        if !ok {
            eprintln!("WARNING: cannot mount a tmpfs here (needs root): the full-disk test was NOT run");
            return None;
        }
        Some(Self { path, _dir: dir })
    }
}

impl Drop for TinyDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.path).status();
    }
}

#[test]
fn a_full_disk_is_reported_leaves_no_temporaries_and_the_run_resumes() {
    // The quick run needs about 100 KiB (4 KiB blocks).
    let Some(disk) = TinyDisk::mount(256) else { return };
    let fill = disk.path.join("fill");
    // Full: not even the manifest fits.
    let _ = std::fs::write(&fill, vec![0u8; 256 * 1024]);
    let dir = disk.path.join("run");
    let (ok, _, stderr) = sweep(Path::new(QUICK), &dir);
    assert!(!ok && stderr.contains("No space left on device"), "{stderr}");
    assert_eq!(stderr.matches("No space left").count(), 1, "{stderr}");
    let leftovers = |d: &Path| -> Vec<PathBuf> {
        let mut out = Vec::new();
        let mut stack = vec![d.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).into_iter().flatten() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.file_name().unwrap().to_string_lossy().contains(".tmp-") {
                    out.push(p);
                }
            }
        }
        out
    };
    assert!(leftovers(&disk.path).is_empty(), "{:?}", leftovers(&disk.path));
    // Nearly full: some chunks fit, then the disk fills mid-run.
    std::fs::remove_file(&fill).unwrap();
    std::fs::write(&fill, vec![0u8; 200 * 1024]).unwrap();
    let (ok, _, stderr) = sweep(Path::new(QUICK), &dir);
    assert!(!ok && stderr.contains("No space left on device"), "{stderr}");
    assert!(leftovers(&disk.path).is_empty(), "{:?}", leftovers(&disk.path));
    // Space freed: the same command finishes the run, every chunk verified.
    std::fs::remove_file(&fill).unwrap();
    let (ok, stdout, stderr) = sweep(Path::new(QUICK), &dir);
    assert!(ok && stdout.contains("complete"), "{stdout}{stderr}");
    assert_eq!(open_run(&dir, Completeness::Complete).unwrap().rows_done(), 610);
}
