//! Bad and extreme input, as the hostile probe of issue 10 gave it: every
//! case ends in a clear error (or a clearly stated choice) instead of a
//! panic, an out-of-memory abort, a hang or a silently wrong result.

use std::io::{BufRead, Read};
use std::path::Path;
use std::process::Stdio;

mod process;
use process::cablemap;

const QUICK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/jobs/quick.toml");


fn run(args: &[&str]) -> (bool, String, String) {
    let out = cablemap().args(args).output().expect("runs");
    let stderr: String = String::from_utf8_lossy(&out.stderr).into();
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    assert_ne!(out.status.code(), Some(101), "{args:?}: exit 101 (panic)");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), stderr)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn refused(args: &[&str], needles: &[&str]) -> String {
    let (ok, stdout, stderr) = run(args);
    assert!(!ok, "{args:?} was accepted: {stdout}");
    for n in needles {
        assert!(stderr.contains(n), "{args:?}: '{n}' not in: {stderr}");
    }
    stderr
}

const R: [&str; 4] = ["--routing", "0,2,-3,4,-2", "--tension", "1.5"];

#[test]
fn orders_the_steps_do_not_resolve_are_refused_with_the_steps_that_would() {
    fn sim<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        [&["simulate"][..], &R, extra].concat()
    }
    // The default solver (collocation, 10 intervals per span) resolves a_0…a_11.
    refused(&sim(&["--order", "12"]), &["order 12 is not resolved at nodes_per_span = 10", "--nodes-per-span 12"]);
    refused(&sim(&["--order", "100"]), &["highest supported order 16"]);
    refused(&sim(&["--order", "100000000000"]), &["highest supported order 16"]);
    // The previous method (RK4) has its own table, in steps per span.
    refused(&sim(&["--method", "rk4", "--order", "12"]), &["order 12 is not resolved at steps_per_span = 24", "--steps-per-span 144"]);
    // With the discretisation the message asks for, the coefficients are the converged ones.
    let a = |extra: &[&str]| -> Vec<f64> {
        let (ok, out, err) = run(&sim(&[extra, &["--json"][..]].concat()));
        assert!(ok, "{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        v["a"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let fine = a(&["--order", "12", "--nodes-per-span", "48"]);
    for coarse in [a(&["--order", "12", "--nodes-per-span", "12"]), a(&["--order", "12", "--method", "rk4", "--steps-per-span", "144"])] {
        for k in 0..=12 {
            assert!((coarse[k] - fine[k]).abs() <= 5e-5, "a_{k}: {} vs {}", coarse[k], fine[k]);
        }
    }
    // The default order is resolved at the default settings.
    assert_eq!(a(&[]).len(), 4);
    // So is a design target, before the search.
    refused(&["design", "--target", "x=50,y=5,a12=0.001"], &["order 12", "--nodes-per-span 12"]);
    // A sweep spec is checked the same way, before any file is written.
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("o.toml");
    std::fs::write(&spec, "[output]\norder = 12\n").unwrap();
    refused(&["sweep", s(&spec), "--out", s(&tmp.path().join("run"))], &["order 12", "nodes_per_span = 12"]);
    assert!(!tmp.path().join("run").exists());
}

#[test]
fn absurd_sizes_are_refused_up_front_and_leave_nothing_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    for (text, needle) in [
        ("[tension]\ncount = 4000000000\n", "count = 4000000000"),
        ("[solver]\nsteps_per_span = 4000000000\n", "steps_per_span = 4000000000"),
        ("[grid]\nlevels = 99\n", "--allow-large"),
        ("[grid]\nlevels = 100\n", "levels = 100"),
        ("[tension]\ncount = 100000\n", "lower chunk_routings"),
    ] {
        let spec = tmp.path().join("big.toml");
        std::fs::write(&spec, text).unwrap();
        refused(&["sweep", s(&spec), "--out", s(&out)], &[needle]);
        assert!(!out.exists(), "{text}: a run directory was created");
    }
    refused(&["simulate", R[0], R[1], R[2], R[3], "--steps-per-span", "2000000000"], &["steps_per_span", "100000"]);
    refused(&["simulate", R[0], R[1], R[2], R[3], "--coefficients", "thesis", "--n-d", "1000000000"], &["--n-d", "100000"]);
    refused(&["synth", "--out", s(&tmp.path().join("m.csv")), "--load-steps", "1000000"], &["--load-steps ≤ 1000"]);
    assert!(!tmp.path().join("m.csv").exists());
    let (ok, _, _) = run(&["sweep", QUICK, "--out", s(&tmp.path().join("q")), "--quiet"]);
    assert!(ok);
    refused(&["reduce", s(&tmp.path().join("q")), "--out", s(&tmp.path().join("m")), "--cell-mm", "5e-324"], &["too small"]);
}

