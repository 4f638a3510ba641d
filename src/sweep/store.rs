//! The run directory on disk: the manifest, the chunk files and their
//! checks.
//!
//! ```text
//! DIR/manifest.json              what the run is: spec, hash, tool version, counts
//! DIR/shards/chunk-000000.parquet  one file per chunk, complete or absent
//! DIR/shards/.chunk-000001.parquet.tmp-TOKEN  a chunk being written (dot: readers skip it)
//! DIR/checksums/chunk-000000.parquet.sha256  SHA-256 of the chunk file, written before it
//! DIR/damaged/chunk-000003.parquet.TOKEN     a chunk that failed its check, moved aside
//! ```
//!
//! Every file appears under its final name only when complete (written to a
//! temporary name in the same folder, fsynced, renamed). Temporary names are
//! unique per writer ([`crate::io::unique_token`]), so two copies of one
//! shard (a Kubernetes retry, a SLURM requeue, both as pid 1 in their
//! containers) never share a file; a writer holds a lock on its temporary,
//! and only unlocked (abandoned) temporaries are ever removed. Each chunk's checksum is
//! committed before the chunk itself and verified whenever the run is
//! scanned (status, resume, reduce): a chunk whose bytes changed is reported
//! as damaged, and the sweep moves it to DIR/damaged and recomputes it.
//! The manifest is created with a hard link, which fails if another process
//! (a concurrent array task) created it first; the loser checks it matches
//! instead. Its spec hash and counts are recomputed on every read, so an
//! edited manifest is refused.

use super::kind::RunKind;
use super::spec::SweepSpec;
use super::SweepError;
use crate::shape::LengthBasis;
use crate::io::FileError;
use arrow::record_batch::RecordBatch;
use parquet::arrow::ArrowWriter;
use parquet::basic::{Compression, ZstdLevel};
use parquet::file::metadata::{KeyValue, ParquetMetaDataReader};
use parquet::file::properties::WriterProperties;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};

/// Format tag of planar manifests and chunk files
/// ([`crate::io::run_markers::PLANAR_FORMAT`], where every run kind's tag is kept).
pub const FORMAT: &str = crate::io::run_markers::PLANAR_FORMAT;
/// Version of the tool writing the files.
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");
/// Manifest file name in DIR ([`crate::io::run_markers::MANIFEST`]).
pub const MANIFEST: &str = crate::io::run_markers::MANIFEST;
/// Folder of chunk files in DIR (only Parquet chunks live there, so any
/// Parquet reader can read the folder as one dataset).
pub const SHARDS_DIR: &str = "shards";
/// Folder of chunk checksums in DIR (`chunk-000000.parquet.sha256`).
pub const CHECKSUMS_DIR: &str = "checksums";
/// Folder in DIR where damaged chunks are moved before being recomputed.
pub const DAMAGED_DIR: &str = "damaged";

/// Key-value metadata keys of each chunk file's footer.
pub mod keys {
    /// [`super::FORMAT`].
    pub const FORMAT: &str = "cablemap.format";
    /// Tool version.
    pub const VERSION: &str = "cablemap.version";
    /// SHA-256 of the canonical spec JSON.
    pub const SPEC_SHA256: &str = "cablemap.spec_sha256";
    /// The canonical spec JSON.
    pub const SPEC: &str = "cablemap.spec";
    /// Chunk index.
    pub const CHUNK: &str = "cablemap.chunk";
    /// Rows in the file.
    pub const ROWS: &str = "cablemap.rows";
    /// JSON object: rows per status.
    pub const STATUS_COUNTS: &str = "cablemap.status_counts";
    /// The length the a_i columns are per unit of: `rest` or `deformed`.
    pub const LENGTH_BASIS: &str = "cablemap.length_basis";
}

/// The run's manifest (`DIR/manifest.json`). Written once, never changed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The format tag of the spec's kind ([`RunKind::format`]).
    pub format: String,
    /// Version of the tool that created the run.
    pub tool_version: String,
    /// SHA-256 of the canonical spec JSON.
    pub spec_sha256: String,
    /// The spec with every default filled in.
    pub spec: SweepSpec,
    /// The length the a_i columns are per unit of (the spec's
    /// `output.length_basis`, repeated here for readers of the manifest).
    pub length_basis: LengthBasis,
    /// Shards the run is split into.
    pub shards: u64,
    /// Routings in the sweep.
    pub routings: u64,
    /// Tensions per routing.
    pub tensions: u64,
    /// Routings per chunk.
    pub chunk_routings: u64,
    /// Chunk files when complete.
    pub chunks: u64,
    /// Rows when complete.
    pub total_rows: u64,
}

