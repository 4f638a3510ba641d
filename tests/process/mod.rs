//! Helpers for tests that run the `cablemap` binary as a user would.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The binary under test, with the cluster variables of the environment the
/// tests run in removed (they must not pick a shard or a thread count).
#[allow(dead_code)]
pub fn cablemap() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cablemap"));
    for v in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX", "SLURM_CPUS_PER_TASK"] {
        c.env_remove(v);
    }
    c
}

/// Every file under `dir` with its bytes.
#[allow(dead_code)]
pub fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}