#[test]
fn huge_thread_counts_are_capped_and_huge_log_intervals_do_not_panic() {
    let tmp = tempfile::tempdir().unwrap();
    let (ok, stdout, stderr) = run(&["sweep", QUICK, "--out", s(&tmp.path().join("a")), "--threads", "10000"]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("more than 4 per core"), "{stderr}");
    let cores = std::thread::available_parallelism().unwrap().get();
    assert!(stdout.contains(&format!("{} threads", 4 * cores)), "{stdout}");
    let (ok, _, stderr) = run(&["sweep", QUICK, "--out", s(&tmp.path().join("b")), "--log-interval-s", "1e20"]);
    assert!(ok, "{stderr}");
}

/// Starts `args`, closes its stdout at once, and returns how it ended.
fn with_closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    let mut child = cablemap().args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take());
    let mut stderr = String::new();
    child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    (child.wait().unwrap(), stderr)
}

#[test]
fn a_closed_pipe_ends_the_command_quietly_instead_of_panicking() {
    use std::os::unix::process::ExitStatusExt;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    assert!(run(&["sweep", QUICK, "--out", s(&dir), "--quiet"]).0);
    for args in [vec!["status", s(&dir)], vec!["sweep", QUICK, "--out", s(&dir), "--quiet"]] {
        let (status, stderr) = with_closed_stdout(&args);
        assert!(!stderr.contains("panicked") && status.code() != Some(101), "{args:?}: {status:?} {stderr}");
        assert!(status.success() || status.signal() == Some(13), "{args:?}: {status:?} {stderr}");
    }
    // The run is intact.
    assert!(run(&["status", s(&dir)]).0);
}

#[test]
fn a_blank_spec_says_it_runs_the_thesis_defaults() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("empty.toml");
    std::fs::write(&spec, "# nothing yet\n").unwrap();
    let mut child = cablemap()
        .args(["sweep", s(&spec), "--out", s(&tmp.path().join("run")), "--threads", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // stderr is unbuffered: one line may arrive in several writes.
    let mut text = String::new();
    std::io::BufReader::new(child.stderr.as_mut().unwrap()).read_line(&mut text).unwrap();
    let _ = child.kill(); // the thesis sweep itself is not needed
    child.wait().unwrap();
    assert!(text.contains("sets nothing") && text.contains("thesis"), "{text}");
}

#[test]
fn synth_keeps_an_existing_file_unless_forced() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("m.csv");
    std::fs::write(&out, "precious").unwrap();
    refused(&["synth", "--out", s(&out)], &["exists", "--force"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    let (ok, _, stderr) = run(&["synth", "--out", s(&out), "--force"]);
    assert!(ok, "{stderr}");
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("measurement,"));
}

#[test]
fn negative_numbers_reach_validation_and_get_its_message() {
    let tmp = tempfile::tempdir().unwrap();
    refused(&["design", "--target", "x=50,y=5", "--tension-min-n", "-1"], &["τ_l = -1"]);
    refused(&["synth", "--out", s(&tmp.path().join("m.csv")), "--noise-mm", "-1"], &["noise_mm = -1"]);
    refused(&[&["simulate"][..], &R, &["--ea-n", "-3"]].concat(), &["ea_n"]);
}

#[test]
fn calibrating_absurd_data_is_an_error_not_a_converged_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("m.csv");
    assert!(run(&["synth", "--out", s(&good)]).0);
    let text = std::fs::read_to_string(&good).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let cols: Vec<&str> = header.split(',').collect();
    let (ix, iy) = (cols.iter().position(|c| *c == "tip_x_mm").unwrap(), cols.iter().position(|c| *c == "tip_y_mm").unwrap());
    let mut absurd = format!("{header}\n");
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(String::from).collect();
        cells[ix] = "1e300".into();
        cells[iy] = "-1e300".into();
        absurd.push_str(&(cells.join(",") + "\n"));
    }
    let bad = tmp.path().join("absurd.csv");
    std::fs::write(&bad, absurd).unwrap();
    let stderr = refused(&["calibrate", s(&bad), "--json"], &["absurdly far", "units"]);
    assert!(stderr.contains("1e300") && !stderr.contains("00000000000"), "{stderr}");
}

