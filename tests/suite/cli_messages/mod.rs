//! The real binary on careless input: every user error exits 1 with a message that points
//! (the flags, slips, counts and sizes, the memory limit, hostile input), and the progress bar
//! shows on a terminal only. Colours and spectra in colours.rs; files never lost in files.rs.

use crate::common::cli::*;

mod colours;
mod files;

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
        err.contains("1e308 is beyond") && !err.contains("00000000"),
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

/// A render that would not fit in memory is refused before it starts, with the estimate, the
/// limit and the flag that set the size.
#[test]
fn renders_beyond_the_memory_limit_are_refused() {
    let d = Dir::new("memory");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("out.exr");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let (code, err) = status(&[
        "render",
        s,
        "-o",
        o,
        "--width",
        "4096",
        "--height",
        "4096",
        "--max-memory",
        "64M",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--width") && err.contains("MiB of memory") && err.contains("64 MiB"),
        "{err}"
    );
    let (code, err) = status(&["render", s, "-o", o, "--max-memory", "lots"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--max-memory"), "{err}");
    let (code, err) = status(&["render", s, "-o", o, "--max-memory", "64M", "-q"]);
    assert_eq!(code, Some(0), "a small render fits: {err}");
    assert!(out.exists());
    // A scene file too large to read within the limit (here 200 kB of comment at 1 MiB: its
    // text, at 8 bytes of memory per byte, before a value is counted).
    let padded = d.file(
        "padded.toml",
        &format!("{GOOD}\n#{}\n", "x".repeat(200_000)),
    );
    let p = padded.to_str().unwrap();
    let (code, err) = status(&["render", p, "-o", o, "--max-memory", "1M"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("padded.toml") && err.contains("reading a scene file"),
        "{err}"
    );
}

/// A render longer than half a second shows a progress bar when stderr is a terminal (here a
/// pseudo-terminal from `script`), and none when it is a file or with --quiet.
#[cfg(unix)]
#[test]
fn a_progress_bar_on_a_terminal_only() {
    let d = Dir::new("progress");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("out.png");
    let args = [
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "2000",
        "--height",
        "2000",
        "--samples",
        "16",
    ];
    let on_a_terminal = |extra: &str| {
        let cmd = format!(
            "{} {} {extra}",
            env!("CARGO_BIN_EXE_rest-embree"),
            args.join(" ")
        );
        let out = std::process::Command::new("script")
            .args(["-qec", &cmd, "/dev/null"])
            .output()
            .expect("script (util-linux) runs a command on a pseudo-terminal");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let shown = on_a_terminal("");
    assert!(
        shown.contains("rendering [")
            && shown.contains("left")
            && shown.contains("out.png: 2000x2000"),
        "a bar, then the summary: {shown}"
    );
    assert!(
        !on_a_terminal("--quiet").contains("rendering ["),
        "--quiet: no bar"
    );
    let (code, err) = status(&args);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        !err.contains("rendering [") && err.contains("out.png: 2000x2000"),
        "{err}"
    );
    // Rounds under a noise target: the round, the samples and the noise so far, within half a
    // second of the start (the bar is drawn a few times a second once shown).
    let path = GOOD.replace("[image]\n", "[image]\nsamples = 4096\n")
        + "[render]\nintegrator = \"path\"\n";
    let path_scene = d.file("path.toml", &path);
    let cmd = format!(
        "{} render {} -o {} --width 400 --height 400 --target-rms 1e-9 --max-time 2",
        env!("CARGO_BIN_EXE_rest-embree"),
        path_scene.display(),
        out.display()
    );
    let t0 = std::time::Instant::now();
    let rounds = std::process::Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .unwrap();
    let shown = String::from_utf8_lossy(&rounds.stdout);
    assert!(t0.elapsed().as_secs() < 20);
    assert!(
        shown.contains("rendering round ")
            && shown.contains("/4096 spp, RMS ")
            && shown.contains("(target 1.0e-9)")
            && shown.contains(" s left")
            && shown.contains("stopped by time"),
        "{shown}"
    );
    // The bench: a bar over its cases on a terminal, a line per case otherwise.
    let out = d.0.join("bench");
    let case = "lattice beta=0.9, no lights";
    let bench = format!(
        "{} bench --quick --repeat 1 --case '{case}' --out {}",
        env!("CARGO_BIN_EXE_rest-embree"),
        out.display()
    );
    let tty = std::process::Command::new("script")
        .args(["-qec", &bench, "/dev/null"])
        .output()
        .unwrap();
    let shown = String::from_utf8_lossy(&tty.stdout);
    assert!(
        shown.contains("bench [") && shown.contains("/1 cases") && shown.contains(case),
        "{shown}"
    );
    let o = out.to_str().unwrap();
    let quick = [
        "bench", "--quick", "--repeat", "1", "--case", case, "--out", o,
    ];
    let (code, err) = status(&quick);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains(&format!("bench: {case}")) && !err.contains("bench ["),
        "{err}"
    );
}

/// A newcomer's slips, each told what is wrong and what is accepted: a table name in the wrong
/// case (at its own line, with what was meant on a line of its own), a colour by name, a
/// number of samples with a point, a `--set` value the shell split at its spaces.
#[test]
fn slips_say_what_would_be_accepted() {
    fails(
        "camera-case",
        &with("[camera]", "[Camera]"),
        &[],
        &[
            "scene.toml:1:",
            "key `Camera`: unknown table\n  did you mean `[camera]`?",
            "case-sensitive",
        ],
    );
    fails(
        "colour-name",
        &with("color = [0.8, 0.8, 0.8]", "color = \"red\""),
        &[],
        &[
            "scene.toml:13",
            "expected a colour, found a string",
            "[r, g, b]",
            "{ blackbody = T }",
        ],
    );
    // A slip inside an inline table: the key blamed, not a missing one.
    fails(
        "checker-colour",
        &with(
            "color = [0.8, 0.8, 0.8]",
            "color = \"squares\"\n[[texture]]\nname = \"squares\"\nchecker = { size = 0.5, colour1 = 0.9, color2 = 0.1 }",
        ),
        &[],
        &[
            "checker.colour1",
            "unknown key\n  did you mean `color1`?",
        ],
    );
    fails(
        "samples-point",
        &with("height = 32", "height = 32\nsamples = 4.5"),
        &[],
        &["image.samples", "whole number", "4 or 5 would do"],
    );
    // An integer past 64 bits: its range said, and a float offered only where any number is
    // taken (a seed of 1e20 is no whole number the seed takes).
    fails(
        "seed-2-64",
        &with(
            "height = 32",
            "height = 32\n[render]\nseed = 18446744073709551616",
        ),
        &[],
        &[
            "does not fit 64 bits (-2^63 to 2^63 - 1",
            "a key that takes any number takes it as a float",
        ],
    );
    let d = Dir::new("set-split");
    let scene = d.file("scene.toml", GOOD);
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        "out.png",
        "--set",
        "group.cube.velocity=[0.9,",
        "0,",
        "0]",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("quote it whole: --set 'group.cube.velocity=[0.9, 0, 0]'"),
        "{err}"
    );
}

/// Counts and sizes said as they are: a film one frame over the limit names its real number
/// of frames, and a memory limit below a MiB is not "0 MiB".
#[test]
fn counts_and_sizes_are_said_exactly() {
    // Frames at 0, 1, ..., 1,000,000: one more than the 1,000,000 allowed.
    fails(
        "film-count",
        &format!("{GOOD}\n[film]\nstart = 0\nend = 1000000\nfps = 1\n"),
        &[],
        &["the film would have 1000001 frames; at most 1000000"],
    );
    fails("memory-1k", GOOD, &["--max-memory", "1K"], &["1 KiB"]);
}

/// A scene file whose values would not fit in the memory allowed is refused before it is
/// parsed, naming the file and the limit, though its text alone would fit: 200,000 vertices
/// of 8 bytes are 1.6 MB of text and about 150 MiB of tree.
#[test]
fn a_scene_whose_values_do_not_fit_is_refused_before_parsing() {
    let vertices = vec!["[0,0,0]"; 200_000].join(",");
    let text = format!(
        "{GOOD}\n[[group]]\nname = \"mesh\"\n[[group.object]]\ntype = \"mesh\"\nvertices = [{vertices}]\nindices = [[0, 1, 2]]\n"
    );
    fails(
        "values-too-big",
        &text,
        &["--max-memory", "60M"],
        &[
            "scene.toml",
            "every value kept with its line",
            "--max-memory",
        ],
    );
}

/// Hostile input, round three: each exits 1 with a message that names the file, line or flag,
/// quickly and small, and never echoes a control character from a file to the terminal.
#[test]
fn round_three_inputs_are_clear_errors() {
    let d = Dir::new("hostile-three");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("out.png");
    let render = |scene: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        status(&args)
    };
    // Flags: a time budget past 31 years, an empty or self-contradicting pass list.
    for (extra, needles) in [
        (&["--max-time", "1e20"][..], &["--max-time", "at most"][..]),
        (&["--passes", ""], &["--passes", "empty"]),
        (&["--passes", "all,none"], &["--passes", "cannot stand"]),
        (&["--passes", "depth,,normal"], &["--passes", "empty name"]),
    ] {
        let (code, err) = render(&scene, extra);
        assert_eq!(code, Some(1), "{extra:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{extra:?}: `{n}` in {err}");
        }
    }
    // A mesh named through a scene: a PLY bomb, an OBJ with escape sequences in a bad line.
    let with_mesh = |file: &str| {
        GOOD.replace(
            "type = \"box\"\nmin = [-0.5, 10, -0.5]\nmax = [0.5, 11, 0.5]",
            &format!("type = \"mesh\"\nfile = \"{file}\""),
        )
    };
    d.file(
        "bomb.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
    );
    d.file(
        "title.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \u{1b}]0;pwned\u{7}\n",
    );
    d.file("bom.obj", "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    for (file, needles) in [
        (
            "bomb.ply",
            &["bomb.ply", "4000000000 entries", "more than the file's"][..],
        ),
        ("title.obj", &["title.obj:4", "\\x1b]0;pwned\\x07"][..]),
        ("bom.obj", &["bom.obj:4", "index 0"][..]),
    ] {
        let s = d.file("mesh.toml", &with_mesh(file));
        assert!(
            std::fs::read_to_string(&s).unwrap().contains(file),
            "the scene names {file}"
        );
        let t0 = std::time::Instant::now();
        let (code, err) = render(&s, &[]);
        assert_eq!(code, Some(1), "{file}: {err}");
        assert!(t0.elapsed().as_secs() < 10, "{file}: quickly");
        assert!(
            !err.contains('\u{1b}') && !err.contains('\u{7}'),
            "{file}: {err:?}"
        );
        for n in needles {
            assert!(err.contains(n), "{file}: `{n}` in {err}");
        }
    }
    // An EXR sky map whose header claims 1,000,000 x 100,000 texels: refused from its header.
    let small = d.0.join("small.exr");
    let (code, err) = status(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        small.to_str().unwrap(),
        "--width",
        "4",
        "--height",
        "4",
        "--passes",
        "none",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let mut bytes = std::fs::read(&small).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    for (k, v) in [0i32, 0, 999_999, 99_999].iter().enumerate() {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
    std::fs::write(d.0.join("huge.exr"), &bytes).unwrap();
    let sky = d.file("sky.toml", &format!("{GOOD}\n[sky]\nmap = \"huge.exr\"\n"));
    let (code, err) = render(&sky, &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("huge.exr") && err.contains("1000000x100000"),
        "{err}"
    );
    // A camera's worldline of too many segments says it is the camera's.
    let segments = vec!["{ until = 0.0, velocity = [0, 0, 0] }"; 4097].join(", ");
    let camera = d.file(
        "camera.toml",
        &GOOD.replace(
            "[camera]\n",
            &format!("[camera]\nworldline = [{segments}]\n"),
        ),
    );
    let (code, err) = render(&camera, &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("camera's worldline") && !err.contains("group"),
        "{err}"
    );
    assert!(!out.exists());
}

/// The fifth trial's unclear words, each now said: a file where `-o`'s folder would go, a grid
/// of more tiles than a u32, an unknown `REST_EMBREE_SIMD`, and a negative number given to a
/// flag (clap took it for an unknown flag).
#[test]
fn odd_outputs_grids_environments_and_negative_flags_are_said() {
    let d = Dir::new("odd-words");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let under = format!("{s}/out.png");
    let (code, err) = status(&["render", s, "-o", &under]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("-o: cannot make the folder")
            && err.contains("scene.toml is a file, not a folder"),
        "{err}"
    );
    let out = d.0.join("out.exr");
    let o = out.to_str().unwrap();
    let (code, err) = status(&[
        "render",
        s,
        "-o",
        o,
        "--tiles",
        "99999999999x1",
        "--tile",
        "0",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("is more tiles than an image has pixels"),
        "{err}"
    );
    let (code, err, _) = status_with_env(&["render", s, "-o", o], &[("REST_EMBREE_SIMD", "maybe")]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("REST_EMBREE_SIMD: `maybe` is neither `off`"),
        "{err}"
    );
    let (code, err, _) =
        status_with_env(&["render", s, "-o", o, "-q"], &[("REST_EMBREE_SIMD", "on")]);
    assert_eq!(code, Some(0), "{err}");
    let (code, err) = status(&["render", s, "-o", o, "--width", "-5"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--width -5: key `image.width`: must be a whole number"),
        "{err}"
    );
}
