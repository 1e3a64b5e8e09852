//! The real binary on colours and on careless input: bad spectra name their line and key, the
//! switches change the picture, every user error exits 1 with a message that points.

use crate::common::cli::*;

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

/// No file is lost: the scene file is never written over, a link is written through, a
/// read-only image is left as it is, a dead run's partial file is cleaned up; and a thread
/// count beyond any use is refused before anything starts.
#[test]
fn files_are_never_lost() {
    let d = Dir::new("files");
    // A scene file whose name ends in .png, given as the output.
    let scene = d.file("scene.png", GOOD);
    let s = scene.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", s]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("-o") && err.contains("scene file"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&scene).unwrap(),
        GOOD,
        "the scene is intact"
    );
    #[cfg(unix)]
    {
        let real = d.file("real.png", "old");
        let link = d.0.join("link.png");
        std::os::unix::fs::symlink("real.png", &link).unwrap();
        let (code, err) = status(&["render", s, "-o", link.to_str().unwrap(), "-q"]);
        assert_eq!(code, Some(0), "{err}");
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(
            &std::fs::read(&real).unwrap()[1..4],
            b"PNG",
            "written through the link"
        );
    }
    let kept = d.file("kept.png", "keep");
    let mut p = std::fs::metadata(&kept).unwrap().permissions();
    p.set_readonly(true);
    std::fs::set_permissions(&kept, p).unwrap();
    let (code, err) = status(&["render", s, "-o", kept.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("read-only"), "{err}");
    assert_eq!(std::fs::read_to_string(&kept).unwrap(), "keep");
    // A partial file of a run that was killed (no process has this id) goes with the next run.
    let out = d.0.join("out.png");
    let stale = rest_embree::output::file::partial_path(&out, 4_194_305);
    std::fs::write(&stale, "half").unwrap();
    let (code, err) = status(&["render", s, "-o", out.to_str().unwrap(), "-q"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        !stale.exists() || !cfg!(target_os = "linux"),
        "the stale partial file is gone"
    );
    let (code, err) = status(&[
        "render",
        s,
        "-o",
        out.to_str().unwrap(),
        "--threads",
        "100000",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--threads") && err.contains("per core"),
        "{err}"
    );
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

/// A render stopped by SIGTERM (or Ctrl-C) leaves no partial file: a PNG is written as it
/// renders, so its partial file exists for the whole render.
#[cfg(unix)]
#[test]
fn a_stopped_render_leaves_no_partial_file() {
    use std::time::{Duration, Instant};
    let d = Dir::new("signal");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("out.png");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args([
            "--width",
            "4000",
            "--height",
            "4000",
            "--samples",
            "64",
            "-q",
        ])
        .spawn()
        .unwrap();
    let partial = rest_embree::output::file::partial_path(&d.0.join("out.png"), child.id());
    let start = Instant::now();
    while !partial.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no partial file appeared"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render ended too soon to stop"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert!(!partial.exists(), "the partial file is removed");
    assert!(!out.exists(), "no image");
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

/// A still goes into a folder that does not exist yet, as a film's frames do.
#[test]
fn a_still_makes_its_folder() {
    let d = Dir::new("still-folder");
    let scene = d.file("scene.toml", GOOD);
    let out = d.0.join("new/deeper/out.png");
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.is_file());
}

/// A special file is neither replaced nor read forever: an output that is, or links to, a FIFO
/// or a device (`-o /dev/null`) is refused and left as it is; a scene path that is a device
/// ends with an error (`/dev/urandom`: not text; `/dev/zero`: text without end).
#[cfg(unix)]
#[test]
fn special_files_are_neither_replaced_nor_read_forever() {
    use std::os::unix::fs::FileTypeExt;
    let d = Dir::new("special");
    let scene = d.file("scene.toml", GOOD);
    let fifo = d.0.join("fifo.png");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let link = d.0.join("link.png");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    // `-o /dev/null` itself is refused for its name (no .png or .exr); a link named so is not.
    let null = d.0.join("null.exr");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    for (out, kind) in [
        (fifo.as_path(), "a FIFO"),
        (link.as_path(), "a FIFO"),
        (null.as_path(), "a character device"),
    ] {
        let (code, err) = status(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, Some(1), "{}: {err}", out.display());
        assert!(
            err.contains(&format!(
                "it is not a regular file ({kind}); it was left as it is"
            )),
            "{}: {err}",
            out.display()
        );
    }
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    for (source, says) in [
        ("/dev/urandom", "not UTF-8 text"),
        (
            "/dev/zero",
            "not a regular file, and more than 256 MiB came from it",
        ),
    ] {
        let out = d.0.join("out.png");
        let (code, err) = status(&["render", source, "-o", out.to_str().unwrap()]);
        assert_eq!(code, Some(1), "{source}: {err}");
        assert!(
            err.contains(source) && err.contains(says),
            "{source}: {err}"
        );
        assert!(!out.exists());
    }
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

/// Colours given as RGB that a scene shows far shifted (a dark-blue sky approached at 0.5c:
/// D = 1.73 ahead) are warned of once, saying why; not where the colour is grey (exactly flat)
/// or the Doppler shift is off.
#[test]
fn far_shifted_rgb_colours_are_warned_of() {
    let scene = "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 10, 0]\nvelocity = [0, 0.5, 0]\n\
                 [image]\nwidth = 16\nheight = 16\nbackground = [0.02, 0.05, 0.3]\n\
                 [[group]]\nname = \"g\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [0, 10, 0]\nradius = 1\n";
    let d = Dir::new("shift-warning");
    let out = d.0.join("out.png");
    let o = out.to_str().unwrap();
    let blue = d.file("blue.toml", scene);
    let (ok, err) = run(&["render", blue.to_str().unwrap(), "-o", o]);
    assert!(ok, "{err}");
    let warning = err
        .lines()
        .skip_while(|l| !l.starts_with("warning:"))
        .take(2)
        .collect::<Vec<_>>();
    assert_eq!(err.matches("warning:").count(), 1, "{err}");
    assert_eq!(warning.len(), 2, "two lines: {err}");
    for needle in [
        "D = 1.73",
        "the background",
        "0.50c",
        "outside 380-780 nm",
        "6.1",
        "as spectra",
        "rgb_shift_warning = false",
        "--quiet",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // --quiet prints nothing at all; the key silences the warning alone.
    let (ok, err) = run(&["render", blue.to_str().unwrap(), "-o", o, "-q"]);
    assert!(ok && err.is_empty(), "{err}");
    let (ok, err) = run(&[
        "render",
        blue.to_str().unwrap(),
        "-o",
        o,
        "--set",
        "render.rgb_shift_warning=false",
    ]);
    assert!(ok && !err.contains("warning:"), "{err}");
    let grey = d.file("grey.toml", &scene.replace("[0.02, 0.05, 0.3]", "0.2"));
    let (ok, err) = run(&["render", grey.to_str().unwrap(), "-o", o]);
    assert!(ok && !err.contains("warning:"), "{err}");
    let (ok, err) = run(&[
        "render",
        blue.to_str().unwrap(),
        "-o",
        o,
        "--set",
        "render.doppler=false",
    ]);
    assert!(ok && !err.contains("warning:"), "{err}");
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