#[test]
fn other_delimiters_and_encodings_are_named() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("m.csv");
    assert!(run(&["synth", "--out", s(&good)]).0);
    let text = std::fs::read_to_string(&good).unwrap();
    for (sep, name) in [(";", "semicolon"), ("\t", "tab")] {
        let path = tmp.path().join(format!("{name}.csv"));
        std::fs::write(&path, text.replace(',', sep)).unwrap();
        refused(&["calibrate", s(&path)], &[&format!("{name}-separated"), "comma"]);
    }
    let latin1 = tmp.path().join("latin1.toml");
    std::fs::write(&latin1, b"# r\xe9glage\n[tension]\ncount = 5\n").unwrap();
    let stderr = refused(&["sweep", s(&latin1), "--out", s(&tmp.path().join("run"))], &["not UTF-8", "iconv"]);
    assert_eq!(stderr.matches("not UTF-8").count(), 1, "{stderr}");
    // OS error texts appear once.
    let stderr = refused(&["sweep", s(&tmp.path().join("missing.toml")), "--out", s(&tmp.path().join("run"))], &["missing.toml"]);
    assert_eq!(stderr.matches("No such file or directory").count(), 1, "{stderr}");
}

#[test]
fn parquet_measurement_files_in_every_standard_codec_are_read() {
    use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::record_batch::RecordBatch;
    use parquet::basic::{BrotliLevel, Compression, GzipLevel, ZstdLevel};
    use std::sync::Arc;
    let tmp = tempfile::tempdir().unwrap();
    let csv = tmp.path().join("m.csv");
    assert!(run(&["synth", "--out", s(&csv)]).0);
    let reference = cablemap::calibrate::data::read_measurements(&csv).unwrap();
    // The CSV as a typed table, as pandas would write it.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    let columns: Vec<(String, ArrayRef)> = header
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let cells = rows.iter().map(|r| r[j].clone());
            let array: ArrayRef = match name.as_str() {
                "measurement" | "step" => Arc::new(Int64Array::from_iter_values(cells.map(|c| c.parse().unwrap()))),
                "routing" | "direction" => Arc::new(StringArray::from_iter_values(cells)),
                _ => Arc::new(Float64Array::from_iter_values(cells.map(|c| c.parse().unwrap()))),
            };
            (name.clone(), array)
        })
        .collect();
    let batch = RecordBatch::try_from_iter(columns).unwrap();
    for (name, codec) in [
        ("snappy", Compression::SNAPPY),
        ("gzip", Compression::GZIP(GzipLevel::default())),
        ("lz4", Compression::LZ4_RAW),
        ("lz4-hadoop", Compression::LZ4),
        ("brotli", Compression::BROTLI(BrotliLevel::default())),
        ("zstd", Compression::ZSTD(ZstdLevel::default())),
        ("none", Compression::UNCOMPRESSED),
    ] {
        let path = tmp.path().join(format!("m-{name}.parquet"));
        let props = parquet::file::properties::WriterProperties::builder().set_compression(codec).build();
        let mut w = parquet::arrow::ArrowWriter::try_new(std::fs::File::create(&path).unwrap(), batch.schema(), Some(props)).unwrap();
        w.write(&batch).unwrap();
        w.close().unwrap();
        let read = cablemap::calibrate::data::read_measurements(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(read.rows.len(), reference.rows.len(), "{name}");
        assert_eq!(format!("{:?}", read.rows), format!("{:?}", reference.rows), "{name}");
    }
}

#[test]
fn calibrate_on_a_large_file_states_its_cost_and_shows_progress() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("big.csv");
    assert!(run(&["synth", "--out", s(&data), "--load-steps", "200"]).0);
    let (ok, stdout, stderr) = run(&["calibrate", s(&data), "--json"]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("2005 readings; one pass over them takes") && stderr.contains("passes"), "{stderr}");
    let iterations: Vec<&str> = stderr.lines().filter(|l| l.starts_with("calibrate: iteration ")).collect();
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert!(!iterations.is_empty(), "{stderr}");
    assert!(iterations.len() as u64 <= v["iterations"].as_u64().unwrap(), "{stderr}\n{v}");
}

