//! A reduction split across processes (cluster array tasks): part I of N
//! does pass 1 over its share of the run's chunk files and keeps the
//! samples and tallies it found; the merge combines the parts and does the
//! rest of the reduction. The merged map equals a single-process reduce
//! for any N, since every later stage sees the same samples under the same
//! row numbers (parts number their rows from their first chunk's offset).
//!
//! Parts live beside the map directory, in `MAP_DIR.parts/`: for part I of
//! N, `part-I-of-N.samples` (scratch records, see `spill`) and
//! `part-I-of-N.json` (what the part covers and found). Each file is
//! written to a temporary name, synced and renamed into place, the record
//! last; a part is done when its record is there. The record holds the
//! SHA-256 of the samples file and of its own content, and the merge
//! checks both: a flipped byte or an edited count is refused, naming the
//! part to run again, instead of merging into a wrong map. A part's content depends
//! only on the run and (I, N), so a part re-run after a kill, or two copies
//! of one part at once, leave the same files. The merge refuses missing,
//! mismatched or mixed-N parts; `MAP_DIR.parts/` may be removed once the
//! map is merged.

use super::pipeline::{check_options, planar_grid, reduce_spilled, run_open_error};
use super::samples::Pass1;
use super::source::run_info;
use super::spill::{self, SpillWriter, RECORD_BYTES};
use super::error::{PartDamage, PartMismatch};
use super::{columns, MapData, PartsError, ReduceError, ReduceOptions};
use crate::solver::SolverOptions;
use crate::sweep::spec::PlanarGrid;
use crate::sweep::{open_run, Completeness, SweepRun};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Format tag of a part record. Version 2: the record holds checksums of
/// its samples file and of itself.
pub const PART_FORMAT: &str = "cablemap-reduce-part/2";

/// What one part covers and found (`part-I-of-N.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct PartRecord {
    format: String,
    shard: u64,
    shards: u64,
    /// The run's spec hash.
    spec_sha256: String,
    /// The run's chunk files.
    run_chunks: usize,
    /// The chunk files this part read, [first, end).
    chunk_range: [usize; 2],
    /// Row number of its first row.
    first_row: u64,
    /// Records in the samples file.
    records: u64,
    /// Pass 1's tallies.
    pass1: Pass1,
    /// SHA-256 of the samples file, hex.
    samples_sha256: String,
    /// SHA-256 of this record's JSON with this field empty, hex.
    record_sha256: String,
}

impl PartRecord {
    /// SHA-256 of the record's content: its compact JSON with
    /// `record_sha256` empty (serde writes the fields in declaration order
    /// and f64 values so that they read back exactly, so the JSON of the
    /// parsed record is the JSON that was hashed).
    fn content_sha256(&self) -> String {
        use sha2::{Digest, Sha256};
        let content = PartRecord {
            record_sha256: String::new(),
            ..self.clone()
        };
        crate::io::hex(&Sha256::digest(serde_json::to_vec(&content).expect("a part record serializes")))
    }
}

/// The parts directory of map directory `map_dir`: `MAP_DIR.parts`.
pub fn parts_dir(map_dir: &Path) -> PathBuf {
    let mut name = map_dir.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "map".into());
    name.push(".parts");
    map_dir.with_file_name(name)
}

fn part_name(shard: u64, shards: u64, ext: &str) -> String {
    format!("part-{shard}-of-{shards}.{ext}")
}

/// The chunk files [first, end) of part `shard` of `shards` among `chunks`.
fn chunk_range(chunks: usize, shard: u64, shards: u64) -> [usize; 2] {
    let at = |i: u64| (i as u128 * chunks as u128 / shards as u128) as usize;
    [at(shard), at(shard + 1)]
}

/// What a part did.
#[derive(Debug, Clone)]
pub struct PartReport {
    /// The part's record file.
    pub record: PathBuf,
    /// Chunk files read.
    pub chunks: usize,
    /// Rows read.
    pub rows: u64,
    /// Converged simulations found (mirror images included).
    pub samples: u64,
}

