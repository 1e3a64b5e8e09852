//! The fixed cases of `rest-embree bench`.

use super::{paper, Case, LazyCase, PAPER_SCENES};
use crate::rng::Rng;
use crate::scene::{load_str, SceneError};
use std::fmt::Write as _;

/// The fast-moving planet (scenes/planet.toml) with overrides: its map written beside a copy
/// of the scene in the temporary folder, so the bench runs from any directory.
pub(crate) fn planet(sets: &[String]) -> Result<crate::scene::Scene, SceneError> {
    let dir = std::env::temp_dir().join(format!("rest-embree-bench-planet-{}", std::process::id()));
    let fail = |e: std::io::Error| {
        SceneError::new("bench", "", format!("cannot write the planet's map: {e}"))
    };
    std::fs::create_dir_all(&dir).map_err(fail)?;
    std::fs::write(
        dir.join("planet-map.png"),
        include_bytes!("../../scenes/planet-map.png"),
    )
    .map_err(fail)?;
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|s| (format!("--set {s}"), s.clone()))
        .collect();
    let name = dir.join("planet.toml").display().to_string();
    let scene = load_str(&name, include_str!("../../scenes/planet.toml"), &sets);
    let _ = std::fs::remove_dir_all(&dir);
    scene
}

fn sets(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// `n` boxes in a cloud in front of the camera, each in its own group with its own velocity
/// (|β| ≤ 0.8), or (`one_group`) all in one group at rest: the same geometry either way. Both
/// render in RGB (no Doppler shift or searchlight), so that the comparison measures what many
/// groups cost, not what spectra cost (the spectral case measures that).
pub(crate) fn many_groups(
    n: usize,
    one_group: bool,
    size: u32,
) -> Result<crate::scene::Scene, SceneError> {
    many_groups_timed(n, one_group, size).map(|(scene, _)| scene)
}

/// [`many_groups`], and how long writing its text took: a bench-made scene's cost that a
/// command, reading a file, does not pay (the row's load leaves it out, `Case::written_in`).
pub(crate) fn many_groups_timed(
    n: usize,
    one_group: bool,
    size: u32,
) -> Result<(crate::scene::Scene, f64), SceneError> {
    let t = std::time::Instant::now();
    let s = many_groups_text(n, one_group, size);
    let text_s = t.elapsed().as_secs_f64();
    Ok((load_str(&format!("many-groups-{n}"), &s, &[])?, text_s))
}

/// The text of [`many_groups`].
fn many_groups_text(n: usize, one_group: bool, size: u32) -> String {
    let mut r = Rng(2024);
    let mut s = format!(
        "[camera]\nposition = [0, -120, 0]\nlook_at = [0, 0, 0]\nfov_y = 50\ntime = 120\n[image]\nwidth = {size}\nheight = {size}\n\
         [render]\ndoppler = false\nsearchlight = false\n[[light]]\nposition = [0, -120, 40]\n"
    );
    if one_group {
        s += "[[group]]\nname = \"all\"\n";
    }
    for i in 0..n {
        let c = [
            r.range(-40.0, 40.0),
            r.range(-40.0, 40.0),
            r.range(-40.0, 40.0),
        ];
        let (d, b) = (
            [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0)],
            r.range(0.0, 0.8),
        );
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-9);
        if !one_group {
            let _ = write!(
                s,
                "[[group]]\nname = \"g{i}\"\nvelocity = [{:?}, {:?}, {:?}]\n",
                d[0] / len * b,
                d[1] / len * b,
                d[2] / len * b
            );
        }
        let h = 0.6;
        let _ = write!(
            s,
            "[[group.object]]\ntype = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
            c[0] - h,
            c[1] - h,
            c[2] - h,
            c[0] + h,
            c[1] + h,
            c[2] + h
        );
    }
    s
}

