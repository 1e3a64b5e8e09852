//! Media (`[[material]] medium = { sigma_a, sigma_s, g }`): Beer-Lambert through an absorbing
//! slab, at rest and moving at 0.6c seen at an angle (the way through is the slab's rest-frame
//! length, found from the aberrated direction), shadows through a medium, and the path
//! integrator's scattering held to equilibrium: inside a uniformly glowing enclosure a fog ball
//! or a milky glass ball that scatters but absorbs nothing changes nothing (docs/physics.md §9.3).

use crate::common::*;

/// A camera at the origin looking along `look` at a glowing backdrop (radiance 1) beyond a
/// slab 1 thick across z (z from −3 to −2), absorbing `sigma_a`, moving at `beta` along x.
fn slab(integrator: &str, sigma_a: f64, beta: f64, look: [f64; 3]) -> String {
    let [x, y, z] = look;
    format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [{x}, {y}, {z}]
up = [0, 1, 0]
fov_y = 0.5
[image]
width = 3
height = 3
background = 0
transparent = false
[render]
integrator = "{integrator}"
max_depth = 0
ambient = 0
[[material]]
name = "glow"
emission = 1
[[material]]
name = "smoke"
medium = {{ sigma_a = {sigma_a} }}
[[group]]
name = "backdrop"
[[group.object]]
type = "box"
min = [-200, -200, -30]
max = [200, 200, -29]
material = "glow"
[[group]]
name = "slab"
velocity = [{beta}, 0, 0]
[[group.object]]
type = "box"
min = [-200, -200, -3]
max = [200, 200, -2]
material = "smoke"
"#
    )
}

fn centre(f: &rest_embree::render::Frame) -> f64 {
    f64::from(f.get(1, 1).color[0])
}

#[test]
fn beer_lambert_through_a_slab_at_rest_and_moving() {
    let a: [f64; 3] = [0.5, 0.0, -1.0];
    let n = (a[0] * a[0] + a[2] * a[2]).sqrt();
    let a = [a[0] / n, a[1], a[2] / n];
    for backend in backends() {
        for integrator in ["whitted", "path"] {
            for (beta, look) in [(0.0, [0.0, 0.0, -1.0]), (0.0, a), (0.6, a), (-0.6, a)] {
                let clear = centre(&render_with(
                    &scene(&slab(integrator, 0.0, beta, look)),
                    backend,
                ));
                let seen = centre(&render_with(
                    &scene(&slab(integrator, 0.4, beta, look)),
                    backend,
                ));
                // The looking direction in the slab's frame (boost along x): its z part is
                // a_z / (γ (1 + β a_x)); the way through the slab is 1 / |that|.
                let gamma = 1.0 / (1.0 - beta * beta).sqrt();
                let way = gamma * (1.0 + beta * look[0]) / look[2].abs();
                let want = (-0.4 * way).exp();
                assert!(clear > 0.5, "the backdrop is seen ({clear})");
                // Embree's hits on boxes carry f32 rounding into the way's length.
                assert_rel(
                    seen / clear,
                    want,
                    1e-4,
                    &format!("{integrator}, β = {beta}, look {look:?} on {backend}"),
                );
            }
        }
    }
}

/// A floor (white, Lambert) under a point light at height 4 (no fall-off), with an absorbing
/// slab 1 thick between them (σ_a = `sigma_a`); the camera looks at the point below the light.
fn shadow_through(integrator: &str, sigma_a: f64) -> String {
    format!(
        r#"
[camera]
position = [3, 1, 0]
look_at = [0, 0, 0]
fov_y = 0.5
[image]
width = 3
height = 3
background = 0
transparent = false
[render]
integrator = "{integrator}"
max_depth = 0
ambient = 0
[[material]]
name = "white"
color = 1
[[material]]
name = "smoke"
medium = {{ sigma_a = {sigma_a} }}
[[light]]
position = [0, 4, 0]
intensity = 2
[[group]]
name = "floor"
[[group.object]]
type = "box"
min = [-50, -1, -50]
max = [50, 0, 50]
material = "white"
[[group.object]]
type = "box"
min = [-2, 2, -2]
max = [2, 3, 2]
material = "smoke"
"#
    )
}