/// Writes part `shard` of `shards` of the reduction of the (complete) run
/// in `run_dir` into `map_dir`'s parts directory.
pub fn write_part(run_dir: &Path, map_dir: &Path, shard: u64, shards: u64) -> Result<PartReport, ReduceError> {
    if shards == 0 || shard >= shards || shards > crate::sweep::MAX_SHARDS {
        return Err(PartsError::BadShard { shard, shards }.into());
    }
    super::output::check_map_out(map_dir)?;
    let run = open_run(run_dir, Completeness::Complete).map_err(run_open_error)?;
    planar_grid(&run)?;
    let info = run_info(&run);
    let [first, end] = chunk_range(run.chunk_count(), shard, shards);
    let first_row: u64 = (0..first).map(|i| run.chunk_rows(i)).sum();
    let dir = parts_dir(map_dir);
    std::fs::create_dir_all(&dir).map_err(|source| PartsError::Io { path: dir.clone(), source })?;
    let samples_path = dir.join(part_name(shard, shards, "samples"));
    let record_path = dir.join(part_name(shard, shards, "json"));
    remove_abandoned_temps(&dir, &samples_path);
    let tmp = crate::io::temp_path(&samples_path);
    let file = crate::io::create_locked(&tmp).map_err(|e| spill::scratch_error(&tmp, e))?;
    let written = (|| {
        let mut out = SpillWriter::from_file(&tmp, file, spill::BUFFER_BYTES);
        let names = columns::RowColumns::names(info.order);
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let batches = (first..end).flat_map(|i| match run.chunk_batches(i, Some(&names)) {
            Ok(b) => Box::new(b.map(|b| b.map_err(ReduceError::from))) as Box<dyn Iterator<Item = _>>,
            Err(e) => Box::new(std::iter::once(Err(e.into()))),
        });
        let pass1 = super::samples::spill_samples(&info, batches, first_row as u32, &mut out)?;
        let records = out.finish(true)?;
        let sha256 = crate::io::sha256_file(&tmp).map_err(|e| spill::scratch_error(&tmp, e))?;
        std::fs::rename(&tmp, &samples_path).map_err(|e| spill::scratch_error(&samples_path, e))?;
        Ok::<_, ReduceError>((pass1, records, sha256))
    })();
    let (pass1, records, samples_sha256) = written.inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })?;
    let record = PartRecord {
        format: PART_FORMAT.into(),
        shard,
        shards,
        spec_sha256: run.manifest().spec_sha256.clone(),
        run_chunks: run.chunk_count(),
        chunk_range: [first, end],
        first_row,
        records,
        pass1: pass1.clone(),
        samples_sha256,
        record_sha256: String::new(),
    };
    let record = PartRecord {
        record_sha256: record.content_sha256(),
        ..record
    };
    let json = serde_json::to_vec_pretty(&record).expect("a part record serializes");
    remove_abandoned_temps(&dir, &record_path);
    write_locked_atomic(&record_path, &json).map_err(|source| PartsError::Io {
        path: record_path.clone(),
        source,
    })?;
    Ok(PartReport {
        record: record_path,
        chunks: end - first,
        rows: pass1.rows_read,
        samples: pass1.samples,
    })
}

