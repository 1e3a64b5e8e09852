//! Films (`[film]`, `--frames`, `--resume`): frame k is, bit for bit, the still rendered at its
//! view time and camera position; a killed film resumed gives the files of an uninterrupted one;
//! bad ranges and patterns are clear errors.

use crate::common::cli::*;
use std::path::Path;

/// The command-line tests' cube scene with its camera moving at `camera_beta` toward the cube.
fn still(camera_beta: f64) -> String {
    GOOD.replace(
        "time = 10\n",
        &format!("time = 10\nvelocity = [0, {camera_beta}, 0]\n"),
    )
}

fn film(camera_beta: f64, tail: &str) -> String {
    format!(
        "{}\n[film]\nstart = 8.0\nend = 9.0\nfps = 4\n{tail}",
        still(camera_beta)
    )
}

fn channels(path: &Path) -> Vec<(String, Vec<u32>)> {
    let (_, _, ch) = rest_embree::output::read_exr_channels(path).unwrap();
    let mut v: Vec<(String, Vec<u32>)> = ch
        .into_iter()
        .map(|(k, vals)| (k, vals.iter().map(|x| x.to_bits()).collect()))
        .collect();
    v.sort();
    v
}

fn render(args: &[&str]) {
    let (ok, err) = run(args);
    assert!(ok, "{args:?}: {err}");
}

#[test]
fn a_frame_is_the_still_at_its_view_time_and_camera_position() {
    for beta in [0.0, 0.6] {
        let d = Dir::new(&format!("film-still-{beta}"));
        let scene = d.file("film.toml", &film(beta, ""));
        let pattern = d.0.join("f-##.exr");
        render(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            pattern.to_str().unwrap(),
            "--frames",
            "1..3",
        ]);
        let files = d.entries();
        for k in 1..=3u64 {
            assert!(files.contains(&format!("f-0{k}.exr")), "{files:?}");
        }
        assert!(!files.contains(&"f-00.exr".to_string()), "--frames 1..3");
        assert!(!files.contains(&"f-04.exr".to_string()), "--frames 1..3");
        let still_scene = d.file("still.toml", &still(beta));
        for k in [1u64, 3] {
            let t = 8.0 + k as f64 / 4.0;
            // The camera is at the origin at world time 10 and moves with it.
            let y = beta * (t - 10.0);
            let out = d.0.join(format!("still-{k}.exr"));
            render(&[
                "render",
                still_scene.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--time",
                &format!("{t:?}"),
                "--set",
                &format!("camera.position=[0.0, {y:?}, 0.0]"),
            ]);
            let a = channels(&d.0.join(format!("f-0{k}.exr")));
            let b = channels(&out);
            assert!(a.len() >= 12, "{} channels", a.len());
            let alpha = &a.iter().find(|(n, _)| n == "A").unwrap().1;
            assert!(alpha.iter().any(|&x| x != 0), "the cube is in view");
            assert!(
                a == b,
                "beta {beta}, frame {k}: the frame differs from the still"
            );
        }
        // Frames differ from one another where the camera or the cube moved.
        if beta > 0.0 {
            assert!(channels(&d.0.join("f-01.exr")) != channels(&d.0.join("f-03.exr")));
        }
    }
}

#[test]
fn a_killed_film_resumed_gives_the_files_of_an_uninterrupted_one() {
    let d = Dir::new("film-resume");
    // Enough frames, and slow enough ones, that the film is still running when it is killed.
    let text = film(0.3, "").replace("end = 9.0", "end = 14.0").replace(
        "width = 48\nheight = 32",
        "width = 160\nheight = 120\nsamples = 4",
    );
    let scene = d.file("film.toml", &text);
    let whole = d.0.join("whole");
    let cut = d.0.join("cut");
    let out = |dir: &Path| dir.join("frame-###.exr").to_str().unwrap().to_string();
    render(&["render", scene.to_str().unwrap(), "-o", &out(&whole)]);
    let frames = std::fs::read_dir(&whole).unwrap().count();
    assert_eq!(frames, 25);

    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_rest-embree"))
        .args(["render", scene.to_str().unwrap(), "-o", &out(&cut), "-q"])
        .spawn()
        .unwrap();
    let finished = |dir: &Path| {
        std::fs::read_dir(dir).map_or(0, |r| {
            r.filter(|e| {
                e.as_ref()
                    .unwrap()
                    .path()
                    .extension()
                    .is_some_and(|x| x == "exr")
            })
            .count()
        })
    };
    while finished(&cut) < 3 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let before = finished(&cut);
    assert!(
        before < 25,
        "the film was killed before its end ({before} frames)"
    );
    // A finished frame of this render is not rendered again; anything else in a frame's place
    // is: garbage (frame 0), a frame cut short (1), another frame's file (2, frame 3's).
    std::fs::write(cut.join("frame-000.exr"), b"garbage").unwrap();
    let one = std::fs::read(cut.join("frame-001.exr")).unwrap();
    std::fs::write(cut.join("frame-001.exr"), &one[..one.len() / 2]).unwrap();
    std::fs::copy(whole.join("frame-003.exr"), cut.join("frame-002.exr")).unwrap();
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        &out(&cut),
        "--resume",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains(&format!(
            "{} frames rendered, {} already there",
            25 - before + 3,
            before - 3
        )),
        "{err}"
    );
    for (k, why) in [
        (0, "not a readable EXR"),
        (1, "cut short or damaged"),
        (2, "from another render"),
    ] {
        assert!(
            err.contains(&format!("frame {k}: ")) && err.contains(why),
            "frame {k}: {err}"
        );
    }
    let mut names: Vec<String> = std::fs::read_dir(&cut)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 25, "no partial file left: {names:?}");
    for n in &names {
        assert_eq!(
            std::fs::read(cut.join(n)).unwrap(),
            std::fs::read(whole.join(n)).unwrap(),
            "{n}"
        );
    }
}

