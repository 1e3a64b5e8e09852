//! OpenEXR's own validator on files the tests write: `tests/exrcheck/exrcheck.cpp` built with g++
//! (once, again when the source changes) against libopenexr-dev (scripts/setup.sh installs both).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn tool() -> &'static Path {
    static TOOL: OnceLock<PathBuf> = OnceLock::new();
    TOOL.get_or_init(|| {
        let exe = Path::new(env!("CARGO_TARGET_TMPDIR")).join("exrcheck");
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/exrcheck/exrcheck.cpp");
        let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
        if modified(&exe).is_some() && modified(&exe) >= modified(&source) {
            return exe;
        }
        // Built beside it, then renamed: a test binary running at the same time sees the old
        // tool or the new one, never half of one.
        let building = exe.with_extension(format!("{}", std::process::id()));
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
            .arg(&building)
            .arg(&source)
            .args(flags.split_whitespace())
            .output()
            .unwrap_or_else(|e| panic!("g++ ({e}): run scripts/setup.sh"));
        assert!(
            built.status.success(),
            "building exrcheck: {}",
            String::from_utf8_lossy(&built.stderr)
        );
        std::fs::rename(&building, &exe).expect("exrcheck put in place");
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