impl Manifest {
    /// The manifest of a run of `spec` in `shards` shards.
    pub fn new(spec: &SweepSpec, shards: u64) -> Self {
        let plan = spec.layout();
        Self {
            format: spec.kind().format().into(),
            tool_version: TOOL_VERSION.into(),
            spec_sha256: spec.hash_hex(),
            spec: spec.clone(),
            length_basis: spec.output.length_basis,
            shards,
            routings: plan.routings,
            tensions: plan.tensions,
            chunk_routings: plan.chunk_routings,
            chunks: plan.chunks,
            total_rows: plan.total_rows(),
        }
    }
}

impl Manifest {
    /// Checks that the manifest is self-consistent: the spec hash is the
    /// hash of the spec it holds and the counts follow from that spec. A
    /// hand-edited field (a changed `tension.max_n`) fails here instead of
    /// silently changing what later stages report.
    pub fn verify(&self) -> Result<(), ManifestMismatch> {
        self.spec.validate().map_err(ManifestMismatch::InvalidSpec)?;
        let hash = self.spec.hash_hex();
        if hash != self.spec_sha256 {
            return Err(ManifestMismatch::Hash { hash, recorded: self.spec_sha256.clone() });
        }
        if self.shards == 0 || self.shards > super::MAX_SHARDS {
            // Status keeps a line per shard: an absurd count must not be allocated.
            return Err(ManifestMismatch::Shards { shards: self.shards });
        }
        let expected = Manifest { tool_version: self.tool_version.clone(), ..Manifest::new(&self.spec, self.shards) };
        if *self != expected {
            let counts = |m: &Self| [m.routings, m.tensions, m.chunk_routings, m.chunks, m.total_rows];
            return Err(ManifestMismatch::Counts { found: counts(self), expected: counts(&expected) });
        }
        Ok(())
    }
}

/// How a manifest disagrees with itself ([`Manifest::verify`]).
#[derive(Debug, thiserror::Error)]
pub enum ManifestMismatch {
    /// The spec it holds is refused.
    #[error("its spec is invalid ({0})")]
    InvalidSpec(super::spec::SpecError),
    /// The spec does not hash to the recorded hash.
    #[error("its spec hashes to {hash}, not the recorded spec_sha256 {recorded} (the file was edited or damaged)")]
    Hash {
        /// The spec's hash.
        hash: String,
        /// The recorded one.
        recorded: String,
    },
    /// An absurd shard count.
    #[error("shards = {shards} is not 1 … {} (the file was edited, or written with an absurd --shards)", super::MAX_SHARDS)]
    Shards {
        /// The recorded count.
        shards: u64,
    },
    /// Counts that do not follow from the spec: routings, tensions, chunk_routings, chunks, total_rows.
    #[error(
        "its counts do not follow from its spec (routings {} tensions {} chunk_routings {} chunks {} total_rows {}; \
         expected {} {} {} {} {}): the file was edited or damaged",
        found[0], found[1], found[2], found[3], found[4], expected[0], expected[1], expected[2], expected[3], expected[4]
    )]
    Counts {
        /// As recorded.
        found: [u64; 5],
        /// As the spec gives them.
        expected: [u64; 5],
    },
}

/// A chunk file that failed its check: bytes changed since it was
/// committed, footer unreadable, or wrong row count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DamagedChunk {
    /// Chunk index.
    pub chunk: u64,
    /// Path of the file.
    pub path: PathBuf,
    /// What is wrong (written as its sentence).
    #[serde(serialize_with = "serialize_display")]
    pub reason: ChunkProblem,
}

/// Serialises a value as the sentence its `Display` makes.
fn serialize_display<T: std::fmt::Display, Z: serde::Serializer>(value: &T, serializer: Z) -> Result<Z::Ok, Z::Error> {
    serializer.collect_str(value)
}

