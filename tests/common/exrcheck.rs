//! OpenEXR's own validator on files the tests write: `tests/exrcheck/exrcheck.cpp` built once
//! per test binary with g++ against libopenexr-dev (scripts/setup.sh installs both).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn tool() -> &'static Path {
    static TOOL: OnceLock<PathBuf> = OnceLock::new();
    TOOL.get_or_init(|| {
        let exe =
            Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("exrcheck-{}", std::process::id()));
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/exrcheck/exrcheck.cpp");
        let flags = Command::new("pkg-config")
            .args(["--cflags", "--libs", "OpenEXR"])
            .output()
            .unwrap_or_else(|e| panic!("pkg-config ({e}): run scripts/setup.sh"));
        assert!(
            flags.status.success(),
            "pkg-config finds no OpenEXR: run scripts/setup.sh (libopenexr-dev)"
        );
        let flags = String::from_utf8(flags.stdout).unwrap();
        let built = Command::new("g++")
            .arg("-O1")
            .arg("-o")
            .arg(&exe)
            .arg(&source)
            .args(flags.split_whitespace())
            .output()
            .unwrap_or_else(|e| panic!("g++ ({e}): run scripts/setup.sh"));
        assert!(
            built.status.success(),
            "building exrcheck: {}",
            String::from_utf8_lossy(&built.stderr)
        );
        exe
    })
}

/// Whether OpenEXR's validator finds `path` a correct OpenEXR file.
pub fn valid(path: &Path) -> bool {
    let out = Command::new(tool())
        .arg(path)
        .output()
        .expect("exrcheck runs");
    out.status.success()
}
