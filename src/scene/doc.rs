//! The scene file as a tree that remembers where each value came from: a line of the file or a
//! command-line flag. Overrides (`--set`) are applied to this tree before it is read, so every
//! error can name its source whichever way a value arrived.

use super::toml_tree;
use super::SceneError;

/// Where a value came from: a 1-based line of the scene file, or the n-th flag that set a
/// value (`Doc::flags`). Four bytes, as there is one per value of the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin(u32);

const FLAG_BIT: u32 = 1 << 31;

impl Origin {
    pub fn line(line: usize) -> Origin {
        Origin(line.min(FLAG_BIT as usize - 1) as u32)
    }
    fn flag(index: usize) -> Origin {
        Origin(FLAG_BIT | index as u32)
    }
}

/// How a table or array was made, which decides what TOML lets extend it (only meaningful while
/// parsing): bits of `IMPLICIT` (made by a header's or a dotted key's path), `DOTTED` (by a
/// dotted key), `INLINE` (`{ … }`, closed), `ARRAY_OF_TABLES` (`[[…]]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Form(u8);

impl Form {
    pub const VALUE: Form = Form(0);
    pub const TABLE: Form = Form(0);
    pub const IMPLICIT: Form = Form(1);
    pub const DOTTED: Form = Form(2);
    pub const INLINE: Form = Form(4);
    pub const ARRAY_OF_TABLES: Form = Form(8);

    pub fn has(self, f: Form) -> bool {
        self.0 & f.0 != 0
    }
    pub fn with(self, f: Form) -> Form {
        Form(self.0 | f.0)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    Table(Vec<(String, Node)>),
    Array(Vec<Node>),
    Str(String),
    Float(f64),
    Int(i64),
    Bool(bool),
    /// A TOML value this format has no use for (dates), kept to report it.
    Other(&'static str),
}

#[derive(Clone, Debug)]
pub struct Node {
    pub val: Val,
    pub origin: Origin,
    pub form: Form,
}

/// Nodes are equal when their values and origins are; how TOML made them does not count.
impl PartialEq for Node {
    fn eq(&self, other: &Node) -> bool {
        self.val == other.val && self.origin == other.origin
    }
}

impl Node {
    pub fn kind(&self) -> &'static str {
        match &self.val {
            Val::Table(_) => "a table",
            Val::Array(_) => "an array",
            Val::Str(_) => "a string",
            Val::Float(_) => "a number",
            Val::Int(_) => "an integer",
            Val::Bool(_) => "a boolean",
            Val::Other(k) => k,
        }
    }

    pub fn entries(&self) -> Option<&[(String, Node)]> {
        match &self.val {
            Val::Table(e) => Some(e),
            _ => None,
        }
    }

    fn name_field(&self) -> Option<&str> {
        self.entries()?
            .iter()
            .find_map(|(k, v)| match (&**k, &v.val) {
                ("name", Val::Str(s)) => Some(s.as_str()),
                _ => None,
            })
    }
}

/// The parsed scene file.
#[derive(Clone, Debug)]
pub struct Doc {
    pub file: String,
    pub root: Node,
    /// The flags that set values, as error messages name them.
    flags: Vec<String>,
}

/// The byte each line of a text starts at.
pub struct Lines(Vec<usize>);

impl Lines {
    pub fn new(text: &str) -> Self {
        Lines(
            std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        )
    }
    /// The 1-based line of byte `at`.
    pub fn line_of(&self, at: usize) -> usize {
        self.0.partition_point(|&start| start <= at).max(1)
    }
}

/// The line `line` (1-based) of `text` with a caret under byte `at`, as cargo shows errors.
fn pointed(text: &str, lines: &Lines, line: usize, at: usize) -> String {
    let start = lines.0.get(line - 1).copied().unwrap_or(0);
    let end = text[start..].find('\n').map_or(text.len(), |e| start + e);
    let shown = text[start..end].trim_end_matches('\r');
    // The caret sits under the character, counted in characters (tabs kept as they are).
    let before: String = text[start..at.clamp(start, end)]
        .chars()
        .map(|c| if c == '\t' { '\t' } else { ' ' })
        .collect();
    let gutter = " ".repeat(line.to_string().len());
    format!("\n{gutter} |\n{line} | {shown}\n{gutter} | {before}^")
}

impl Doc {
    /// Parse a scene file's text; `file` names it in errors.
    pub fn parse(file: &str, text: &str) -> Result<Doc, SceneError> {
        let lines = Lines::new(text);
        let root = toml_tree::parse_document(text, &lines).map_err(|e| {
            let line = e.at.map_or(1, |at| lines.line_of(at));
            let shown =
                e.at.map(|at| pointed(text, &lines, line, at))
                    .unwrap_or_default();
            SceneError::new(
                format!("{file}:{line}"),
                "",
                format!("not valid TOML: {}{shown}", e.message),
            )
        })?;
        Ok(Doc {
            file: file.to_string(),
            root,
            flags: Vec::new(),
        })
    }

