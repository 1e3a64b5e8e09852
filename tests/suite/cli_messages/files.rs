//! The real binary never loses a file: the scene is never written over, a stopped render
//! leaves no partial file, a still makes its folder, special files are neither replaced nor
//! read forever.

use crate::common::cli::*;

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

/// A render never writes over a file its scene reads: a texture, a sky map, named as `-o`
/// however spelt, or met by one of a film's frames, is refused and left as it is (it was
/// replaced by the render, from a fifth newcomer's trial).
#[test]
fn a_render_never_writes_over_a_file_its_scene_reads() {
    let d = Dir::new("inputs");
    let plain = d.file("plain.toml", GOOD);
    let paint = d.0.join("paint.png");
    let (code, err) = status(&[
        "render",
        plain.to_str().unwrap(),
        "-o",
        paint.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let painted = GOOD.replace(
        "color = [0.8, 0.8, 0.8]",
        "color = \"paint\"\n[[texture]]\nname = \"paint\"\nimage = \"paint.png\"",
    );
    let scene = d.file("scene.toml", &painted);
    let s = scene.to_str().unwrap();
    let before = std::fs::read(&paint).unwrap();
    let spelt = format!("{}/./paint.png", d.0.display());
    for out in [paint.to_str().unwrap(), spelt.as_str()] {
        let (code, err) = status(&["render", s, "-o", out]);
        assert_eq!(code, Some(1), "{err}");
        assert!(
            err.contains("-o")
                && err.contains("which the scene reads")
                && err.contains("paint.png"),
            "{err}"
        );
        assert_eq!(
            std::fs::read(&paint).unwrap(),
            before,
            "the texture is intact"
        );
    }
    // The same picture as a sky map.
    let sky = d.file("sky.toml", &format!("{GOOD}\n[sky]\nmap = \"paint.png\"\n"));
    let (code, err) = status(&[
        "render",
        sky.to_str().unwrap(),
        "-o",
        paint.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("which the scene reads"), "{err}");
    assert_eq!(
        std::fs::read(&paint).unwrap(),
        before,
        "the sky map is intact"
    );
    // A film whose second frame's file is the texture: refused before any frame is written.
    std::fs::copy(&paint, d.0.join("f1.png")).unwrap();
    let film = d.file(
        "film.toml",
        &format!(
            "{}\n[film]\nstart = 10\nend = 11\nfps = 1\n",
            painted.replace("image = \"paint.png\"", "image = \"f1.png\"")
        ),
    );
    let pattern = d.0.join("f#.png");
    let (code, err) = status(&[
        "render",
        film.to_str().unwrap(),
        "-o",
        pattern.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("frame 1") && err.contains("which the scene reads"),
        "{err}"
    );
    assert!(!d.0.join("f0.png").exists(), "no frame was written");
    assert_eq!(std::fs::read(d.0.join("f1.png")).unwrap(), before);
}
