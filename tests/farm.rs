//! Tiles and farms without a cluster: tiles rendered with `--tiles NxM --tile I` and joined by
//! `rest-embree assemble` make the whole render's EXR, byte for byte; `farm slurm` writes job
//! arrays that, run as SLURM runs them (a stand-in `sbatch` on PATH records the submissions, and
//! each task's script is run with its SLURM_ARRAY_TASK_ID), make the same files as local renders.
//! A real one-node SLURM cluster runs the same in scripts/slurm-test.sh.

mod common;
use common::cli::*;
use std::path::{Path, PathBuf};
use std::process::Command;

fn render(args: &[&str]) {
    let (ok, err) = run(args);
    assert!(ok, "{args:?}: {err}");
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn assembled_tiles_are_the_whole_render() {
    let d = Dir::new("tiles");
    let scene = d.file("scene.toml", GOOD);
    let size = ["--width", "45", "--height", "31", "--samples", "2"];
    let whole = d.0.join("whole.exr");
    render(&[&["render", s(&scene), "-o", s(&whole)][..], &size].concat());
    let mut tiles = Vec::new();
    for i in 0..6 {
        let t = d.0.join(format!("t{i}.exr"));
        render(
            &[
                &[
                    "render",
                    s(&scene),
                    "-o",
                    s(&t),
                    "--tiles",
                    "3x2",
                    "--tile",
                    &i.to_string(),
                ][..],
                &size,
            ]
            .concat(),
        );
        tiles.push(t);
    }
    let (w, h, _) = rest_embree::output::read_exr_channels(&tiles[4]).unwrap();
    assert_eq!((w, h), (15, 16), "tile 4: columns 15..30, rows 15..31");
    tiles.reverse();
    let joined = d.0.join("joined.exr");
    let mut args = vec!["assemble", "-o", s(&joined)];
    args.extend(tiles.iter().map(|t| s(t)));
    render(&args);
    assert!(
        std::fs::read(&joined).unwrap() == std::fs::read(&whole).unwrap(),
        "the assembled tiles are the whole render's file"
    );
    // Missing and doubled tiles are refused, and nothing is written.
    let bad = d.0.join("bad.exr");
    let (ok, err) = run(&["assemble", "-o", s(&bad), s(&tiles[0]), s(&tiles[1])]);
    assert!(!ok && err.contains("uncovered"), "{err}");
    let (ok, err) = run(&["assemble", "-o", s(&bad), s(&tiles[0]), s(&tiles[0])]);
    assert!(!ok && err.contains("overlaps"), "{err}");
    // A tile of another render (another view time) among them is refused.
    let other = d.0.join("other.exr");
    render(
        &[
            &[
                "render",
                s(&scene),
                "-o",
                s(&other),
                "--tiles",
                "3x2",
                "--tile",
                "0",
                "--time",
                "10.5",
            ][..],
            &size,
        ]
        .concat(),
    );
    let mut mixed = vec!["assemble", "-o", s(&bad)];
    mixed.extend(
        tiles
            .iter()
            .filter(|t| !t.ends_with("t0.exr"))
            .map(|t| s(t)),
    );
    mixed.push(s(&other));
    let (ok, err) = run(&mixed);
    assert!(!ok && err.contains("another render"), "{err}");
    assert!(!bad.exists());
}

/// `scene` with a 32768 x 32768 image: 2^30 pixels, four times what one render's frame holds.
fn huge_image(scene: &str) -> String {
    let text = scene.replace("width = 48\nheight = 32", "width = 32768\nheight = 32768");
    assert_ne!(text, scene, "the scene's [image] size is replaced");
    text
}

/// An image larger than one render's frame renders in tiles (each a frame), and is refused
/// whole, or in tiles still too large, naming the key or the flags.
#[test]
fn an_image_larger_than_a_frame_renders_in_tiles() {
    let d = Dir::new("huge-tiles");
    let scene = d.file("huge.toml", &huge_image(GOOD));
    let out = d.0.join("t.exr");
    let base = ["render", s(&scene), "-o", s(&out), "--passes", "none"];
    let (code, err) = status(&base);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("key `image.width`") && err.contains("--tiles"),
        "{err}"
    );
    let (code, err) = status(&[&base[..], &["--tiles", "1x2", "--tile", "1"]].concat());
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--tiles 1x2 --tile 1") && err.contains("finer grid"),
        "{err}"
    );
    render(&[&base[..], &["--tiles", "64x64", "--tile", "4095"]].concat());
    let (w, h, _) = rest_embree::output::read_exr_channels(&out).unwrap();
    assert_eq!((w, h), (512, 512));
}