/// Runs `args`, killing it after `limit` (a hang is a failure, not a stuck suite).
fn run_within(args: &[&str], env: &[(&str, &str)], limit: std::time::Duration) -> (bool, String, String) {
    let mut child = cablemap().args(args).envs(env.iter().copied()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            child.wait().unwrap();
            panic!("{args:?} still running after {limit:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let stderr: String = String::from_utf8_lossy(&out.stderr).into();
    assert!(!stderr.contains("panicked") && out.status.code() != Some(101), "{args:?} panicked: {stderr}");
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into(), stderr)
}

#[test]
fn output_files_never_replace_a_fifo_a_symlink_or_a_device_node() {
    use std::os::unix::fs::FileTypeExt;
    let tmp = tempfile::tempdir().unwrap();
    let target = tmp.path().join("target.txt");
    std::fs::write(&target, "precious").unwrap();
    let link = tmp.path().join("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let fifo = tmp.path().join("fifo.csv");
    let c = |p: &Path| std::ffi::CString::new(p.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c(&fifo).as_ptr(), 0o644) }, 0);
    // A copy of /dev/null's node (root only; elsewhere the FIFO and the link stand for it).
    let device = tmp.path().join("null.csv");
    // SAFETY: a valid NUL-terminated path; makedev(1, 3) is /dev/null.
    let have_device = unsafe { libc::mknod(c(&device).as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) } == 0;
    let mut cases = vec![(link.clone(), "symbolic link"), (fifo.clone(), "FIFO")];
    if have_device {
        cases.push((device.clone(), "character device"));
    }
    for (path, kind) in &cases {
        let csv = [&["simulate"][..], &R, &["--csv", s(path)]].concat();
        let (ok, _, stderr) = run_within(&csv, &[], std::time::Duration::from_secs(60));
        assert!(!ok && stderr.contains(s(path)) && stderr.contains(kind) && stderr.contains("not a regular file"), "{stderr}");
        let (ok, _, stderr) = run_within(&["synth", "--force", "--out", s(path)], &[], std::time::Duration::from_secs(60));
        assert!(!ok && stderr.contains(kind), "{stderr}");
        // Pictures too (plotters writes them itself, so they are checked first).
        let png = [&["simulate"][..], &R, &["--png", s(path)]].concat();
        let (ok, _, stderr) = run_within(&png, &[], std::time::Duration::from_secs(60));
        assert!(!ok && stderr.contains(kind) && stderr.contains("not a regular file"), "{stderr}");
    }
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(!have_device || std::fs::symlink_metadata(&device).unwrap().file_type().is_char_device());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
    // A regular file is still replaced.
    let (ok, _, stderr) = run(&[&["simulate"][..], &R, &["--csv", s(&target)]].concat());
    assert!(ok && std::fs::read_to_string(&target).unwrap().starts_with("s_mm"), "{stderr}");
}