/// The damaged chunk files of a run split into `shards` shards, each with
/// its shard and problem, for a message.
pub fn damaged_text(damaged: &[DamagedChunk], shards: u64) -> String {
    damaged.iter().map(|d| format!("{} (shard {}: {})", d.path.display(), d.chunk % shards.max(1), d.reason)).collect::<Vec<_>>().join("; ")
}

/// Why a manifest cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ManifestProblem {
    /// It is not the JSON of a manifest.
    #[error("{0}")]
    Json(#[source] serde_json::Error),
    /// Its format tag is another than this kind's.
    #[error(
        "format '{found}' is not '{wanted}' (a run made by another cablemap version; version 1 runs stored a_i per unit deformed \
         length: sweep again into a new directory)"
    )]
    Format {
        /// The manifest's tag.
        found: String,
        /// This kind's tag.
        wanted: &'static str,
    },
    /// Its length basis is not its spec's.
    #[error("length_basis '{manifest}' disagrees with the spec's output.length_basis '{spec}'")]
    LengthBasis {
        /// As recorded beside the spec.
        manifest: LengthBasis,
        /// As the spec says.
        spec: LengthBasis,
    },
    /// It disagrees with itself.
    #[error("{0}")]
    Mismatch(#[source] ManifestMismatch),
    /// It was there, then gone (another process removed it).
    #[error("vanished while being read")]
    Vanished,
}

/// Why a chunk file is damaged.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ChunkProblem {
    /// No checksum was recorded for it.
    #[error("no checksum recorded in {}", sum_path.display())]
    NoChecksum {
        /// Where the checksum should be.
        sum_path: PathBuf,
    },
    /// Its bytes changed since it was written.
    #[error("its SHA-256 is {actual}, not the {recorded} recorded when it was written")]
    Checksum {
        /// The file's digest, hex.
        actual: String,
        /// The digest recorded when it was written, hex.
        recorded: String,
    },
    /// Parquet cannot read it.
    #[error("{0}")]
    Parquet(#[source] std::sync::Arc<parquet::errors::ParquetError>),
    /// Its columns are not the run's.
    #[error("its columns differ from the run's schema")]
    Columns,
    /// It holds another number of rows than its chunk.
    #[error("it holds {found} rows where chunk {chunk} has {rows}")]
    Rows {
        /// Rows in the file.
        found: i64,
        /// The chunk.
        chunk: u64,
        /// Rows of the chunk.
        rows: u64,
    },
    /// Its status counts metadata is missing or not JSON.
    #[error("status counts unreadable")]
    StatusCounts,
}

impl ChunkProblem {
    /// The problem of a Parquet error.
    pub fn parquet(e: parquet::errors::ParquetError) -> Self {
        Self::Parquet(std::sync::Arc::new(e))
    }
}

/// Two problems are the same when they say the same (a Parquet error has
/// no equality of its own).
impl PartialEq for ChunkProblem {
    fn eq(&self, other: &Self) -> bool {
        self.to_string() == other.to_string()
    }
}

/// Why a chunk-named file belongs to another job.
#[derive(Debug, thiserror::Error)]
pub enum ForeignReason {
    /// It has no format tag of this kind.
    #[error("it has no '{key}' = '{format}' metadata")]
    NoFormat {
        /// The metadata key.
        key: &'static str,
        /// This kind's format tag.
        format: &'static str,
    },
    /// It was written for another spec.
    #[error("it was written for spec {found} but this run's spec is {wanted}")]
    OtherSpec {
        /// The spec hash in its metadata (`(none)` when missing).
        found: String,
        /// This run's spec hash.
        wanted: String,
    },
    /// It names another chunk.
    #[error("its metadata names chunk '{found}', not {chunk}")]
    OtherChunk {
        /// The chunk in its metadata (`(none)` when missing).
        found: String,
        /// The chunk its name says.
        chunk: u64,
    },
}

/// What a chunk file's footer says.
#[derive(Debug, Clone, PartialEq)]
pub struct ChunkInfo {
    /// Chunk index.
    pub chunk: u64,
    /// Path of the file.
    pub path: PathBuf,
    /// Rows in the file.
    pub rows: u64,
    /// Rows per status.
    pub status_counts: BTreeMap<String, u64>,
}

