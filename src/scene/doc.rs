//! The scene file as a tree that remembers where each value came from: a line of the file or a
//! command-line flag. Overrides (`--set`) are applied to this tree before it is read, so every
//! error can name its source whichever way a value arrived.

pub use super::node::{Form, Lines, Node, Origin, Val};
use super::toml_tree;
use super::SceneError;

/// The parsed scene file.
#[derive(Clone, Debug)]
pub struct Doc {
    pub file: String,
    pub root: Node,
    /// The flags that set values, as error messages name them.
    flags: Vec<String>,
}

/// The line `line` (1-based) of `text` with a caret under byte `at`, as cargo shows errors.
fn pointed(text: &str, lines: &Lines, line: usize, at: usize) -> String {
    let start = lines.start_of(line).unwrap_or(0);
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
        match origin.source() {
            Ok(line) => format!("{}:{line}", self.file),
            Err(flag) => self.flags.get(flag).cloned().unwrap_or_default(),
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
        // Dotted, as TOML's keys are: a part in quotes is a name as it is (`group."g.x".velocity`
        // reaches the group named g.x; `group."1"` the one named 1, never the second entry).
        let parts = key_parts(key).filter(|p| !p.is_empty() && p.iter().all(|s| !s.0.is_empty()));
        let Some(parts) = parts else {
            return Err(bad(
                key,
                "the key must be a dotted path like group.cube.velocity (a name with dots in quotes: group.\"g.x\".velocity)".into(),
            ));
        };
        let origin = Origin::flag(self.flags.len());
        let value = parse_set_value(text.trim(), origin, &bad(key, String::new()))?;
        self.flags.push(shown.clone());
        let segs: Vec<&str> = parts.iter().map(|(s, _)| s.as_str()).collect();
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
                    let quoted = parts[i].1;
                    let p = items
                        .iter()
                        .position(|n| n.name_field() == Some(seg))
                        .or_else(|| {
                            seg.parse::<usize>()
                                .ok()
                                .filter(|&j| j < items.len() && !quoted)
                        });
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

/// `name` as a part of a `--set` key: as it is, or in quotes where it holds a dot or a quote.
pub(crate) fn key_part(name: &str) -> String {
    if !name.contains(['.', '"', '\'']) {
        name.to_string()
    } else if name.contains('"') {
        format!("'{name}'")
    } else {
        format!("\"{name}\"")
    }
}

/// A `--set` key's parts, split at the dots outside quotes, each with whether it was quoted
/// (`"..."` or `'...'`, taken as written); None for an unclosed quote.
pub(crate) fn key_parts(key: &str) -> Option<Vec<(String, bool)>> {
    let mut parts = vec![(String::new(), false)];
    let mut quote: Option<char> = None;
    for c in key.chars() {
        let part = parts.last_mut().expect("one at least");
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => part.0.push(c),
            (None, '"' | '\'') if part.0.is_empty() && !part.1 => {
                quote = Some(c);
                part.1 = true;
            }
            (None, '.') => parts.push((String::new(), false)),
            (None, c) => part.0.push(c),
        }
    }
    quote.is_none().then_some(parts)
}

/// A `--set` value is TOML; a bare word that is not valid TOML is taken as a string, so
/// `--set camera.projection=orthographic` and `--set texture.t.image=maps/wood.png` work
/// without shell-quoted quotes (a word: letters, digits and `_ - . / ~ +`, not starting with a
/// digit or `-`, which a number would). `at`: the flag and key an error names.
fn parse_set_value(text: &str, origin: Origin, at: &SceneError) -> Result<Node, SceneError> {
    let bad = |message: String| SceneError {
        message,
        ..at.clone()
    };
    if text.is_empty() {
        return Err(bad("the value is empty".into()));
    }
    match toml_tree::parse_value(text, origin) {
        Ok(v) => Ok(v),
        Err(e) => {
            let word = text
                .chars()
                .all(|c| c.is_alphanumeric() || "_-./~+".contains(c));
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
                Err(bad(format!("`{text}` is not a TOML value: {}", e.message)))
            }
        }
    }
}
