//! The path integrator's settings on the command line and in the scene: bad values named, the
//! time and noise budgets.

use super::lit_by_points;

#[test]
fn bad_integrator_and_roughness_are_named() {
    let base = lit_by_points("path", 1);
    for (from, to, needles) in [
        (
            "integrator = \"path\"",
            "integrator = \"pathtracer\"",
            vec![
                "integrator",
                "unknown integrator `pathtracer`",
                "whitted, path",
            ],
        ),
        (
            "name = \"floor\"\ncolor = [0.7, 0.6, 0.5]",
            "name = \"floor\"\ncolor = [0.7, 0.6, 0.5]\nroughness = 1.5",
            vec!["roughness", "between 0 and 1"],
        ),
        ("max_depth = 1", "max_depth = 1\nseed = -1", vec!["seed"]),
    ] {
        assert!(base.contains(from), "{from}");
        let text = base.replace(from, to);
        let err = rest_embree::scene::load_str("bad.toml", &text, &[])
            .err()
            .unwrap_or_else(|| panic!("{to} is refused"))
            .to_string();
        assert!(err.contains("bad.toml:"), "{err}");
        for n in needles {
            assert!(err.contains(n), "`{n}` in: {err}");
        }
    }
}

#[test]
fn time_and_noise_budgets_on_the_command_line() {
    use crate::common::cli::{fails, run, Dir};
    let text = lit_by_points("path", 2).replace("samples = 1", "samples = 64");
    let d = Dir::new("path-budgets");
    let scene = d.file("scene.toml", &text);
    let out = d.0.join("out.exr");
    let (s, o) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let (ok, err) = run(&["render", s, "-o", o, "--target-rms", "1e-9"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("64 spp in 16 rounds, stopped by samples"),
        "{err}"
    );
    let (ok, err) = run(&[
        "render",
        s,
        "-o",
        o,
        "--max-time",
        "60",
        "--target-rms",
        "3",
    ]);
    assert!(ok && err.contains("stopped by target"), "{err}");
    assert!(out.exists());
    // The header says the samples the rounds took, and the rule that stopped them (so that
    // `--resume` with another rule renders again); a tile cannot stop on its own.
    let taken: u32 = err
        .split(" spp in ")
        .next()
        .and_then(|a| a.rsplit(|c: char| !c.is_ascii_digit()).next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("the samples taken in: {err}"));
    assert!(taken < 64, "{err}");
    let info = crate::common::cli::oiiotool(&["--info", "-v", o]);
    assert!(
        info.contains(&format!("renderSamples: {taken}\n"))
            && info.contains("--max-time 60.0")
            && info.contains("--target-rms 3.0"),
        "{taken} spp: {info}"
    );
    let (code, err) = crate::common::cli::status(&[
        "render",
        s,
        "-o",
        o,
        "--target-rms",
        "3",
        "--tiles",
        "2x1",
        "--tile",
        "0",
    ]);
    assert!(
        code == Some(1) && err.contains("--target-rms") && err.contains("tiles"),
        "{err}"
    );
    for (flag, value, needles) in [
        ("--target-rms", "0", vec!["--target-rms", "must be above 0"]),
        ("--max-time", "-1", vec!["--max-time", "must be above 0"]),
        ("--max-time", "inf", vec!["--max-time", "finite"]),
    ] {
        fails("path-budget", &text, &[flag, value], &needles);
    }
    let film = format!("{text}\n[film]\nend = 1\nfps = 2\n");
    let d = Dir::new("path-budget-film");
    let scene = d.file("scene.toml", &film);
    let out = d.0.join("f####.png");
    let (ok, err) = run(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--max-time",
        "1",
    ]);
    assert!(
        !ok && err.contains("--max-time") && err.contains("still image"),
        "{err}"
    );
}
