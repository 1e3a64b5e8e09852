//! The view's values, as the page's controls set them, checked and written as edits of the
//! scene file: the scene the viewer renders is the user's file with those edits (and without
//! its film: the viewer shows one instant), and "render this view" saves exactly that text, so
//! `rest-embree render` of it gives the viewer's final frame.

use crate::Error;
use serde_json::Value;
use toml_edit::{DocumentMut, Item, Table};

/// A view's value refused: the crate's `Error::Invalid`, its message formatted.
macro_rules! refuse {
    ($($t:tt)*) => {
        crate::Error::invalid(format!($($t)*))
    };
}

/// The most a coordinate or a time may be (the scene loader refuses more anyway).
const MAX_MAGNITUDE: f64 = 1e12;

/// Where an edit goes.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Place {
    Camera,
    Render,
    /// The `[[group]]` of this name.
    Group(String),
}

/// One value of the file set by the view: `key = value` (a TOML literal) in `place`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Edit {
    pub place: Place,
    pub key: &'static str,
    pub value: String,
}

impl Edit {
    /// The edit as a `--set` assignment, `TABLE.KEY=VALUE`: the scene a view renders is the
    /// file read once with these, as `rest-embree render --set` reads it.
    pub fn assignment(&self) -> String {
        let table = match &self.place {
            Place::Camera => "camera".to_string(),
            Place::Render => "render".to_string(),
            Place::Group(name) => format!("group.{}", crate::scene::doc::key_part(name)),
        };
        format!("{table}.{}={}", self.key, self.value)
    }
}

/// What the viewer may change of the scene it was started on.
#[derive(Clone, Debug)]
pub(crate) struct Editable {
    /// Groups that move uniformly and are named once: their velocity may be set.
    pub groups: Vec<String>,
    /// Whether the camera is a pinhole (its field of view may be set).
    pub pinhole: bool,
}

/// A view's values checked, as edits; an error names the value and says why.
pub(crate) fn edits(view: &Value, editable: &Editable) -> crate::Result<Vec<Edit>> {
    let view = view
        .as_object()
        .ok_or_else(|| Error::invalid("the view must be a JSON object"))?;
    let mut out = Vec::new();
    for (key, value) in view {
        match key.as_str() {
            "groups" => {
                let groups = value
                    .as_object()
                    .ok_or_else(|| Error::invalid("`groups` must map names to velocities"))?;
                for (name, v) in groups {
                    if !editable.groups.contains(name) {
                        return Err(refuse!(
                            "group `{}`: no uniformly moving group of that name",
                            clip(name)
                        ));
                    }
                    let b = vec3(v, &format!("groups.{name}"))?;
                    let speed = b.iter().map(|x| x * x).sum::<f64>().sqrt();
                    if speed.is_nan() || speed >= 1.0 {
                        return Err(refuse!(
                            "groups.{name}: the speed |β| = {speed} must be below 1 (the speed of light)"
                        ));
                    }
                    out.push(Edit {
                        place: Place::Group(name.clone()),
                        key: "velocity",
                        value: literal3(b),
                    });
                }
            }
            "camera" => out.extend(camera(value, editable)?),
            "doppler" | "searchlight" => {
                let on = value
                    .as_bool()
                    .ok_or_else(|| refuse!("`{key}` must be true or false"))?;
                out.push(Edit {
                    place: Place::Render,
                    key: if key == "doppler" {
                        "doppler"
                    } else {
                        "searchlight"
                    },
                    value: on.to_string(),
                });
            }
            other => return Err(refuse!("unknown view value `{}`", clip(other))),
        }
    }
    Ok(out)
}