/// Rows per status, summed over chunks.
pub fn total_status_counts<'a>(chunks: impl IntoIterator<Item = &'a ChunkInfo>) -> BTreeMap<String, u64> {
    let mut counts = BTreeMap::new();
    for chunk in chunks {
        for (status, n) in &chunk.status_counts {
            *counts.entry(status.clone()).or_insert(0) += n;
        }
    }
    counts
}

/// Rows of failed solves (status other than `ok`) in a status count.
pub fn failures(counts: &BTreeMap<String, u64>) -> u64 {
    counts.iter().filter(|(s, _)| s.as_str() != crate::solver::STATUS_OK).map(|(_, n)| n).sum()
}

/// Paths of a run directory.
#[derive(Debug, Clone)]
pub struct RunDir {
    root: PathBuf,
}

impl RunDir {
    /// A run directory at `root` (nothing is touched).
    pub fn new(root: &Path) -> Self {
        Self { root: root.to_path_buf() }
    }

    /// DIR.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// DIR/manifest.json.
    pub fn manifest_path(&self) -> PathBuf {
        self.root.join(MANIFEST)
    }

    /// DIR/shards.
    pub fn shards_dir(&self) -> PathBuf {
        self.root.join(SHARDS_DIR)
    }

    /// DIR/checksums.
    pub fn checksums_dir(&self) -> PathBuf {
        self.root.join(CHECKSUMS_DIR)
    }

    /// DIR/checksums/chunk-….parquet.sha256: the recorded checksum of chunk `chunk`.
    pub fn checksum_path(&self, chunk: u64) -> PathBuf {
        self.checksums_dir().join(format!("{}.sha256", chunk_file_name(chunk)))
    }

