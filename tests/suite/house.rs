//! House rules a change could quietly break: Embree is called through its thin layer only, the
//! code cites nothing outside the repository, and every section of docs/physics.md it cites
//! exists.

use std::path::{Path, PathBuf};

fn files_ending(dir: &Path, exts: &[&str], out: &mut Vec<PathBuf>) {
    if dir.is_file() {
        out.push(dir.to_path_buf());
        return;
    }
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files_ending(&p, exts, out);
        } else if p.extension().is_some_and(|x| exts.iter().any(|e| x == *e)) {
            out.push(p);
        }
    }
}

/// The Rust files under `dirs`, with their text.
fn sources(dirs: &[&str]) -> Vec<(PathBuf, String)> {
    files_of(dirs, &["rs"])
}

/// The files under `dirs` (or the files `dirs` names) ending in one of `exts`, with their text.
fn files_of(dirs: &[&str], exts: &[&str]) -> Vec<(PathBuf, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for d in dirs {
        files_ending(&root.join(d), exts, &mut files);
    }
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text)
        })
        .collect()
}

/// The code of a line, without its comment.
fn code(line: &str) -> &str {
    line.split("//").next().unwrap_or("")
}

#[test]
fn embree_is_called_through_its_layer_only() {
    let mut calls = 0;
    for (path, text) in sources(&["src"]) {
        let layer = path.ends_with("accel/embree/rtc.rs");
        for (n, line) in text.lines().enumerate() {
            let c = code(line);
            let found = c.match_indices("rtc").any(|(i, _)| {
                let rest = &c[i + 3..];
                let name: String = rest.chars().take_while(|ch| ch.is_alphanumeric()).collect();
                name.starts_with(|ch: char| ch.is_ascii_uppercase())
                    && rest[name.len()..].starts_with('(')
                    && !c[..i].ends_with(|ch: char| ch.is_alphanumeric() || ch == '_')
            });
            if found {
                assert!(
                    layer,
                    "{}:{}: an Embree call outside accel/embree/rtc.rs: {line}",
                    path.display(),
                    n + 1
                );
                calls += 1;
            }
        }
    }
    assert!(calls > 10, "the layer makes Embree's calls ({calls} found)");
}

#[test]
fn nothing_cites_files_outside_the_repository() {
    let places = [
        "src",
        "tests",
        "examples",
        "docs",
        "scripts",
        "README.md",
        "Makefile",
    ];
    for (path, text) in files_of(&places, &["rs", "md", "sh", "py", "toml"]) {
        if path.ends_with("tests/suite/house.rs") {
            continue;
        }
        // The names are put together here so that this file does not cite them itself.
        let outside = [
            ["..", "/shared"].concat(),
            ["PHYSICS", ".md"].concat(),
            ["DESIGN", ".md"].concat(),
        ];
        for (n, line) in text.lines().enumerate() {
            for bad in &outside {
                assert!(
                    !line.contains(bad),
                    "{}:{}: cites `{bad}`, which is not in the repository",
                    path.display(),
                    n + 1
                );
            }
        }
    }
}

#[test]
fn every_cited_section_of_the_physics_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let physics = std::fs::read_to_string(root.join("docs/physics.md")).unwrap();
    let headings: Vec<String> = physics
        .lines()
        .filter(|l| l.starts_with('#'))
        .filter_map(|l| l.trim_start_matches('#').split_whitespace().next())
        .map(|n| n.trim_end_matches('.').to_string())
        .collect();
    let mut cited = 0;
    for (path, text) in sources(&["src", "tests"]) {
        if path.ends_with("tests/suite/house.rs") {
            continue;
        }
        for (at, _) in text.match_indices("docs/physics.md §") {
            let rest = &text[at + "docs/physics.md §".len()..];
            let number: String = rest
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.')
                .collect();
            let number = number.trim_end_matches('.');
            assert!(
                headings.iter().any(|h| h == number),
                "{} cites docs/physics.md §{number}, which has no such section",
                path.display()
            );
            cited += 1;
        }
    }
    assert!(cited > 10, "the code cites the physics ({cited} citations)");
}