#[test]
fn bad_films_are_clear_errors() {
    let f = film(0.0, "");
    fails(
        "frames-outside",
        &f,
        &["--frames", "3..9"],
        &["--frames 3..9", "frames 0..4"],
    );
    fails(
        "frames-reversed",
        &f,
        &["--frames", "3..1"],
        &["--frames", "empty"],
    );
    fails(
        "frames-no-film",
        GOOD,
        &["--frames", "0..1"],
        &["--frames", "not a film"],
    );
    // `fails` renders to out.png: no frame pattern.
    fails("no-pattern", &f, &[], &["-o", "frame pattern"]);
    let bad = |name: &str, from: &str, to: &str, needles: &[&str]| {
        fails(name, &f.replace(from, to), &[], needles)
    };
    bad(
        "end-before",
        "end = 9.0",
        "end = 7.0",
        &["film.end", "before start"],
    );
    bad(
        "fps-and-step",
        "fps = 4",
        "fps = 4\nstep = 0.5",
        &["film.step", "not both"],
    );
    bad("no-spacing", "fps = 4\n", "", &["film.fps", "missing"]);
    bad(
        "zero-fps",
        "fps = 4",
        "fps = 0",
        &["film.fps", "more than 0"],
    );
    bad(
        "too-many",
        "fps = 4",
        "fps = 1e9",
        &["film.fps", "at most 1000000"],
    );
    bad(
        "unknown",
        "fps = 4",
        "fps = 4\nspeed = 2",
        &["film.speed", "unknown key"],
    );
}

/// The same for PNG frames: one cut short and one of another render (other samples) are
/// rendered again, the rest kept, and the film ends as an uninterrupted one.
#[test]
fn a_png_film_resumed_renders_again_what_is_not_its_own() {
    let d = Dir::new("film-png-resume");
    let scene = d.file("film.toml", &film(0.3, ""));
    let pattern = |dir: &str| d.0.join(dir).join("f-#.png").to_str().unwrap().to_string();
    render(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        &pattern("whole"),
        "-q",
    ]);
    render(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        &pattern("cut"),
        "-q",
    ]);
    let other = ["--set", "image.samples=2", "-q"];
    let mut args = vec!["render", scene.to_str().unwrap(), "-o"];
    let other_pattern = pattern("other");
    args.push(&other_pattern);
    args.extend(other);
    render(&args);
    let cut = d.0.join("cut");
    let one = std::fs::read(cut.join("f-1.png")).unwrap();
    std::fs::write(cut.join("f-1.png"), &one[..one.len() - 40]).unwrap();
    std::fs::copy(d.0.join("other/f-2.png"), cut.join("f-2.png")).unwrap();
    let frames = std::fs::read_dir(&cut).unwrap().count();
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        &pattern("cut"),
        "--resume",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains(&format!("2 frames rendered, {} already there", frames - 2)),
        "{err}"
    );
    for k in 0..frames {
        let name = format!("f-{k}.png");
        assert_eq!(
            std::fs::read(cut.join(&name)).unwrap(),
            std::fs::read(d.0.join("whole").join(&name)).unwrap(),
            "{name}"
        );
    }
}