/// Writes `bytes` to `path` by a locked temporary (so that another copy of
/// the part can tell it from a killed writer's), synced and renamed.
fn write_locked_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let tmp = crate::io::temp_path(path);
    let written = (|| {
        let mut f = crate::io::create_locked(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    crate::io::sync_dir(path.parent().unwrap_or(Path::new(".")));
    Ok(())
}

/// Removes temporaries of `final_path` left by killed writers.
fn remove_abandoned_temps(dir: &Path, final_path: &Path) {
    let final_name = final_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            if crate::io::is_temp_of(&e.file_name().to_string_lossy(), &final_name) && crate::io::is_abandoned(&e.path()) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// The parts of `dir`, checked against `run`: their sample files in part
/// order and pass 1's combined results.
fn read_parts(dir: &Path, run: &SweepRun) -> Result<(Vec<PathBuf>, Pass1), PartsError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(PartsError::NoParts { dir: dir.to_path_buf() }),
        Err(source) => {
            return Err(PartsError::Io {
                path: dir.to_path_buf(),
                source,
            })
        }
    };
    let mut found: std::collections::BTreeSet<(u64, u64)> = std::collections::BTreeSet::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let parsed = name
            .strip_prefix("part-")
            .and_then(|r| r.strip_suffix(".json"))
            .and_then(|r| r.split_once("-of-"));
        if let Some((i, n)) = parsed.and_then(|(i, n)| Some((i.parse::<u64>().ok()?, n.parse::<u64>().ok()?))) {
            found.insert((i, n));
        }
    }
    if found.is_empty() {
        return Err(PartsError::NoParts { dir: dir.to_path_buf() });
    }
    let mut counts: Vec<u64> = found.iter().map(|p| p.1).collect();
    counts.sort_unstable();
    counts.dedup();
    if counts.len() > 1 {
        return Err(PartsError::Mixed {
            dir: dir.to_path_buf(),
            counts,
        });
    }
    let shards = counts[0];
    if shards > crate::sweep::MAX_SHARDS {
        return Err(PartsError::TooMany {
            dir: dir.to_path_buf(),
            shards,
        });
    }
    let missing: Vec<u64> = (0..shards).filter(|i| !found.contains(&(*i, shards))).collect();
    if !missing.is_empty() {
        return Err(PartsError::Missing {
            dir: dir.to_path_buf(),
            shards,
            missing,
        });
    }
    if let Some(&(i, _)) = found.iter().find(|p| p.0 >= shards) {
        let path = dir.join(part_name(i, shards, "json"));
        return Err(PartsError::Mismatch {
            path,
            problem: PartMismatch::BeyondParts { part: i, shards },
        });
    }
    let mut files = Vec::new();
    let mut pass1 = Pass1::default();
    for shard in 0..shards {
        let path = dir.join(part_name(shard, shards, "json"));
        let mismatch = |problem| PartsError::Mismatch {
            path: path.clone(),
            problem,
        };
        let text = std::fs::read(&path).map_err(|source| PartsError::Io {
            path: path.clone(),
            source,
        })?;
        let record: PartRecord = serde_json::from_slice(&text).map_err(|e| mismatch(PartMismatch::NotARecord(e)))?;
        if record.format != PART_FORMAT {
            return Err(mismatch(PartMismatch::Format { found: record.format, wanted: PART_FORMAT }));
        }
        if (record.shard, record.shards) != (shard, shards) {
            return Err(mismatch(PartMismatch::OtherPart { shard: record.shard, shards: record.shards }));
        }
        if record.spec_sha256 != run.manifest().spec_sha256 {
            return Err(mismatch(PartMismatch::OtherRun));
        }
        let damaged = |path: &Path, problem| PartsError::Damaged {
            path: path.to_path_buf(),
            shard,
            shards,
            problem,
        };
        let content = record.content_sha256();
        if content != record.record_sha256 {
            return Err(damaged(&path, PartDamage::Record { content, recorded: record.record_sha256.clone() }));
        }
        let range = chunk_range(run.chunk_count(), shard, shards);
        let first_row: u64 = (0..range[0]).map(|i| run.chunk_rows(i)).sum();
        let rows: u64 = (range[0]..range[1]).map(|i| run.chunk_rows(i)).sum();
        if record.run_chunks != run.chunk_count()
            || record.chunk_range != range
            || record.first_row != first_row
            || record.pass1.rows_read != rows
        {
            return Err(mismatch(PartMismatch::OtherCoverage));
        }
        let samples = dir.join(part_name(shard, shards, "samples"));
        let len = std::fs::metadata(&samples).map(|m| m.len()).map_err(|source| PartsError::Io {
            path: samples.clone(),
            source,
        })?;
        if len != record.records * RECORD_BYTES as u64 {
            return Err(PartsError::Mismatch {
                path: samples,
                problem: PartMismatch::SamplesLength { bytes: len, samples: record.records },
            });
        }
        let actual = crate::io::sha256_file(&samples).map_err(|source| PartsError::Io {
            path: samples.clone(),
            source,
        })?;
        if actual != record.samples_sha256 {
            return Err(damaged(&samples, PartDamage::Samples { actual, recorded: record.samples_sha256.clone() }));
        }
        files.push(samples);
        pass1.merge(&record.pass1);
    }
    Ok((files, pass1))
}

