//! Running the real binary on scene files in a folder of their own (the command-line tests).

use std::path::PathBuf;
use std::process::Command;

pub const GOOD: &str = r#"[camera]
position = [0, 0, 0]
look_at = [0, 10, 0]
fov_y = 30
time = 10

[image]
width = 48
height = 32

[[material]]
name = "white"
color = [0.8, 0.8, 0.8]

[[light]]
position = [0, 0, 20]
group = "cube"

[[group]]
name = "cube"
velocity = [0.5, 0, 0]
[[group.object]]
type = "box"
min = [-0.5, 10, -0.5]
max = [0.5, 11, 0.5]
material = "white"
"#;

pub struct Dir(pub PathBuf);

impl Dir {
    pub fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("rest-embree-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    pub fn file(&self, name: &str, text: &str) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }
    pub fn entries(&self) -> Vec<String> {
        std::fs::read_dir(&self.0)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect()
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Whether the command with these arguments succeeded, and its standard error.
pub fn run(args: &[&str]) -> (bool, String) {
    let (code, err) = status(args);
    (code == Some(0), err)
}

/// Render `scene_text` with extra args; expect failure with every `needles` in the message and
/// no file written beside the scene.
pub fn fails(name: &str, scene_text: &str, extra: &[&str], needles: &[&str]) {
    let d = Dir::new(name);
    let scene = d.file("scene.toml", scene_text);
    let out = d.0.join("out.png");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (ok, err) = run(&args);
    assert!(!ok, "{name}: expected failure, stderr: {err}");
    for n in needles {
        assert!(
            err.contains(n),
            "{name}: error should mention `{n}`:\n{err}"
        );
    }
    assert_eq!(
        d.entries(),
        vec!["scene.toml".to_string()],
        "{name}: no output file, no partial file"
    );
}

pub fn with(line_from: &str, line_to: &str) -> String {
    assert!(
        GOOD.contains(line_from),
        "test bug: `{line_from}` not in the scene"
    );
    GOOD.replacen(line_from, line_to, 1)
}

/// The exit status of the command with these arguments, and its standard error.
pub fn status(args: &[&str]) -> (Option<i32>, String) {
    let (code, err, _) = status_with_env(args, &[]);
    assert!(!err.contains("panicked"), "the command panicked: {err}");
    (code, err)
}

/// The exit status (None: killed by a signal, an abort) of the command with these arguments
/// and environment variables (the Embree backend's own, `REST_EMBREE_ISA` and
/// `REST_EMBREE_FAULT`, only as given), its standard error and its standard output.
pub fn status_with_env(args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(args)
        .env_remove("REST_EMBREE_ISA")
        .env_remove("REST_EMBREE_FAULT")
        .envs(env.iter().copied())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    (out.status.code(), err, stdout)
}

/// oiiotool's standard output for `args` (OpenImageIO's tool, from Debian's openimageio-tools,
/// which scripts/setup.sh installs); it failing, or missing, fails the test, saying which.
pub fn oiiotool(args: &[&str]) -> String {
    let out = Command::new("oiiotool")
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("oiiotool ({e}): run scripts/setup.sh (openimageio-tools)"));
    assert!(
        out.status.success(),
        "oiiotool {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}