#[test]
fn bad_tiles_are_clear_errors() {
    fails(
        "tiles-png",
        GOOD,
        &["--tiles", "2x2", "--tile", "1"],
        &["--tiles 2x2 --tile 1", ".exr"],
    );
    for (grid, tile, needle) in [
        ("2x2", "4", "tiles are 0..3"),
        ("49x1", "0", "does not fit"),
        ("0x2", "0", "count of tiles"),
    ] {
        let d = Dir::new(&format!("bad-tile-{grid}"));
        let scene = d.file("scene.toml", GOOD);
        let out = d.0.join("out.exr");
        let (code, err) = status(&[
            "render",
            s(&scene),
            "-o",
            s(&out),
            "--tiles",
            grid,
            "--tile",
            tile,
        ]);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains(needle), "{grid} {tile}: {err}");
        assert!(!out.exists());
    }
}

/// A stand-in `sbatch` that records each submission and answers with a job id.
fn fake_sbatch(dir: &Path) -> std::path::PathBuf {
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let path = bin.join("sbatch");
    std::fs::write(
        &path,
        format!(
            "#!/bin/bash\necho \"$@\" >> {}\nn=$(wc -l < {})\necho \"$((4000 + n))\"\n",
            dir.join("submitted").display(),
            dir.join("submitted").display()
        ),
    )
    .unwrap();
    Command::new("chmod")
        .args(["+x", s(&path)])
        .status()
        .unwrap();
    bin
}

fn farm(dir: &Path, args: &[&str]) -> (bool, String) {
    let path = format!(
        "{}:{}",
        fake_sbatch(dir).display(),
        std::env::var("PATH").unwrap()
    );
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(args)
        .env("PATH", path)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    (out.status.success(), err)
}

/// Run a job script as SLURM would run task `task` of it.
fn run_task(script: &Path, task: u64) {
    let st = Command::new("bash")
        .arg(script)
        .env("SLURM_ARRAY_TASK_ID", task.to_string())
        .status()
        .unwrap();
    assert!(st.success(), "{} task {task}", script.display());
}

#[test]
fn farm_scripts_make_the_local_renders() {
    let d = Dir::new("farm");
    let film = format!("{GOOD}\n[film]\nstart = 9.0\nend = 10.0\nfps = 2\n");
    let scene = d.file("film.toml", &film);
    let pattern = d.0.join("frames").join("f-###.exr");
    let (ok, err) = farm(
        &d.0,
        &[
            "farm",
            "slurm",
            s(&scene),
            "-o",
            s(&pattern),
            "--sbatch-arg=--time=5",
            "--set",
            "image.samples=2",
        ],
    );
    assert!(ok, "{err}");
    let submitted = std::fs::read_to_string(d.0.join("submitted")).unwrap();
    assert_eq!(submitted.lines().count(), 1, "{submitted}");
    assert!(submitted.starts_with("--parsable --time=5 "), "{submitted}");
    let script = d.0.join("frames/rest-embree-farm/f-frames.sbatch");
    let text = std::fs::read_to_string(&script).unwrap();
    assert!(text.contains("#SBATCH --array=0-2"), "{text}");
    for task in 0..3 {
        run_task(&script, task);
    }
    let local = d.0.join("local").join("f-###.exr");
    render(&[
        "render",
        s(&scene),
        "-o",
        s(&local),
        "-q",
        "--set",
        "image.samples=2",
    ]);
    for k in 0..3 {
        let name = format!("f-00{k}.exr");
        assert!(
            std::fs::read(d.0.join("frames").join(&name)).unwrap()
                == std::fs::read(d.0.join("local").join(&name)).unwrap(),
            "{name}"
        );
    }

    // A still in 2x2 tiles: the array, then the assembly after it.
    let still = d.file("still.toml", GOOD);
    let out = d.0.join("still.exr");
    let (ok, err) = farm(
        &d.0,
        &["farm", "slurm", s(&still), "-o", s(&out), "--tiles", "2x2"],
    );
    assert!(ok, "{err}");
    let submitted = std::fs::read_to_string(d.0.join("submitted")).unwrap();
    let lines: Vec<&str> = submitted.lines().collect();
    assert_eq!(lines.len(), 3, "{submitted}");
    assert!(
        lines[2].contains("--dependency=afterok:4002"),
        "{submitted}"
    );
    let logs = d.0.join("rest-embree-farm");
    for task in 0..4 {
        run_task(&logs.join("still-tiles.sbatch"), task);
    }
    run_task(&logs.join("still-assemble.sbatch"), 0);
    let whole = d.0.join("whole.exr");
    render(&["render", s(&still), "-o", s(&whole), "-q"]);
    assert!(std::fs::read(&out).unwrap() == std::fs::read(&whole).unwrap());
    assert!(
        !d.0.join("still.tile-0.exr").exists(),
        "tiles removed once assembled"
    );
}