#[test]
fn absurd_shard_counts_memory_sizes_and_cells_are_refused_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let limit = std::time::Duration::from_secs(60);
    let out = tmp.path().join("run");
    // Shard counts that overflowed an allocation (the manifest was already
    // written, so every later status panicked too).
    for shards in ["18446744073709551615", "4294967296"] {
        refused(&["sweep", QUICK, "--out", s(&out), "--shard", "0", "--shards", shards], &["at most 1000000 shards", shards]);
        assert!(!out.exists(), "--shards {shards}: a run directory was created");
    }
    refused(&["bench", "--routings", "18446744073709551615"], &["--routings", "59049"]);
    // Sizes estimated before allocating: 992 M one-row chunks (tables of
    // hundreds of GiB), and a centreline of 200 001 points per row.
    for (text, needles) in [
        (
            "[grid]\nlevels = 63\nmirror_dedup = false\n[tension]\ncount = 1\nmax_n = 1.0\n[output]\nchunk_routings = 1\n",
            &["of memory", "chunk_routings", "--allow-large"][..],
        ),
        (
            "[grid]\nlevels = 3\n[tension]\ncount = 100\n[solver]\nsteps_per_span = 100000\n[output]\ncentreline = true\nchunk_routings = 16\n",
            &["200001 centreline points", "steps_per_span", "centreline = false"][..],
        ),
    ] {
        let spec = tmp.path().join("big.toml");
        std::fs::write(&spec, text).unwrap();
        let (ok, _, stderr) = run_within(&["sweep", s(&spec), "--out", s(&out)], &[], limit);
        assert!(!ok && needles.iter().all(|n| stderr.contains(n)), "{text}: {stderr}");
        assert!(!out.exists(), "{text}: a run directory was created");
    }
    // A cable's anchor is not swept: off the rod, every row was invalid_routing and the sweep "succeeded".
    let cable = tmp.path().join("cable.toml");
    std::fs::write(&cable, "[[cable]]\ny_mm = [2, 2, 2, 2, 2]\nanchor_mm = -1\ntension_n = { min = 0.5, max = 1.0, count = 2 }\n").unwrap();
    refused(&["sweep", s(&cable), "--out", s(&out)], &["cable 1: anchor_mm = -1", "length_mm"]);
    assert!(!out.exists());
    let (ok, _, stderr) = run_within(&["sweep", QUICK, "--out", s(&out)], &[("SLURM_CPUS_PER_TASK", "0")], limit);
    assert!(!ok && stderr.contains("SLURM_CPUS_PER_TASK = 0") && !stderr.contains("--threads"), "{stderr}");
    // A finished run: a manifest edited to an absurd shard count is refused, not allocated.
    assert!(run(&["sweep", QUICK, "--out", s(&out), "--quiet"]).0);
    let edited = tmp.path().join("edited");
    std::fs::create_dir(&edited).unwrap();
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    std::fs::write(edited.join("manifest.json"), manifest.replace("\"shards\": 1,", "\"shards\": 18446744073709551615,")).unwrap();
    refused(&["status", s(&edited)], &["shards = 18446744073709551615"]);
    // A cell so large the map's corners overflowed hung the drawing; parts
    // of an absurd split hung the merge.
    let (ok, _, stderr) = run_within(&["reduce", s(&out), "--out", s(&tmp.path().join("m")), "--cell-mm", "1e308"], &[], limit);
    assert!(!ok && stderr.contains("cell size 1e308 mm is larger") && stderr.contains("--cell-mm"), "{stderr}");
    for shards in ["18446744073709551615", "4294967296"] {
        refused(&["reduce", s(&out), "--out", s(&tmp.path().join("m")), "--shard", "0", "--shards", shards], &["1 … 1000000"]);
    }
    let parts = tmp.path().join("m.parts");
    std::fs::create_dir(&parts).unwrap();
    std::fs::write(parts.join("part-0-of-18446744073709551615.json"), "{}").unwrap();
    let (ok, _, stderr) = run_within(&["reduce", s(&out), "--out", s(&tmp.path().join("m")), "--merge"], &[], limit);
    assert!(!ok && stderr.contains("more than 1000000"), "{stderr}");
    assert!(!tmp.path().join("m").exists());
}

#[test]
fn status_of_many_shards_is_a_summary_and_a_directory_under_a_temporary_name_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    // 40 shards of 8 chunks: shard 0 done, 1…7 not started, 8…39 own nothing.
    assert!(run(&["sweep", QUICK, "--out", s(&dir), "--shard", "0", "--shards", "40", "--quiet"]).0);
    let (ok, stdout, stderr) = run(&["status", s(&dir)]);
    assert!(ok, "{stderr}");
    let shard_lines = stdout.lines().filter(|l| l.trim_start().split(' ').next().is_some_and(|w| w.parse::<u64>().is_ok())).count();
    assert_eq!(shard_lines, 7, "only the unfinished shards are listed: {stdout}");
    assert!(stdout.contains("40 shards: 33 finished") && stdout.contains("status --json"), "{stdout}");
    let (ok, stdout, _) = run(&["status", s(&dir), "--json"]);
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert!(ok && v["shards"].as_array().unwrap().len() == 40);
    // A directory named like a chunk being written is not one: it is named,
    // not removed as an abandoned temporary ("Is a directory").
    let odd = dir.join("shards/.chunk-000001.parquet.tmp-abc");
    std::fs::create_dir(&odd).unwrap();
    let stderr = refused(&["sweep", QUICK, "--out", s(&dir), "--shard", "1", "--shards", "40", "--quiet"], &[s(&odd), "move it out"]);
    assert!(!stderr.contains("Is a directory"), "{stderr}");
    assert!(odd.is_dir());
}

// --- advice: wrong advice and formatting (issue "What a new user and a hostile probe found") ---

/// A target written with spaces or semicolons between its components is
/// told to use commas, not that "50 y=5" is not a number.
#[test]
fn a_target_without_commas_is_told_to_use_them() {
    for target in ["x=50 y=5", "x=50;y=5"] {
        refused(&["design", "--target", target], &["separate components with commas", "x=50,y=5"]);
        refused(&["feasible", "--map", "nowhere", "--target", target], &["separate components with commas"]);
    }
}

