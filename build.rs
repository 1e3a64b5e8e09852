//! Records the git commit (when built from a checkout) for `rest-embree --version`, so a picture
//! in a paper can name the exact build that made it.

use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=.git/HEAD");
    println!("cargo:rerun-if-changed=.git/refs");
    let commit = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    let backends = if std::env::var_os("CARGO_FEATURE_EMBREE").is_some() {
        "embree, bvh"
    } else {
        "bvh"
    };
    println!(
        "cargo:rustc-env=REST_EMBREE_LONG_VERSION={} (commit {commit}; backends: {backends})",
        std::env::var("CARGO_PKG_VERSION").unwrap()
    );
}
