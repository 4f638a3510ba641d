//! `scripts/test.sh` counts every check: it runs here with stand-ins for
//! cargo, the cablemap binary, Python and Chromium on PATH (so nothing is
//! built, installed or solved, and it takes a second), one failing Rust test
//! and one Python check that dies before printing its count.

#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::Path;
use std::process::Command;

fn script(path: &Path, text: &str) {
    std::fs::write(path, format!("#!/bin/sh\n{text}")).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn test_script_ends_with_one_count_of_every_check_and_fails_on_any_failure() {
    let tmp = tempfile::tempdir().unwrap();
    let (bin, target, venv) = (tmp.path().join("bin"), tmp.path().join("target"), tmp.path().join("venv"));
    for dir in [&bin, &target.join("release"), &venv.join("bin")] {
        std::fs::create_dir_all(dir).unwrap();
    }
    // cargo: builds succeed; the test run has two binaries, one test failing.
    script(
        &bin.join("cargo"),
        &format!(
            r#"case "$1" in
  metadata) echo '{{"target_directory": "{}"}}' ;;
  build) ;;
  test) case "$*" in *--no-run*) exit 0 ;; esac
    echo "test result: ok. 5 passed; 0 failed; 0 ignored; 0 measured; 0 filtered out; finished in 0.1s"
    echo "test result: FAILED. 3 passed; 1 failed; 0 ignored; 0 measured; 0 filtered out; finished in 0.1s"
    exit 101 ;;
esac
"#,
            target.display()
        ),
    );
    // The binary writes nothing; every Python check passes two checks, except
    // the mould check, which dies before its count.
    script(&target.join("release/cablemap"), "exit 0\n");
    script(
        &venv.join("bin/python"),
        r#"case "$1" in
  -c) exit 0 ;;
  *check_moulds.py) echo "Traceback: boom"; exit 1 ;;
esac
echo "PASS one"; echo "PASS two"; echo "python: 2 passed, 0 failed"
"#,
    );
    script(&bin.join("chromium"), "exit 0\n");
    script(&bin.join("chromedriver"), "exit 0\n");
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let out = Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/test.sh"))
        .env("PATH", path)
        .env("CABLEMAP_VENV", &venv)
        .env("CABLEMAP_TEST_ARTEFACTS", tmp.path().join("artefacts"))
        .env_remove("CARGO_TARGET_DIR")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success(), "a failing test must fail the script: {stdout}");
    // Rust 8 + 1; five Python and browser checks and the Python package's
    // pytest (the fake python's last line, "2 passed") × 2 passed, the mould
    // check one failure.
    assert_eq!(stdout.lines().last(), Some("20 passed, 2 failed"), "{stdout}");
    assert!(stdout.contains("rust: 8 passed, 1 failed") && stdout.contains("failed: check_moulds (1)"), "{stdout}");
    assert!(stdout.contains("FAIL check_moulds: exited with status 1 before counting its checks"), "{stdout}");
}