    /// Where a node came from, for an error message.
    pub fn locate(&self, origin: &Origin) -> String {
        if origin.0 & FLAG_BIT == 0 {
            format!("{}:{}", self.file, origin.0)
        } else {
            let i = (origin.0 & !FLAG_BIT) as usize;
            self.flags.get(i).cloned().unwrap_or_default()
        }
    }

    /// Apply one override `KEY=VALUE`, KEY dotted; entries of arrays of tables are addressed by
    /// their `name` (or by index). `shown` is how errors name the flag, e.g. `--set camera.time=3`.
    ///
    /// `superseded(path, key)` names the keys of the same table that the new key replaces (other
    /// forms of one setting, e.g. `beta` replaces `velocity`); they are removed.
    pub fn apply_set(
        &mut self,
        shown: &str,
        assignment: &str,
        superseded: fn(&[&str], &str) -> &'static [&'static str],
    ) -> Result<(), SceneError> {
        let shown = shown.to_string();
        let bad = |key: &str, msg: String| SceneError::new(shown.clone(), key, msg);
        let (key, text) = assignment
            .split_once('=')
            .ok_or_else(|| bad("", "expected KEY=VALUE, e.g. camera.time=5".into()))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|s| s.is_empty()) {
            return Err(bad(
                key,
                "the key must be a dotted path like group.cube.velocity".into(),
            ));
        }
        let origin = Origin::flag(self.flags.len());
        let value = parse_set_value(text.trim(), origin).map_err(|m| bad(key, m))?;
        self.flags.push(shown.clone());
        let segs: Vec<&str> = key.split('.').collect();
        let mut cur = &mut self.root;
        for (i, seg) in segs.iter().enumerate() {
            let last = i + 1 == segs.len();
            let prefix = segs[..=i].join(".");
            let kind = cur.kind();
            match &mut cur.val {
                Val::Table(entries) => {
                    let pos = entries.iter().position(|(k, _)| k == seg);
                    if last {
                        match pos {
                            Some(p) => entries[p].1 = value,
                            None => entries.push((seg.to_string(), value)),
                        }
                        let gone = superseded(&segs[..i], seg);
                        entries.retain(|(k, _)| !gone.contains(&k.as_str()));
                        return Ok(());
                    }
                    let p = match pos {
                        Some(p) => p,
                        None => {
                            entries.push((
                                seg.to_string(),
                                Node {
                                    val: Val::Table(Vec::new()),
                                    origin,
                                    form: Form::TABLE,
                                },
                            ));
                            entries.len() - 1
                        }
                    };
                    cur = &mut entries[p].1;
                }
                Val::Array(items) => {
                    if last {
                        return Err(bad(
                            key,
                            format!("`{prefix}` names a whole entry; set one of its keys"),
                        ));
                    }
                    let names: Vec<String> = items
                        .iter()
                        .enumerate()
                        .map(|(j, n)| {
                            n.name_field()
                                .map(str::to_string)
                                .unwrap_or_else(|| j.to_string())
                        })
                        .collect();
                    let p = items
                        .iter()
                        .position(|n| n.name_field() == Some(seg))
                        .or_else(|| seg.parse::<usize>().ok().filter(|&j| j < items.len()));
                    let Some(p) = p else {
                        let parent = segs[..i].join(".");
                        return Err(bad(
                            key,
                            format!(
                                "no [[{parent}]] entry named `{seg}` (entries: {})",
                                if names.is_empty() {
                                    "none".into()
                                } else {
                                    names.join(", ")
                                }
                            ),
                        ));
                    };
                    cur = &mut items[p];
                }
                _ => {
                    let parent = segs[..i].join(".");
                    return Err(bad(key, format!("`{parent}` is {kind}, not a table")));
                }
            }
        }
        unreachable!("the loop returns at the last segment")
    }
}

/// A `--set` value is TOML; a bare word that is not valid TOML is taken as a string, so
/// `--set camera.projection=orthographic` works without shell-quoted quotes.
fn parse_set_value(text: &str, origin: Origin) -> Result<Node, String> {
    if text.is_empty() {
        return Err("the value is empty".into());
    }
    match toml_tree::parse_value(text, origin) {
        Ok(v) => Ok(v),
        Err(e) => {
            let word = text
                .chars()
                .all(|c| c.is_alphanumeric() || "_-".contains(c));
            if word
                && !text
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_digit() || c == '-')
            {
                Ok(Node {
                    val: Val::Str(text.to_string()),
                    origin,
                    form: Form::VALUE,
                })
            } else {
                Err(format!("`{text}` is not a TOML value: {}", e.message))
            }
        }
    }
}