/// Errors are the crate's `Error` (or a scene's `SceneError`); a bare `String` as the error
/// is left to the parsers clap calls for a flag's value (`value_parser = name`), and to at
/// most three functions besides.
#[test]
fn errors_are_the_crates_own() {
    let files = sources(&["src"]);
    let parsers: Vec<String> = files
        .iter()
        .flat_map(|(_, text)| {
            text.match_indices("value_parser = ")
                .map(|(at, _)| {
                    let rest = &text[at + "value_parser = ".len()..];
                    let path: String = rest
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                        .collect();
                    path.rsplit("::").next().unwrap_or("").to_string()
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut others = Vec::new();
    for (path, text) in &files {
        if path.components().any(|c| c.as_os_str() == "tests") {
            continue;
        }
        // A signature may span lines: from each `fn` to its body's brace.
        for (at, _) in text.match_indices("fn ") {
            let sig = &text[at..];
            let sig = &sig[..sig.find('{').unwrap_or(sig.len()).min(600)];
            let compact: String = sig.split_whitespace().collect::<Vec<_>>().join(" ");
            let returns = compact.rsplit_once("->").map(|(_, r)| r.trim());
            if returns.is_some_and(|r| r.starts_with("Result<") && r.ends_with(", String>")) {
                let name: String = compact[3..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !parsers.contains(&name) {
                    others.push(format!("{}: {name}", path.display()));
                }
            }
        }
    }
    assert!(
        others.len() <= 3,
        "functions returning Result<_, String> outside clap's parsers: {others:#?}"
    );
}

/// Every picture's commands (docs/gallery.md, which the README's pictures link to) are the ones
/// `scripts/readme-images.sh` runs to make it: the gallery's `rest-embree render … -o
/// docs/img/NAME.png` lines are the script's (`$r` for `rest-embree`, `$o/` for `docs/img/`,
/// `$q` for its --quiet), the same set both ways; each film's six frames and their mosaic name
/// the frames the script joins; and every picture the README or the gallery shows is made by
/// one of them.
#[test]
fn every_readme_picture_says_the_command_that_makes_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("docs/gallery.md")).unwrap();
    let front = std::fs::read_to_string(root.join("README.md")).unwrap();
    let script = std::fs::read_to_string(root.join("scripts/readme-images.sh")).unwrap();
    let from_readme: std::collections::BTreeSet<String> = readme
        .lines()
        .filter(|l| l.starts_with("rest-embree render ") && l.contains("-o docs/img/"))
        .map(str::to_string)
        .collect();
    let from_script: std::collections::BTreeSet<String> = script
        .lines()
        .filter(|l| l.starts_with("$r render "))
        .map(|l| {
            l.replacen("$r render ", "rest-embree render ", 1)
                .replace(" $q", "")
                .replace("\"$o/", "docs/img/")
                .replace(".png\"", ".png")
        })
        .collect();
    assert!(from_script.len() > 30, "{from_script:?}");
    let only_readme: Vec<_> = from_readme.difference(&from_script).collect();
    let only_script: Vec<_> = from_script.difference(&from_readme).collect();
    assert!(
        only_readme.is_empty() && only_script.is_empty(),
        "in the README only: {only_readme:#?}\nin the script only: {only_script:#?}"
    );
    // Films: `six SCENE NAME K...` in the script, the same frames under the picture.
    for line in script.lines().filter(|l| l.starts_with("six ")) {
        let words: Vec<&str> = line.split_whitespace().collect();
        let (scene, name, ks) = (words[1], words[2], words[3..].join(" "));
        assert!(
            readme.contains(&format!("for k in {ks}; do"))
                && readme.contains(&format!(
                    "rest-embree render scenes/{scene}.toml -o {name}-$k.png --width 320 --height 180 --frames $k"
                ))
                && readme.contains(&format!("--mosaic 3x2 -o docs/img/{name}.png")),
            "the README's commands for {name}: frames {ks} of scenes/{scene}.toml"
        );
    }
    // Every picture shown is made by a command above (or is the viewer's screenshot).
    let shown = |page: &str, prefix: &str| -> Vec<String> {
        page.split(prefix)
            .skip(1)
            .map(|s| s.split(')').next().unwrap().to_string())
            .collect()
    };
    let pictures = [shown(&front, "](docs/img/"), shown(&readme, "](img/")].concat();
    assert!(pictures.len() > 30, "{pictures:?}");
    for pic in &pictures {
        let made = from_readme
            .iter()
            .any(|c| c.contains(&format!("-o docs/img/{pic}")))
            || readme.contains(&format!("-o docs/img/{pic}"))
            || pic.as_str() == "viewer.png";
        assert!(made, "no command makes docs/img/{pic}");
    }
}
