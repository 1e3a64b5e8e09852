//! The scene file as a tree that remembers where each value came from: a line of the file or a
//! command-line flag. Overrides (`--set`) are applied to this tree before it is read, so every
//! error can name its source whichever way a value arrived.

use super::SceneError;
use toml_edit::{ImDocument, Item, Value};

#[derive(Clone, Debug, PartialEq)]
pub enum Origin {
    /// 1-based line in the scene file.
    Line(usize),
    /// The flag that set the value, e.g. `--set camera.time=3`.
    Flag(String),
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

#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub val: Val,
    pub origin: Origin,
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
}

struct Lines(Vec<usize>);

impl Lines {
    fn new(text: &str) -> Self {
        Lines(
            std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect(),
        )
    }
    fn line(&self, span: Option<std::ops::Range<usize>>) -> usize {
        span.map(|s| self.0.partition_point(|&start| start <= s.start))
            .unwrap_or(1)
    }
}

fn convert_value(v: &Value, origin: Origin, lines: &Lines) -> Node {
    let val = match v {
        Value::String(s) => Val::Str(s.value().clone()),
        Value::Integer(i) => Val::Int(*i.value()),
        Value::Float(f) => Val::Float(*f.value()),
        Value::Boolean(b) => Val::Bool(*b.value()),
        Value::Datetime(_) => Val::Other("a date"),
        Value::Array(a) => Val::Array(
            a.iter()
                .map(|e| convert_value(e, line_origin(lines, e.span(), &origin), lines))
                .collect(),
        ),
        Value::InlineTable(t) => Val::Table(
            t.iter()
                .map(|(k, e)| {
                    let o =
                        line_origin(lines, t.key(k).and_then(|k| k.span()).or(e.span()), &origin);
                    (k.to_string(), convert_value(e, o, lines))
                })
                .collect(),
        ),
    };
    Node { val, origin }
}

fn line_origin(lines: &Lines, span: Option<std::ops::Range<usize>>, fallback: &Origin) -> Origin {
    match (span, fallback) {
        (Some(s), _) => Origin::Line(lines.line(Some(s))),
        (None, f) => f.clone(),
    }
}

fn convert_table(t: &toml_edit::Table, origin: Origin, lines: &Lines) -> Node {
    let entries = t
        .iter()
        .map(|(k, item)| {
            let o = line_origin(
                lines,
                t.key(k).and_then(|k| k.span()).or(item.span()),
                &origin,
            );
            (k.to_string(), convert_item(item, o, lines))
        })
        .collect();
    Node {
        val: Val::Table(entries),
        origin,
    }
}

fn convert_item(item: &Item, origin: Origin, lines: &Lines) -> Node {
    match item {
        Item::Value(v) => convert_value(v, origin, lines),
        Item::Table(t) => convert_table(t, origin, lines),
        Item::ArrayOfTables(a) => Node {
            val: Val::Array(
                a.iter()
                    .map(|t| {
                        let o = line_origin(lines, t.span(), &origin);
                        convert_table(t, o, lines)
                    })
                    .collect(),
            ),
            origin,
        },
        Item::None => Node {
            val: Val::Other("nothing"),
            origin,
        },
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
        let doc = ImDocument::parse(text.to_string()).map_err(|e| {
            let line = lines.line(e.span());
            let message = e.message().trim().replace('\n', ", ");
            let shown = e
                .span()
                .map(|s| pointed(text, &lines, line, s.start))
                .unwrap_or_default();
            SceneError::new(
                format!("{file}:{line}"),
                "",
                format!("not valid TOML: {message}{shown}"),
            )
        })?;
        Ok(Doc {
            file: file.to_string(),
            root: convert_table(doc.as_table(), Origin::Line(1), &lines),
        })
    }

    /// Where a node came from, for an error message.
    pub fn locate(&self, origin: &Origin) -> String {
        match origin {
            Origin::Line(l) => format!("{}:{l}", self.file),
            Origin::Flag(f) => f.clone(),
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
        let origin = Origin::Flag(shown.clone());
        let value = parse_set_value(text.trim())
            .map(|v| convert_value(&v, origin.clone(), &Lines(vec![0])))
            .map_err(|m| bad(key, m))?;
        let value = reorigin(value, &origin);
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
                                    origin: origin.clone(),
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

fn reorigin(mut n: Node, o: &Origin) -> Node {
    n.origin = o.clone();
    n.val = match n.val {
        Val::Array(a) => Val::Array(a.into_iter().map(|e| reorigin(e, o)).collect()),
        Val::Table(t) => Val::Table(t.into_iter().map(|(k, e)| (k, reorigin(e, o))).collect()),
        v => v,
    };
    n
}

/// A `--set` value is TOML; a bare word that is not valid TOML is taken as a string, so
/// `--set camera.projection=orthographic` works without shell-quoted quotes.
fn parse_set_value(text: &str) -> Result<Value, String> {
    if text.is_empty() {
        return Err("the value is empty".into());
    }
    match text.parse::<Value>() {
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
                Ok(Value::from(text))
            } else {
                Err(format!(
                    "`{text}` is not a TOML value: {}",
                    e.to_string().trim()
                ))
            }
        }
    }
}