fn camera(value: &Value, editable: &Editable) -> crate::Result<Vec<Edit>> {
    let cam = value
        .as_object()
        .ok_or_else(|| Error::invalid("`camera` must be an object"))?;
    let mut out = Vec::new();
    for (key, v) in cam {
        let shown = format!("camera.{key}");
        let (key, value) = match key.as_str() {
            "position" => ("position", literal3(vec3(v, &shown)?)),
            "direction" | "up" => {
                let d = vec3(v, &shown)?;
                if d.iter().all(|&x| x == 0.0) {
                    return Err(refuse!("{shown} must not be zero"));
                }
                (if key == "up" { "up" } else { "direction" }, literal3(d))
            }
            "time" => ("time", literal(number(v, &shown)?)),
            "fov_y" => {
                let f = number(v, &shown)?;
                if !editable.pinhole {
                    return Err(refuse!("{shown}: the camera is not a pinhole"));
                }
                if !(1e-6..180.0).contains(&f) {
                    return Err(refuse!(
                        "{shown} = {f}: at least 1e-6 and below 180 degrees"
                    ));
                }
                ("fov_y", literal(f))
            }
            other => return Err(refuse!("unknown camera value `{}`", clip(other))),
        };
        out.push(Edit {
            place: Place::Camera,
            key,
            value,
        });
    }
    Ok(out)
}

/// A new view time for a camera that moves, its position not given: the camera moves along its
/// worldline to that time (as a film's frames do), rather than jumping to another worldline
/// through its old place.
pub(crate) fn follow_worldline(edits: &mut Vec<Edit>, camera: &crate::scene::Camera) {
    let on_camera = |e: &&Edit, key: &str| e.place == Place::Camera && e.key == key;
    let time = edits
        .iter()
        .find(|e| on_camera(e, "time"))
        .and_then(|e| e.value.parse::<f64>().ok());
    let placed = edits.iter().any(|e| on_camera(&e, "position"));
    let moves = !camera.velocity.is_zero() || camera.worldline.is_some();
    if let (Some(t), false, true) = (time, placed, moves) {
        let p = camera.at_time(t).position;
        edits.push(Edit {
            place: Place::Camera,
            key: "position",
            value: literal3([p.x, p.y, p.z]),
        });
    }
}

/// A finite number of moderate size.
fn number(v: &Value, shown: &str) -> crate::Result<f64> {
    let x = v
        .as_f64()
        .ok_or_else(|| refuse!("{shown} must be a number"))?;
    if !x.is_finite() || x.abs() > MAX_MAGNITUDE {
        return Err(refuse!(
            // Rust's shortest form (`1e300`), not every digit of the number.
            "{shown} = {x:?}: must be finite and at most {MAX_MAGNITUDE:e} in size"
        ));
    }
    Ok(x)
}

fn vec3(v: &Value, shown: &str) -> crate::Result<[f64; 3]> {
    let a = v
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or_else(|| refuse!("{shown} must be three numbers"))?;
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(a) {
        *o = number(x, shown)?;
    }
    Ok(out)
}

/// A TOML float that reads back as the same f64 (Rust's shortest round-trip form).
fn literal(x: f64) -> String {
    // `1e-7` and `1e20` are TOML floats too; never `inf` or `NaN` here (checked finite).
    format!("{x:?}")
}

fn literal3(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", literal(v[0]), literal(v[1]), literal(v[2]))
}

/// At most 40 characters of a name the request gave, for an error.
pub(super) fn clip(s: &str) -> String {
    s.chars().take(40).collect()
}

/// The scene text with `edits` made (each edit's other ways of giving the same setting taken
/// out, as `--set` does), without its `[film]`, and a first line saying where it came from.
pub(crate) fn saved_text(original: &str, source: &str, edits: &[Edit]) -> crate::Result<String> {
    let mut doc: DocumentMut = original
        .parse()
        .map_err(|e| refuse!("{source} is not TOML the viewer can edit: {e}"))?;
    doc.remove("film");
    for e in edits {
        let value: toml_edit::Value = e.value.parse().map_err(|err| refuse!("{}: {err}", e.key))?;
        let (path, table): (Vec<&str>, &mut Table) = match &e.place {
            Place::Camera => (vec!["camera"], table_in(&mut doc, "camera")),
            Place::Render => (vec!["render"], table_in(&mut doc, "render")),
            Place::Group(name) => (vec!["group", name.as_str()], group_in(&mut doc, name)?),
        };
        for gone in crate::scene::superseded(&path, e.key) {
            table.remove(gone);
        }
        table.insert(e.key, Item::Value(value));
    }
    absolute_paths(&mut doc, source);
    // The path goes into a comment: escaped, so that no character of it can end the comment
    // and write TOML of its own.
    let from = crate::text::shown(source);
    Ok(format!(
        "# The view saved by `rest-embree view` from {from}: render it with `rest-embree render`\n# from anywhere (the files it names are given by their full paths).\n{doc}"
    ))
}

