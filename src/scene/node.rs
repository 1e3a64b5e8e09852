//! The values of the scene file's tree and where each came from (a line of the file, or a
//! command-line flag): what the TOML reader (toml_tree.rs) makes and the document (doc.rs)
//! keeps, overrides and reads.

/// Where a value came from: a 1-based line of the scene file, or the n-th flag that set a
/// value (`Doc::flags`). Four bytes, as there is one per value of the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin(u32);

/// The bit that marks an origin as a flag's.
const FLAG_BIT: u32 = 1 << 31;

impl Origin {
    pub fn line(line: usize) -> Origin {
        Origin(line.min(FLAG_BIT as usize - 1) as u32)
    }
    /// Ok(the line of the file), or Err(the index of the flag).
    pub(super) fn source(self) -> Result<usize, usize> {
        match self.0 & FLAG_BIT {
            0 => Ok(self.0 as usize),
            _ => Err((self.0 & !FLAG_BIT) as usize),
        }
    }
    pub(super) fn flag(index: usize) -> Origin {
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

    pub(super) fn name_field(&self) -> Option<&str> {
        self.entries()?
            .iter()
            .find_map(|(k, v)| match (&**k, &v.val) {
                ("name", Val::Str(s)) => Some(s.as_str()),
                _ => None,
            })
    }
}

/// The byte each line of a text starts at.
pub struct Lines(Vec<usize>);

impl Lines {
    pub fn new(text: &str) -> Self {
        Lines(
            std::iter::once(0)
                .chain(memchr::memchr_iter(b'\n', text.as_bytes()).map(|i| i + 1))
                .collect(),
        )
    }
    /// The byte line `line` (1-based) starts at.
    pub fn start_of(&self, line: usize) -> Option<usize> {
        self.0.get(line.checked_sub(1)?).copied()
    }
    /// The 1-based line of byte `at`.
    pub fn line_of(&self, at: usize) -> usize {
        self.0.partition_point(|&start| start <= at).max(1)
    }
}