    /// Moves a damaged chunk file to DIR/damaged (kept for inspection,
    /// under a unique name) and forgets its checksum, so the chunk is
    /// recomputed. A file already gone (another copy of the shard moved it)
    /// is not an error. Returns where it went.
    pub fn move_aside(&self, damaged: &DamagedChunk) -> Result<Option<PathBuf>, SweepError> {
        let dir = self.root.join(DAMAGED_DIR);
        std::fs::create_dir_all(&dir).map_err(FileError::on("creating", &dir))?;
        let to = dir.join(format!("{}.{}", chunk_file_name(damaged.chunk), crate::io::unique_token()));
        let moved = match std::fs::rename(&damaged.path, &to) {
            Ok(()) => Some(to),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(source) => return Err(SweepError::MoveAside { from: damaged.path.clone(), to, source }),
        };
        match std::fs::remove_file(self.checksum_path(damaged.chunk)) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(FileError::new("removing", self.checksum_path(damaged.chunk), e).into()),
        }
        crate::io::sync_dir(&self.shards_dir());
        Ok(moved)
    }

    /// Final path of chunk `chunk`.
    pub fn chunk_path(&self, chunk: u64) -> PathBuf {
        self.shards_dir().join(chunk_file_name(chunk))
    }

    /// Reads and parses the manifest; `Ok(None)` when there is none.
    pub fn read_manifest(&self) -> Result<Option<Manifest>, SweepError> {
        let path = self.manifest_path();
        let text = match crate::io::read_utf8(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(source) => return Err(FileError::new("reading", path, source).into()),
        };
        let manifest: Manifest =
            serde_json::from_str(&text).map_err(|e| SweepError::CorruptManifest { path: path.clone(), problem: ManifestProblem::Json(e) })?;
        let wanted = manifest.spec.kind().format();
        if manifest.format != wanted {
            return Err(SweepError::CorruptManifest { path, problem: ManifestProblem::Format { found: manifest.format, wanted } });
        }
        if manifest.length_basis != manifest.spec.output.length_basis {
            return Err(SweepError::CorruptManifest {
                path,
                problem: ManifestProblem::LengthBasis { manifest: manifest.length_basis, spec: manifest.spec.output.length_basis },
            });
        }
        manifest.verify().map_err(|e| SweepError::CorruptManifest { path, problem: ManifestProblem::Mismatch(e) })?;
        Ok(Some(manifest))
    }

    /// Creates DIR and its manifest for a new run, or checks that an
    /// existing run is the same job (spec, tool version, shard count).
    /// Returns the manifest in force.
    pub fn create_or_check(&self, spec: &SweepSpec, shards: u64) -> Result<Manifest, SweepError> {
        let io = |op: &'static str, source| SweepError::from(FileError::new(op, &self.root, source));
        std::fs::create_dir_all(&self.root).map_err(|e| io("creating output directory", e))?;
        let wanted = Manifest::new(spec, shards);
        let existing = match self.read_manifest()? {
            Some(m) => m,
            None => {
                self.check_fresh_dir()?;
                match self.publish_manifest(&wanted)? {
                    true => wanted.clone(),
                    // Another process created it between our look and our link.
                    false => self.read_manifest()?.ok_or_else(|| SweepError::CorruptManifest {
                        path: self.manifest_path(),
                        problem: ManifestProblem::Vanished,
                    })?,
                }
            }
        };
        if existing.format != wanted.format {
            // A run of the other kind (planar or cables): name its format.
            return Err(SweepError::OtherKind { dir: self.root.clone(), found: existing.format, wanted: wanted.format });
        }
        if existing.spec_sha256 != wanted.spec_sha256 {
            return Err(SweepError::SpecMismatch {
                dir: self.root.clone(),
                existing: existing.spec_sha256,
                wanted: wanted.spec_sha256,
            });
        }
        if existing.tool_version != TOOL_VERSION {
            return Err(SweepError::VersionMismatch { dir: self.root.clone(), existing: existing.tool_version });
        }
        if existing.shards != shards {
            return Err(SweepError::ShardCountMismatch { dir: self.root.clone(), existing: existing.shards, wanted: shards });
        }
        std::fs::create_dir_all(self.shards_dir()).map_err(|e| io("creating shard folder in", e))?;
        std::fs::create_dir_all(self.checksums_dir()).map_err(|e| io("creating checksum folder in", e))?;
        Ok(existing)
    }

    /// A directory without a manifest may hold only what a concurrent task
    /// of the same run is creating (the manifest, its temporary file, the
    /// shard folder, whose chunks [`Self::scan`] then checks): anything else
    /// was not written by cablemap, and a sweep must not mix its files with it.
    fn check_fresh_dir(&self) -> Result<(), SweepError> {
        for entry in list_dir(&self.root)? {
            let name = entry.to_string_lossy();
            if !is_run_entry(&name) {
                return Err(SweepError::NotARunDir { dir: self.root.clone(), entry: name.into_owned() });
            }
        }
        Ok(())
    }

    /// Writes the manifest under a temporary name and links it into place
    /// unless one exists. Returns false when another process won.
    fn publish_manifest(&self, manifest: &Manifest) -> Result<bool, SweepError> {
        let path = self.manifest_path();
        let tmp = crate::io::temp_path(&path);
        let text = serde_json::to_string_pretty(manifest).expect("manifest serialises") + "\n";
        let io = |op: &'static str, source| SweepError::from(FileError::new(op, &path, source));
        let written = (|| {
            use std::io::Write;
            let mut f = File::create(&tmp)?;
            f.write_all(text.as_bytes())?;
            f.sync_all()
        })();
        if let Err(e) = written {
            // A full disk must not leave a 0-byte temporary behind.
            let _ = std::fs::remove_file(&tmp);
            return Err(io("writing", e));
        }
        let linked = std::fs::hard_link(&tmp, &path);
        let _ = std::fs::remove_file(&tmp);
        crate::io::sync_dir(&self.root);
        match linked {
            Ok(()) => Ok(true),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(false),
            Err(e) => Err(io("creating", e)),
        }
    }

    /// Lists DIR/shards: verified chunk files (footer checked against the
    /// manifest) and temporary files. Anything else is an error, as is a
    /// chunk file that is unreadable or belongs to another job.
    pub fn scan(&self, manifest: &Manifest) -> Result<Scan, SweepError> {
        for entry in list_dir(&self.root)? {
            let name = entry.to_string_lossy();
            if !is_run_entry(&name) {
                return Err(SweepError::ForeignFile { path: self.root.join(&entry) });
            }
        }
        let plan = manifest.spec.layout();
        let mut scan = Scan::default();
        let shards_dir = self.shards_dir();
        let mut names = match list_dir(&shards_dir) {
            Ok(n) => n,
            Err(SweepError::File(e)) if e.is_not_found() => Vec::new(),
            Err(e) => return Err(e),
        };
        names.sort();
        for entry in names {
            let path = shards_dir.join(&entry);
            let name = entry.to_string_lossy();
            if let Some(chunk) = temp_chunk(&name) {
                // Writers create temporaries as files: anything else under
                // such a name (a directory) is not theirs, and removing it
                // as an abandoned chunk would fail. One that vanished was
                // renamed into place by its writer.
                match std::fs::symlink_metadata(&path) {
                    Ok(m) if !m.is_file() => return Err(SweepError::ForeignFile { path }),
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                    _ => {}
                }
                scan.temporaries.push((chunk, path));
                continue;
            }
            match parse_chunk_name(&name) {
                Some(chunk) if chunk < manifest.chunks && path.is_file() => {
                    // A file of another job is refused (left for the user to
                    // move) even when its checksum fails; any other failure
                    // marks the chunk damaged.
                    let footer = check_chunk(&path, chunk, manifest, plan.chunk_rows(chunk));
                    let checked = match (self.verify_checksum(chunk, &path), footer) {
                        (_, Err(e @ SweepError::ForeignChunk { .. })) => Err(e),
                        (Err(e), _) => Err(e),
                        (Ok(()), footer) => footer,
                    };
                    match checked {
                        Ok(info) => {
                            scan.chunks.insert(chunk, info);
                        }
                        Err(SweepError::CorruptChunk { path, problem }) => {
                            scan.damaged.push(DamagedChunk { chunk, path, reason: problem })
                        }
                        Err(e) => return Err(e),
                    }
                }
                _ => return Err(SweepError::ForeignFile { path }),
            }
        }
        Ok(scan)
    }

    /// Compares a chunk file's SHA-256 with the one recorded when it was
    /// committed; a mismatch or a missing record is [`SweepError::CorruptChunk`].
    fn verify_checksum(&self, chunk: u64, path: &Path) -> Result<(), SweepError> {
        let corrupt = |problem| SweepError::CorruptChunk { path: path.to_path_buf(), problem };
        let sum_path = self.checksum_path(chunk);
        let recorded = match std::fs::read_to_string(&sum_path) {
            Ok(text) => text.trim().to_string(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(corrupt(ChunkProblem::NoChecksum { sum_path }))
            }
            Err(e) => return Err(FileError::new("reading", sum_path, e).into()),
        };
        let actual = crate::io::sha256_file(path)
            .map_err(FileError::on("reading", path))?;
        if actual != recorded {
            return Err(corrupt(ChunkProblem::Checksum { actual, recorded }));
        }
        Ok(())
    }

    /// Writes one chunk atomically: temporary file (unique to this writer),
    /// footer, fsync, checksum record, rename, directory fsync.
    pub fn write_chunk(&self, manifest: &Manifest, chunk: u64, batch: &RecordBatch) -> Result<ChunkInfo, SweepError> {
        let path = self.chunk_path(chunk);
        let tmp = crate::io::temp_path(&path);
        let io = |source| SweepError::from(FileError::new("writing", &tmp, source));
        let status_counts = count_statuses(batch);
        let kv = |k: &str, v: String| KeyValue::new(k.to_string(), v);
        let metadata = vec![
            kv(keys::FORMAT, manifest.format.clone()),
            kv(keys::VERSION, TOOL_VERSION.into()),
            kv(keys::SPEC_SHA256, manifest.spec_sha256.clone()),
            kv(keys::SPEC, manifest.spec.canonical_json()),
            kv(keys::CHUNK, chunk.to_string()),
            kv(keys::ROWS, batch.num_rows().to_string()),
            kv(keys::STATUS_COUNTS, serde_json::to_string(&status_counts).expect("counts serialise")),
            kv(keys::LENGTH_BASIS, manifest.length_basis.to_string()),
        ];
        let props = WriterProperties::builder()
            .set_compression(Compression::ZSTD(ZstdLevel::try_new(3).expect("valid zstd level")))
            .set_max_row_group_row_count(Some(batch.num_rows().max(1)))
            .set_created_by(format!("cablemap {TOOL_VERSION}"))
            .set_key_value_metadata(Some(metadata))
            .build();
        let file = crate::io::create_locked(&tmp).map_err(io)?;
        let written = (|| {
            let mut writer = ArrowWriter::try_new(file, batch.schema(), Some(props))?;
            writer.write(batch)?;
            writer.into_inner()
        })();
        let file = written.map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            SweepError::Parquet { context: super::error::FileOp::writing(&tmp), source: e }
        })?;
        let committed = (|| {
            file.sync_all()?;
            // The checksum goes first: a chunk under its final name always
            // has its record. Two copies of a shard write identical bytes
            // (results do not depend on threads), so their records agree.
            let sum = crate::io::sha256_file(&tmp)?;
            crate::io::write_atomic_in_run(&self.checksum_path(chunk), format!("{sum}\n").as_bytes())?;
            // Renamed while still locked: a cleaner never sees it unlocked
            // under its temporary name.
            std::fs::rename(&tmp, &path)?;
            drop(file);
            Ok(())
        })();
        if let Err(e) = committed {
            let _ = std::fs::remove_file(&tmp);
            return Err(io(e));
        }
        crate::io::sync_dir(&self.shards_dir());
        Ok(ChunkInfo { chunk, path, rows: batch.num_rows() as u64, status_counts })
    }
}

