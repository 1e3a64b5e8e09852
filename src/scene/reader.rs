//! Typed reading of one table of the scene tree, with errors that name file, line and key, and
//! a check that every key was understood.

use super::doc::{Doc, Node, Val};
use super::SceneError;
use glam::DVec3;
use std::cell::RefCell;

pub struct Table<'a> {
    doc: &'a Doc,
    node: &'a Node,
    /// Dotted path of this table, e.g. `group.cube` (for messages).
    pub path: String,
    used: RefCell<Vec<bool>>,
}

pub type SceneResult<T> = Result<T, SceneError>;

impl<'a> Table<'a> {
    pub fn new(doc: &'a Doc, node: &'a Node, path: String) -> SceneResult<Table<'a>> {
        let Some(entries) = node.entries() else {
            return Err(SceneError::new(
                doc.locate(&node.origin),
                path,
                format!("expected a table, found {}", node.kind()),
            ));
        };
        Ok(Table {
            doc,
            node,
            path,
            used: RefCell::new(vec![false; entries.len()]),
        })
    }

    /// The scene file's name, as errors give it (a path: meshes are found beside it).
    pub fn file(&self) -> &'a str {
        &self.doc.file
    }

    /// A file the scene names: relative to the scene file's folder.
    pub fn path_beside(&self, name: &str) -> std::path::PathBuf {
        let base = std::path::Path::new(self.file())
            .parent()
            .unwrap_or(std::path::Path::new(""));
        base.join(name)
    }

    pub fn root(doc: &'a Doc) -> SceneResult<Table<'a>> {
        Table::new(doc, &doc.root, String::new())
    }

    fn entries(&self) -> &'a [(String, Node)] {
        self.node.entries().unwrap_or(&[])
    }

    pub fn key_path(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The table's keys, in the file's order.
    pub fn keys(&self) -> impl Iterator<Item = &'a str> {
        self.entries().iter().map(|(k, _)| k.as_str())
    }

    pub fn has(&self, key: &str) -> bool {
        self.entries().iter().any(|(k, _)| k == key)
    }

    /// Whether key `key` is given by a command-line flag (`--set`), not the file.
    pub fn set_by_flag(&self, key: &str) -> bool {
        self.entries()
            .iter()
            .any(|(k, n)| k == key && n.origin.source().is_err())
    }

    /// The node of a key, marking it understood.
    pub fn get(&self, key: &str) -> Option<&'a Node> {
        let i = self.entries().iter().position(|(k, _)| k == key)?;
        self.used.borrow_mut()[i] = true;
        Some(&self.entries()[i].1)
    }

    /// An error about key `key` of this table: at the key's line where the table has it (a
    /// conflict, a value that does not fit the others), else at the table's (a missing key).
    pub fn error(&self, key: &str, msg: impl Into<String>) -> SceneError {
        if let Some(n) = self.get(key) {
            return self.error_at(n, key, msg);
        }
        // A key said missing that is written nearly so (`colour1` for `color1` in an inline
        // table, which is read before its unknown keys are looked for): that key is blamed,
        // with the name meant, as `finish` blames an unknown key.
        let near = self
            .entries()
            .iter()
            .find(|(k, _)| !self.used.borrow()[self.index_of(k)] && closest(k, &[key]).is_some());
        if let Some((k, n)) = near {
            return self.error_at(
                n,
                k,
                format!("unknown key\n  did you mean `{key}`?{}", case_note(k, key)),
            );
        }
        SceneError::new(self.doc.locate(&self.node.origin), self.key_path(key), msg)
    }

    /// The index of entry `key` among the entries (as `used` counts them).
    fn index_of(&self, key: &str) -> usize {
        self.entries()
            .iter()
            .position(|(k, _)| k == key)
            .unwrap_or(0)
    }

    /// An error about one value.
    pub fn error_at(&self, node: &Node, key: &str, msg: impl Into<String>) -> SceneError {
        SceneError::new(self.doc.locate(&node.origin), self.key_path(key), msg)
    }

    pub fn f64(&self, key: &str) -> SceneResult<Option<f64>> {
        self.get(key).map(|n| self.num(n, key)).transpose()
    }

    fn num(&self, n: &Node, key: &str) -> SceneResult<f64> {
        let v = match n.val {
            Val::Float(f) => f,
            Val::Int(i) => i as f64,
            _ => {
                return Err(self.error_at(n, key, format!("expected a number, found {}", n.kind())))
            }
        };
        if !v.is_finite() {
            return Err(self.error_at(n, key, format!("expected a finite number, found {v}")));
        }
        if v.abs() > super::envelope::MAX_MAGNITUDE {
            return Err(self.error_at(n, key, super::envelope::too_large(v)));
        }
        Ok(v)
    }

    pub fn f64_or(&self, key: &str, default: f64) -> SceneResult<f64> {
        Ok(self.f64(key)?.unwrap_or(default))
    }

    /// A number checked by `ok`, whose failure text says what is expected.
    pub fn f64_where(
        &self,
        key: &str,
        default: Option<f64>,
        ok: fn(f64) -> bool,
        expect: &str,
    ) -> SceneResult<f64> {
        match self.get(key) {
            Some(n) => {
                let v = self.num(n, key)?;
                if ok(v) {
                    Ok(v)
                } else {
                    Err(self.error_at(n, key, format!("must be {expect} (got {v:?})")))
                }
            }
            None => {
                default.ok_or_else(|| self.error(key, format!("missing: give a number ({expect})")))
            }
        }
    }

    pub fn uint(&self, key: &str, default: Option<u64>, min: u64, max: u64) -> SceneResult<u64> {
        match self.get(key) {
            Some(n) => self.uint_of(n, key, min, max),
            None => default.ok_or_else(|| {
                self.error(
                    key,
                    format!("missing: give a whole number from {min} to {max}"),
                )
            }),
        }
    }

    fn uint_of(&self, n: &Node, key: &str, min: u64, max: u64) -> SceneResult<u64> {
        match n.val {
            Val::Int(i) if i >= min as i64 && (i as u64) <= max => Ok(i as u64),
            Val::Int(i) => Err(self.error_at(
                n,
                key,
                format!("must be a whole number from {min} to {max} (got {i})"),
            )),
            // A number with a fraction: say which, and what would do.
            Val::Float(f) => Err(self.error_at(
                n,
                key,
                format!(
                    "must be a whole number from {min} to {max}, written without a point (got {f:?}{})",
                    if f.fract() != 0.0 && f.is_finite() {
                        format!("; {} or {} would do", f.floor().max(min as f64), f.ceil().max(min as f64))
                    } else {
                        String::new()
                    }
                ),
            )),
            _ => Err(self.error_at(
                n,
                key,
                format!(
                    "expected a whole number from {min} to {max}, found {}",
                    n.kind()
                ),
            )),
        }
    }

    pub fn string(&self, key: &str) -> SceneResult<Option<&'a str>> {
        match self.get(key) {
            Some(Node {
                val: Val::Str(s), ..
            }) => Ok(Some(s.as_str())),
            Some(n) => Err(self.error_at(n, key, format!("expected a string, found {}", n.kind()))),
            None => Ok(None),
        }
    }

    pub fn req_string(&self, key: &str) -> SceneResult<&'a str> {
        self.string(key)?
            .ok_or_else(|| self.error(key, "missing: give a string"))
    }

    /// An array of strings, with its node (for errors about an element).
    pub fn strings(&self, key: &str) -> SceneResult<Option<(&'a Node, Vec<&'a str>)>> {
        let Some(n) = self.get(key) else {
            return Ok(None);
        };
        let Val::Array(items) = &n.val else {
            return Err(self.error_at(
                n,
                key,
                format!("expected an array of strings, found {}", n.kind()),
            ));
        };
        let strings = items
            .iter()
            .map(|e| match &e.val {
                Val::Str(s) => Ok(s.as_str()),
                _ => Err(self.error_at(
                    e,
                    key,
                    format!("expected an array of strings, found {} in it", e.kind()),
                )),
            })
            .collect::<SceneResult<_>>()?;
        Ok(Some((n, strings)))
    }

    pub fn numbers_of(&self, n: &Node, key: &str, len: Option<usize>) -> SceneResult<Vec<f64>> {
        let Val::Array(items) = &n.val else {
            let want = len
                .map(|l| format!("an array of {l} numbers"))
                .unwrap_or("an array of numbers".into());
            return Err(self.error_at(n, key, format!("expected {want}, found {}", n.kind())));
        };
        if let Some(l) = len {
            if items.len() != l {
                return Err(self.error_at(
                    n,
                    key,
                    format!("expected {l} numbers, found {}", items.len()),
                ));
            }
        }
        items.iter().map(|e| self.num(e, key)).collect()
    }

    pub fn vec3(&self, key: &str) -> SceneResult<Option<DVec3>> {
        let Some(n) = self.get(key) else {
            return Ok(None);
        };
        self.vec3_of(n, key).map(Some)
    }

    /// `numbers_of(n, key, Some(3))` as a vector, with the same errors, without a list made
    /// for each (an inline mesh reads one per vertex; 100,000 moving boxes, a velocity, min and
    /// max each).
    pub(crate) fn vec3_of(&self, n: &Node, key: &str) -> SceneResult<DVec3> {
        match &n.val {
            Val::Array(items) if items.len() == 3 => Ok(DVec3::new(
                self.num(&items[0], key)?,
                self.num(&items[1], key)?,
                self.num(&items[2], key)?,
            )),
            _ => {
                let v = self.numbers_of(n, key, Some(3))?;
                Ok(DVec3::new(v[0], v[1], v[2]))
            }
        }
    }

    pub fn req_vec3(&self, key: &str) -> SceneResult<DVec3> {
        self.vec3(key)?
            .ok_or_else(|| self.error(key, "missing: give [x, y, z]"))
    }

    /// A colour: `[r, g, b]` or one number for grey; every channel ≥ 0.
    pub fn color(&self, key: &str) -> SceneResult<Option<DVec3>> {
        let Some(n) = self.get(key) else {
            return Ok(None);
        };
        let c = match n.val {
            Val::Array(_) => self.vec3_of(n, key)?,
            _ => DVec3::splat(self.num(n, key)?),
        };
        if c.min_element() < 0.0 {
            return Err(self.error_at(n, key, "colour channels must not be negative"));
        }
        Ok(Some(c))
    }

    /// A number or an array of `len` numbers, each checked to be > 0.
    pub fn positive_scalar_or_array(
        &self,
        key: &str,
        len: usize,
        default: Option<f64>,
    ) -> SceneResult<Vec<f64>> {
        let v = match self.get(key) {
            None => match default {
                Some(d) => vec![d; len],
                None => return Err(self.error(key, "missing")),
            },
            Some(n) => match n.val {
                Val::Array(_) => self.numbers_of(n, key, Some(len))?,
                _ => vec![self.num(n, key)?; len],
            },
        };
        if v.iter().any(|&x| x <= 0.0) {
            let n = self.get(key).unwrap_or(self.node);
            return Err(self.error_at(n, key, "must be greater than 0"));
        }
        Ok(v)
    }

    /// Whole numbers, exactly `len` of them, each in [min, max].
    pub fn uints(
        &self,
        key: &str,
        len: usize,
        min: u64,
        max: u64,
    ) -> SceneResult<Option<Vec<u64>>> {
        let Some(n) = self.get(key) else {
            return Ok(None);
        };
        let Val::Array(items) = &n.val else {
            return Err(self.error_at(
                n,
                key,
                format!(
                    "expected an array of {len} whole numbers, found {}",
                    n.kind()
                ),
            ));
        };
        if items.len() != len {
            return Err(self.error_at(
                n,
                key,
                format!("expected {len} whole numbers, found {}", items.len()),
            ));
        }
        items
            .iter()
            .map(|e| self.uint_of(e, key, min, max))
            .collect::<SceneResult<Vec<_>>>()
            .map(Some)
    }

    /// A sub-table.
    pub fn table(&self, key: &str) -> SceneResult<Option<Table<'a>>> {
        self.get(key)
            .map(|n| Table::new(self.doc, n, self.key_path(key)))
            .transpose()
    }

    /// An array of tables (`[[key]]`); each entry's path uses its `name` when it has one.
    pub fn tables(&self, key: &str) -> SceneResult<Vec<Table<'a>>> {
        let Some(n) = self.get(key) else {
            return Ok(Vec::new());
        };
        let Val::Array(items) = &n.val else {
            return Err(self.error_at(
                n,
                key,
                format!(
                    "expected [[{}]] entries, found {}",
                    self.key_path(key),
                    n.kind()
                ),
            ));
        };
        let base = self.key_path(key);
        items
            .iter()
            .enumerate()
            .map(|(i, item)| {
                let name = item
                    .entries()
                    .and_then(|e| e.iter().find(|(k, _)| k == "name"))
                    .and_then(|(_, v)| match &v.val {
                        Val::Str(s) => Some(s.as_str()),
                        _ => None,
                    });
                let path = match name {
                    Some(name) => format!("{base}.{name}"),
                    None => format!("{base}.{i}"),
                };
                Table::new(self.doc, item, path)
            })
            .collect()
    }

    /// Every key must have been read: report the first that was not, with a suggestion.
    pub fn finish(&self, known: &[&str]) -> SceneResult<()> {
        let used = self.used.borrow();
        for (i, (k, n)) in self.entries().iter().enumerate() {
            if !used[i] {
                if known.contains(&k.as_str()) {
                    return Err(self.error_at(n, k, "not used with the other keys given here"));
                }
                let what = if n.entries().is_some() {
                    "unknown table"
                } else {
                    "unknown key"
                };
                let hint = closest(k, known)
                    .map(|s| format!("\n  did you mean `{s}`?{}", case_note(k, s)))
                    .unwrap_or_else(|| format!("; known keys here: {}", known.join(", ")));
                return Err(self.error_at(n, k, format!("{what}{hint}")));
            }
        }
        Ok(())
    }

    /// The error for a required table `wanted` that is missing: at a key written nearly so
    /// (`[Camera]`, `[camra]`), if there is one, saying what was meant; else at the table.
    pub fn missing_table(&self, wanted: &str, why: &str) -> SceneError {
        let near = self
            .entries()
            .iter()
            .find(|(k, _)| k != wanted && closest(k, &[wanted]).is_some());
        match near {
            Some((k, n)) => self.error_at(
                n,
                k,
                format!(
                    "unknown table\n  did you mean `[{wanted}]`?{} ({why})",
                    case_note(k, wanted)
                ),
            ),
            None => self.error(wanted, format!("missing: {why}")),
        }
    }
}

