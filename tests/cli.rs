//! The real binary: good renders write EXR and PNG; bad input of each kind gives a clear error
//! naming the file, line and key (or the flag), a non-zero exit, and no output file.

use std::path::{Path, PathBuf};
use std::process::Command;

const GOOD: &str = r#"[camera]
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

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("rest-embree-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    fn file(&self, name: &str, text: &str) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }
    fn entries(&self) -> Vec<String> {
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

fn run(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "the command panicked: {err}");
    (out.status.success(), err)
}

/// Render `scene_text` with extra args; expect failure with every `needles` in the message and
/// no file written beside the scene.
fn fails(name: &str, scene_text: &str, extra: &[&str], needles: &[&str]) {
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

fn with(line_from: &str, line_to: &str) -> String {
    assert!(
        GOOD.contains(line_from),
        "test bug: `{line_from}` not in the scene"
    );
    GOOD.replacen(line_from, line_to, 1)
}

#[test]
fn good_scene_writes_png_and_exr_with_the_passes() {
    let d = Dir::new("good");
    let scene = d.file("scene.toml", GOOD);
    let png = d.0.join("out.png");
    let exr = d.0.join("out.exr");
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--samples",
        "4",
        "--width",
        "40",
    ]);
    assert!(ok, "{err}");
    let (w, h, ch) = rest_embree::output::read_exr_channels(&exr).unwrap();
    assert_eq!((w, h), (40, 32));
    for name in ["R", "G", "B", "A", "lookback", "doppler", "object_id"] {
        let c = ch
            .get(name)
            .unwrap_or_else(|| panic!("channel {name} missing; have {:?}", ch.keys()));
        assert!(c.iter().all(|v| v.is_finite()), "channel {name} is finite");
    }
    let ids = &ch["object_id"];
    let lookback = &ch["lookback"];
    let doppler = &ch["doppler"];
    let hit = ids
        .iter()
        .position(|&i| i == 1.0)
        .expect("the cube is in view");
    // The cube is about 10 light-units away, and it recedes slightly off-axis: redshifted.
    assert!(
        lookback[hit] > 9.0 && lookback[hit] < 13.0,
        "lookback {}",
        lookback[hit]
    );
    assert!(
        doppler[hit] > 0.3 && doppler[hit] < 1.5,
        "doppler {}",
        doppler[hit]
    );
    assert!(ids.contains(&0.0), "background is id 0");
    // The colour channels say what they are: linear Rec. 709 / sRGB primaries, D65 white.
    let meta = exr::meta::MetaData::read_from_file(&exr, false).unwrap();
    let c = meta.headers[0]
        .shared_attributes
        .chromaticities
        .expect("a chromaticities attribute");
    let xy = |v: exr::math::Vec2<f32>| (v.0, v.1);
    assert_eq!(
        [xy(c.red), xy(c.green), xy(c.blue), xy(c.white)],
        [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06), (0.3127, 0.3290)]
    );
    assert_eq!(
        d.entries().len(),
        3,
        "only the scene and two images: {:?}",
        d.entries()
    );
}

