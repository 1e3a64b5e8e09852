//! Tiles without a cluster: `render --tiles NxM --tile I` and `rest-embree assemble`. Tiles
//! joined make the whole render's EXR byte for byte; hostile tiles are refused before anything
//! is written; images larger than one frame render in tiles.

use super::*;

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
    // An output that is no EXR, a folder or a PNG, is asked for as the EXR assemble writes
    // (a folder was told ".exr or .png", from the fifth trial).
    for out in [d.0.clone(), d.0.join("joined.png")] {
        let (ok, err) = run(&["assemble", "-o", s(&out), s(&tiles[0]), s(&tiles[1])]);
        assert!(
            !ok && err.contains("the assembled image is an EXR: give a name ending in .exr"),
            "{err}"
        );
    }
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
        crate::common::exrcheck::valid(&joined),
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
            made("mip.exr", &|p: &Path| {
                oiiotool(&[s(&t0), "-otex", s(p)]);
            }),
            "mipmap",
        ),
        (
            made("dwaa.exr", &from_t0(&["--compression", "dwaa"])),
            "lossy",
        ),
        (
            made("parts.exr", &|p: &Path| {
                oiiotool(&[s(&t0), s(&t0), "--siappend", "-o", s(p)]);
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
            // A 4x4 float matrix renamed and retyped as a double one, its 64 bytes left: what
            // the fuzz suite found joined into a file OpenEXR rejects.
            made("m44d.exr", &|p: &Path| {
                let mut b = bytes.clone();
                let name = b
                    .windows(13)
                    .position(|w| w == b"worldToCamera")
                    .expect("its name");
                b[name + 10] = b'E';
                let at = b
                    .windows(4)
                    .position(|w| w == b"m44f")
                    .expect("worldToCamera");
                b[at + 3] = b'd';
                std::fs::write(p, b).unwrap()
            }),
            "malformed attribute",
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