/// The files a scene names (a mesh's `file`, a texture's `image`, the sky's `map`) relative to
/// its folder, given instead by their full paths: the saved view renders the same wherever it
/// is kept.
fn absolute_paths(doc: &mut DocumentMut, source: &str) {
    let folder = std::path::Path::new(source)
        .parent()
        .unwrap_or(std::path::Path::new(""));
    let folder = std::fs::canonicalize(if folder.as_os_str().is_empty() {
        std::path::Path::new(".")
    } else {
        folder
    });
    let Ok(folder) = folder else { return };
    let fix = |item: Option<&mut Item>| {
        let Some(item) = item else { return };
        let Some(name) = item.as_str() else { return };
        let path = std::path::Path::new(name);
        if path.is_relative() {
            let full = folder.join(path).to_string_lossy().into_owned();
            *item = toml_edit::value(full);
        }
    };
    if let Some(textures) = doc
        .get_mut("texture")
        .and_then(|t| t.as_array_of_tables_mut())
    {
        for t in textures.iter_mut() {
            fix(t.get_mut("image"));
        }
    }
    if let Some(sky) = doc.get_mut("sky").and_then(|t| t.as_table_like_mut()) {
        fix(sky.get_mut("map"));
    }
    if let Some(groups) = doc
        .get_mut("group")
        .and_then(|t| t.as_array_of_tables_mut())
    {
        for g in groups.iter_mut() {
            if let Some(objects) = g.get_mut("object").and_then(|t| t.as_array_of_tables_mut()) {
                for o in objects.iter_mut() {
                    fix(o.get_mut("file"));
                }
            }
        }
    }
}

/// The table `[name]`, made if the file has none.
fn table_in<'a>(doc: &'a mut DocumentMut, name: &str) -> &'a mut Table {
    let item = doc.entry(name).or_insert_with(|| Item::Table(Table::new()));
    if !item.is_table() {
        *item = Item::Table(Table::new());
    }
    item.as_table_mut().expect("made a table")
}

