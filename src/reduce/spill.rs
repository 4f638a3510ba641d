//! Samples on disk: pass 1 writes every converged row's sample to a file
//! instead of keeping it, so that the reducer's memory does not grow with
//! the run. Later stages read the files back as many times as they need
//! (counting passes, the partition pass) and hold at most one partition of
//! samples at a time.
//!
//! A record is 48 bytes, little-endian: tip x, tip y, a_0, a_1, a_2 (f64),
//! the row number (u32) and flags (u32: bit 0, the row stands for its
//! mirror image too, which is restored on reading by the rule in `mirror`;
//! bit 1, the record is itself a mirror image). The files are scratch of
//! one reduction (and of a part, see `parts`), not an exchange format.

use super::mirror::Mirror;
use super::sample::{RowRef, Sample};
use super::ReduceError;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Bytes per record.
pub(crate) const RECORD_BYTES: usize = 48;
const WITH_MIRROR: u32 = 1;
const IS_MIRROR: u32 = 2;
pub(crate) const BUFFER_BYTES: usize = 1 << 20;

/// Extent of the tips, mm (after mirroring).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Extent {
    /// Smallest and largest tip x.
    pub x_mm: [f64; 2],
    /// Smallest and largest tip y.
    pub y_mm: [f64; 2],
}

impl Default for Extent {
    fn default() -> Self {
        Self {
            x_mm: [f64::MAX, f64::MIN],
            y_mm: [f64::MAX, f64::MIN],
        }
    }
}

impl Extent {
    /// Widens the extent to hold the tip of `s`.
    pub fn add(&mut self, s: &Sample) {
        self.x_mm = [self.x_mm[0].min(s.x_mm), self.x_mm[1].max(s.x_mm)];
        self.y_mm = [self.y_mm[0].min(s.y_mm), self.y_mm[1].max(s.y_mm)];
    }

    /// Widens the extent to hold `other`'s.
    pub fn merge(&mut self, other: &Extent) {
        self.x_mm = [self.x_mm[0].min(other.x_mm[0]), self.x_mm[1].max(other.x_mm[1])];
        self.y_mm = [self.y_mm[0].min(other.y_mm[0]), self.y_mm[1].max(other.y_mm[1])];
    }
}