/// A film's frame that is a symbolic link (to another frame) is refused before any frame is
/// written, naming the frame and where the link leads, with and without --resume; the frame
/// it leads to is left as it was. A tile's output likewise; a still's `-o` may be a link to a
/// regular file, which it writes through.
#[test]
fn no_output_of_a_run_is_written_through_a_link() {
    let d = Dir::new("film-links");
    let scene = d.file("film.toml", &film(0.3, ""));
    let pattern = d.0.join("f-#.png").to_str().unwrap().to_string();
    render(&["render", scene.to_str().unwrap(), "-o", &pattern, "-q"]);
    let zero = std::fs::read(d.0.join("f-0.png")).unwrap();
    std::fs::remove_file(d.0.join("f-3.png")).unwrap();
    std::os::unix::fs::symlink("f-0.png", d.0.join("f-3.png")).unwrap();
    for resume in [true, false] {
        let mut args = vec!["render", scene.to_str().unwrap(), "-o", &pattern, "-q"];
        if resume {
            args.push("--resume");
        }
        let (code, err) = status(&args);
        assert_eq!(code, Some(1), "{err}");
        assert!(
            err.contains("frame 3") && err.contains("f-3.png") && err.contains("f-0.png"),
            "{err}"
        );
        assert_eq!(std::fs::read(d.0.join("f-0.png")).unwrap(), zero);
    }
    // A tile of a farm's grid.
    let tile = d.0.join("tile.exr");
    std::os::unix::fs::symlink("f-0.png", &tile).unwrap();
    let still_scene = d.file("still.toml", &still(0.3));
    let (code, err) = status(&[
        "render",
        still_scene.to_str().unwrap(),
        "-o",
        tile.to_str().unwrap(),
        "--tiles",
        "2x2",
        "--tile",
        "1",
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("tile 1") && err.contains("symbolic link"),
        "{err}"
    );
    assert_eq!(std::fs::read(d.0.join("f-0.png")).unwrap(), zero);
    // A still through a link to a regular file: written through, the link kept.
    let target = d.0.join("target.png");
    std::fs::write(&target, b"old").unwrap();
    let link = d.0.join("link.png");
    std::os::unix::fs::symlink("target.png", &link).unwrap();
    render(&[
        "render",
        still_scene.to_str().unwrap(),
        "-o",
        link.to_str().unwrap(),
        "-q",
    ]);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read(&target).unwrap().starts_with(b"\x89PNG"));
}

/// --resume keeps an EXR frame only if every block of it decodes: a byte flipped in the middle
/// of the file, or its last 100 bytes zeroed, and the frame is rendered again, to the bytes of
/// an untouched run.
#[test]
fn a_damaged_exr_frame_is_rendered_again() {
    let d = Dir::new("film-exr-damage");
    let scene = d.file("film.toml", &film(0.3, ""));
    let pattern = |dir: &str| d.0.join(dir).join("f-#.exr").to_str().unwrap().to_string();
    for dir in ["whole", "cut"] {
        render(&["render", scene.to_str().unwrap(), "-o", &pattern(dir), "-q"]);
    }
    let cut = d.0.join("cut");
    let mut one = std::fs::read(cut.join("f-1.exr")).unwrap();
    // In the last block's compressed pixels: the header, half of so small a file, holds
    // names and text a flipped byte can leave readable.
    let inside = one.len() * 7 / 8;
    one[inside] ^= 0x5a;
    std::fs::write(cut.join("f-1.exr"), &one).unwrap();
    let mut two = std::fs::read(cut.join("f-2.exr")).unwrap();
    let n = two.len();
    two[n - 100..].fill(0);
    std::fs::write(cut.join("f-2.exr"), &two).unwrap();
    let frames = std::fs::read_dir(&cut).unwrap().count();
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        &pattern("cut"),
        "--resume",
    ]);
    assert!(ok, "{err}");
    assert!(
        err.contains(&format!("2 frames rendered, {} already there", frames - 2)),
        "{err}"
    );
    for k in 0..frames {
        let name = format!("f-{k}.exr");
        assert_eq!(
            std::fs::read(cut.join(&name)).unwrap(),
            std::fs::read(d.0.join("whole").join(&name)).unwrap(),
            "{name}"
        );
    }
}

/// --resume keeps an EXR frame only if it is stored as this run would store it: resumed with
/// `--half` or another `--compression`, every frame is rendered again (not a film of two kinds
/// of file); resumed as it was, none is.
#[test]
fn a_frame_stored_otherwise_is_rendered_again() {
    let d = Dir::new("film-exr-storage");
    let scene = d.file("film.toml", &film(0.3, ""));
    let pattern = d.0.join("f-#.exr").to_str().unwrap().to_string();
    let s = scene.to_str().unwrap();
    render(&["render", s, "-o", &pattern, "-q"]);
    let frames = std::fs::read_dir(&d.0)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .ends_with(".exr")
        })
        .count();
    assert!(frames > 1);
    for (extra, rendered) in [
        (&["--half"][..], frames),
        (&["--half"][..], 0),
        (&["--compression", "rle", "--half"][..], frames),
        (&["--compression", "rle", "--half"][..], 0),
    ] {
        let mut args = vec!["render", s, "-o", &pattern, "--resume"];
        args.extend_from_slice(extra);
        let (ok, err) = run(&args);
        assert!(ok, "{err}");
        assert!(
            err.contains(&format!(
                "{rendered} frames rendered, {} already there",
                frames - rendered
            )),
            "{extra:?}: {err}"
        );
    }
}

/// `--still` renders one picture of a film's scene: with one frame that frame, with a range of
/// frames it is refused naming `--frames` (it rendered one picture and said nothing).
#[test]
fn still_takes_one_frame_not_a_range() {
    let d = Dir::new("film-still-flag");
    let scene = d.file("film.toml", &film(0.3, ""));
    let s = scene.to_str().unwrap();
    let out = d.0.join("plain.png");
    let o = out.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", o, "--still", "--frames", "0..2"]);
    assert!(
        code == Some(1) && err.contains("--frames") && err.contains("not a range"),
        "{err}"
    );
    assert!(!out.exists());
    let (code, err) = status(&["render", s, "-o", o, "--still", "--frames", "1", "-q"]);
    assert!(code == Some(0) && out.exists(), "{err}");
}