/// Which kind of sweep `dir` holds (read from `DIR/manifest.json`'s
/// `format`); [`SweepError::no_run`] without a manifest. Unknown formats are
/// reported as planar, whose reader then names the format it expected.
pub fn run_kind(dir: &Path) -> Result<RunKind, SweepError> {
    let path = dir.join(MANIFEST);
    let text = match crate::io::read_utf8(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(SweepError::no_run(dir)),
        Err(source) => return Err(FileError::new("reading", path, source).into()),
    };
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| SweepError::CorruptManifest { path: path.clone(), problem: ManifestProblem::Json(e) })?;
    Ok(match value.get("format").and_then(|f| f.as_str()) {
        Some(crate::io::run_markers::CABLES_FORMAT) => RunKind::Cables,
        _ => RunKind::Planar,
    })
}

/// What [`RunDir::scan`] found.
#[derive(Debug, Clone, Default)]
pub struct Scan {
    /// Complete, verified chunk files by index.
    pub chunks: BTreeMap<u64, ChunkInfo>,
    /// Temporary files (chunk index, path): chunks being written now or
    /// left by an interrupted run.
    pub temporaries: Vec<(u64, PathBuf)>,
    /// Chunk files that failed their check (not in `chunks`).
    pub damaged: Vec<DamagedChunk>,
}