// ---------------------------------------------------------------------------
// What a new user and a hostile probe found (issue "honest"): the solver
// resolves what it reports, non-finite results, measurement files, mould
// limits and unclear errors.

/// `simulate --json` with `extra`, parsed; the exit status too.
fn simulate_json(extra: &[&str]) -> (bool, serde_json::Value, String) {
    let (ok, stdout, stderr) = run(&[&["simulate", "--json"][..], extra].concat());
    let v = serde_json::from_str(stdout.trim()).unwrap_or(serde_json::Value::Null);
    (ok, v, stderr)
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn absurd_parameters_are_refused_by_name_instead_of_non_finite_results_reported_ok() {
    let planar = ["--routing", "1,1,1,1,1", "--tension-n", "1.5"];
    for (extra, name) in [
        (&["--ga-n", "5e-324"][..], "ga_n = 5e-324"),
        (&["--ga-n", "1e-310"], "ga_n = 1e-310"),
        (&["--length-mm", "5e-324"], "length_mm = 5e-324"),
        (&["--density-g-cm3", "1e300"], "density_g_cm3 = 1e300"),
        (&["--gravity-scale", "1e300"], "gravity.scale = 1e300"),
        (&["--length-mm", "1e300", "--no-gravity"], "length_mm = 1e300"),
    ] {
        let (ok, v, stderr) = simulate_json(&[&planar[..], extra].concat());
        assert!(!ok && v["status"] != "ok", "{extra:?} accepted: {v}");
        assert!(stderr.contains(name) && stderr.contains(" to "), "{extra:?}: no parameter and range in: {stderr}");
    }
    let (ok, v, stderr) = simulate_json(&["--cable", "y=1,1,1,1,1 tension=1.5", "--length-mm", "1e-300"]);
    assert!(!ok && v["status"] != "ok" && stderr.contains("length_mm = 1e-300"), "{v} {stderr}");
    // A solve that cannot be resolved is refused with its status in the JSON record.
    let (ok, v, stderr) = simulate_json(&[&planar[..], &["--length-mm", "1e5", "--no-gravity"]].concat());
    assert!(!ok && v["status"] == "unresolved" && stderr.contains("does not resolve"), "{v} {stderr}");
}

#[test]
fn coiling_rods_are_resolved_before_they_are_reported() {
    // 13 turns of an exact circular arc (a straight routing without gravity).
    let coil = [
        "--routing", "0.147,0.147,0.147,0.147,0.147", "--tension", "8", "--length-mm", "189.8", "--radius-mm", "0.5184",
        "--ei-n-mm2", "2.6536", "--ea-n", "32.048", "--ga-n", "1.2513", "--no-gravity",
    ];
    let (ok, v, stderr) = simulate_json(&coil);
    assert!(ok, "{stderr}");
    let (ok, fine, stderr) = simulate_json(&[&coil[..], &["--nodes-per-span", "64"]].concat());
    assert!(ok, "{stderr}");
    let (x, y) = (v["tip_x_mm"].as_f64().unwrap(), v["tip_y_mm"].as_f64().unwrap());
    assert!((x - 1.1025).abs() < 1e-3 && (y - 2.9783).abs() < 1e-3, "tip ({x}, {y}): the 13-turn arc ends at (1.10, 2.98)");
    assert!((x - fine["tip_x_mm"].as_f64().unwrap()).hypot(y - fine["tip_y_mm"].as_f64().unwrap()) < 1e-3);
    // Several cables on a 10 m rod: the tip within the stretched length, and
    // where a solve at 1280 steps per span puts it.
    let cables = ["--cable", "y=1,-2,3,0.5,-3 z=0.5,0.5,0,0,-1 tension=1.2", "--cable", "y=-2,-2,-2,-2,-2 tension=0.5", "--length-mm", "1e4", "--no-gravity"];
    let tip = |v: &serde_json::Value| ["tip_x_mm", "tip_y_mm", "tip_z_mm"].map(|k| v[k].as_f64().unwrap());
    let (ok, v, stderr) = simulate_json(&cables);
    assert!(ok, "{stderr}");
    let p = tip(&v);
    let reach = p.iter().map(|c| c * c).sum::<f64>().sqrt();
    assert!(reach <= v["length_mm"].as_f64().unwrap(), "|tip| = {reach} mm beyond ℓ = {}", v["length_mm"]);
    let (ok, fine, stderr) = simulate_json(&[&cables[..], &["--steps-per-span", "1280"]].concat());
    assert!(ok, "{stderr}");
    let q = tip(&fine);
    let off = (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt();
    assert!(off < 0.1, "{p:?} vs {q:?} at 1280 steps: {off} mm");
}

#[test]
fn high_orders_off_the_thesis_rod_are_within_the_promised_tolerance() {
    let rod = [
        "--routing", "0.9837509673644185,-2.326467243062671,-2.5569015396039316,3.4514597946044425,2.244894957755583",
        "--tension", "4.678486105953747", "--length-mm", "134.95512015867718", "--ei-n-mm2", "39.48677215002417", "--order", "11",
    ];
    let (ok, v, stderr) = simulate_json(&rod);
    assert!(ok, "{stderr}");
    let (ok, fine, stderr) = simulate_json(&[&rod[..], &["--nodes-per-span", "64"]].concat());
    assert!(ok, "{stderr}");
    for (k, (a, b)) in numbers(&v["a"]).iter().zip(numbers(&fine["a"])).enumerate() {
        assert!((a - b).abs() <= 5e-5, "a_{k}: {a} vs {b} at 64 intervals");
    }
}

#[test]
fn measurement_files_with_duplicate_columns_wrong_units_cr_lines_or_absurd_tilts_are_named() {
    use cablemap::calibrate::data::read_measurements;
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("m.csv");
    assert!(run(&["synth", "--out", s(&good), "--load-steps", "3"]).0);
    let text = std::fs::read_to_string(&good).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let edit = |name: &str, f: &dyn Fn(usize, &mut Vec<String>)| {
        let path = tmp.path().join(name);
        let lines: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                let mut cells: Vec<String> = l.split(',').map(String::from).collect();
                f(i, &mut cells);
                cells.join(",")
            })
            .collect();
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        path
    };
    // A column given twice: which one is meant is not clear.
    let twice = edit("twice.csv", &|i, c| c.push(if i == 0 { "tip_x_mm".into() } else { "0".into() }));
    let e = read_measurements(&twice).unwrap_err().to_string();
    assert!(e.contains("twice.csv") && e.contains("'tip_x_mm' twice"), "{e}");
    // Tips in µm: far beyond any shape of the rod, with the likely cause.
    let (ix, iy) = (col("tip_x_mm"), col("tip_y_mm"));
    let microns = edit("um.csv", &|i, c| {
        if i > 0 {
            for k in [ix, iy] {
                c[k] = (c[k].parse::<f64>().unwrap() * 1000.0).to_string();
            }
        }
    });
    refused(&["calibrate", s(&microns)], &["farther from the clamp than the rod is long", "µm"]);
    // Lines ending in CR alone are lines.
    let cr = tmp.path().join("cr.csv");
    std::fs::write(&cr, text.replace('\n', "\r")).unwrap();
    let (a, b) = (read_measurements(&good).unwrap(), read_measurements(&cr).unwrap_or_else(|e| panic!("{e}")));
    assert_eq!(format!("{:?}", a.rows), format!("{:?}", b.rows));
    // A clamp tilt no clamp has.
    let tilted = edit("tilt.csv", &|i, c| {
        if i > 0 {
            c[col("clamp_tilt_rad")] = "1e300".into();
        }
    });
    let e = read_measurements(&tilted).unwrap_err().to_string();
    assert!(e.contains("clamp_tilt_rad") && e.contains("2π"), "{e}");
}