/// " Names are case-sensitive." where `typed` differs from `meant` in case alone.
fn case_note(typed: &str, meant: &str) -> &'static str {
    if typed != meant && typed.eq_ignore_ascii_case(meant) {
        " Names are case-sensitive."
    } else {
        ""
    }
}

/// The known key nearest in edit distance, if it is near enough to be a typo.
fn closest<'k>(key: &str, known: &[&'k str]) -> Option<&'k str> {
    known
        .iter()
        .map(|k| (edit_distance(&key.to_lowercase(), &k.to_lowercase()), *k))
        .filter(|(d, k)| *d <= 2.max(k.len() / 3))
        .min()
        .map(|(_, k)| k)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use crate::scene::load_str;

    /// Three numbers are read without a list made for them: each element is still checked in
    /// order and named at its own line, and a length other than three, or a value that is no
    /// list, is still said as such.
    #[test]
    fn three_numbers_keep_their_errors() {
        let scene = |velocity: &str, color: &str| {
            let text = format!(
                "[camera]\nposition = [0, -5, 0]\nlook_at = [0, 0, 0]\n[[material]]\nname = \"m\"\ncolor = {color}\n[[group]]\nname = \"g\"\n\
                 velocity = {velocity}\n[[group.object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n"
            );
            load_str("t.toml", &text, &[])
                .map(|_| ())
                .map_err(|e| e.to_string())
        };
        assert_eq!(scene("[0.1, 0, 0]", "[0.5, 0.5, 0.5]"), Ok(()));
        let (v, c) = ("group.g.velocity", "material.m.color");
        let cases = [
            (
                "[0.1, \"a\", true]",
                "[1, 1, 1]",
                v,
                "expected a number, found a string",
            ),
            ("[0.1, 0]", "[1, 1, 1]", v, "expected 3 numbers, found 2"),
            (
                "[0.1, 0, 0, 0]",
                "[1, 1, 1]",
                v,
                "expected 3 numbers, found 4",
            ),
            (
                "[0.1, 0, inf]",
                "[1, 1, 1]",
                v,
                "expected a finite number, found inf",
            ),
            (
                "[0.1, 0, 0]",
                "[1, -1, 1]",
                c,
                "colour channels must not be negative",
            ),
            ("[0.1, 0, 0]", "[1, 1]", c, "expected 3 numbers, found 2"),
            (
                "[0.1, 0, 0]",
                "[1, {a = 1}, 1]",
                c,
                "expected a number, found a table",
            ),
        ];
        for (velocity, color, key, want) in cases {
            let e = scene(velocity, color).unwrap_err();
            assert!(
                e.contains(want) && e.contains(key),
                "{velocity} {color}: {e}"
            );
        }
        // An element's error names its own line (the velocity opens on line 9, "a" is on
        // 11), and a value that is no list says so.
        let e = scene("[\n0.1,\n\"a\",\n0]", "[1, 1, 1]").unwrap_err();
        assert!(e.starts_with("t.toml:11:") && e.contains(v), "{e}");
        let e = scene("0.1", "[1, 1, 1]").unwrap_err();
        assert!(
            e.contains("expected an array of 3 numbers, found a number"),
            "{e}"
        );
    }
}