/// The 11 × 11 bars, each bar its own group, all at one velocity (merging makes them one).
pub(crate) fn bars_as_groups(beta: f64) -> Result<crate::scene::Scene, SceneError> {
    let base = PAPER_SCENES[1].1;
    let head = &base[..base.find("[[group]]").expect("bar_array.toml has a group")];
    let mut s = head.replace("group = \"bars\"\n", "").to_string();
    for j in 0..11 {
        for i in 0..11 {
            let (x, y) = (-10.0 + 2.0 * i as f64, -10.0 + 2.0 * j as f64);
            let _ = write!(
                s,
                "[[group]]\nname = \"bar{i}_{j}\"\nvelocity = [{beta:?}, 0, 0]\n[[group.object]]\ntype = \"box\"\n\
                 min = [{:?}, {:?}, -3]\nmax = [{:?}, {:?}, 0]\nmaterial = \"bar\"\n",
                x - 0.3,
                y - 0.3,
                x + 0.3,
                y + 0.3
            );
        }
    }
    load_str("bars-as-groups", &s, &[])
}

/// Settings measured on every lattice speed.
const LATTICE_SETTINGS: [&str; 7] = [
    "embree",
    "embree-8",
    "embree-single",
    "bvh",
    "bvh-f32",
    "embree no-cull",
    "embree no-fused",
];

/// The fixed suite, each case built only when it runs (so a row's peak memory is its own).
/// `quick` shrinks images and scenes for a fast look (CI-sized).
/// An image of `w` × `w` pixels at one sample each.
fn size(w: u32) -> Vec<String> {
    vec![
        format!("image.width={w}"),
        format!("image.height={w}"),
        "image.samples=1".into(),
    ]
}

pub(crate) fn cases(quick: bool) -> Vec<LazyCase> {
    let px: u32 = if quick { 128 } else { 512 };
    let mut out = Vec::new();
    lattice_cases(px, &mut out);
    planet_cases(px, &mut out);
    light_cases(px, &mut out);
    large_cases(quick, px, &mut out);
    group_cases(quick, px, &mut out);
    time_cases(px, &mut out);
    out
}

/// The paper's lattice with its motion given as a worldline of `segments` (None: its uniform
/// velocity -0.9c), its lights left out (a light cannot rest in a group whose velocity changes).
fn lattice_in_segments(px: u32, segments: Option<&str>) -> Result<crate::scene::Scene, SceneError> {
    let (_, text) = PAPER_SCENES[2];
    let motion = match segments {
        Some(w) => format!("worldline = {w}"),
        None => "velocity = [-0.9, 0.0, 0.0]".into(),
    };
    let text = text.replacen("velocity = [0.0, 0.0, 0.0]", &motion, 1);
    let mut s = size(px);
    s.push("light=[]".into());
    let sets: Vec<(String, String)> = s
        .iter()
        .map(|x| (format!("--set {x}"), x.clone()))
        .collect();
    load_str("scenes/lattice.toml", &text, &sets)
}

