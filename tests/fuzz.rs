//! Mutated scenes (numbers swapped for hostile values, lines dropped, doubled or swapped, values
//! of the wrong kind, `--set` overrides of random keys): each is refused with an error or
//! renders with every channel finite; none panics. A fixed seed, so a failure reproduces; the
//! failing scene is printed.

mod common;
use common::*;

const HOSTILE_NUMBERS: [&str; 24] = [
    "0",
    "-0.0",
    "1",
    "-1",
    "2",
    "0.5",
    "0.999999999",
    "1.0000001",
    "1e-300",
    "-1e-300",
    "1e-6",
    "1e15",
    "-1e15",
    "1e16",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "65536",
    "65537",
    "4294967296",
    "9223372036854775807",
    "3e-17",
];
const HOSTILE_VALUES: [&str; 8] = [
    "\"x\"",
    "[]",
    "[1, 2]",
    "[1, 2, 3, 4]",
    "{ a = 1 }",
    "true",
    "[[1, 2, 3]]",
    "{ blackbody = 1e15, luminance = 1 }",
];
const KEYS: [&str; 16] = [
    "camera.time",
    "camera.fov_y",
    "camera.up",
    "camera.position",
    "camera.velocity",
    "camera.rapidity",
    "image.samples",
    "image.background",
    "render.max_depth",
    "render.max_rays",
    "render.ambient",
    "light.0.intensity",
    "light.0.position",
    "group.0.velocity",
    "group.0.one_minus_beta",
    "material.0.color",
];

fn pick<'a>(rng: &mut Rng, items: &[&'a str]) -> &'a str {
    items[(rng.next_u64() % items.len() as u64) as usize]
}

/// One mutation of `text`.
fn mutate(rng: &mut Rng, text: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return text.to_string();
    }
    let k = (rng.next_u64() % lines.len() as u64) as usize;
    match rng.next_u64() % 6 {
        0 | 1 => {
            // A number of the line swapped for a hostile one.
            let line = lines[k].clone();
            let starts: Vec<usize> = line
                .char_indices()
                .filter(|&(i, c)| {
                    (c.is_ascii_digit() || c == '-')
                        && !line[..i].ends_with(|p: char| p.is_alphanumeric() || p == '.')
                })
                .map(|(i, _)| i)
                .collect();
            if let Some(&at) = starts.get((rng.next_u64() % starts.len().max(1) as u64) as usize) {
                let end = line[at + 1..]
                    .find(|c: char| {
                        !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+')
                    })
                    .map_or(line.len(), |e| at + 1 + e);
                lines[k] = format!(
                    "{}{}{}",
                    &line[..at],
                    pick(rng, &HOSTILE_NUMBERS),
                    &line[end..]
                );
            }
        }
        2 => {
            lines.remove(k);
        }
        3 => {
            let l = lines[k].clone();
            lines.insert(k, l);
        }
        4 => {
            let j = (rng.next_u64() % lines.len() as u64) as usize;
            lines.swap(k, j);
        }
        _ => {
            if let Some((key, _)) = lines[k].split_once('=') {
                lines[k] = format!("{key}= {}", pick(rng, &HOSTILE_VALUES));
            }
        }
    }
    lines.join("\n")
}

/// Load, and where that succeeds, render small on every backend: never a panic, never a
/// non-finite channel.
fn check(text: &str, sets: &[(String, String)], what: &str) -> bool {
    let mut all = vec![
        ("--width 8".to_string(), "image.width=8".to_string()),
        ("--height 6".to_string(), "image.height=6".to_string()),
    ];
    all.extend_from_slice(sets);
    let outcome = std::panic::catch_unwind(|| {
        let Ok(s) = rest_embree::scene::load_str("fuzz.toml", text, &all) else {
            return false;
        };
        // Large generated objects cost time, not coverage.
        if s.primitive_count() > 20_000 || s.image.samples > 4 {
            return false;
        }
        for b in backends() {
            let f = render_with(&s, b);
            assert_all_finite(&f, b);
        }
        true
    });
    match outcome {
        Ok(rendered) => rendered,
        Err(_) => panic!("{what} panicked; the scene:\n{text}\noverrides: {sets:?}"),
    }
}

#[test]
fn ten_thousand_mutated_scenes_neither_panic_nor_give_nan() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut bases: Vec<String> = std::fs::read_dir(root.join("scenes"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .collect();
    bases.sort();
    bases.push(common::cli::GOOD.to_string());
    let mut rng = Rng(0x5eed_f00d);
    let (mut rendered, total) = (0, 10_000);
    for n in 0..total {
        let base = &bases[n % bases.len()];
        let mut text = mutate(&mut rng, base);
        for _ in 0..rng.next_u64() % 3 {
            text = mutate(&mut rng, &text);
        }
        let sets = if n.is_multiple_of(4) {
            let key = pick(&mut rng, &KEYS);
            let value = if rng.next_u64().is_multiple_of(2) {
                pick(&mut rng, &HOSTILE_NUMBERS)
            } else {
                pick(&mut rng, &HOSTILE_VALUES)
            };
            vec![(format!("--set {key}={value}"), format!("{key}={value}"))]
        } else {
            vec![]
        };
        if check(&text, &sets, &format!("mutation {n}")) {
            rendered += 1;
        }
    }
    // The mutations must leave many scenes valid, or the renders would go untested.
    assert!(
        rendered > total / 5,
        "only {rendered} of {total} mutated scenes rendered"
    );
    eprintln!("fuzz: {rendered} of {total} mutated scenes rendered, the rest refused");
}