#[test]
fn missing_scene_file() {
    let d = Dir::new("missing");
    let out = d.0.join("out.png");
    let (ok, err) = run(&[
        "render",
        "/nonexistent/scene.toml",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        err.contains("/nonexistent/scene.toml") && err.contains("cannot read"),
        "{err}"
    );
    assert!(d.entries().is_empty());
}

#[test]
fn toml_syntax_error_names_the_line() {
    fails(
        "syntax",
        &with("fov_y = 30", "fov_y = = 30"),
        &[],
        &["scene.toml:4", "not valid TOML"],
    );
}

#[test]
fn unknown_key_names_line_key_and_suggests() {
    fails(
        "unknown",
        &with("velocity = [0.5, 0, 0]", "velocty = [0.5, 0, 0]"),
        &[],
        &[
            "scene.toml:21",
            "group.cube.velocty",
            "did you mean `velocity`",
        ],
    );
    fails(
        "unknown-table",
        &format!("{GOOD}\n[rendr]\nmax_depth = 2\n"),
        &[],
        &["scene.toml:28", "rendr", "did you mean `render`"],
    );
}

#[test]
fn bad_values_name_line_and_key() {
    fails(
        "type",
        &with("fov_y = 30", "fov_y = \"wide\""),
        &[],
        &["scene.toml:4", "camera.fov_y", "expected a number"],
    );
    fails(
        "range",
        &with("fov_y = 30", "fov_y = 190"),
        &[],
        &["scene.toml:4", "camera.fov_y", "between 0 and 180"],
    );
    fails(
        "width",
        &with("width = 48", "width = 0"),
        &[],
        &["scene.toml:8", "image.width"],
    );
    fails(
        "material",
        &with("material = \"white\"", "material = \"gold\""),
        &[],
        &["scene.toml:26", "no material named `gold`", "white"],
    );
    fails(
        "box",
        &with("max = [0.5, 11, 0.5]", "max = [0.5, 9, 0.5]"),
        &[],
        &["group.cube.object", "max"],
    );
    fails(
        "vec",
        &with("look_at = [0, 10, 0]", "look_at = [0, 10]"),
        &[],
        &["scene.toml:3", "camera.look_at", "expected 3 numbers"],
    );
}

#[test]
fn speeds_of_light_and_beyond_are_refused() {
    fails(
        "c",
        &with("velocity = [0.5, 0, 0]", "velocity = [1.0, 0, 0]"),
        &[],
        &["scene.toml:21", "group.cube.velocity", "not below 1"],
    );
    fails(
        "faster",
        &with("velocity = [0.5, 0, 0]", "velocity = [0.8, 0.7, 0]"),
        &[],
        &["scene.toml:21", "not below 1"],
    );
    fails(
        "set-c",
        GOOD,
        &["--set", "group.cube.velocity=[1.5,0,0]"],
        &[
            "--set group.cube.velocity=[1.5,0,0]",
            "group.cube.velocity",
            "not below 1",
        ],
    );
    fails(
        "beta",
        &with(
            "velocity = [0.5, 0, 0]",
            "direction = [1, 0, 0]\nbeta = 1.0",
        ),
        &[],
        &["group.cube.beta", "not below 1"],
    );
    fails(
        "omb",
        &with(
            "velocity = [0.5, 0, 0]",
            "direction = [1, 0, 0]\none_minus_beta = 0",
        ),
        &[],
        &["group.cube.one_minus_beta", "(0, 1]"],
    );
}

#[test]
fn empty_scenes_are_refused() {
    let no_objects = GOOD.split("[[group.object]]").next().unwrap().to_string();
    fails("empty", &no_objects, &[], &["scene is empty"]);
    let no_groups = GOOD
        .split("[[group]]")
        .next()
        .unwrap()
        .replace("group = \"cube\"\n", "");
    fails("nogroups", &no_groups, &[], &["scene is empty"]);
    fails(
        "nocamera",
        "[image]\nwidth = 4\n",
        &[],
        &["camera", "missing"],
    );
}

#[test]
fn bad_flags_are_named() {
    fails(
        "backend",
        GOOD,
        &["--backend", "optix"],
        &["--backend", "unknown backend 'optix'"],
    );
    fails(
        "set-name",
        GOOD,
        &["--set", "group.ship.velocity=[0.1,0,0]"],
        &[
            "--set group.ship.velocity",
            "no [[group]] entry named `ship`",
            "cube",
        ],
    );
    fails(
        "set-syntax",
        GOOD,
        &["--set", "camera.time"],
        &["--set camera.time", "KEY=VALUE"],
    );
    fails(
        "set-value",
        GOOD,
        &["--set", "camera.time=[1,"],
        &["--set camera.time=[1,", "not a TOML value"],
    );
    fails(
        "set-unknown",
        GOOD,
        &["--set", "camera.tme=3"],
        &["--set camera.tme=3", "camera.tme", "did you mean `time`"],
    );
    fails(
        "set-object-key",
        GOOD,
        &["--set", "group.cube.min=[0,0,0]"],
        &[
            "--set group.cube.min",
            "belongs to an object",
            "group.cube.object.<object name or index>.min",
        ],
    );
    fails(
        "width0",
        GOOD,
        &["--width", "0"],
        &["--width 0", "image.width"],
    );
    let d = Dir::new("ext");
    let scene = d.file("scene.toml", GOOD);
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        d.0.join("out.jpg").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("-o") && err.contains(".exr or .png"),
        "{err}"
    );
    assert_eq!(d.entries(), vec!["scene.toml".to_string()]);
}

#[test]
fn set_addresses_entries_by_name_and_overrides_any_value() {
    let d = Dir::new("set");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("o.exr");
    let args = [
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "group.cube.velocity=[0.99,0,0]",
        "--set",
        "image.background=[0.25, 0.5, 1]",
        "--set",
        "camera.projection=orthographic",
        "--set",
        "camera.view_height=4",
    ];
    let (ok, err) = run(&args);
    assert!(ok, "{err}");
    let (_, _, ch) = rest_embree::output::read_exr_channels(Path::new(&out)).unwrap();
    let bg = ch["object_id"].iter().position(|&i| i == 0.0).unwrap();
    assert_eq!((ch["R"][bg], ch["G"][bg], ch["B"][bg]), (0.25, 0.5, 1.0));
}