/// Motion and light in time: a worldline of segments against the uniform group, pulsed lights
/// against steady ones, an open shutter against an instant.
fn time_cases(px: u32, out: &mut Vec<LazyCase>) {
    // Eight segments, their ends spread over the emission times the view sees (t0 = 3, the
    // far face's light left ~60 earlier at 0.9c), each a copy of the lattice.
    out.push(LazyCase::new("lattice beta=0.9, 8 segments", move || {
        let line = "[{until=-40, velocity=[-0.9,0,0]}, {until=-20, velocity=[-0.88,0,0]}, \
                    {until=-10, velocity=[-0.9,0,0]}, {until=-5, velocity=[-0.88,0,0]}, \
                    {until=-2, velocity=[-0.9,0,0]}, {until=0, velocity=[-0.88,0,0]}, \
                    {until=1, velocity=[-0.9,0,0]}, {velocity=[-0.88,0,0]}]";
        Case::new(
            "lattice beta=0.9, 8 segments",
            lattice_in_segments(px, Some(line))?,
            &["embree", "bvh"],
        )
        .beside("the lattice moving uniformly at 0.9c", || {
            lattice_in_segments(px, None)
        })
    }));
    // Both lights as Gaussian pulses (a factor per shadow ray, and no shadow ray where it is 0).
    out.push(LazyCase::new(
        "lattice beta=0.9, pulsed lights",
        move || {
            let mut s = size(px);
            s.push("group.lattice.velocity=[-0.9,0,0]".into());
            let steady = s.clone();
            s.extend(sets(&[
                "light.0.pulse={at=-8, width=6}",
                "light.1.pulse={at=-8, width=6}",
            ]));
            Case::new(
                "lattice beta=0.9, pulsed lights",
                paper("lattice", &s)?,
                &["embree", "bvh"],
            )
            .beside("the same lights steady", || paper("lattice", &steady))
        },
    ));
    // A planet at rest spinning with its equator at 0.9c against the same planet still: each
    // hit carried into its point's frame (a boost per hit), and no fans.
    out.push(LazyCase::new("planet spinning at 0.9c", move || {
        let mut s = size(px);
        s.extend(sets(&[
            "group.planet.velocity=[0,0,0]",
            "camera.direction=[0,1,0]",
            "camera.time=0",
        ]));
        let still = s.clone();
        s.push("group.planet.object.planet.spin={axis=[0,0,1], omega=0.6}".into());
        Case::new("planet spinning at 0.9c", planet(&s)?, &["embree", "bvh"])
            .without_hi_reference()
            .beside("the same planet still", || planet(&still))
    }));
    // The train accelerating Born-rigidly past the camera against the same train at rest:
    // every ray tries each car in closed form, in Rindler coordinates, without a tree.
    out.push(LazyCase::new("train accelerating at 0.5", move || {
        const TRAIN: &str = include_str!("../../scenes/accelerating_train.toml");
        let motion = "worldline = [{ until = 0.0, velocity = [0, 0, 0] }, { until = 8.0, acceleration = [0.5, 0, 0] }]";
        assert!(TRAIN.contains(motion), "the bench's train is the scene's");
        let mut s = size(px);
        s.push("camera.time=18".into());
        let sets: Vec<(String, String)> = s
            .iter()
            .map(|x| (format!("--set {x}"), x.clone()))
            .collect();
        let load = |text: &str| load_str("scenes/accelerating_train.toml", text, &sets);
        Case::new(
            "train accelerating at 0.5",
            load(TRAIN)?,
            &["embree", "bvh"],
        )
        .without_hi_reference()
        .beside("the same train at rest", || {
            load(&TRAIN.replacen(motion, "velocity = [0, 0, 0]", 1))
        })
    }));
    // The spoked wheel with its rim at 0.9c against the same wheel without spin: every ray
    // marched through the turning wheel, against the still one's exact tests.
    out.push(LazyCase::new("wheel spinning at 0.9c", move || {
        const WHEEL: &str = include_str!("../../scenes/spoked_wheel.toml");
        let spin = "spin = { axis = [0.0, -1.0, 0.4], omega = 0.43 }";
        assert!(WHEEL.contains(spin), "the bench's wheel is the scene's");
        let s = size(px);
        let sets: Vec<(String, String)> = s
            .iter()
            .map(|x| (format!("--set {x}"), x.clone()))
            .collect();
        let load = |text: &str| load_str("scenes/spoked_wheel.toml", text, &sets);
        Case::new("wheel spinning at 0.9c", load(WHEEL)?, &["embree", "bvh"])
            .without_hi_reference()
            .beside("the same wheel still", || {
                load(&WHEEL.replacen(spin, "", 1))
            })
    }));
    // An open shutter: every sample from its own event, so no fans and no screen cull.
    out.push(LazyCase::new("lattice beta=0.9, shutter 0.5", move || {
        let mut s = size(px);
        s.extend(sets(&[
            "group.lattice.velocity=[-0.9,0,0]",
            "image.samples=4",
        ]));
        let instant = s.clone();
        s.push("camera.shutter=0.5".into());
        Case::new(
            "lattice beta=0.9, shutter 0.5",
            paper("lattice", &s)?,
            &["embree", "bvh"],
        )
        .without_hi_reference()
        .with_spp(&[4])
        .beside("the same view at an instant", || paper("lattice", &instant))
    }));
}