#[test]
fn light_through_a_medium_is_attenuated_not_stopped() {
    for backend in backends() {
        for integrator in ["whitted", "path"] {
            let open = centre(&render_with(
                &scene(&shadow_through(integrator, 0.0)),
                backend,
            ));
            let dim = centre(&render_with(
                &scene(&shadow_through(integrator, 0.5)),
                backend,
            ));
            assert_rel(open, 2.0, 1e-3, &format!("{integrator}: I · cos"));
            let what = format!("{integrator} on {backend}");
            assert_rel(dim / open, (-0.5f64).exp(), 1e-4, &what);
        }
    }
}

/// Inside a glowing sphere (radius 10, radiance 1, emitting inward and reflecting nothing),
/// looking at a ball of radius 2 that scatters (σ_s = 1.5, g = 0.6) and absorbs nothing: a fog
/// ball (`glass` false: its surface invisible) or milky glass (`ior` 1.5).
fn enclosure(glass: bool) -> String {
    let surface = if glass {
        "color = 0\ntransmit = 1\nior = 1.5\n"
    } else {
        ""
    };
    format!(
        r#"
[camera]
position = [0, 0, 6]
look_at = [0, 0, 0]
up = [0, 1, 0]
fov_y = 30
[image]
width = 16
height = 16
samples = 128
background = 0
transparent = false
[render]
integrator = "path"
max_depth = 64
[[material]]
name = "glow"
emission = 1
[[material]]
name = "fog"
{surface}medium = {{ sigma_s = 1.5, g = 0.6 }}
[[group]]
name = "room"
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 10
material = "glow"
[[group]]
name = "ball"
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 2
material = "fog"
"#
    )
}

#[test]
fn scattering_without_absorption_keeps_a_uniform_glow() {
    for backend in backends() {
        for glass in [false, true] {
            let f = render_with(&scene(&enclosure(glass)), backend);
            let mut sum = 0.0;
            for p in &f.pixels {
                sum += f64::from(p.color[0]);
            }
            let mean = sum / f.pixels.len() as f64;
            let what = if glass {
                "milky glass ball"
            } else {
                "fog ball"
            };
            report(
                &format!("path: {what} in a glowing enclosure"),
                backend,
                1.0,
                mean,
                0.01,
                "",
            );
            assert_rel(mean, 1.0, 0.01, &format!("{what} on {backend}"));
        }
    }
}