/// `chunk-000012.parquet`.
pub fn chunk_file_name(chunk: u64) -> String {
    format!("chunk-{chunk:06}.parquet")
}

/// The chunk index of a final chunk file name.
pub fn parse_chunk_name(name: &str) -> Option<u64> {
    let digits = name.strip_prefix("chunk-")?.strip_suffix(".parquet")?;
    if digits.len() < 6 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let chunk: u64 = digits.parse().ok()?;
    (chunk_file_name(chunk) == name).then_some(chunk)
}

/// The chunk index of a temporary chunk file name (`.chunk-….parquet.tmp-TOKEN`).
fn temp_chunk(name: &str) -> Option<u64> {
    let rest = name.strip_prefix('.')?;
    let (final_name, _) = rest.split_once(".tmp-")?;
    let chunk = parse_chunk_name(final_name)?;
    crate::io::is_temp_of(name, final_name).then_some(chunk)
}

fn is_manifest_temp(name: &str) -> bool {
    crate::io::is_temp_of(name, MANIFEST)
}

/// Entries cablemap itself puts at the top of a run directory.
fn is_run_entry(name: &str) -> bool {
    [MANIFEST, SHARDS_DIR, CHECKSUMS_DIR, DAMAGED_DIR].contains(&name) || is_manifest_temp(name)
}

fn list_dir(dir: &Path) -> Result<Vec<std::ffi::OsString>, SweepError> {
    let io = |source| SweepError::from(FileError::new("listing", dir, source));
    std::fs::read_dir(dir).map_err(io)?.map(|e| e.map(|e| e.file_name()).map_err(io)).collect()
}