#[test]
fn bad_farms_are_clear_errors() {
    let d = Dir::new("farm-bad");
    let film = d.file(
        "film.toml",
        &format!("{GOOD}\n[film]\nstart = 9.0\nend = 10.0\nfps = 2\n"),
    );
    let still = d.file("still.toml", GOOD);
    let huge = d.file("huge.toml", &huge_image(GOOD));
    let out = d.0.join("f-##.exr");
    for (args, needle) in [
        (
            vec![s(&huge), "-o", "x.exr", "--tiles", "2x1"],
            "up to 16384x32768",
        ),
        (
            vec![s(&film), "-o", s(&out), "--frames", "1..7"],
            "frames 0..2",
        ),
        (vec![s(&film), "-o", s(&out), "--tiles", "2x2"], "is a film"),
        (
            vec![s(&still), "-o", s(&out), "--frames", "0..1"],
            "not a film",
        ),
        (vec![s(&still), "-o", "x.png", "--tiles", "2x2"], ".exr"),
        (
            vec![s(&still), "-o", "x.exr", "--tiles", "100x1"],
            "does not fit",
        ),
        (vec![s(&film), "-o", "x.exr"], "frame pattern"),
        (vec![s(&still), "-o", "my renders/x.exr"], "has a space"),
    ] {
        let mut all = vec!["farm", "slurm"];
        all.extend(args);
        let (code, err) = status(&all);
        assert_eq!(code, Some(1), "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
    }
    // Without sbatch on PATH: an error that says so (a PATH with nothing on it).
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(["farm", "slurm", s(&still), "-o", s(&d.0.join("x.exr"))])
        .env("PATH", d.0.join("nothing"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("sbatch is not on PATH") && err.contains("--dry-run"),
        "{err}"
    );
    // --dry-run prints the scripts and submits nothing.
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args([
            "farm",
            "slurm",
            s(&film),
            "-o",
            s(&out_pattern(&d.0)),
            "--dry-run",
        ])
        .env("PATH", d.0.join("nothing"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("#SBATCH --array=0-2"),
        "{text}"
    );
    assert!(
        !d.0.join("rest-embree-farm").exists(),
        "a dry run writes nothing"
    );
}

fn out_pattern(dir: &Path) -> std::path::PathBuf {
    dir.join("g-##.exr")
}

/// An output name is text in the job scripts, never shell: `$(...)` and backticks in it run
/// nothing when the tasks run, the tiles and the whole image get that very name, and a `%` is
/// not taken by SLURM's `#SBATCH --output` pattern. A line break in it is refused by name.
#[test]
fn output_names_are_not_shell_or_slurm_patterns() {
    let d = Dir::new("farm-names");
    let still = d.file("still.toml", GOOD);
    for (k, name) in [
        "x$(touch${IFS}PWNED).exr",
        "y`touch${IFS}PWNED2`;touch${IFS}PWNED3;%j.exr",
    ]
    .iter()
    .enumerate()
    {
        let out = d.0.join(name);
        let (ok, err) = farm(
            &d.0,
            &["farm", "slurm", s(&still), "-o", s(&out), "--tiles", "2x1"],
        );
        assert!(ok, "{name}: {err}");
        let logs = d.0.join("rest-embree-farm");
        let scripts: Vec<_> = std::fs::read_dir(&logs)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "sbatch"))
            .collect();
        let tiles = scripts
            .iter()
            .find(|p| p.to_string_lossy().ends_with("-tiles.sbatch"))
            .unwrap();
        let assemble = scripts
            .iter()
            .find(|p| p.to_string_lossy().ends_with("-assemble.sbatch"))
            .unwrap();
        for p in &scripts {
            let text = std::fs::read_to_string(p).unwrap();
            for line in text.lines().filter(|l| l.starts_with("#SBATCH --output=")) {
                // The log folder's own `%` (none here) doubled; the patterns SLURM is meant
                // to fill are its own.
                assert!(!line.contains("%j.exr"), "{line}");
            }
        }
        for task in 0..2 {
            let st = Command::new("bash")
                .arg(tiles)
                .current_dir(&d.0)
                .env("SLURM_ARRAY_TASK_ID", task.to_string())
                .status()
                .unwrap();
            assert!(st.success(), "{name}: task {task}");
        }
        let st = Command::new("bash")
            .arg(assemble)
            .current_dir(&d.0)
            .status()
            .unwrap();
        assert!(st.success(), "{name}: assemble");
        assert!(out.is_file(), "{name}: the whole image under its own name");
        for pwned in ["PWNED", "PWNED2", "PWNED3"] {
            assert!(!d.0.join(pwned).exists(), "{name}: the name ran a command");
            assert!(
                !std::path::Path::new(pwned).exists(),
                "{name}: ran a command"
            );
        }
        std::fs::remove_dir_all(&logs).unwrap();
        let _ = k;
    }
    let (ok, err) = farm(
        &d.0,
        &[
            "farm",
            "slurm",
            s(&still),
            "-o",
            s(&d.0.join("a\nb.exr")),
            "--dry-run",
        ],
    );
    assert!(!ok);
    assert!(err.contains("has a line break"), "{err}");
}

/// A grid of more tiles than a job array takes (SLURM's MaxArraySize, read with scontrol where
/// it can be, else SLURM's default of 1001) is refused before anything is written or
/// submitted, with a grid that fits.
#[test]
fn a_grid_larger_than_a_job_array_is_refused() {
    let d = Dir::new("farm-array");
    let still = d.file("still.toml", GOOD);
    let out = d.0.join("big.exr");
    let (ok, err) = farm(
        &d.0,
        &[
            "farm",
            "slurm",
            s(&still),
            "-o",
            s(&out),
            "--tiles",
            "250x200",
            "--set",
            "image.width=1000",
            "--set",
            "image.height=1000",
        ],
    );
    assert!(!ok);
    assert!(
        err.contains("50000 tiles") && err.contains("MaxArraySize") && err.contains("--tiles "),
        "{err}"
    );
    assert!(!d.0.join("submitted").exists() && !d.0.join("rest-embree-farm").exists());
}

/// `oiiotool` with `args`; a missing tool is a set-up error, said so.
fn oiiotool(args: &[&str]) {
    let out = Command::new("oiiotool")
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("oiiotool ({e}): run scripts/setup.sh (openimageio-tools)"));
    assert!(
        out.status.success(),
        "oiiotool {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Tiles that are not what `render` writes, or not of one render, are refused before anything
/// is written, each with its name and why: whatever a header claims (a display window of 1e9
/// squared, pixels outside it, tiles, mipmaps, a lossy compression, parts, a line order), a
/// file cut short, junk, an empty file, a FIFO, a directory. Tiles with odd names join, and
/// what assemble writes passes OpenEXR's own validator.
#[test]
fn hostile_tiles_are_refused() {
    let d = Dir::new("hostile-tiles");
    let scene = d.file("scene.toml", GOOD);
    let size = ["--width", "40", "--height", "24"];
    let tile = |name: &str, i: usize, extra: &[&str]| {
        let t = d.0.join(name);
        let i = i.to_string();
        let mut args = vec![
            "render",
            s(&scene),
            "-o",
            s(&t),
            "--tiles",
            "2x1",
            "--tile",
            &i,
        ];
        args.extend_from_slice(&size);
        args.extend_from_slice(extra);
        render(&args);
        t
    };
    // Odd names join; the result is the whole render, and valid.
    let t0 = tile("tile one ünï\ncode.exr", 0, &[]);
    let t1 = tile("-t1.exr", 1, &[]);
    let whole = d.0.join("whole.exr");
    render(&[&["render", s(&scene), "-o", s(&whole)][..], &size].concat());
    let joined = d.0.join("joined \"quoted\".exr");
    render(&["assemble", "-o", s(&joined), "--", s(&t0), s(&t1)]);
    assert!(std::fs::read(&joined).unwrap() == std::fs::read(&whole).unwrap());
    assert!(
        common::exrcheck::valid(&joined),
        "exrcheck rejects the assembled file"
    );

    let made = |name: &str, make: &dyn Fn(&Path)| {
        let p = d.0.join(name);
        make(&p);
        p
    };
    let from_t0 = |args: &'static [&'static str]| {
        let t0 = t0.clone();
        move |p: &Path| {
            let mut all = vec![s(&t0)];
            all.extend_from_slice(args);
            all.extend(["-o", s(p)]);
            oiiotool(&all);
        }
    };
    let bytes = std::fs::read(&t0).unwrap();
    let cases: Vec<(PathBuf, &str)> = vec![
        (
            made(
                "huge.exr",
                &from_t0(&["--fullsize", "1000000000x1000000000"]),
            ),
            "display window) is 1000000000x1000000000",
        ),
        (
            made("outside.exr", &from_t0(&["--origin", "+1000+0"])),
            "lie outside the 40x24 full image",
        ),
        (
            made("tiled.exr", &from_t0(&["--tile", "16", "16"])),
            "stored in tiles",
        ),
        (
            made("mip.exr", &|p: &Path| oiiotool(&[s(&t0), "-otex", s(p)])),
            "mipmap",
        ),
        (
            made("dwaa.exr", &from_t0(&["--compression", "dwaa"])),
            "lossy",
        ),
        (
            made("parts.exr", &|p: &Path| {
                oiiotool(&[s(&t0), s(&t0), "--siappend", "-o", s(p)])
            }),
            "2 parts",
        ),
        (
            made("cut.exr", &|p: &Path| {
                std::fs::write(p, &bytes[..bytes.len() / 2]).unwrap()
            }),
            "not a readable EXR",
        ),
        (
            made("last-block-cut.exr", &|p: &Path| {
                std::fs::write(p, &bytes[..bytes.len() - 10]).unwrap()
            }),
            "cannot be read",
        ),
        (
            made("junk.exr", &|p: &Path| {
                std::fs::write(p, vec![0x5a; 5000]).unwrap()
            }),
            "not a readable EXR",
        ),
        (
            made("empty.exr", &|p: &Path| std::fs::write(p, b"").unwrap()),
            "not a readable EXR",
        ),
        (
            made("fifo.exr", &|p: &Path| {
                assert!(Command::new("mkfifo").arg(p).status().unwrap().success())
            }),
            "a FIFO",
        ),
        (
            made("dir.exr", &|p: &Path| std::fs::create_dir(p).unwrap()),
            "a directory",
        ),
        (
            made("decreasing.exr", &|p: &Path| decreasing_copy(&t0, p)),
            "not stored top to bottom",
        ),
        (tile("colour.exr", 0, &["--passes", "none"]), "channels"),
    ];
    let out = d.0.join("out.exr");
    for (bad, needle) in &cases {
        let (code, err) = status(&["assemble", "-o", s(&out), "--", s(bad), s(&t1)]);
        assert_eq!(code, Some(1), "{}: {err}", bad.display());
        assert!(
            err.contains(&bad.display().to_string()) && err.contains(needle),
            "{}: wanted `{needle}` in: {err}",
            bad.display()
        );
        assert!(!out.exists(), "{}: nothing is written", bad.display());
    }
}

/// `from` written again with its blocks stored bottom to top (a valid EXR, not one render writes).
fn decreasing_copy(from: &Path, to: &Path) {
    use exr::prelude::*;
    let mut image = read_all_flat_layers_from_file(from).unwrap();
    image.layer_data[0].encoding.line_order = LineOrder::Decreasing;
    image.write().to_file(to).unwrap();
}

/// Pieces of names that mean something to a shell, to SLURM's `#SBATCH --output` patterns or to
/// a terminal.
const ODD: [&str; 27] = [
    "$(touch${IFS}PWNED)",
    "`touch${IFS}PWNED`",
    ";touch${IFS}PWNED;",
    "'",
    "\"",
    "\\",
    "%j",
    "%%",
    "%A_%a",
    "*",
    "?",
    "[a]",
    "{a,b}",
    "!",
    "#",
    "~",
    "&",
    "|",
    "<>",
    "é",
    "雪",
    "=",
    "-",
    "--x",
    "$HOME",
    "${IFS}",
    "\t",
];

/// Scene files and outputs with random odd names, through `farm slurm --tiles` and its job
/// scripts run as SLURM would run them: each is refused with exit status 1, or makes the whole
/// image under its own name; no name runs a command. A fixed seed, so a failure reproduces.
#[test]
fn random_odd_names_run_no_commands() {
    let d = Dir::new("farm-odd-names");
    let mut rng = rest_embree::rng::Rng(0x0dd_5eed);
    let mut pick = || ODD[(rng.next_u64() % ODD.len() as u64) as usize];
    let (mut made, mut refused) = (0, 0);
    for n in 0..24 {
        let case = d.0.join(format!("case{n}"));
        std::fs::create_dir_all(&case).unwrap();
        let scene_name = format!("{}{}scene.toml", pick(), pick());
        let out_name = format!("{}{}{}.exr", pick(), pick(), pick());
        let scene = case.join(&scene_name);
        std::fs::write(&scene, GOOD).unwrap();
        let out = case.join("out").join(&out_name);
        let sets = ["--set", "image.width=8", "--set", "image.height=4"];
        let mut args = vec!["farm", "slurm", s(&scene), "-o", s(&out), "--tiles", "2x1"];
        args.extend(sets);
        let (ok, err) = farm(&case, &args);
        if !ok {
            // Refused with a clear message (farm() checked that it did not panic).
            assert!(
                err.starts_with("error: "),
                "{scene_name} -> {out_name}: {err}"
            );
            refused += 1;
            continue;
        }
        let logs = out.parent().unwrap().join("rest-embree-farm");
        let scripts: Vec<PathBuf> = std::fs::read_dir(&logs)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "sbatch"))
            .collect();
        let named = |end: &str| {
            scripts
                .iter()
                .find(|p| p.to_string_lossy().ends_with(end))
                .unwrap_or_else(|| panic!("{out_name}: no {end} in {scripts:?}"))
                .clone()
        };
        let (tiles, assemble) = (named("-tiles.sbatch"), named("-assemble.sbatch"));
        for task in 0..2 {
            let st = Command::new("bash")
                .arg(&tiles)
                .current_dir(&case)
                .env("SLURM_ARRAY_TASK_ID", task.to_string())
                .status()
                .unwrap();
            assert!(st.success(), "{scene_name} -> {out_name}: task {task}");
        }
        let st = Command::new("bash")
            .arg(&assemble)
            .current_dir(&case)
            .status()
            .unwrap();
        assert!(st.success(), "{scene_name} -> {out_name}: assemble");
        assert!(
            out.is_file(),
            "{scene_name} -> {out_name}: the image under its own name"
        );
        made += 1;
    }
    // No command ran, wherever a script or the shell might have run it.
    let found = Command::new("find")
        .args([s(&d.0), "/tmp", "-maxdepth", "4", "-name", "PWNED*"])
        .output()
        .unwrap();
    let found = String::from_utf8_lossy(&found.stdout);
    assert!(found.trim().is_empty(), "a name ran a command: {found}");
    eprintln!("24 odd names: {made} made the image, {refused} refused");
    assert!(made >= 8, "made {made}, refused {refused}");
}