/// The paper's lattice at four speeds, and what its shadow and secondary rays cost at 0.9c.
fn lattice_cases(px: u32, out: &mut Vec<LazyCase>) {
    for b in ["0", "0.5", "0.9", "0.99"] {
        out.push(LazyCase::new(&format!("lattice beta={b}"), move || {
            let mut s = size(px);
            s.push(format!("group.lattice.velocity=[-{b},0,0]"));
            let name = format!("lattice beta={b}");
            Ok(Case::new(&name, paper("lattice", &s)?, &LATTICE_SETTINGS)
                .with_bare()
                .with_spp(&[4]))
        }));
    }
    // What shadow and secondary rays cost the paper's lattice at 0.9c.
    out.push(LazyCase::new("lattice beta=0.9, no lights", move || {
        let mut s = size(px);
        s.extend(sets(&["group.lattice.velocity=[-0.9,0,0]", "light=[]"]));
        Ok(Case::new(
            "lattice beta=0.9, no lights",
            paper("lattice", &s)?,
            &["embree", "bvh"],
        ))
    }));
    out.push(LazyCase::new("lattice beta=0.9, mirror rods", move || {
        let mut s = size(px);
        s.extend(sets(&[
            "group.lattice.velocity=[-0.9,0,0]",
            "material.rod.reflect=0.5",
        ]));
        Ok(Case::new(
            "lattice beta=0.9, mirror rods",
            paper("lattice", &s)?,
            &["embree", "bvh"],
        ))
    }));
}

/// Textures, a sky map and a star field on the planet, each beside the planet without it.
fn planet_cases(px: u32, out: &mut Vec<LazyCase>) {
    // What an image texture costs (three colour lookups per hit on the map's basis), against
    // the same planet in one colour; what a sky map costs, and a star field (placing 40,000
    // stars in their pixels, once a frame, and a look up per ray that meets nothing), against
    // a black background.
    for (name, set, beside, beside_set) in [
        (
            "planet 0.9c, image texture",
            None,
            "the same planet in one colour",
            Some("material.surface.color=0.6"),
        ),
        (
            "planet 0.9c, sky map",
            Some("sky.map=\"planet-map.png\""),
            "the same planet against a black background",
            None,
        ),
        (
            "planet 0.9c, star field",
            Some("sky.stars={count=40000, seed=1}"),
            "the same planet against a black background",
            None,
        ),
    ] {
        out.push(LazyCase::new(name, move || {
            let with = |extra: Option<&str>| {
                let mut s = size(px);
                s.extend(extra.map(String::from));
                planet(&s)
            };
            Case::new(name, with(set)?, &["embree", "bvh"])
                .without_hi_reference()
                .beside(beside, || with(beside_set))
        }));
    }
}

/// Spectral light against RGB, and what the EXR passes cost.
fn light_cases(px: u32, out: &mut Vec<LazyCase>) {
    // Light as a camera records it (Doppler shift and searchlight on every leg of a path)
    // against the RGB render of the same scene, measured side by side.
    out.push(LazyCase::new("lattice beta=0.9, spectral", move || {
        let mut s = size(px);
        s.push("group.lattice.velocity=[-0.9,0,0]".into());
        let rgb = s.clone();
        s.extend(sets(&["render.doppler=true", "render.searchlight=true"]));
        Case::new(
            "lattice beta=0.9, spectral",
            paper("lattice", &s)?,
            &["embree", "bvh"],
        )
        .beside("the same scene in RGB (both effects off)", || {
            paper("lattice", &rgb)
        })
    }));
    // What the EXR passes cost: the default EXR, an EXR of colour and alpha alone, and a PNG
    // (colour alone); without passes no ray of their own goes through each pixel's centre when
    // there are several samples.
    out.push(LazyCase::new("lattice beta=0.9, passes", move || {
        let mut s = size(px);
        s.push("group.lattice.velocity=[-0.9,0,0]".into());
        Ok(Case::new(
            "lattice beta=0.9, passes",
            paper("lattice", &s)?,
            &["embree", "embree rgba", "embree colour-only"],
        )
        .with_spp(&[4]))
    }));
}

