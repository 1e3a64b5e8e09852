//! `--set`'s keys: which entry a name reaches (unique names, names with dots in quotes), and
//! which of a setting's forms a value replaces.

use crate::common::cli::GOOD;

/// A name `--set` addresses is one entry's: two lights of a name, or two objects of a name in
/// one group, are refused (the second could not be reached: the fifth trial's mesh and
/// sphere both named `rock`); the same object name in two groups is two addresses.
#[test]
fn names_set_addresses_are_unique() {
    let load = |text: &str| rest_embree::scene::load_str("test.toml", text, &[]).map(|_| ());
    let twice = GOOD.replace(
        "material = \"white\"\n",
        "material = \"white\"\nname = \"rock\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [0, 12, 0]\nradius = 0.5\nname = \"rock\"\n",
    );
    let e = load(&twice).unwrap_err().to_string();
    assert!(
        e.contains("group.cube.object.rock.name")
            && e.contains("group `cube` holds two objects named `rock`"),
        "{e}"
    );
    let apart = twice.replace(
        "name = \"rock\"\n[[group.object]]",
        "name = \"rock\"\n[[group]]\nname = \"other\"\n[[group.object]]",
    );
    load(&apart).unwrap();
    let lights = GOOD.replace(
        "[[light]]\n",
        "[[light]]\nname = \"sun\"\nposition = [0, 0, 30]\n[[light]]\nname = \"sun\"\n",
    );
    let e = load(&lights).unwrap_err().to_string();
    assert!(
        e.contains("light.sun.name") && e.contains("a light named `sun` is defined twice"),
        "{e}"
    );
}

/// `--set` of one way of giving a motion replaces the others, whichever the file gives: a
/// worldline over a group's, the camera's or a light's velocity and back, a film's step over
/// its frame rate (each was "give either ..., not both", from the fifth trial).
#[test]
fn set_replaces_the_other_forms_of_a_motion() {
    use rest_embree::scene::FrameSpacing;
    let film = format!(
        "{}\n[film]\nend = 12\nfps = 1\n",
        GOOD.replace(
            "[[light]]\n",
            "[[light]]\nname = \"lamp\"\nvelocity = [0.1, 0, 0]\n",
        )
        .replace("group = \"cube\"\n", "")
    );
    let line = "[{ until = 5, velocity = [0.5, 0, 0] }, { velocity = [0, 0, 0] }]";
    let set = |pairs: &[(&str, String)]| {
        let sets: Vec<(String, String)> = pairs
            .iter()
            .map(|(k, v)| (format!("--set {k}={v}"), format!("{k}={v}")))
            .collect();
        rest_embree::scene::load_str("test.toml", &film, &sets)
    };
    let s = set(&[
        ("group.cube.worldline", line.to_string()),
        ("camera.worldline", line.to_string()),
        ("light.lamp.worldline", line.to_string()),
        ("film.step", "0.5".to_string()),
    ])
    .unwrap();
    assert_eq!(s.groups.len(), 2, "the group's worldline of two pieces");
    assert!(s.camera.worldline.is_some());
    let f = s.film.as_ref().unwrap();
    assert_eq!(f.spacing, FrameSpacing::Step(0.5));
    assert_eq!(
        f.frame_count(),
        5,
        "frames every 0.5 from the camera's 10 to 12"
    );
    // And back: a velocity over the worldline the step gave.
    let s = set(&[
        ("camera.worldline", line.to_string()),
        ("camera.velocity", "[0.2, 0, 0]".to_string()),
        ("film.step", "0.5".to_string()),
        ("film.fps", "2".to_string()),
    ])
    .unwrap();
    assert!(s.camera.worldline.is_none());
    assert!((s.camera.velocity.beta() - 0.2).abs() < 1e-12);
    assert_eq!(s.film.unwrap().spacing, FrameSpacing::Fps(2.0));
}

/// A name with dots is reached in quotes, as in a TOML key (`group."g.x".velocity`; the
/// fifth trial could not reach it), and a quoted number is a name, never an index.
#[test]
fn set_reaches_names_with_dots_in_quotes() {
    let two = format!(
        "{}\n[[group]]\nname = \"g.x\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [3, 12, 0]\nradius = 0.5\n",
        GOOD.replace("name = \"cube\"", "name = \"7\"")
            .replace("group = \"cube\"", "group = \"7\"")
    );
    let set = |pairs: &[&str]| {
        let sets: Vec<(String, String)> = pairs
            .iter()
            .map(|s| (format!("--set {s}"), s.to_string()))
            .collect();
        rest_embree::scene::load_str("test.toml", &two, &sets)
    };
    let s = set(&[
        "group.\"g.x\".velocity=[0.3, 0, 0]",
        "group.'7'.velocity=[0, 0.2, 0]",
    ])
    .unwrap();
    let beta = |name: &str| {
        s.groups
            .iter()
            .find(|g| g.name == name)
            .unwrap()
            .velocity
            .beta_vec()
    };
    assert!((beta("g.x").x - 0.3).abs() < 1e-12 && (beta("7").y - 0.2).abs() < 1e-12);
    // Unquoted, the dots split the name; a quote left open is said.
    let e = set(&["group.g.x.velocity=[0.3, 0, 0]"])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("no [[group]] entry named `g`") && e.contains("g.x"),
        "{e}"
    );
    let e = set(&["group.\"g.x.velocity=[0.3, 0, 0]"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("a name with dots in quotes"), "{e}");
    // A quoted number is a name: no group is named 1, though there is a second entry.
    let e = set(&["group.\"1\".velocity=[0.3, 0, 0]"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("no [[group]] entry named `1`"), "{e}");
    set(&["group.1.velocity=[0.3, 0, 0]"]).unwrap();
}
