//! The real binary: good renders write EXR and PNG; bad input of each kind gives a clear error
//! naming the file, line and key (or the flag), a non-zero exit, and no output file.

use crate::common::cli::*;
use std::path::Path;

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
    for name in [
        "R",
        "G",
        "B",
        "A",
        "lookback.V",
        "doppler.V",
        "object_id.V",
        "Z",
    ] {
        let c = ch
            .get(name)
            .unwrap_or_else(|| panic!("channel {name} missing; have {:?}", ch.keys()));
        assert!(c.iter().all(|v| v.is_finite()), "channel {name} is finite");
    }
    let ids = &ch["object_id.V"];
    let lookback = &ch["lookback.V"];
    let doppler = &ch["doppler.V"];
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
    // The line is shown with a caret under the place, as cargo shows errors.
    let d = Dir::new("caret");
    let scene = d.file("scene.toml", &with("fov_y = 30", "fov_y = [1 2]"));
    let (ok, err) = run(&["render", scene.to_str().unwrap(), "-o", "x.png"]);
    assert!(!ok);
    assert!(
        err.contains("\n4 | fov_y = [1 2]\n  |            ^"),
        "{err}"
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
        &["scene.toml:4", "camera.fov_y", "below 180 degrees"],
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
    // Values that do not fit the others are named at their own line, not the table's.
    fails(
        "same",
        &with("look_at = [0, 10, 0]", "look_at = [0, 0, 0]"),
        &[],
        &["scene.toml:3", "camera.look_at", "zero length"],
    );
    fails(
        "up",
        &with(
            "look_at = [0, 10, 0]",
            "look_at = [0, 10, 0]\nup = [0, 1, 0]",
        ),
        &[],
        &["scene.toml:4", "camera.up", "parallel"],
    );
    fails(
        "direction",
        &with(
            "velocity = [0.5, 0, 0]",
            "direction = [0, 0, 0]\nbeta = 0.5",
        ),
        &[],
        &["scene.toml:21", "group.cube.direction", "zero vector"],
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
    // A flag whose value would be lost: the same value set twice, an EXR's option on a PNG.
    fails(
        "set-twice",
        GOOD,
        &["--width", "20", "--set", "image.width=10"],
        &["--width", "`--set image.width=10` sets the same value"],
    );
    for (flag, value) in [
        ("--half", None),
        ("--compression", Some("piz")),
        ("--passes", Some("depth")),
    ] {
        let mut extra = vec![flag];
        extra.extend(value);
        fails(
            &format!("png{flag}"),
            GOOD,
            &extra,
            &[flag, "applies to an EXR", "PNG"],
        );
    }
    let d = Dir::new("bench-case");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("bench");
    let (code, err) = status(&[
        "bench",
        scene.to_str().unwrap(),
        "--case",
        "nothing",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--case") && err.contains("suite"), "{err}");
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
        "--set",
        "image.transparent=false",
    ];
    let (ok, err) = run(&args);
    assert!(ok, "{err}");
    let (_, _, ch) = rest_embree::output::read_exr_channels(Path::new(&out)).unwrap();
    let bg = ch["object_id.V"].iter().position(|&i| i == 0.0).unwrap();
    assert_eq!((ch["R"][bg], ch["G"][bg], ch["B"][bg]), (0.25, 0.5, 1.0));
    assert!(ch["A"].iter().all(|&a| a == 1.0), "opaque: alpha 1");
}

/// A bare file name or path given with `--set` is a string, as a bare word is: the scene then
/// fails at the file it names (which is missing), not at the value.
#[test]
fn set_takes_a_bare_file_name_as_a_string() {
    let d = Dir::new("set-file");
    let text = format!("{GOOD}\n[[texture]]\nname = \"map\"\nimage = \"here.png\"\n");
    let scene = d.file("scene.toml", &text);
    let out = d.0.join("o.png");
    for name in [
        "nothere.png",
        "infile.png",
        "x.png",
        "maps/x.png",
        "./x.png",
    ] {
        let set = format!("texture.map.image={name}");
        let (ok, err) = run(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--set",
            &set,
        ]);
        assert!(!ok);
        assert!(
            err.contains(name.trim_start_matches("./")) && !err.contains("TOML value"),
            "{name}: {err}"
        );
    }
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "camera.fov_y=1.5.2",
    ]);
    assert!(!ok && err.contains("not a TOML value"), "{err}");
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
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .arg("backends")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("embree (default)"), "{text}");
    assert!(text.contains("bvh"));
}