#[test]
fn bad_media_are_named() {
    let base = slab("path", 0.4, 0.0, [0.0, 0.0, -1.0]);
    for (from, to, needles) in [
        (
            "medium = { sigma_a = 0.4 }",
            "medium = { g = 0.2 }",
            vec!["sigma_a", "missing"],
        ),
        (
            "medium = { sigma_a = 0.4 }",
            "medium = { sigma_s = 1, g = 1 }",
            vec!["g", "between -1 and 1"],
        ),
        (
            "medium = { sigma_a = 0.4 }",
            "medium = { sigma_a = -1 }",
            vec!["sigma_a"],
        ),
        (
            "medium = { sigma_a = 0.4 }",
            "medium = { sigma_a = 0.4 }\ncolor = 0.5",
            vec!["color", "no surface"],
        ),
        (
            "medium = { sigma_a = 0.4 }",
            "medium = { sigma_a = 0.4, sigma_x = 1 }",
            vec!["sigma_x"],
        ),
    ] {
        assert!(base.contains(from));
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

/// A camera at the origin looking down −z at a glowing backdrop 29 away, through a fog
/// absorbing `sigma` per unit length at rest in the frame of group `drift` (a small ball out of
/// view), which moves at `beta` along z.
fn fogged(integrator: &str, beta: f64, sigma: f64) -> String {
    format!(
        r#"
[camera]
position = [0, 0, 0]
direction = [0, 0, -1]
up = [0, 1, 0]
fov_y = 0.5
[image]
width = 3
height = 3
background = 0
transparent = false
[render]
integrator = "{integrator}"
max_depth = 0
ambient = 0
[[material]]
name = "glow"
emission = 1
[fog]
sigma_a = {sigma}
group = "drift"
[[group]]
name = "backdrop"
[[group.object]]
type = "box"
min = [-200, -200, -30]
max = [200, 200, -29]
material = "glow"
[[group]]
name = "drift"
velocity = [0, 0, {beta}]
[[group.object]]
type = "sphere"
center = [0, 500, 0]
radius = 1
"#
    )
}

#[test]
fn a_fog_everywhere_attenuates_by_its_own_frames_way() {
    for backend in backends() {
        for integrator in ["whitted", "path"] {
            for beta in [0.0, 0.6, -0.6] {
                let clear = centre(&render_with(
                    &scene(&fogged(integrator, beta, 0.0)),
                    backend,
                ));
                let seen = centre(&render_with(
                    &scene(&fogged(integrator, beta, 0.02)),
                    backend,
                )) / clear;
                // Looking along −z, the fog's frame (moving at β along z) stretches the way
                // by s = γ (1 − β) (§7.1).
                let gamma = 1.0 / (1.0 - beta * beta).sqrt();
                let want = (-0.02 * gamma * (1.0 - beta) * 29.0).exp();
                let what = format!("{integrator}, fog at β = {beta} on {backend}");
                assert_rel(seen, want, 1e-4, &what);
            }
        }
    }
}

#[test]
fn a_scattering_fog_in_a_glowing_room_keeps_it_uniform() {
    let text = enclosure(false).replace(
        "[[group]]\nname = \"ball\"",
        "[fog]\nsigma_s = 0.3\ng = 0.4\ngroup = \"room\"\n[[group]]\nname = \"ball\"",
    );
    assert!(text.contains("[fog]"));
    for backend in backends() {
        let f = render_with(&scene(&text), backend);
        let mean =
            f.pixels.iter().map(|p| f64::from(p.color[0])).sum::<f64>() / f.pixels.len() as f64;
        report(
            "path: fog ball in a fog, in a glowing enclosure",
            backend,
            1.0,
            mean,
            0.01,
            "",
        );
        assert_rel(mean, 1.0, 0.01, &format!("fog everywhere on {backend}"));
    }
}

#[test]
fn a_bad_fog_is_named() {
    let base = fogged("path", 0.0, 0.02);
    for (from, to, needles) in [
        (
            "group = \"drift\"",
            "group = \"drifter\"",
            vec!["fog.group", "no group is named `drifter`"],
        ),
        (
            "sigma_a = 0.02\n",
            "sigma_a = 0.02\ncolor = 1\n",
            vec!["color", "unknown"],
        ),
        ("sigma_a = 0.02\n", "", vec!["sigma_a", "missing"]),
    ] {
        assert!(base.contains(from));
        let err = rest_embree::scene::load_str("bad.toml", &base.replace(from, to), &[])
            .err()
            .unwrap_or_else(|| panic!("{to} is refused"))
            .to_string();
        for n in needles {
            assert!(err.contains(n), "`{n}` in: {err}");
        }
    }
    let empty = base
        .replace(
            "[[group]]\nname = \"drift\"",
            "[[group]]\nname = \"still\"\n[[group]]\nname = \"drift\"",
        )
        .replace("group = \"drift\"", "group = \"still\"");
    let err = rest_embree::scene::load_str("bad.toml", &empty, &[])
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("holds no objects"), "{err}");
}

/// A fog bank reaching 1e15 in a group with small lamps: the group's ε (from its bounds) is
/// then larger than a shadow ray toward a lamp, whose last crossing of the fog's boundary
/// steps past its end; that stretch has no length (it once had a negative one, and the
/// transmittance e^{+σd} overflowed into NaN pixels; found by tests/suite/fuzz.rs).
#[test]
fn a_vast_fog_bank_beside_small_lamps_gives_finite_pixels() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/glowing_pass.toml"
    ))
    .unwrap();
    let needle = "min = [3.0, 0.0, -4.0]";
    assert!(
        text.contains(needle),
        "the fog bank of scenes/glowing_pass.toml"
    );
    let text = text.replacen(needle, "min = [3.0, 0.0, -1e15]", 1);
    let mut s = rest_embree::scene::load_str("scenes/glowing_pass.toml", &text, &[]).unwrap();
    s.image.width = 48;
    s.image.height = 27;
    s.image.samples = 4;
    for backend in backends() {
        // render_with asserts that no pixel is NaN or infinite.
        let f = render_with(&s, backend);
        assert_all_finite(&f, backend);
    }
}
