//! The EXR as compositors read it, checked with OpenImageIO's own tools (`oiiotool`, from
//! Debian's openimageio-tools, which scripts/setup.sh installs): channels in layers, pixel
//! types, compression and header attributes; "over" a plate equals the plate as background
//! (premultiplied colour); depth along the look axis; the PNG's colour chunks.

mod common;
use common::cli::*;
use common::*;

/// oiiotool's standard output for `args`; a missing tool is a set-up error, said so.
fn oiiotool(args: &[&str]) -> String {
    let out = std::process::Command::new("oiiotool")
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

#[test]
fn channels_types_compression_and_header_as_openimageio_reads_them() {
    let d = Dir::new("exr-header");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let plain = d.0.join("plain.exr");
    let p = plain.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", p, "-q", "--set", "camera.time=10"]);
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", plain.to_str().unwrap()]);
    for needle in [
        "17 channel, float openexr",
        "channel list: R, G, B, A, object_id, N.X, N.Y, N.Z, P.X, P.Y, P.Z, Pref.X, Pref.Y, Pref.Z, depth.Z, relativity.doppler, relativity.lookback",
        "compression: \"zip\"",
        "software: \"rest-embree",
        "chromaticities: 0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329",
        "worldToCamera:",
        "cameraTime: 10",
        "groupVelocities: \"cube: beta = [0.5, 0.0, 0.0]\"",
        "renderSamples: 1",
        "renderBackend:",
        "renderScene:",
        "renderOverrides: \"--set camera.time=10\"",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
    assert!(!info.contains("tile"), "scanlines, not tiles:\n{info}");
    let half = d.0.join("half.exr");
    let h = half.to_str().unwrap();
    let (code, err) = status(&["render", s, "-o", h, "-q", "--half", "--compression", "piz"]);
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", h]);
    for needle in [
        "R (half)",
        "A (half)",
        "N.X (half)",
        "relativity.doppler (half)",
        "depth.Z (float)",
        "relativity.lookback (float)",
        "P.X (float)",
        "object_id (float)",
        "compression: \"piz\"",
    ] {
        assert!(info.contains(needle), "`{needle}` in:\n{info}");
    }
    let (code, err) = status(&["render", s, "-o", h, "--compression", "lzma"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--compression") && err.contains("zip"),
        "{err}"
    );
}

/// A transparent EXR (the default) "over" a constant plate in OpenImageIO equals a render
/// with that plate as the background (opaque: alpha 1), to 1e-6.
#[test]
fn over_a_plate_equals_the_plate_as_background() {
    let d = Dir::new("exr-over");
    let text = GOOD.replace(
        "height = 32\n",
        "height = 32\nsamples = 4\nbackground = [0.2, 0.3, 0.4]\n",
    );
    let scene = d.file("scene.toml", &text);
    let s = scene.to_str().unwrap();
    let (cut, plate, over) = (
        d.0.join("cut.exr"),
        d.0.join("plate.exr"),
        d.0.join("over.exr"),
    );
    for (out, set) in [
        (&cut, "image.transparent=true"),
        (&plate, "image.transparent=false"),
    ] {
        let (code, err) = status(&["render", s, "-o", out.to_str().unwrap(), "-q", "--set", set]);
        assert_eq!(code, Some(0), "{err}");
    }
    oiiotool(&[
        cut.to_str().unwrap(),
        "--ch",
        "R,G,B,A",
        "--pattern",
        "constant:color=0.2,0.3,0.4,1",
        "48x32",
        "4",
        "--over",
        "-o",
        over.to_str().unwrap(),
    ]);
    let read = |p: &std::path::Path| rest_embree::output::read_exr_channels(p).unwrap().2;
    let (cut, plate, over) = (read(&cut), read(&plate), read(&over));
    let edges = cut["A"].iter().filter(|&&a| a > 0.0 && a < 1.0).count();
    assert!(edges > 0, "the test needs partly covered pixels");
    assert!(
        plate["A"].iter().all(|&a| a == 1.0),
        "an opaque render has alpha 1"
    );
    for c in ["R", "G", "B"] {
        for (i, (o, p)) in over[c].iter().zip(&plate[c]).enumerate() {
            assert!(
                (o - p).abs() <= 1e-6,
                "{c} at {i}: over {o}, plate as background {p}"
            );
        }
    }
}

/// depth.Z is the distance along the camera's look axis in its rest frame: the calibration
/// cube's near face lies in the plane y = 10, and a motion along x (of the cube or of the
/// camera) leaves that distance as it is.
#[test]
fn depth_is_the_distance_along_the_look_axis() {
    use rest_embree::spacetime::Velocity;
    // The camera's speeds are small: aberration turns what lies ahead toward its motion, out
    // of the narrow view at larger speeds.
    for (cube, camera) in [(0.0, 0.0), (0.9, 0.0), (0.0, 0.1), (0.5, -0.1)] {
        let speed = format!("velocity = [{cube:?}, 0, 0]");
        let text = cube_scene(10.0, &speed, -0.5, 10.0, [0.0, 0.0, 0.0]);
        let mut s = scene(&text);
        if camera != 0.0 {
            s.camera.velocity = Velocity::from_beta_vec(glam::DVec3::X * camera).unwrap();
        }
        for backend in backends() {
            let f = render_with(&s, backend);
            let near: Vec<f32> = f
                .pixels
                .iter()
                .filter(|p| p.normal == [0.0, -1.0, 0.0])
                .map(|p| p.depth)
                .collect();
            assert!(near.len() > 50, "the near face is seen ({})", near.len());
            for z in near {
                assert!(
                    (z - 10.0).abs() <= 1e-5,
                    "{backend}, {cube}/{camera}: depth {z}"
                );
            }
            for p in f.pixels.iter().filter(|p| p.alpha == 0.0) {
                assert_eq!(p.depth, rest_embree::render::DEPTH_FAR);
            }
        }
    }
}

/// A PNG is sRGB with the Software chunk, RGB unless the scene asks for transparency (then
/// RGBA, straight alpha).
#[test]
fn png_chunks_and_alpha() {
    let d = Dir::new("png-chunks");
    let scene = d.file("scene.toml", GOOD);
    let s = scene.to_str().unwrap();
    let (rgb, rgba) = (d.0.join("rgb.png"), d.0.join("rgba.png"));
    let (code, err) = status(&["render", s, "-o", rgb.to_str().unwrap(), "-q"]);
    assert_eq!(code, Some(0), "{err}");
    let set = ["--set", "image.transparent=true"];
    let (code, err) =
        status(&[&["render", s, "-o", rgba.to_str().unwrap(), "-q"][..], &set].concat());
    assert_eq!(code, Some(0), "{err}");
    let info = oiiotool(&["--info", "-v", rgb.to_str().unwrap()]);
    assert!(
        info.contains("3 channel") && info.contains("Software: \"rest-embree"),
        "{info}"
    );
    assert!(info.contains("sRGB"), "{info}");
    let info = oiiotool(&["--info", "-v", rgba.to_str().unwrap()]);
    assert!(
        info.contains("4 channel") && info.contains("R, G, B, A"),
        "{info}"
    );
}
