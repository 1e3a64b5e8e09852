//! The scene tree read by `scene::toml_tree` (from toml_parser's events) is the tree read
//! through `toml_edit`'s document, the reference: the same tables, arrays, values and lines, or
//! an error from both. On the project's scenes, on cases chosen to probe TOML's rules for
//! tables, and on thousands of mutated scenes.

use crate::rng::Rng;
use crate::scene::doc::{Form, Lines, Node, Origin, Val};
use crate::scene::toml_tree::parse_document;
use toml_edit::{Item, Value};

/// The reference: toml_edit's document, converted node by node; values take their key's line,
/// array elements their own.
fn reference(text: &str) -> Option<Node> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let lines = Lines::new(text);
    Some(table(doc.as_table(), Origin::line(1), &lines))
}

fn node(val: Val, origin: Origin) -> Node {
    Node {
        val,
        origin,
        form: Form::VALUE,
    }
}

fn at(lines: &Lines, span: Option<std::ops::Range<usize>>, fallback: Origin) -> Origin {
    span.map_or(fallback, |s| Origin::line(lines.line_of(s.start)))
}

fn value(v: &Value, origin: Origin, lines: &Lines) -> Node {
    let val = match v {
        Value::String(s) => Val::Str(s.value().clone()),
        Value::Integer(i) => Val::Int(*i.value()),
        Value::Float(f) => Val::Float(*f.value()),
        Value::Boolean(b) => Val::Bool(*b.value()),
        Value::Datetime(_) => Val::Other("a date"),
        Value::Array(a) => Val::Array(
            a.iter()
                .map(|e| value(e, at(lines, e.span(), origin), lines))
                .collect(),
        ),
        Value::InlineTable(t) => Val::Table(
            t.iter()
                .map(|(k, e)| {
                    let o = at(lines, t.key(k).and_then(|k| k.span()).or(e.span()), origin);
                    (k.to_string(), value(e, o, lines))
                })
                .collect(),
        ),
    };
    node(val, origin)
}

fn table(t: &toml_edit::Table, origin: Origin, lines: &Lines) -> Node {
    let entries = t
        .iter()
        .map(|(k, i)| {
            let o = at(lines, t.key(k).and_then(|k| k.span()).or(i.span()), origin);
            (k.to_string(), item(i, o, lines))
        })
        .collect();
    node(Val::Table(entries), origin)
}

fn item(i: &Item, origin: Origin, lines: &Lines) -> Node {
    match i {
        Item::Value(v) => value(v, origin, lines),
        Item::Table(t) => table(t, origin, lines),
        Item::ArrayOfTables(a) => node(
            Val::Array(
                a.iter()
                    .map(|t| table(t, at(lines, t.span(), origin), lines))
                    .collect(),
            ),
            origin,
        ),
        Item::None => node(Val::Other("nothing"), origin),
    }
}

/// Tables compared as sets of keys: toml_edit orders a table's entries by where they were
/// written, headers included, this reader by when each was made.
fn same(a: &Node, b: &Node) -> bool {
    if a.origin != b.origin {
        return false;
    }
    match (&a.val, &b.val) {
        (Val::Table(x), Val::Table(y)) => {
            x.len() == y.len()
                && x.iter().all(|(k, v)| {
                    y.iter()
                        .find(|(k2, _)| k2 == k)
                        .is_some_and(|(_, w)| same(v, w))
                })
        }
        (Val::Array(x), Val::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(v, w)| same(v, w))
        }
        (Val::Float(x), Val::Float(y)) => x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
        (x, y) => x == y,
    }
}

/// Both read `text` to the same tree, or both refuse it; and where the file read in runs
/// (scene/toml_runs.rs, used for long files) gives a tree, it is ours.
fn agree(text: &str) -> Result<bool, String> {
    let lines = Lines::new(text);
    let ours = parse_document(text, &lines);
    for runs in [2, 3, 7] {
        if let Some(tree) = crate::scene::toml_runs::in_runs(text, &lines, runs) {
            if ours.as_ref().ok() != Some(&tree) {
                return Err(format!("read in {runs} runs to another tree:\n{text}"));
            }
        }
    }
    match (ours, reference(text)) {
        (Ok(a), Some(b)) if same(&a, &b) => Ok(true),
        (Err(_), None) => Ok(false),
        (Ok(a), Some(b)) => Err(format!(
            "different trees for\n{text}\n--- ours: {a:?}\n--- toml_edit: {b:?}"
        )),
        (Ok(a), None) => Err(format!("only ours accepts\n{text}\n--- {a:?}")),
        (Err(e), Some(_)) => Err(format!("only toml_edit accepts\n{text}\n--- {e:?}")),
    }
}

fn scenes() -> Vec<String> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    let mut out: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    out.sort();
    assert!(out.len() >= 4, "the scenes directory");
    out
}

#[test]
fn the_project_scenes_read_the_same() {
    for s in scenes() {
        assert_eq!(agree(&s), Ok(true));
    }
}