/// Merges the parts in `map_dir`'s parts directory into the map of the
/// run in `run_dir` (a complete run). Returns the map and the run's spec.
pub fn merge_parts(run_dir: &Path, map_dir: &Path, options: &ReduceOptions) -> Result<(MapData, PlanarGrid, SolverOptions), ReduceError> {
    let run = open_run(run_dir, Completeness::Complete).map_err(run_open_error)?;
    let grid = planar_grid(&run)?.clone();
    let info = run_info(&run);
    check_options(&info, options)?;
    let (files, pass1) = read_parts(&parts_dir(map_dir), &run)?;
    let scratch = spill::ScratchDir::new(&options.scratch_parent())?;
    let names = columns::RowColumns::names(info.order);
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let map = reduce_spilled(&info, options, spill::Samples::Files(files), &pass1, &scratch.path, || {
        Ok(run.batches_projected(&names)?.map(|b| b.map_err(ReduceError::from)))
    })?;
    Ok((map, grid, run.spec().solver.clone()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_ranges_cover_every_chunk_once_for_any_split() {
        for chunks in [0usize, 1, 5, 17] {
            for shards in 1..25u64 {
                let ranges: Vec<[usize; 2]> = (0..shards).map(|i| chunk_range(chunks, i, shards)).collect();
                assert_eq!(ranges[0][0], 0);
                assert_eq!(ranges.last().unwrap()[1], chunks);
                assert!(ranges.windows(2).all(|w| w[0][1] == w[1][0]));
            }
        }
    }

    #[test]
    fn a_records_checksum_survives_its_json_and_catches_an_edit() {
        let mut pass1 = Pass1::default();
        pass1.tally.rows_total = 1234;
        pass1.extent.x_mm = [12.345678901234567, 1.0 / 3.0];
        let record = PartRecord {
            format: PART_FORMAT.into(),
            shard: 1,
            shards: 3,
            spec_sha256: "ab".into(),
            run_chunks: 8,
            chunk_range: [3, 5],
            first_row: 240,
            records: 7,
            pass1,
            samples_sha256: "cd".into(),
            record_sha256: String::new(),
        };
        let record = PartRecord {
            record_sha256: record.content_sha256(),
            ..record
        };
        let read: PartRecord = serde_json::from_slice(&serde_json::to_vec_pretty(&record).unwrap()).unwrap();
        assert_eq!(read.content_sha256(), record.record_sha256);
        let mut edited = read.clone();
        edited.pass1.extent.x_mm[1] += 1e-12;
        assert_ne!(edited.content_sha256(), record.record_sha256);
        let missing = PartsError::Missing { dir: PathBuf::from("p"), shards: 25, missing: (0..25).collect() }.to_string();
        assert!(missing.contains("(part 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, … (5 more))"), "{missing}");
    }

    #[test]
    fn the_parts_directory_sits_beside_the_map() {
        assert_eq!(parts_dir(Path::new("out/map")), Path::new("out/map.parts"));
    }
}