#[test]
fn moulds_of_absurd_sizes_are_refused_quickly_and_their_output_is_atomic() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("M");
    let out_text = s(&out).to_string();
    let mould = |extra: &[&str]| -> Vec<String> {
        ["mould", "--routing", "1,-2,3,0.5,-3", "--out", &out_text].iter().chain(extra).map(|a| a.to_string()).collect()
    };
    let refused = |args: Vec<String>, needles: &[&str]| refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), needles);
    let run = |args: Vec<String>| run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    for (extra, flag) in [
        (&["--wall-mm", "1e308"][..], "--wall-mm"),
        (&["--clamp-mm", "1e308"], "--clamp-mm"),
        (&["--wall-mm", "1e6"], "--wall-mm"),
        (&["--clamp-mm", "1e7"], "--clamp-mm"),
        (&["--length-mm", "1e6"], "--length-mm"),
        (&["--length-mm", "1e9"], "length_mm"),
        (&["--wall-mm", "nan"], "--wall-mm"),
        (&["--wall-mm", "2000", "--length-mm", "9000"], "triangles"),
    ] {
        let stderr = refused(mould(extra), &[flag]);
        assert!(!stderr.contains("MouldParams {"), "{extra:?}: a debug dump: {stderr}");
        assert!(!out.exists(), "{extra:?} left {}", out.display());
    }
    // A large radius is a large mould, made quickly (its preview too).
    let started = std::time::Instant::now();
    assert!(run(mould(&["--radius-mm", "5000"])).0);
    assert!(started.elapsed().as_secs() < 20);
    // Written again over an earlier mould directory; a directory of other files is refused.
    assert!(run(mould(&[])).0);
    let names = |d: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    };
    let whole = names(&out);
    assert_eq!(whole, ["channel.csv", "mould.json", "mould1.png", "mould1.stl", "mould2.png", "mould2.stl"]);
    let other = tmp.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("notes.txt"), "mine").unwrap();
    refused(["mould", "--routing", "1,-2,3,0.5,-3", "--out", s(&other)].map(String::from).to_vec(), &["not a mould directory"]);
    // Killed while writing, a run leaves the mould directory as it was or whole, never partial.
    let fresh = tmp.path().join("K");
    let mut child = cablemap()
        .args(["mould", "--routing", "1,-2,3,0.5,-3", "--length-mm", "2000", "--out", s(&fresh)])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!fresh.exists() || names(&fresh) == whole, "a killed run left {:?}", names(&fresh));
    assert!(names(tmp.path()).iter().all(|n| !n.starts_with(".K.tmp") || tmp.path().join(n).is_dir()));
    assert!(run(["mould", "--routing", "1,-2,3,0.5,-3", "--out", s(&fresh)].map(String::from).to_vec()).0);
    assert_eq!(names(&fresh), whole);
    assert!(!names(tmp.path()).iter().any(|n| n.starts_with(".K.")), "leftovers: {:?}", names(tmp.path()));
}