/// TOML's rules for which tables may be opened or extended, where each rule bites.
const CASES: &[&str] = &[
    "a = 1\nb = 2.5\nc = 'x'\nd = true\ne = 1979-05-27T07:32:00Z",
    "a.b.c = 1\na.b.d = 2",
    "[a]\nb = 1\n[a.c]\nd = 2",
    "[a.c]\nd = 2\n[a]\nb = 1",
    "[a]\nb = 1\n[a]\nc = 2",
    "[a]\nb.c = 1\n[a.b]\nd = 2",
    "[a]\nb.c = 1\n[a.b.e]\nd = 2",
    "[a.b]\nc = 1\n[a]\nb.d = 2",
    "a = 1\n[a]\nb = 2",
    "a = {b = 1}\n[a]\nc = 2",
    "a = {b = 1}\na.c = 2",
    "a = {b = 1, b = 2}",
    "a = {b.c = 1, b.d = 2}",
    "a = {b = {c = 1}, b.d = 2}",
    "[[a]]\nb = 1\n[[a]]\nb = 2\n[a.c]\nd = 3",
    "[[a]]\nb = 1\n[[a.c]]\nd = 3\n[[a.c]]\nd = 4\n[[a]]\nb = 2",
    "a = [1, 2]\n[[a]]\nb = 1",
    "[a]\n[[a]]",
    "[[a]]\n[a]",
    "[[a.b]]\n[a]\nc = 1",
    "a.b = 1\n[[a.c]]",
    "a = 1\na = 2",
    "a = [\n  [1, 2, 3], # comment\n  [4, 5, 6],\n]\nb = 1",
    "s = \"\"\"\nx = [\n[a]\n\"\"\"\nt = 1",
    "s = '''\n]\n'''\n[a]",
    "\"quoted key\" = 1\n'lit.key' = 2\na.\"b.c\" = 3",
    "x = 0x10\ny = 0o17\nz = 0b101\nw = 1_000\nv = -0.0\nu = 6.02e23",
    "x = 9223372036854775807",
    "x = 9223372036854775808",
    "x = 1e400",
    "x = inf\ny = -inf\nz = nan",
    "x = 1979-05-27\ny = 07:32:00\nz = 1979-05-27 07:32:00",
    "x = 1979-13-45",
    "x = [1, 'a', {b = 1}, [2]]",
    "x = [\n]",
    "x = [1,,2]",
    "x = {a = 1,}",
    "[a\nb = 1",
    "a = [1, 2\nb = 3",
    "a = \"unclosed\nb = 1",
    "= 1",
    "a = ",
    "a = 1 b = 2",
    "[a.b.c]\n[a]\n[a.b]",
    "[a.b.c]\n[a.b]\n[a.b]",
    "\u{feff}a = 1",
    "a = 1\r\nb = 2\r\n",
    "# only a comment",
    "",
    "a = \"\\u00e9\\n\\t\"",
    "a = \"\\q\"",
    "[ a . b ]\nc = 1",
    "[[ a ]]\n[[a]]",
    "a = { b = 1 }\n[a.c]",
];

#[test]
fn tomls_table_rules_are_kept() {
    let mut accepted = 0;
    for case in CASES {
        match agree(case) {
            Ok(ok) => accepted += ok as usize,
            Err(why) => panic!("{why}"),
        }
    }
    // Both kinds are probed.
    assert!(accepted > 20 && accepted < CASES.len() - 10, "{accepted}");
}

/// One random edit of a scene: a character deleted or inserted (one of TOML's punctuation, a
/// quote, a newline), a line dropped, doubled or moved.
fn mutate(rng: &mut Rng, text: &str) -> String {
    const INSERTS: [&str; 14] = [
        "[", "]", "{", "}", "=", ".", ",", "\"", "'", "#", "\n", " ", "a", "[[",
    ];
    let pick = |rng: &mut Rng, n: usize| (rng.next_u64() % n.max(1) as u64) as usize;
    let mut s = text.to_string();
    match pick(rng, 4) {
        0 | 1 => {
            let mut at = pick(rng, s.len());
            while !s.is_char_boundary(at) {
                at -= 1;
            }
            if pick(rng, 2) == 0 {
                s.insert_str(at, INSERTS[pick(rng, INSERTS.len())]);
            } else if let Some(c) = s[at..].chars().next() {
                s.replace_range(at..at + c.len_utf8(), "");
            }
        }
        _ => {
            let mut lines: Vec<&str> = s.lines().collect();
            let (k, j) = (pick(rng, lines.len()), pick(rng, lines.len()));
            if !lines.is_empty() {
                match pick(rng, 3) {
                    0 => {
                        lines.remove(k);
                    }
                    1 => lines.insert(j, lines[k]),
                    _ => lines.swap(k, j),
                }
            }
            s = lines.join("\n");
        }
    }
    s
}

#[test]
fn mutated_scenes_read_the_same() {
    let scenes = scenes();
    let mut rng = Rng(23);
    let (mut accepted, mut refused) = (0, 0);
    for i in 0..4000 {
        let mut text = scenes[i % scenes.len()].clone();
        for _ in 0..=rng.next_u64() % 3 {
            text = mutate(&mut rng, &text);
        }
        match agree(&text) {
            Ok(true) => accepted += 1,
            Ok(false) => refused += 1,
            Err(why) => panic!("case {i}: {why}"),
        }
    }
    assert!(accepted > 500 && refused > 500, "{accepted} {refused}");
}
