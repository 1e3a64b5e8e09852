//! The real binary on the Embree backend's own switches: a panic inside a callback (forced by
//! the test hook `REST_EMBREE_FAULT`) is an error, not an abort; `REST_EMBREE_ISA` runs the
//! instruction set it names, and `backends` reports it.

#![cfg(feature = "embree")]

use crate::common::cli::*;

/// A panic inside one of Embree's callbacks (forced by the test hook `REST_EMBREE_FAULT`) does
/// not abort the process: the render fails with status 1, says which scene and why, and writes
/// no file, for a PNG and an EXR alike.
#[cfg(feature = "embree")]
#[test]
fn a_panic_in_an_embree_callback_is_an_error_not_an_abort() {
    // The paper's lattice: thousands of primitives, traced through Embree (a group of a few
    // is intersected directly, with no callback to fail).
    let lattice = include_str!("../../scenes/lattice.toml");
    for ext in ["png", "exr"] {
        let d = Dir::new(&format!("fault-{ext}"));
        let scene = d.file("scene.toml", lattice);
        let out = d.0.join(format!("out.{ext}"));
        let render = [
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "48",
        ];
        let (code, err, _) = status_with_env(&render, &[("REST_EMBREE_FAULT", "callback")]);
        assert_eq!(code, Some(1), "{ext}: exit status 1, no abort: {err}");
        for needle in [
            scene.to_str().unwrap(),
            "callback panicked",
            "Embree's",
            "the file was not written",
        ] {
            assert!(err.contains(needle), "{ext}: should say `{needle}`:\n{err}");
        }
        assert_eq!(
            d.entries(),
            vec!["scene.toml".to_string()],
            "{ext}: no file"
        );
        // Without the hook the same render succeeds.
        let (code, err, _) = status_with_env(&render, &[]);
        assert_eq!(code, Some(0), "{err}");
    }
    let d = Dir::new("fault-bogus");
    let scene = d.file("scene.toml", GOOD);
    let (code, err, _) = status_with_env(
        &["render", scene.to_str().unwrap(), "-o", "out.png"],
        &[("REST_EMBREE_FAULT", "everything")],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("REST_EMBREE_FAULT") && err.contains("callback"),
        "{err}"
    );
}

/// `REST_EMBREE_ISA` runs Embree with the instruction set it names, which `backends` reports
/// with its native packet widths: SSE2 on every x86-64 CPU; the rest where the CPU has them,
/// else a clear refusal. A name Embree does not know is refused with the choices.
#[cfg(all(feature = "embree", target_arch = "x86_64"))]
#[test]
fn embree_runs_the_instruction_set_the_environment_names() {
    let d = Dir::new("isa");
    // The paper's lattice, traced through Embree's callbacks (a single box would be intersected
    // directly).
    let scene = d.file("scene.toml", include_str!("../../scenes/lattice.toml"));
    let out = d.0.join("out.png");
    let render = [
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "32",
    ];
    for (isa, width) in [
        ("sse2", "4"),
        ("sse4.2", "4"),
        ("avx", "8"),
        ("avx2", "8"),
        ("avx512", "16"),
    ] {
        let env = [("REST_EMBREE_ISA", isa)];
        let (code, err, stdout) = status_with_env(&["backends"], &env);
        match code {
            Some(0) => {
                let want = format!("instruction set {isa} (as REST_EMBREE_ISA asks");
                assert!(stdout.contains(&want), "{isa}: {stdout}");
                assert!(
                    stdout.contains(&format!("traces packets of {width}")),
                    "{stdout}"
                );
                let (code, err, _) = status_with_env(&render, &env);
                assert_eq!(code, Some(0), "{isa}: {err}");
            }
            _ => {
                assert_ne!(isa, "sse2", "every x86-64 CPU has SSE2: {err}");
                assert_eq!(code, Some(1), "{isa}: {err}");
                assert!(
                    err.contains("REST_EMBREE_ISA: this CPU does not have"),
                    "{err}"
                );
                let (code, err, _) = status_with_env(&render, &env);
                assert_eq!(code, Some(1), "{isa}: {err}");
                assert!(err.contains("REST_EMBREE_ISA"), "{err}");
            }
        }
    }
    let (code, err, _) = status_with_env(&render, &[("REST_EMBREE_ISA", "avx3")]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("\"avx3\"") && err.contains("sse2, sse4.2, avx, avx2, avx512"),
        "{err}"
    );
    // Unset, `backends` says which it is and that it is the CPU's best.
    let (code, _, stdout) = status_with_env(&["backends"], &[]);
    assert_eq!(code, Some(0));
    assert!(stdout.contains("(the CPU's best;"), "{stdout}");
}
