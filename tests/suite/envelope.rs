//! The validity envelope (docs/scene-format.md, "Valid scenes"): values beyond it are refused
//! with the key that gave them, and scenes at its corners render with every channel finite,
//! the same on Embree as on the f64 BVH.

use crate::common::*;
use rest_embree::compare::compare;

/// A sphere, a box and a rod in one group, lit, seen from `distance` along −y, every length
/// and time times `s`; `extra` is added to the file (a `[render]` table, a velocity, …).
fn scaled(s: f64, group: &str, extra: &str) -> String {
    format!(
        r#"
[camera]
position = [0, {cy:?}, 0]
look_at = [0, 0, 0]
fov_y = 30
time = {t:?}
[image]
width = 48
height = 40
{extra}
[[light]]
position = [{lx:?}, {ly:?}, {lz:?}]
[[material]]
name = "white"
color = 0.8
[[group]]
name = "g"
{group}
[[group.object]]
type = "sphere"
center = [{sx:?}, 0, 0]
radius = {r:?}
material = "white"
[[group.object]]
type = "box"
min = [{bmin:?}, {bmin:?}, {bmin:?}]
max = [{bmax:?}, {bmax:?}, {bmax:?}]
[[group.object]]
type = "rod"
from = [0, 0, {rz:?}]
to = [{rx:?}, 0, {rz:?}]
radius = {rr:?}
"#,
        cy = -10.0 * s,
        t = 10.0 * s,
        lx = -3.0 * s,
        ly = -8.0 * s,
        lz = 6.0 * s,
        sx = 1.2 * s,
        r = 0.7 * s,
        bmin = -s,
        bmax = -0.2 * s,
        rz = 1.2 * s,
        rx = 1.5 * s,
        rr = 0.2 * s,
    )
}

/// Every reproducer of a value beyond the envelope gives an error at its key.
#[test]
fn values_beyond_the_envelope_name_their_key() {
    let base = scaled(1.0, "direction = [1, 0, 0]\nbeta = 0.5", "");
    let cases: [(&str, &str); 12] = [
        ("camera.up=[0, 0, 1e200]", "camera.up"),
        ("camera.position=[1e200, 0, 0]", "camera.position"),
        ("camera.time=1e300", "camera.time"),
        ("camera.fov_y=1e-200", "camera.fov_y"),
        ("group.g.direction=[1e200, 0, 0]", "group.g.direction"),
        ("group.g.rapidity=709", "group.g.rapidity"),
        ("group.g.one_minus_beta=1e-300", "group.g.one_minus_beta"),
        ("material.white.color=[1e308, 0, 0]", "material.white.color"),
        ("light.0.intensity=1e308", "light.0.intensity"),
        ("image.background=1e300", "image.background"),
        ("group.g.object.0.radius=1e308", "group.g.object.0.radius"),
        // The object reaches too far: the flag that placed it is named (the object's `type`
        // line in the file was, which the flag had not touched).
        (
            "group.g.object.0.center=[1e15, 0, 0]",
            "group.g.object.0.center",
        ),
    ];
    for (set, key) in cases {
        let sets = vec![(format!("--set {set}"), set.to_string())];
        let Err(e) = rest_embree::scene::load_str("t.toml", &base, &sets) else {
            panic!("{set}: accepted");
        };
        let e = e.to_string();
        assert!(e.contains(&format!("key `{key}`")), "{set}: {e}");
        assert!(
            e.contains("renders correctly") || e.contains("at least"),
            "{set}: {e}"
        );
    }
}

/// A mesh whose vertices reach past 1e15 is blamed on its `file` (it was on its `type`).
#[test]
fn a_mesh_beyond_the_envelope_names_its_file() {
    let d = crate::common::cli::Dir::new("envelope-mesh");
    std::fs::write(
        d.0.join("far.obj"),
        "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let scene = d.file(
        "scene.toml",
        "[camera]\nposition = [0, 0, 0]\nlook_at = [0, 10, 0]\n[[group]]\nname = \"g\"\n[[group.object]]\ntype = \"mesh\"\nfile = \"far.obj\"\n",
    );
    let e = rest_embree::scene::load_file(&scene, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.toml:8: key `group.g.object.0.file`: the mesh reaches 1e300"),
        "{e}"
    );
}

/// The corners: objects near 1e15 from the origin, the fastest group and camera, the largest
/// colours and intensities, the narrowest view. Every channel finite, Embree as the BVH.
#[test]
fn scenes_at_the_corners_render_finite_and_agree() {
    let fast = "direction = [1, 0, 0]\nrapidity = 20";
    let spectral = "[render]\ndoppler = true\nsearchlight = true\nambient = 1e15";
    let corners = [
        ("far", scaled(1e14, "velocity = [0.5, 0, 0]", "")),
        ("small", scaled(1e-9, "velocity = [0.5, 0, 0]", "")),
        ("fastest group", scaled(1.0, fast, spectral)),
        (
            "fastest camera",
            scaled(1.0, "", &format!("{spectral}\n")).replace(
                "time = 10.0",
                "time = 10.0\nvelocity_direction = [1, 0, 0]\nrapidity = 20",
            ),
        ),
        (
            "brightest",
            scaled(1.0, fast, spectral).replace("color = 0.8", "color = 1e15\nemission = 1e15"),
        ),
        (
            "narrowest view",
            scaled(1.0, "", "").replace("fov_y = 30", "fov_y = 1e-6"),
        ),
    ];
    for (what, text) in corners {
        let s = scene(&text);
        let frames: Vec<_> = backends()
            .into_iter()
            .map(|b| (b, render_with(&s, b)))
            .collect();
        for (b, f) in &frames {
            assert_all_finite(f, &format!("{what}, {b}"));
        }
        let c = compare(&frames[0].1, &frames.last().unwrap().1);
        assert!(
            c.differing_off_edges == 0 && c.differing_share() < 0.02,
            "{what}: the backends disagree: {c:?}"
        );
    }
}

/// Physics has no unit of length: the scene scaled by 1e12 or 1e-9, lengths and times together,
/// is the same picture.
#[test]
fn scaling_every_length_and_time_changes_no_pixel() {
    let group = "velocity = [0.6, 0, 0]";
    for backend in backends() {
        let one = render_with(&scene(&scaled(1.0, group, "")), backend);
        assert!(
            one.pixels.iter().any(|p| p.alpha > 0.0),
            "something is seen"
        );
        for s in [1e12, 1e-9] {
            let other = render_with(&scene(&scaled(s, group, "")), backend);
            let c = compare(&one, &other);
            assert!(
                c.differing_off_edges == 0 && c.differing_share() < 0.01,
                "{backend}, scale {s:e}: {c:?}"
            );
        }
    }
}