/// Reads a chunk file's footer and checks it is chunk `chunk` of this run
/// with `rows` rows.
pub fn check_chunk(path: &Path, chunk: u64, manifest: &Manifest, rows: u64) -> Result<ChunkInfo, SweepError> {
    let file =
        File::open(path).map_err(FileError::on("opening", path))?;
    let meta = ParquetMetaDataReader::new()
        .parse_and_finish(&file)
        .map_err(|e| SweepError::CorruptChunk { path: path.to_path_buf(), problem: ChunkProblem::parquet(e) })?;
    let kv: BTreeMap<&str, &str> = meta
        .file_metadata()
        .key_value_metadata()
        .map(|v| v.iter().filter_map(|k| Some((k.key.as_str(), k.value.as_deref()?))).collect())
        .unwrap_or_default();
    let foreign = |reason| SweepError::ForeignChunk { path: path.to_path_buf(), reason };
    let format = manifest.spec.kind().format();
    if kv.get(keys::FORMAT) != Some(&format) {
        return Err(foreign(ForeignReason::NoFormat { key: keys::FORMAT, format }));
    }
    if kv.get(keys::SPEC_SHA256) != Some(&manifest.spec_sha256.as_str()) {
        let found = kv.get(keys::SPEC_SHA256).unwrap_or(&"(none)").to_string();
        return Err(foreign(ForeignReason::OtherSpec { found, wanted: manifest.spec_sha256.clone() }));
    }
    if kv.get(keys::CHUNK).and_then(|c| c.parse::<u64>().ok()) != Some(chunk) {
        return Err(foreign(ForeignReason::OtherChunk { found: kv.get(keys::CHUNK).unwrap_or(&"(none)").to_string(), chunk }));
    }
    let file_rows = meta.file_metadata().num_rows();
    if file_rows != rows as i64 {
        return Err(SweepError::CorruptChunk { path: path.to_path_buf(), problem: ChunkProblem::Rows { found: file_rows, chunk, rows } });
    }
    let status_counts = kv
        .get(keys::STATUS_COUNTS)
        .and_then(|s| serde_json::from_str(s).ok())
        .ok_or_else(|| SweepError::CorruptChunk { path: path.to_path_buf(), problem: ChunkProblem::StatusCounts })?;
    Ok(ChunkInfo { chunk, path: path.to_path_buf(), rows, status_counts })
}

fn count_statuses(batch: &RecordBatch) -> BTreeMap<String, u64> {
    let mut counts = BTreeMap::new();
    let column = batch.column_by_name(super::schema::STATUS).expect("status column");
    let strings = column.as_any().downcast_ref::<arrow::array::StringArray>().expect("status is utf8");
    for s in strings.iter().flatten() {
        *counts.entry(s.to_string()).or_insert(0) += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunk_names_round_trip_and_nothing_else_matches() {
        assert_eq!(parse_chunk_name(&chunk_file_name(12)), Some(12));
        assert_eq!(parse_chunk_name(&chunk_file_name(1_234_567)), Some(1_234_567));
        for name in ["chunk-12.parquet", "chunk-000012.parquet.bak", "chunk-00001x.parquet", "xchunk-000012.parquet", "chunk-0000012.parquet"] {
            assert_eq!(parse_chunk_name(name), None, "{name}");
        }
        assert_eq!(temp_chunk(".chunk-000007.parquet.tmp-4242"), Some(7));
        assert_eq!(temp_chunk("chunk-000007.parquet.tmp-4242"), None);
        assert_eq!(temp_chunk(".chunk-000007.parquet.tmp-1-00ab12cd34ef5678-3"), Some(7));
        assert_eq!(temp_chunk(".chunk-000007.parquet.tmp-42/x"), None);
        assert!(is_manifest_temp(".manifest.json.tmp-12-345"));
    }

    #[test]
    fn an_absurd_shard_count_is_refused_before_status_allocates_it() {
        let spec = SweepSpec::from_toml("[grid]\nlevels = 3\n", "t").unwrap();
        assert!(Manifest::new(&spec, super::super::MAX_SHARDS).verify().is_ok());
        for shards in [0, super::super::MAX_SHARDS + 1, u64::MAX] {
            let e = Manifest::new(&spec, shards).verify().unwrap_err();
            assert!(e.to_string().contains(&format!("shards = {shards} is not 1")), "{e}");
        }
    }

    #[test]
    fn failures_count_everything_but_ok() {
        let counts: BTreeMap<String, u64> = [("ok".to_string(), 5), ("rod_collapsed".into(), 2), ("non_finite".into(), 1)].into();
        assert_eq!(failures(&counts), 3);
    }
}