/// The scene text with `--set` overrides written into it (comments and layout kept), so that
/// the viewer serves, and a saved view holds, the scene the overrides make. Each is checked by
/// the scene loader first (its errors are the command line's); then written where the loader
/// puts it: a table of the path made if missing, an entry of an array of tables found by its
/// `name` or its index, the keys the value replaces (`superseded`) removed.
pub(crate) fn with_overrides(
    text: &str,
    source: &str,
    overrides: &[(String, String)],
) -> crate::Result<String> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    crate::scene::load_str(source, text, overrides)?;
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e| refuse!("{source} is not TOML the viewer can edit: {e}"))?;
    for (shown, assignment) in overrides {
        let (key, raw) = assignment
            .split_once('=')
            .ok_or_else(|| refuse!("{shown}: expected KEY=VALUE"))?;
        let raw = raw.trim();
        // As the loader takes a `--set` value: TOML, or a bare word as a string.
        let value: toml_edit::Value = raw
            .parse()
            .unwrap_or_else(|_| toml_edit::Value::from(raw.to_string()));
        // Split as the loader splits it: at the dots outside quotes (`group."Cube.001"`).
        let parts = crate::scene::doc::key_parts(key.trim())
            .ok_or_else(|| refuse!("{shown}: a quote in the key is not closed"))?;
        let segs: Vec<&str> = parts.iter().map(|(s, _)| s.as_str()).collect();
        let lost = || refuse!("{shown}: the file has no place for `{}`", key.trim());
        let mut table: &mut dyn toml_edit::TableLike = doc.as_table_mut();
        let mut i = 0;
        while i + 1 < segs.len() {
            let item = table.entry(segs[i]).or_insert(Item::Table(Table::new()));
            // An entry of an array of tables: the next segment is its name or index.
            let pick = |names: Vec<Option<&str>>| {
                let sel = segs[i + 1];
                names
                    .iter()
                    .position(|n| *n == Some(sel))
                    .or_else(|| sel.parse::<usize>().ok().filter(|&j| j < names.len()))
            };
            table = match item {
                Item::ArrayOfTables(entries) => {
                    let names = entries.iter().map(|t| t.get("name").and_then(Item::as_str));
                    let j = pick(names.collect()).ok_or_else(lost)?;
                    i += 2;
                    entries.get_mut(j).ok_or_else(lost)?
                }
                Item::Value(toml_edit::Value::Array(entries)) => {
                    let names = entries.iter().map(|v| {
                        v.as_inline_table()
                            .and_then(|t| t.get("name"))
                            .and_then(|n| n.as_str())
                    });
                    let j = pick(names.collect()).ok_or_else(lost)?;
                    i += 2;
                    entries
                        .get_mut(j)
                        .and_then(|v| v.as_inline_table_mut())
                        .map(|t| t as &mut dyn toml_edit::TableLike)
                        .ok_or_else(lost)?
                }
                other => {
                    i += 1;
                    other.as_table_like_mut().ok_or_else(lost)?
                }
            };
        }
        let last = *segs.last().ok_or_else(lost)?;
        for gone in crate::scene::superseded(&segs[..segs.len() - 1], last) {
            table.remove(gone);
        }
        table.insert(last, Item::Value(value));
    }
    Ok(doc.to_string())
}

