//! Tiles and farms without a cluster: tiles rendered with `--tiles NxM --tile I` and joined by
//! `rest-embree assemble` make the whole render's EXR, byte for byte; `farm slurm` writes job
//! arrays that, run as SLURM runs them (a stand-in `sbatch` on PATH records the submissions, and
//! each task's script is run with its SLURM_ARRAY_TASK_ID), make the same files as local renders.
//! A real one-node SLURM cluster runs the same in scripts/slurm-test.sh.

mod tiles;
use crate::common::cli::*;
use std::path::{Path, PathBuf};
use std::process::Command;

fn render(args: &[&str]) {
    let (ok, err) = run(args);
    assert!(ok, "{args:?}: {err}");
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `scene` with a 32768 x 32768 image: 2^30 pixels, four times what one render's frame holds.
fn huge_image(scene: &str) -> String {
    let text = scene.replace("width = 48\nheight = 32", "width = 32768\nheight = 32768");
    assert_ne!(text, scene, "the scene's [image] size is replaced");
    text
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
        // What every task's render would refuse, or sbatch would (the fifth trial's: each
        // was written into the scripts and submitted).
        (
            vec![s(&still), "-o", "x.png", "--passes", "depth"],
            "--passes: applies to an EXR",
        ),
        (
            vec![
                s(&still),
                "-o",
                "x.exr",
                "--width",
                "20",
                "--set",
                "image.width=10",
            ],
            "sets the same value",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--mem", "abc"],
            "--mem: `abc` is no value sbatch takes",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--mem", "8GiB"],
            "K, M, G or T",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--mem", "8B"],
            "K, M, G or T",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--sbatch-arg=--arr=0-3"],
            "the farm makes the job array itself",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--time", "abc"],
            "--time: `abc` is no value sbatch takes",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--time", "1:2:3:4"],
            "UNLIMITED",
        ),
        (
            vec![s(&still), "-o", "x.exr", "--sbatch-arg=--array=0-5"],
            "the farm makes the job array itself",
        ),
    ] {
        let mut all = vec!["farm", "slurm"];
        all.extend(args);
        let (code, err) = status(&all);
        assert_eq!(code, Some(1), "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
    }
    // A file the scene reads as the output, of a still, a tiled still (written by the
    // assembly) or a film's frame: refused before anything is submitted (from a review).
    let map = d.0.join("map.exr");
    render(&["render", s(&still), "-o", s(&map), "-q"]);
    let sky = d.file("sky.toml", &format!("{GOOD}\n[sky]\nmap = \"map.exr\"\n"));
    std::fs::copy(&map, d.0.join("m-01.exr")).unwrap();
    let sky_film = d.file(
        "sky-film.toml",
        &format!("{GOOD}\n[sky]\nmap = \"m-01.exr\"\n[film]\nstart = 9.0\nend = 10.0\nfps = 2\n"),
    );
    let frames = d.0.join("m-##.exr");
    for args in [
        vec![s(&sky), "-o", s(&map), "--dry-run"],
        vec![s(&sky), "-o", s(&map), "--tiles", "2x1", "--dry-run"],
        vec![s(&sky_film), "-o", s(&frames), "--dry-run"],
    ] {
        let mut all = vec!["farm", "slurm"];
        all.extend(args);
        let (code, err) = status(&all);
        assert_eq!(code, Some(1), "{all:?}: {err}");
        assert!(err.contains("which the scene reads"), "{all:?}: {err}");
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
    // The render's flags, as render takes them; the sbatch arguments, memory and time as
    // #SBATCH lines of the script itself (a resubmitted script keeps them), each default said.
    let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args([
            "farm",
            "slurm",
            s(&film),
            "-o",
            s(&out_pattern(&d.0)),
            "--dry-run",
            "--width",
            "64",
            "--samples",
            "2",
            "--passes",
            "depth",
            "--sbatch-arg=--partition=long",
            "--sbatch-arg=--cpus-per-task=2",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    for needle in [
        "#SBATCH --partition=long",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --mem=",
        "# (--mem: the render's estimate",
        "#SBATCH --time=0-",
        "on 2 CPUs",
        " --width '64'",
        " --samples '2'",
        " --passes 'depth'",
        "--resume",
        "a file system every node sees",
    ] {
        assert!(text.contains(needle), "`{needle}` in {text}");
    }
    let given = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args([
            "farm",
            "slurm",
            s(&film),
            "-o",
            s(&out_pattern(&d.0)),
            "--dry-run",
            "--mem",
            "4G",
            "--time",
            "1:00:00",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&given.stdout);
    assert!(
        text.contains("#SBATCH --mem=4G\n") && text.contains("#SBATCH --time=1:00:00\n"),
        "{text}"
    );
    // Every form sbatch documents is taken as it is.
    for (mem, time) in [
        ("0", "90"),
        ("512", "90:30"),
        ("8g", "1-12"),
        ("16GB", "45"),
        ("512mb", "45"),
        ("1T", "2-0:30"),
        ("64M", "3-04:05:06"),
        ("2K", "UNLIMITED"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_rest-embree"))
            .args([
                "farm",
                "slurm",
                s(&still),
                "-o",
                s(&d.0.join("x.exr")),
                "--dry-run",
                "--mem",
                mem,
                "--time",
                time,
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success()
                && text.contains(&format!("#SBATCH --mem={mem}\n"))
                && text.contains(&format!("#SBATCH --time={time}\n")),
            "{mem} {time}: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
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