#[test]
fn errors_print_short_numbers_accept_negative_values_and_refuse_absurd_angles() {
    // Negative numbers reach validation (not "unexpected argument '-1'").
    refused(&[&["simulate"][..], &R, &["--length-mm", "-1e-300"]].concat(), &["length_mm = -1e-300", "positive"]);
    // Huge numbers print short.
    let stderr = refused(&["simulate", "--routing", "1e300,1,1,1,1", "--tension", "1"], &["1e300"]);
    assert!(!stderr.contains("0000000000"), "{stderr}");
    let stderr = refused(&["simulate", "--routing", "1,1,1,1,1", "--tension", "1e300"], &["1e300 N"]);
    assert!(!stderr.contains("0000000000"), "{stderr}");
    // A clamp tilt is an angle.
    refused(&[&["simulate"][..], &R, &["--gravity-direction-rad", "1e300"]].concat(), &["gravity.direction_rad", "2π"]);
    // A tension the continuation would climb for hours (on a rod stiff enough not to give way first).
    let stiff = ["--ea-n", "1e12", "--ga-n", "1e12", "--ei-n-mm2", "1e15"];
    refused(&[&["simulate", "--routing", "1,1,1,1,1", "--tension", "1e7"][..], &stiff].concat(), &["tension_n = 10000000", "25000 N"]);
    refused(&["simulate", "--cable", "y=1,1,1,1,1 tension=1e7"], &["10000000", "25000 N"]);
    // The smallest cell printed is the actual bound: a cell just below it is
    // refused with a number above the one given, and the number printed works.
    let tmp = tempfile::tempdir().unwrap();
    let run_dir = tmp.path().join("q");
    assert!(run(&["sweep", QUICK, "--out", s(&run_dir), "--quiet"]).0);
    let bound_in = |stderr: &str| -> f64 { stderr.rsplit("use --cell-mm ≥ ").next().unwrap().trim().trim_end_matches(')').parse().unwrap() };
    let reduce = |cell: &str, name: &str| run(&["reduce", s(&run_dir), "--out", s(&tmp.path().join(name)), "--cell-mm", cell]);
    let (ok, _, stderr) = reduce("1e-9", "tiny");
    assert!(!ok, "{stderr}");
    let bound = bound_in(&stderr);
    let below = format!("{:.3e}", bound * (1.0 - 1e-9));
    let (ok, _, stderr) = reduce(&below, "below");
    if !ok {
        assert!(bound_in(&stderr) > below.parse::<f64>().unwrap(), "{below} refused with a bound no larger: {stderr}");
    }
    let (ok, _, stderr) = reduce(&bound.to_string(), "at");
    assert!(ok, "the bound {bound} printed was refused: {stderr}");
}