/// The error of a scratch file.
pub(crate) fn scratch_error(path: &Path, source: std::io::Error) -> ReduceError {
    ReduceError::Scratch {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes records to one file.
pub(crate) struct SpillWriter {
    path: PathBuf,
    out: BufWriter<File>,
    /// Records written.
    pub records: u64,
}

impl SpillWriter {
    /// Creates (truncates) the file at `path`.
    pub fn create(path: &Path) -> Result<Self, ReduceError> {
        Self::with_buffer(path, BUFFER_BYTES)
    }

    /// Like [`Self::create`], buffering `bytes` (smaller when many files
    /// are written at once).
    pub fn with_buffer(path: &Path, bytes: usize) -> Result<Self, ReduceError> {
        let file = File::create(path).map_err(|e| scratch_error(path, e))?;
        Ok(Self::from_file(path, file, bytes))
    }

    /// Writes to `file`, opened at `path`.
    pub fn from_file(path: &Path, file: File, bytes: usize) -> Self {
        Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(bytes, file),
            records: 0,
        }
    }

    /// Writes sample `s`; `with_mirror` when its mirror image is to be
    /// restored on reading.
    pub fn push(&mut self, s: &Sample, with_mirror: bool) -> Result<(), ReduceError> {
        let mut rec = [0u8; RECORD_BYTES];
        for (i, v) in [s.x_mm, s.y_mm, s.a[0], s.a[1], s.a[2]].iter().enumerate() {
            rec[8 * i..8 * i + 8].copy_from_slice(&v.to_le_bytes());
        }
        rec[40..44].copy_from_slice(&s.at.row.to_le_bytes());
        let flags = if with_mirror { WITH_MIRROR } else { 0 } | if s.at.mirrored { IS_MIRROR } else { 0 };
        rec[44..48].copy_from_slice(&flags.to_le_bytes());
        self.records += 1;
        self.out.write_all(&rec).map_err(|e| scratch_error(&self.path, e))
    }

    /// Flushes the file (and syncs it to disk when `durable`, for parts that
    /// outlive the process).
    pub fn finish(self, durable: bool) -> Result<u64, ReduceError> {
        let path = self.path;
        let file = self.out.into_inner().map_err(|e| scratch_error(&path, e.into_error()))?;
        if durable {
            file.sync_all().map_err(|e| scratch_error(&path, e))?;
        }
        Ok(self.records)
    }
}

/// Where pass 1 put a run's samples: in memory (a run within the memory
/// bound: no scratch file at all) or in scratch files.
pub(crate) enum Samples {
    /// Every sample, mirror images included.
    Memory(Vec<Sample>),
    /// Scratch files, read in order.
    Files(Vec<PathBuf>),
}

impl Samples {
    /// Calls `f` with every sample (the same sequence each time).
    pub fn for_each(&self, mut f: impl FnMut(&Sample)) -> Result<(), ReduceError> {
        match self {
            Samples::Memory(v) => {
                v.iter().for_each(f);
                Ok(())
            }
            Samples::Files(paths) => for_each(paths, &mut f),
        }
    }
}

/// Where pass 1 writes samples.
pub(crate) trait SampleOut {
    /// Takes sample `s`, and its mirror image when `with_mirror`.
    fn push(&mut self, s: &Sample, with_mirror: bool) -> Result<(), ReduceError>;
}

impl SampleOut for SpillWriter {
    fn push(&mut self, s: &Sample, with_mirror: bool) -> Result<(), ReduceError> {
        SpillWriter::push(self, s, with_mirror)
    }
}

/// Pass 1's samples kept in memory up to a bound; beyond it, all of them go
/// to a scratch file.
pub(crate) struct SampleSink {
    limit: usize,
    memory: Vec<Sample>,
    path: PathBuf,
    writer: Option<SpillWriter>,
}

impl SampleSink {
    /// Keeps up to `limit` samples in memory, then spills to `path`.
    pub fn new(path: &Path, limit: usize) -> Self {
        Self {
            limit,
            memory: Vec::with_capacity(limit.saturating_add(2).min(1 << 16)),
            path: path.to_path_buf(),
            writer: None,
        }
    }

    /// The samples taken.
    pub fn finish(self) -> Result<Samples, ReduceError> {
        match self.writer {
            Some(w) => {
                w.finish(false)?;
                Ok(Samples::Files(vec![self.path]))
            }
            None => Ok(Samples::Memory(self.memory)),
        }
    }
}

impl SampleOut for SampleSink {
    fn push(&mut self, s: &Sample, with_mirror: bool) -> Result<(), ReduceError> {
        if let Some(w) = &mut self.writer {
            return w.push(s, with_mirror);
        }
        self.memory.push(*s);
        if with_mirror {
            self.memory.push(s.mirror());
        }
        if self.memory.len() > self.limit {
            let mut w = SpillWriter::create(&self.path)?;
            for m in std::mem::take(&mut self.memory) {
                w.push(&m, false)?;
            }
            self.writer = Some(w);
        }
        Ok(())
    }
}

/// Calls `f` with every sample of the files, in file order, each stored
/// sample followed by its restored mirror image.
pub(crate) fn for_each(files: &[PathBuf], mut f: impl FnMut(&Sample)) -> Result<(), ReduceError> {
    let mut buf = vec![0u8; RECORD_BYTES * 8192];
    for path in files {
        let file = File::open(path).map_err(|e| scratch_error(path, e))?;
        let mut reader = BufReader::with_capacity(BUFFER_BYTES, file);
        loop {
            let n = read_full(&mut reader, &mut buf).map_err(|e| scratch_error(path, e))?;
            if n % RECORD_BYTES != 0 {
                return Err(scratch_error(
                    path,
                    std::io::Error::other("the file ends inside a record: it was cut short"),
                ));
            }
            for rec in buf[..n].chunks_exact(RECORD_BYTES) {
                let (s, with_mirror) = decode(rec);
                f(&s);
                if with_mirror {
                    f(&s.mirror());
                }
            }
            if n < buf.len() {
                break;
            }
        }
    }
    Ok(())
}

/// Reads all samples of one file into memory (mirror images restored).
pub(crate) fn load(path: &Path, capacity: usize) -> Result<Vec<Sample>, ReduceError> {
    let mut samples = Vec::with_capacity(capacity);
    for_each(&[path.to_path_buf()], |s| samples.push(*s))?;
    Ok(samples)
}

fn decode(rec: &[u8]) -> (Sample, bool) {
    let f = |i: usize| f64::from_le_bytes(rec[8 * i..8 * i + 8].try_into().expect("8 bytes"));
    let row = u32::from_le_bytes(rec[40..44].try_into().expect("4 bytes"));
    let flags = u32::from_le_bytes(rec[44..48].try_into().expect("4 bytes"));
    let s = Sample {
        x_mm: f(0),
        y_mm: f(1),
        a: [f(2), f(3), f(4)],
        at: RowRef {
            row,
            mirrored: flags & IS_MIRROR != 0,
        },
    };
    (s, flags & WITH_MIRROR != 0)
}

/// Fills `buf` as far as the reader allows; returns the bytes read.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match reader.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// A scratch directory removed when dropped (a killed reduce leaves it:
/// the next reduce with the same scratch parent removes abandoned ones).
pub(crate) struct ScratchDir {
    /// The directory.
    pub path: PathBuf,
    _lock: Option<File>,
}

/// Prefix of scratch directory names.
const SCRATCH_PREFIX: &str = ".cablemap-reduce-";

impl ScratchDir {
    /// Creates a fresh scratch directory in `parent`, first removing those
    /// that killed reductions left there.
    pub fn new(parent: &Path) -> Result<Self, ReduceError> {
        std::fs::create_dir_all(parent).map_err(|e| scratch_error(parent, e))?;
        if let Ok(entries) = std::fs::read_dir(parent) {
            for e in entries.flatten() {
                let p = e.path();
                let ours = e.file_name().to_string_lossy().starts_with(SCRATCH_PREFIX);
                if ours && p.is_dir() && crate::io::is_abandoned(&p) {
                    let _ = std::fs::remove_dir_all(&p);
                }
            }
        }
        let path = parent.join(format!("{SCRATCH_PREFIX}{}", crate::io::unique_token()));
        std::fs::create_dir(&path).map_err(|e| scratch_error(&path, e))?;
        // Locked while in use so that another reduce does not take it for abandoned.
        let lock = File::open(&path).ok();
        if let Some(l) = &lock {
            let _ = l.try_lock();
        }
        Ok(Self { path, _lock: lock })
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_read_back_with_mirror_images_restored() {
        let dir = ScratchDir::new(&std::env::temp_dir()).unwrap();
        let path = dir.path.join("s");
        let mut w = SpillWriter::create(&path).unwrap();
        let s = Sample {
            x_mm: 1.5,
            y_mm: -2.0,
            a: [0.1, -0.2, 0.3],
            at: RowRef { row: 7, mirrored: false },
        };
        w.push(&s, true).unwrap();
        w.push(
            &Sample {
                at: RowRef { row: 8, mirrored: true },
                ..s
            },
            false,
        )
        .unwrap();
        assert_eq!(w.finish(false).unwrap(), 2);
        let back = load(&path, 0).unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!((back[0].x_mm, back[0].y_mm, back[0].a, back[0].at), (s.x_mm, s.y_mm, s.a, s.at));
        assert_eq!(
            (back[1].y_mm, back[1].a[1], back[1].at),
            (2.0, 0.2, RowRef { row: 7, mirrored: true })
        );
        assert_eq!(back[2].at, RowRef { row: 8, mirrored: true });
        // A file cut inside a record is refused.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..50]).unwrap();
        assert!(load(&path, 0).unwrap_err().to_string().contains("cut short"));
        let kept = dir.path.clone();
        drop(dir);
        assert!(!kept.exists());
    }
}