/// The bench's whole-command rows come from `bench-lattice` in a process of its own: its
/// Markdown line names the lattice and the backend, and its seconds follow for the ratio.
#[test]
fn bench_lattice_prints_its_line_and_its_seconds() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(["bench-lattice", "10", "32", "bvh", "1"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with("- "))
        .unwrap_or_default();
    assert!(
        line.starts_with(
            "- lattice 10^3 (3700 primitives) at 32^2, 1 spp, 0.9c, EXR, bvh: whole command "
        ),
        "{text}"
    );
    let seconds: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("whole_s "))
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no seconds: {text}"));
    assert!(seconds > 0.0 && seconds.is_finite(), "{seconds}");
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
    let svg = std::fs::read_to_string(out.join("bench.svg")).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("render time (s)") && svg.contains("<circle"),
        "a plot with points: {svg}"
    );
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
    // Said plainly, and leaving no folder behind (the fifth trial): the file in --out's way,
    // no repeat, and a refused scene's bench.
    let (ok, err) = run(&["bench", "--quick", "--out", blocker.to_str().unwrap()]);
    assert!(
        !ok && err.contains("not-a-folder is a file, not a folder"),
        "{err}"
    );
    let fresh = d.0.join("fresh");
    let (ok, err) = run(&["bench", "--repeat", "0", "--out", fresh.to_str().unwrap()]);
    assert!(!ok && err.contains("--repeat"), "{err}");
    let scene = d.file("scene.toml", GOOD);
    let (ok, err) = run(&[
        "bench",
        scene.to_str().unwrap(),
        "--backend",
        "no-such",
        "--out",
        fresh.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("no-such"), "{err}");
    assert!(!fresh.exists(), "a refused bench leaves no folder it made");
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

/// A reader that has gone (`rest-embree backends | head -1`) ends the output quietly: no panic,
/// no error, the command's status unchanged.
#[test]
fn output_to_a_closed_pipe_is_dropped_quietly() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .arg("backends")
        .stdout(writer)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "status {:?}: {err}", out.status);
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.trim().is_empty(), "nothing on standard error: {err}");
}

/// Messages that cannot be written (standard error on a full device, or a closed pipe) are
/// lost, not turned into a panic: a refused scene still exits 1, a good render 0, and a
/// command whose standard output and error are both full still ends with its own status.
#[test]
fn messages_that_cannot_be_written_leave_the_exit_status() {
    let d = Dir::new("unwritable-stderr");
    let bad = d.0.join("bad.toml");
    std::fs::write(&bad, with("fov_y = 30", "fov_y = -30")).unwrap();
    let good = d.0.join("good.toml");
    std::fs::write(&good, GOOD).unwrap();
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let run = |args: &[&str], stdout_full: bool| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"));
        c.args(args).stderr(full());
        if stdout_full {
            c.stdout(full());
        }
        c.status().unwrap().code()
    };
    let png = d.0.join("x.png");
    let (bad, good, png) = (
        bad.to_str().unwrap(),
        good.to_str().unwrap(),
        png.to_str().unwrap(),
    );
    assert_eq!(run(&["render", bad, "-o", png], false), Some(1));
    assert!(!Path::new(png).exists(), "no file from a refused scene");
    assert_eq!(run(&["render", good, "-o", png], false), Some(0));
    assert!(Path::new(png).exists());
    assert_eq!(run(&["backends"], true), Some(0));
    assert_eq!(run(&["no-such-command"], true), Some(1));
}