/// A large lattice and a large bar array, instanced and listed.
fn large_cases(quick: bool, px: u32, out: &mut Vec<LazyCase>) {
    // A large lattice: 100^3 nodes (1M spheres, ~3M rods) at 1024^2.
    let n = if quick { 30 } else { 100 };
    let big_name = format!("lattice {n}^3 beta=0.9");
    out.push(LazyCase::new(&big_name.clone(), move || {
        let big = paper(
            "lattice",
            &[
                format!("image.width={}", 2 * px),
                format!("image.height={}", 2 * px),
                "image.samples=1".into(),
                format!("group.lattice.object.lattice.counts=[{n},{n},{n}]"),
                format!(
                    "group.lattice.object.lattice.origin=[0,{h},{h}]",
                    h = -(n as f64 - 1.0) / 2.0
                ),
                "group.lattice.velocity=[-0.9,0,0]".into(),
            ],
        )?;
        // Instanced (as lattices of over 100,000 primitives are) beside listed primitive by
        // primitive: the comparison with the f64 BVH's frame counts the pixels that differ.
        Ok(Case::new(
            &big_name,
            big,
            &["embree", "bvh", "embree listed", "bvh listed"],
        )
        .without_hi_reference())
    }));
    // A large bar array (a million bars; 10,000 in the quick suite), instanced and listed.
    let bars = if quick { 100 } else { 1000 };
    let bars_name = format!("bar array {bars}x{bars} beta=0.9");
    out.push(LazyCase::new(&bars_name.clone(), move || {
        let mut s = size(px);
        s.extend([
            "group.bars.velocity=[0.9,0,0]".to_string(),
            format!("group.bars.object.array.counts=[{bars},{bars}]"),
        ]);
        Ok(Case::new(
            &bars_name,
            paper("bar_array", &s)?,
            &["embree", "bvh", "embree listed", "bvh listed"],
        )
        .without_hi_reference())
    }));
}

/// Many velocity groups against one, and merging groups of one velocity.
fn group_cases(quick: bool, px: u32, out: &mut Vec<LazyCase>) {
    // Many velocity groups, against one group holding the same boxes.
    let gpx = px / 2;
    let many = if quick {
        [1usize, 100, 1000]
    } else {
        [1, 1000, 10000]
    };
    let top = many[2];
    out.push(LazyCase::new(
        &format!("{top} boxes in 1 group"),
        move || {
            let (scene, text_s) = many_groups_timed(top, true, gpx)?;
            Ok(Case::new(
                &format!("{top} boxes in 1 group"),
                scene,
                &["embree", "bvh"],
            )
            .without_hi_reference()
            .written_in(text_s))
        },
    ));
    for g in many[1..].iter().copied() {
        out.push(LazyCase::new(
            &format!("{g} boxes in {g} groups"),
            move || {
                let settings: &[&str] = if g <= 1000 {
                    &["embree", "bvh", "embree no-tree"]
                } else {
                    &["embree", "bvh"]
                };
                let (scene, text_s) = many_groups_timed(g, false, gpx)?;
                Case::new(&format!("{g} boxes in {g} groups"), scene, settings)
                    .without_hi_reference()
                    .written_in(text_s)
                    .beside("the same boxes in one group", || many_groups(g, true, gpx))
            },
        ));
    }
    // Issue 24's row: 100,000 groups at 1024², against the same boxes in one group.
    if !quick {
        let name = "100000 boxes in 100000 groups at 1024^2";
        out.push(LazyCase::new(name, move || {
            let (scene, text_s) = many_groups_timed(100_000, false, 1024)?;
            Case::new(name, scene, &["embree"])
                .without_hi_reference()
                .written_in(text_s)
                .beside("the same boxes in one group", || {
                    many_groups(100_000, true, 1024)
                })
        }));
    }
    // Merging groups of one velocity: 121 bars, 121 groups.
    out.push(LazyCase::new("121 bars as 121 groups, beta=0.9", || {
        Ok(Case::new(
            "121 bars as 121 groups, beta=0.9",
            bars_as_groups(0.9)?,
            &["embree", "embree no-merge"],
        )
        .without_hi_reference())
    }));
}

#[cfg(test)]
mod tests {
    use super::LATTICE_SETTINGS;
    use crate::bench::parse_setting;

    /// The suite's settings parse, and a setting with a word the bench does not know is an
    /// error (else it would be measured as plain `embree` under its own label).
    #[test]
    fn settings_are_checked() {
        for s in LATTICE_SETTINGS.iter().chain(&[
            "bvh",
            "embree no-tree",
            "embree no-merge",
            "embree colour-only",
            "embree instanced",
            "bvh listed",
        ]) {
            assert!(parse_setting(s).is_ok(), "{s}");
        }
        let (_, o, _) = parse_setting("embree no-cull no-fused").unwrap();
        assert!(!o.bounds_cull && !o.fused_primary && o.group_tree);
        let e = parse_setting("embree no-such-switch")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no-such-switch") && e.contains("no-cull"), "{e}");
    }
}
