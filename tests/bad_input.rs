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