/// The `[[group]]` named `name`.
fn group_in<'a>(doc: &'a mut DocumentMut, name: &str) -> crate::Result<&'a mut Table> {
    doc.get_mut("group")
        .and_then(|g| g.as_array_of_tables_mut())
        .and_then(|groups| {
            groups
                .iter_mut()
                .find(|t| t.get("name").and_then(|n| n.as_str()) == Some(name))
        })
        .ok_or_else(|| refuse!("no [[group]] named `{}` in the file", clip(name)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn editable() -> Editable {
        Editable {
            groups: vec!["lattice".into()],
            pinhole: true,
        }
    }

    /// A group whose name holds a dot is edited through a quoted key, which the scene's
    /// reader takes as that name.
    #[test]
    fn a_name_with_dots_is_quoted_in_the_assignment() {
        let edit = Edit {
            place: Place::Group("Cube.001".into()),
            key: "velocity",
            value: "[0.5, 0, 0]".into(),
        };
        let set = edit.assignment();
        assert_eq!(set, "group.\"Cube.001\".velocity=[0.5, 0, 0]");
        let text = "[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0]\n[[group]]\nname = \"Cube.001\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [5, 0, 0]\nradius = 1\n";
        let scene = crate::scene::load_str("t.toml", text, &[(set.clone(), set)]).unwrap();
        assert!((scene.groups[0].velocity.beta() - 0.5).abs() < 1e-12);
        assert_eq!(crate::scene::doc::key_part("a \"b\".c"), "'a \"b\".c'");
        assert_eq!(crate::scene::doc::key_part("cube"), "cube");
    }

    const TEXT: &str = "# top\n[camera]\nposition = [0, 0, 0]\nlook_at = [1, 0, 0] # aim\nfov_y = 60\n\n[[group]]\nname = \"lattice\"\ndirection = [1, 0, 0]\nbeta = 0.5\n[[group.object]]\ntype = \"sphere\"\n\n[film]\nframes = 3\n";

    #[test]
    fn overrides_are_written_where_the_loader_puts_them() {
        let sets = |list: &[&str]| -> Vec<(String, String)> {
            list.iter()
                .map(|s| (format!("--set {s}"), s.to_string()))
                .collect()
        };
        let over = sets(&[
            "group.lattice.velocity=[-0.9, 0, 0]",
            "group.lattice.object.0.radius=2",
            "image.width=64",
            "camera.projection=orthographic",
            "camera.view_height=3",
        ]);
        const SCENE: &str = "# top\n[camera]\nposition = [0, 0, 0]\nlook_at = [10, 0, 0] # aim\n\n[[group]]\nname = \"lattice\"\ndirection = [1, 0, 0]\nbeta = 0.5\n[[group.object]]\ntype = \"sphere\"\ncenter = [10, 0, 0]\nradius = 1\n";
        let text = with_overrides(SCENE, "v.toml", &over).unwrap();
        // The text loads as the file with the overrides does, and keeps its comments.
        let a = crate::scene::load_str("v.toml", SCENE, &over).unwrap();
        let b = crate::scene::load_str("v.toml", &text, &[]).unwrap();
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert!(
            text.contains("# aim") && !text.contains("beta = 0.5"),
            "{text}"
        );
        // A refused override is the loader's error, and nothing is written.
        let why = with_overrides(
            SCENE,
            "v.toml",
            &sets(&["group.nothing.velocity=[0.1, 0, 0]"]),
        )
        .unwrap_err()
        .to_string();
        assert!(
            why.contains("--set group.nothing") && why.contains("nothing"),
            "{why}"
        );
        // A name with dots, in quotes, as the loader reads it (it was split at its dot here).
        let dotted = SCENE.replace("\"lattice\"", "\"Cube.001\"");
        let over = sets(&["group.\"Cube.001\".velocity=[0.3, 0, 0]"]);
        let text = with_overrides(&dotted, "v.toml", &over).unwrap();
        let a = crate::scene::load_str("v.toml", &dotted, &over).unwrap();
        let b = crate::scene::load_str("v.toml", &text, &[]).unwrap();
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert!((b.groups[0].velocity.beta() - 0.3).abs() < 1e-12, "{text}");
    }

    #[test]
    fn edits_replace_the_other_ways_of_giving_a_value_and_keep_the_rest() {
        let view = json!({
            "groups": { "lattice": [-0.9, 0.0, 1e-7] },
            "camera": { "direction": [0.0, 1.0, 0.0], "time": 2.5, "fov_y": 45.0 },
            "doppler": true
        });
        let e = edits(&view, &editable()).unwrap();
        let text = saved_text(TEXT, "a.toml", &e).unwrap();
        assert!(text.contains("# top"), "{text}");
        assert!(text.contains("velocity = [-0.9, 0.0, 1e-7]"), "{text}");
        assert!(
            !text.contains("beta") && !text.contains("look_at"),
            "{text}"
        );
        assert!(text.contains("direction = [0.0, 1.0, 0.0]"), "{text}");
        assert!(
            text.contains("time = 2.5") && text.contains("fov_y = 45.0"),
            "{text}"
        );
        assert!(
            text.contains("[render]") && text.contains("doppler = true"),
            "{text}"
        );
        assert!(!text.contains("[film]"), "{text}");
        let back: DocumentMut = text.parse().unwrap();
        assert_eq!(back["group"][0]["velocity"][2].as_float(), Some(1e-7));
    }

    /// A velocity replaces a group's worldline of one segment; the files a scene names are
    /// given by full path, so the saved view renders the same from any folder.
    #[test]
    fn a_velocity_replaces_a_worldline_and_files_get_full_paths() {
        let text = "[camera]\nposition = [0, 0, 0]\ndirection = [1, 0, 0]\n[[texture]]\nname = \"t\"\nimage = \"paint.png\"\n[sky]\nmap = \"/abs/sky.exr\"\n[[group]]\nname = \"g\"\nworldline = [{ velocity = [0.1, 0, 0] }]\n[[group.object]]\ntype = \"mesh\"\nfile = \"m.obj\"\n";
        let e = edits(
            &json!({ "groups": { "g": [0.2, 0.0, 0.0] } }),
            &Editable {
                groups: vec!["g".into()],
                pinhole: true,
            },
        )
        .unwrap();
        let saved = saved_text(text, "scenes/x.toml", &e).unwrap();
        let doc: DocumentMut = saved.parse().unwrap();
        let g = &doc["group"][0];
        assert!(
            g.get("worldline").is_none() && g.get("velocity").is_some(),
            "{saved}"
        );
        let here = std::fs::canonicalize("scenes").unwrap();
        assert_eq!(
            doc["texture"][0]["image"].as_str(),
            Some(here.join("paint.png").to_str().unwrap())
        );
        assert_eq!(
            g["object"][0]["file"].as_str(),
            Some(here.join("m.obj").to_str().unwrap())
        );
        assert_eq!(doc["sky"]["map"].as_str(), Some("/abs/sky.exr"));
    }

    /// A moving camera given a new view time moves along its worldline to it.
    #[test]
    fn a_moving_camera_follows_its_worldline_to_a_new_time() {
        let text = "[camera]\nposition = [1, 0, 0]\ndirection = [0, 1, 0]\nvelocity = [0.5, 0, 0]\ntime = 2\n[[group]]\nname = \"g\"\n[[group.object]]\ntype = \"sphere\"\ncenter = [0, 5, 0]\nradius = 1\n";
        let camera = crate::scene::load_str("t.toml", text, &[]).unwrap().camera;
        let mut e = edits(&json!({ "camera": { "time": 6.0 } }), &editable()).unwrap();
        follow_worldline(&mut e, &camera);
        let saved = saved_text(text, "t.toml", &e).unwrap();
        assert!(saved.contains("position = [3.0, 0.0, 0.0]"), "{saved}");
        // Given a position, or at rest, the camera stays where it is told.
        let mut e = edits(
            &json!({ "camera": { "time": 6.0, "position": [0.0, 0.0, 0.0] } }),
            &editable(),
        )
        .unwrap();
        follow_worldline(&mut e, &camera);
        assert_eq!(e.iter().filter(|e| e.key == "position").count(), 1);
    }

    #[test]
    fn bad_values_are_refused_with_their_name() {
        let bad = [
            (
                json!({ "groups": { "lattice": [1.0, 0.0, 0.0] } }),
                "must be below 1",
            ),
            (
                json!({ "groups": { "lattice": [0.6, 0.6, 0.6] } }),
                "must be below 1",
            ),
            (
                json!({ "groups": { "lattice": [0.1, 0.0] } }),
                "three numbers",
            ),
            (
                json!({ "groups": { "lattice": ["0.1", 0.0, 0.0] } }),
                "must be a number",
            ),
            (
                json!({ "groups": { "other": [0.1, 0.0, 0.0] } }),
                "group `other`",
            ),
            (
                json!({ "camera": { "position": [1e300, 0.0, 0.0] } }),
                "must be finite and at most",
            ),
            (
                json!({ "camera": { "direction": [0.0, 0.0, 0.0] } }),
                "must not be zero",
            ),
            (json!({ "camera": { "fov_y": 180.0 } }), "below 180"),
            (json!({ "camera": { "zoom": 1.0 } }), "unknown camera value"),
            (json!({ "width": 100000 }), "unknown view value"),
            (json!([1, 2]), "JSON object"),
        ];
        for (view, needle) in bad {
            let e = edits(&view, &editable()).unwrap_err();
            assert!(e.to_string().contains(needle), "{view}: {e}");
        }
        // A huge number is said in its short form, not in its 301 digits.
        let huge = json!({ "camera": { "position": [1e300, 0.0, 0.0] } });
        let e = edits(&huge, &editable()).unwrap_err().to_string();
        assert!(e.contains("= 1e300:") && e.len() < 120, "{e}");
    }
}
