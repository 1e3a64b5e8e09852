//! The real binary on colours: bad spectra name their line and key, the switches change the
//! picture, colours far shifted are warned of.

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