#[cfg(not(feature = "embree"))]
#[test]
fn asking_a_build_without_embree_for_embree_is_a_clear_error() {
    fails(
        "no-embree",
        GOOD,
        &["--backend", "embree"],
        &["--backend", "not in this build", "--features embree"],
    );
}

#[cfg(feature = "embree")]
#[test]
fn embree_is_the_default_backend() {
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .arg("backends")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("embree (default)"), "{text}");
    assert!(text.contains("bvh"));
}

#[test]
fn bench_writes_its_table_csv_and_plot() {
    let d = Dir::new("bench");
    let out = d.0.join("b");
    let (ok, err) = run(&[
        "bench",
        "--quick",
        "--repeat",
        "1",
        "--case",
        "lattice beta=0.9, no lights",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    assert!(csv.starts_with("case,setting,spp,"), "{csv}");
    assert!(csv.lines().count() >= 2, "a row per setting: {csv}");
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(md.contains("| lattice beta=0.9, no lights | bvh |"), "{md}");
    assert_eq!(&std::fs::read(out.join("bench.png")).unwrap()[1..4], b"PNG");
    let (ok, err) = run(&[
        "bench",
        "--quick",
        "--case",
        "no such case",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("--case"), "{err}");
    // Refused before anything is measured: an empty --case, --set without a scene, an --out
    // that cannot be written (a file where the folder should be).
    let blocker = d.file("not-a-folder", "");
    let out = out.to_str().unwrap();
    for (args, flag) in [
        (vec!["--case", "", "--out", out], "--case"),
        (vec!["--set", "camera.time=3", "--out", out], "--set"),
        (vec!["--out", blocker.to_str().unwrap()], "--out"),
    ] {
        let mut all = vec!["bench", "--quick", "--case", "lattice beta=0.9, no lights"];
        all.extend(args.iter().copied());
        let (ok, err) = run(&all);
        assert!(!ok && err.contains(flag), "{flag}: {err}");
        assert!(
            !err.contains("bench: lattice"),
            "{flag}: refused before measuring: {err}"
        );
    }
}

#[test]
fn the_same_render_writes_the_same_file() {
    // EXR blocks are compressed in parallel; the file must not depend on which finished first.
    let d = Dir::new("same-file");
    let scene = d.file("scene.toml", GOOD);
    let mut files = Vec::new();
    for (i, threads) in ["2", "2", "1"].iter().enumerate() {
        for ext in ["exr", "png"] {
            let out = d.0.join(format!("out{i}.{ext}"));
            let (ok, err) = run(&[
                "render",
                scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--width",
                "300",
                "--height",
                "200",
                "--samples",
                "2",
                "--threads",
                threads,
                "--quiet",
            ]);
            assert!(ok, "{err}");
            files.push((ext, std::fs::read(&out).unwrap()));
        }
    }
    for (ext, bytes) in &files[2..] {
        let first = &files.iter().find(|(e, _)| e == ext).unwrap().1;
        assert!(bytes == first, "{ext}: the same render, a different file");
    }
}

/// Bad spectra, and colours of the wrong kind, name the line and key; nothing is written.
#[test]
fn bad_spectra_name_line_and_key() {
    let colour = "color = [0.8, 0.8, 0.8]";
    let cases: &[(&str, &str, &str, &[&str])] = &[
        (
            "cold",
            "position = [0, 0, 20]",
            "position = [0, 0, 20]\ncolor = { blackbody = 0 }",
            &["scene.toml:17", "light.0.color.blackbody", "above 0"],
        ),
        (
            "negative-scale",
            "position = [0, 0, 20]",
            "position = [0, 0, 20]\ncolor = { blackbody = 3000, scale = -1 }",
            &["scene.toml:17", "light.0.color.scale", "negative"],
        ),
        (
            "fwhm",
            "position = [0, 0, 20]",
            "position = [0, 0, 20]\ncolor = { line = 500, fwhm = 0 }",
            &["scene.toml:17", "light.0.color.fwhm", "above 0"],
        ),
        (
            "unsorted",
            colour,
            "color = { wavelengths = [400, 700, 500], values = [0.1, 0.5, 0.9] }",
            &[
                "scene.toml:13",
                "material.white.color.wavelengths",
                "increase",
            ],
        ),
        (
            "mismatched",
            colour,
            "color = { wavelengths = [400, 700], values = [0.1, 0.5, 0.9] }",
            &[
                "scene.toml:13",
                "material.white.color.values",
                "3 values for 2",
            ],
        ),
        (
            "blackbody-reflectance",
            colour,
            "color = { blackbody = 5800 }",
            &[
                "scene.toml:13",
                "material.white.color",
                "reflectance cannot be a blackbody",
            ],
        ),
        (
            "line-reflectance",
            colour,
            "color = { line = 500, fwhm = 20 }",
            &["scene.toml:13", "material.white.color", "emission line"],
        ),
        (
            "nan",
            colour,
            "color = { wavelengths = [400, 700], values = [nan, 0.5] }",
            &["scene.toml:13", "material.white.color.values", "finite"],
        ),
        (
            "unknown",
            "position = [0, 0, 20]",
            "position = [0, 0, 20]\ncolor = { blackbody = 5000, kelvins = 3 }",
            &["scene.toml:17", "light.0.color.kelvins", "unknown key"],
        ),
        (
            "switch",
            "[[material]]",
            "[render]\ndoppler = \"yes\"\n[[material]]",
            &["scene.toml:12", "render.doppler", "true or false"],
        ),
    ];
    for (name, from, to, needles) in cases {
        fails(name, &with(from, to), &[], needles);
    }
    // And through --set.
    fails(
        "set",
        GOOD,
        &["--set", "material.white.emission={ blackbody = -5 }"],
        &["--set", "material.white.emission.blackbody", "above 0"],
    );
}

/// Spectra given in the file or with --set render; the switches change the picture.
#[test]
fn spectra_and_switches_render() {
    let d = Dir::new("spectra");
    let scene = d.file(
        "scene.toml",
        &with(
            "position = [0, 0, 20]",
            "position = [0, 0, 20]\ncolor = { blackbody = 5800, luminance = 1 }",
        ),
    );
    let mut pixels = Vec::new();
    for (i, sets) in [
        vec!["render.doppler=false", "render.searchlight=false"],
        vec!["render.doppler=true", "render.searchlight=false"],
        vec!["render.doppler=true", "render.searchlight=true"],
        vec!["material.white.color={ wavelengths = [380, 780], values = [0.2, 0.9] }"],
    ]
    .iter()
    .enumerate()
    {
        let out = d.0.join(format!("out{i}.exr"));
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        let (ok, err) = run(&args);
        assert!(ok, "{sets:?}: {err}");
        let (_, _, ch) = rest_embree::output::read_exr_channels(&out).unwrap();
        let sum: f64 = ["R", "G", "B"]
            .iter()
            .map(|c| ch[*c].iter().map(|&v| f64::from(v)).sum::<f64>())
            .sum();
        assert!(sum.is_finite() && sum > 0.0, "{sets:?}: {sum}");
        pixels.push(ch["B"].iter().sum::<f32>() / ch["R"].iter().sum::<f32>());
    }
    // The cube recedes sideways (β = 0.5 along x, seen along y): Doppler alone changes its
    // colour, the searchlight then its brightness but not its colour much.
    assert!((pixels[0] - pixels[1]).abs() > 0.01, "{pixels:?}");
}

/// The exit status of the command with these arguments, and its standard error.
fn status(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "the command panicked: {err}");
    (out.status.code(), err)
}

/// Every user error exits with 1 (argument errors too, where clap's own is 2), help with 0;
/// numbers are echoed in their shortest form; a frame too large is blamed on the flag that
/// made it so; a time that is not a finite number is the flag's error.
#[test]
fn messages_and_exit_status() {
    let d = Dir::new("messages");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("out.png");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let (code, err) = status(&["render", "--nonsense"]);
    assert_eq!(code, Some(1), "{err}");
    let (code, _) = status(&["--help"]);
    assert_eq!(code, Some(0));
    let (code, err) = status(&["render", s, "-o", o, "--time", "nan"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--time") && err.contains("finite"), "{err}");
    let (code, err) = status(&["render", s, "-o", o, "--set", "camera.fov_y=1e308"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("(got 1e308)") && !err.contains("00000000"),
        "{err}"
    );
    let (code, err) = status(&[
        "render", s, "-o", o, "--width", "20000", "--height", "20000",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--width 20000") && !err.contains("scene.toml"),
        "{err}"
    );
    // A key rejected where it stands says why, and does not suggest itself.
    let lone = d.file(
        "lone.toml",
        &with("velocity = [0.5, 0, 0]", "direction = [1, 0, 0]"),
    );
    let (code, err) = status(&["render", lone.to_str().unwrap(), "-o", o]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("group.cube.direction") && err.contains("give the speed too"),
        "{err}"
    );
    assert!(!err.contains("did you mean `direction`"), "{err}");
    let mut entries = d.entries();
    entries.sort();
    assert_eq!(entries, ["lone.toml", "scene.toml"], "nothing written");
}
