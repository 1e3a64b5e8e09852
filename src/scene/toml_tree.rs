//! TOML read straight into the scene tree ([`Node`]s) from the events of `toml_parser`, the
//! grammar under the `toml` crate. No general-purpose document is built on the way: a parse
//! costs the file's tokens, which are dropped when it ends, and the tree itself. (A document that
//! keeps formatting, as `toml_edit`'s does, took about 32 bytes of memory per byte of a file of
//! numbers; together with the tree, 44.)
//!
//! What the grammar does not decide, this module does, as TOML 1.0 says and as the `toml` crate
//! applies it: dotted keys make tables; a `[table]` may be opened once, and only where no value
//! or dotted key defined it; `[[array]]` appends to an array of tables and nothing else; inline
//! tables and arrays are closed. A differential test (`src/tests/toml_tree.rs`) holds this to
//! `toml_edit` on hostile input.

use super::node::{Form, Lines, Node, Origin, Val};
use toml_parser::decoder::{Encoding, ScalarKind};
use toml_parser::lexer::{Token, TokenKind};
use toml_parser::parser::{EventReceiver, RecursionGuard, ValidateWhitespace};
use toml_parser::{ErrorSink, Expected, ParseError, Source, Span};

/// Arrays and inline tables nested deeper than this are an error (the tree is walked and dropped
/// recursively, so depth must be bounded).
const MAX_NESTING: u32 = 80;

/// A parse error: its message and the byte it points at.
#[derive(Debug)]
pub struct TomlError {
    pub message: String,
    pub at: Option<usize>,
}

/// Parse a whole document. Values take the line of their key; elements of arrays their own.
/// A long file of many `[[group]]` tables is read in runs on every thread where it can be
/// (toml_runs.rs); the tree is the same either way.
pub(crate) fn parse_document(text: &str, lines: &Lines) -> Result<Node, TomlError> {
    // The length first: asking for the thread count starts rayon's pool.
    if text.len() >= super::toml_runs::RUNS_FROM {
        let threads = rayon::current_num_threads();
        if threads > 1 {
            if let Some(root) = super::toml_runs::in_runs(text, lines, 4 * threads) {
                return Ok(root);
            }
        }
    }
    parse_part(text, lines, 0)
}

/// Parse `text`, a whole document or the part of one that starts at byte `offset` of the file
/// `lines` counts (at the start of a line, outside any value); errors point into `text`.
pub(super) fn parse_part(text: &str, lines: &Lines, offset: usize) -> Result<Node, TomlError> {
    let mut b = Builder::new(text, Some(lines), Origin::line(1));
    b.place.offset = offset;
    let source = Source::new(text);
    let mut first: Option<ParseError> = None;
    // The grammar is a sequence of expressions (a key/value, a header), each ending at a newline
    // outside brackets: each is parsed from its own tokens, so only the longest one's tokens are
    // held at once, not the whole file's.
    let mut tokens = Vec::new();
    let mut depth = 0usize;
    for token in source.lex() {
        let kind = token.kind();
        tokens.push(token);
        match kind {
            TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => depth += 1,
            TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => {
                depth = depth.saturating_sub(1)
            }
            TokenKind::Newline if depth == 0 => {
                grammar(
                    &mut b,
                    source,
                    &tokens,
                    toml_parser::parser::parse_document,
                    &mut first,
                );
                tokens.clear();
                if first.is_some() {
                    break;
                }
            }
            _ => {}
        }
    }
    if first.is_none() {
        grammar(
            &mut b,
            source,
            &tokens,
            toml_parser::parser::parse_document,
            &mut first,
        );
    }
    if first.is_none() {
        if let Some(e) = b.finish_table() {
            first = Some(e);
        }
    }
    match first {
        None => Ok(b.root),
        Some(e) => Err(error(&e, text)),
    }
}

/// Parse one value (a `--set` override); every node gets `origin`.
pub(crate) fn parse_value(text: &str, origin: Origin) -> Result<Node, TomlError> {
    let mut b = Builder::new(text, None, origin);
    let source = Source::new(text);
    let tokens = source.lex().into_vec();
    let mut first: Option<ParseError> = None;
    grammar(
        &mut b,
        source,
        &tokens,
        toml_parser::parser::parse_value,
        &mut first,
    );
    match (first, b.value) {
        (None, Some(v)) => Ok(v),
        (Some(e), _) => Err(error(&e, text)),
        (None, None) => Err(TomlError {
            message: "no value".into(),
            at: None,
        }),
    }
}

type Grammar = fn(&[Token], &mut dyn EventReceiver, &mut dyn ErrorSink);

/// Run the grammar over `tokens`, its events into `b`, checking whitespace and comments and
/// bounding the nesting; the first error is kept.
fn grammar(
    b: &mut Builder,
    source: Source,
    tokens: &[Token],
    rule: Grammar,
    first: &mut Option<ParseError>,
) {
    let mut checked = ValidateWhitespace::new(b, source);
    let mut guarded = RecursionGuard::new(&mut checked, MAX_NESTING);
    rule(tokens, &mut guarded, first);
}

fn error(e: &ParseError, text: &str) -> TomlError {
    let span = e.unexpected().or(e.context());
    let at = span.map(|s| s.start());
    // An unquoted word is taken for a string the author forgot to quote; two numbers with a
    // space between are one such word, and deserve a plainer message.
    if e.description().starts_with("string values must be quoted") {
        if let Some(raw) = span.and_then(|s| text.get(s.start()..s.end())) {
            let raw = raw.trim_end();
            if let Some(gap) = raw.find([' ', '\t']) {
                let next = gap + (raw[gap..].len() - raw[gap..].trim_start().len());
                if raw.starts_with(|c: char| c.is_ascii_digit() || "+-.".contains(c)) {
                    return TomlError {
                        message: format!("`{raw}` is not one value: separate values with `,`"),
                        at: at.map(|a| a + next),
                    };
                }
            }
            return TomlError {
                message: format!("a string must be quoted: \"{raw}\""),
                at,
            };
        }
    }
    TomlError {
        message: describe(e),
        at,
    }
}

fn describe(e: &ParseError) -> String {
    let mut m = e.description().to_string();
    if let Some(expected) = e.expected().filter(|x| !x.is_empty()) {
        let names: Vec<String> = expected
            .iter()
            .map(|x| match x {
                Expected::Literal("\n") => "a new line".to_string(),
                Expected::Literal(l) => format!("`{l}`"),
                Expected::Description(d) => d.to_string(),
                _ => "something else".into(),
            })
            .collect();
        m.push_str(&format!(", expected {}", names.join(" or ")));
    }
    m
}

/// A simple key and the byte it starts at.
struct Key {
    name: String,
    at: usize,
}

/// An array or inline table still open, innermost last.
enum Open {
    Array(Node),
    /// An inline table and the dotted key of the value being read into it.
    Table(Node, Vec<Key>),
}

/// A `[table]` or `[[array]]` header.
struct Header {
    path: Vec<Key>,
    array: bool,
    at: usize,
}

/// Where a byte of the text is, as a node's origin.
#[derive(Clone, Copy)]
struct Place<'l> {
    lines: Option<&'l Lines>,
    /// Where the parsed text starts in the file `lines` counts.
    offset: usize,
    /// The origin of every node when there are no lines (a `--set` value).
    fixed: Origin,
}

impl Place<'_> {
    fn at(&self, byte: usize) -> Origin {
        match self.lines {
            Some(l) => Origin::line(l.line_of(self.offset + byte)),
            None => self.fixed,
        }
    }
}

struct Builder<'i, 'l> {
    source: Source<'i>,
    place: Place<'l>,
    root: Node,
    /// The table the key/value lines go into: the root's own before the first header, then the
    /// last header's (inserted into the root when the next header or the end comes).
    current: Node,
    header: Option<Header>,
    /// Keys read and not yet used (a dotted key in progress).
    keys: Vec<Key>,
    /// The key of the document-level value being read.
    doc_key: Vec<Key>,
    /// Whether the keys being read belong to a header.
    in_header: Option<(bool, usize)>,
    open: Vec<Open>,
    /// A value parsed on its own.
    value: Option<Node>,
    /// Where each key of `current` is among its entries: a table of a million keys is read in
    /// linear time, not by a search of its entries per key.
    current_keys: KeyIndex,
    /// A scalar's decoded text, kept from one scalar to the next: a number's text is only read,
    /// so a scene of a million numbers makes no allocation for each (a string's text moves out
    /// into its node).
    decoded: String,
}

fn table(origin: Origin, form: Form) -> Node {
    Node {
        val: Val::Table(Vec::new()),
        origin,
        form,
    }
}

fn err(message: impl Into<String>, at: usize) -> ParseError {
    let at = Span::new_unchecked(at, at);
    ParseError::new(message.into()).with_unexpected(at)
}

impl<'i, 'l> Builder<'i, 'l> {
    fn new(text: &'i str, lines: Option<&'l Lines>, fixed: Origin) -> Self {
        Builder {
            source: Source::new(text),
            place: Place {
                lines,
                offset: 0,
                fixed,
            },
            root: table(fixed, Form::TABLE),
            current: table(fixed, Form::TABLE),
            header: None,
            keys: Vec::new(),
            doc_key: Vec::new(),
            in_header: None,
            open: Vec::new(),
            value: None,
            current_keys: KeyIndex::default(),
            decoded: String::new(),
        }
    }

    /// A value is complete: put it where it belongs.
    fn deliver(&mut self, node: Node, error: &mut dyn ErrorSink) {
        match self.open.last_mut() {
            Some(Open::Array(a)) => {
                if let Val::Array(items) = &mut a.val {
                    items.push(node);
                }
            }
            Some(Open::Table(t, key)) => {
                let key = std::mem::take(key);
                insert(t, key, node, self.place, error);
            }
            None if self.place.lines.is_none() => self.value = Some(node),
            None => {
                let key = std::mem::take(&mut self.doc_key);
                let index = Some(&mut self.current_keys);
                insert_indexed(&mut self.current, index, key, node, self.place, error);
            }
        }
    }

    /// The key/value lines of the last header are done: hang its table in the root.
    fn finish_table(&mut self) -> Option<ParseError> {
        let done = std::mem::replace(&mut self.current, table(self.place.fixed, Form::TABLE));
        self.current_keys.clear();
        let Some(header) = self.header.take() else {
            self.root = done;
            return None;
        };
        let (last, path) = header.path.split_last()?;
        let place = self.place;
        let parent = match descend(&mut self.root, path, false, place) {
            Ok(p) => p,
            Err(e) => return Some(e),
        };
        let Val::Table(entries) = &mut parent.val else {
            return None;
        };
        let mut done = done;
        done.origin = place.at(header.at);
        if header.array {
            let i = match entries.iter().position(|(k, _)| *k == last.name) {
                Some(i) => i,
                None => {
                    entries.push((
                        last.name.clone(),
                        Node {
                            val: Val::Array(Vec::new()),
                            origin: place.at(header.at),
                            form: Form::ARRAY_OF_TABLES,
                        },
                    ));
                    entries.len() - 1
                }
            };
            match &mut entries[i].1 {
                Node {
                    val: Val::Array(items),
                    form,
                    ..
                } if form.has(Form::ARRAY_OF_TABLES) => items.push(done),
                _ => return Some(err("duplicate key", last.at)),
            }
        } else {
            entries.push((last.name.clone(), done));
        }
        None
    }

    /// A header is read: take up its table (an implicit one made earlier keeps its entries).
    fn start_table(&mut self, header: Header) -> Option<ParseError> {
        let place = self.place;
        let mut fresh = table(place.at(header.at), Form::TABLE);
        if !header.array {
            let (last, path) = header.path.split_last()?;
            let parent = match descend(&mut self.root, path, false, place) {
                Ok(p) => p,
                Err(e) => return Some(e),
            };
            if let Val::Table(entries) = &mut parent.val {
                if let Some(i) = entries.iter().position(|(k, _)| *k == last.name) {
                    let (_, old) = entries.remove(i);
                    let reopenable = matches!(old.val, Val::Table(_))
                        && old.form.has(Form::IMPLICIT)
                        && !old.form.has(Form::DOTTED);
                    if !reopenable {
                        return Some(err("duplicate key", last.at));
                    }
                    fresh.val = old.val;
                }
            }
        }
        self.header = Some(header);
        self.current_keys.clear();
        if let Val::Table(entries) = &fresh.val {
            for i in 0..entries.len() {
                self.current_keys.insert(entries, i);
            }
        }
        self.current = fresh;
        None
    }
}

/// A finished array or table, its spare capacity returned (a mesh is millions of small arrays).
fn fitted(mut node: Node) -> Node {
    match &mut node.val {
        Val::Array(items) => items.shrink_to_fit(),
        Val::Table(entries) => entries.shrink_to_fit(),
        _ => {}
    }
    node
}

/// Walk `path` from `table`, making implicit tables where nothing is (dotted ones when the path is
/// a dotted key), and entering the last table of an array of tables.
fn descend<'t>(
    node: &'t mut Node,
    path: &[Key],
    dotted: bool,
    place: Place,
) -> Result<&'t mut Node, ParseError> {
    descend_indexed(node, None, path, dotted, place)
}

/// `descend`, with `index` (where each key of `node` is among its entries, kept up to date)
/// for the first step.
fn descend_indexed<'t>(
    mut node: &'t mut Node,
    mut index: Option<&mut KeyIndex>,
    path: &[Key],
    dotted: bool,
    place: Place,
) -> Result<&'t mut Node, ParseError> {
    for key in path {
        let inline = node.form.has(Form::INLINE);
        let Val::Table(entries) = &mut node.val else {
            return Err(err("cannot extend a value with a dotted key", key.at));
        };
        let index = index.take();
        let found = match &index {
            Some(index) => index.find(entries, &key.name),
            None => entries.iter().position(|(k, _)| *k == key.name),
        };
        let i = match found {
            Some(i) => i,
            None => {
                let mut form = Form::TABLE.with(Form::IMPLICIT);
                if dotted {
                    form = form.with(Form::DOTTED);
                }
                if inline {
                    form = form.with(Form::INLINE);
                }
                entries.push((key.name.clone(), table(place.at(key.at), form)));
                if let Some(index) = index {
                    index.insert(entries, entries.len() - 1);
                }
                entries.len() - 1
            }
        };
        let child = &mut entries[i].1;
        let (form, is_table) = (child.form, matches!(child.val, Val::Table(_)));
        let kind = child.kind();
        if is_table {
            if form.has(Form::INLINE) && !inline {
                return Err(err(
                    "cannot extend an inline table with a dotted key or a header",
                    key.at,
                ));
            }
            if dotted && !form.has(Form::IMPLICIT) {
                return Err(err("duplicate key", key.at));
            }
            node = child;
            continue;
        }
        node = match &mut child.val {
            Val::Array(items) if form.has(Form::ARRAY_OF_TABLES) && !inline => {
                match items.last_mut() {
                    Some(last) if matches!(last.val, Val::Table(_)) => last,
                    _ => return Err(err("cannot extend this value with a dotted key", key.at)),
                }
            }
            _ => {
                return Err(err(
                    format!("cannot extend {kind} with a dotted key"),
                    key.at,
                ))
            }
        };
    }
    Ok(node)
}

/// Where each key of a table is among its entries, found by the key's hash and checked against
/// the entry's own name (no copy of the name is kept). Seeded per process, so that a file
/// cannot be written to collide.
#[derive(Default)]
struct KeyIndex {
    /// Each entry's hash (kept, so growing the table reads no names) and index.
    table: hashbrown::HashTable<(u64, usize)>,
    hasher: hashbrown::DefaultHashBuilder,
}

impl KeyIndex {
    fn clear(&mut self) {
        self.table.clear();
    }

    fn hash(&self, name: &str) -> u64 {
        use std::hash::BuildHasher;
        self.hasher.hash_one(name)
    }

    /// Which of `entries` is named `name`.
    fn find(&self, entries: &[(String, Node)], name: &str) -> Option<usize> {
        self.find_hashed(entries, name, self.hash(name))
    }

    /// Which of `entries` is named `name`, whose hash is `hash`.
    fn find_hashed(&self, entries: &[(String, Node)], name: &str, hash: u64) -> Option<usize> {
        self.table
            .find(hash, |&(h, i)| h == hash && entries[i].0 == name)
            .map(|&(_, i)| i)
    }

    /// Index `entries[i]`, whose name is not indexed yet.
    fn insert(&mut self, entries: &[(String, Node)], i: usize) {
        self.insert_hashed(self.hash(&entries[i].0), i);
    }

    /// Index entry `i`, whose name's hash is `hash` and is not indexed yet.
    fn insert_hashed(&mut self, hash: u64, i: usize) {
        self.table.insert_unique(hash, (hash, i), |&(h, _)| h);
    }
}

/// Put `value` at the dotted key `key` of `table`.
fn insert(table: &mut Node, key: Vec<Key>, value: Node, place: Place, error: &mut dyn ErrorSink) {
    insert_indexed(table, None, key, value, place, error)
}

/// `insert`, with `index` (where each key of `table` is among its entries, kept up to date).
fn insert_indexed(
    table: &mut Node,
    mut index: Option<&mut KeyIndex>,
    mut key: Vec<Key>,
    mut value: Node,
    place: Place,
    error: &mut dyn ErrorSink,
) {
    // The last key's name moves into the table.
    let Some(last) = key.pop() else {
        return;
    };
    let path = &key[..];
    // The index is the table's own: it serves the first step of a dotted key, or the key.
    let (step, own) = match path.is_empty() {
        true => (None, index.take()),
        false => (index.take(), None),
    };
    let parent = match descend_indexed(table, step, path, true, place) {
        Ok(p) => p,
        Err(e) => return error.report_error(e),
    };
    // A table made by a header takes plain keys; one made by a dotted key, only dotted ones.
    if parent.form.has(Form::DOTTED) == path.is_empty() {
        return error.report_error(err("duplicate key", last.at));
    }
    let Val::Table(entries) = &mut parent.val else {
        return;
    };
    let hash = own.as_ref().map(|index| index.hash(&last.name));
    let taken = match (&own, hash) {
        (Some(index), Some(hash)) => index.find_hashed(entries, &last.name, hash).is_some(),
        _ => entries.iter().any(|(k, _)| *k == last.name),
    };
    if taken {
        return error.report_error(err("duplicate key", last.at));
    }
    value.origin = place.at(last.at);
    entries.push((last.name, value));
    if let (Some(index), Some(hash)) = (own, hash) {
        index.insert_hashed(hash, entries.len() - 1);
    }
}

impl EventReceiver for Builder<'_, '_> {
    fn std_table_open(&mut self, span: Span, error: &mut dyn ErrorSink) {
        if let Some(e) = self.finish_table() {
            error.report_error(e);
        }
        self.keys.clear();
        self.in_header = Some((false, span.start()));
    }

    fn std_table_close(&mut self, _span: Span, error: &mut dyn ErrorSink) {
        let Some((array, at)) = self.in_header.take() else {
            return;
        };
        let header = Header {
            path: std::mem::take(&mut self.keys),
            array,
            at,
        };
        if let Some(e) = self.start_table(header) {
            error.report_error(e);
        }
    }

    fn array_table_open(&mut self, span: Span, error: &mut dyn ErrorSink) {
        self.std_table_open(span, error);
        self.in_header = Some((true, span.start()));
    }

    fn array_table_close(&mut self, span: Span, error: &mut dyn ErrorSink) {
        self.std_table_close(span, error);
    }

    fn inline_table_open(&mut self, span: Span, _error: &mut dyn ErrorSink) -> bool {
        let t = table(self.place.at(span.start()), Form::TABLE.with(Form::INLINE));
        self.open.push(Open::Table(t, Vec::new()));
        true
    }

    fn inline_table_close(&mut self, _span: Span, error: &mut dyn ErrorSink) {
        if let Some(Open::Table(t, _)) = self.open.pop() {
            self.deliver(fitted(t), error);
        }
    }

    fn array_open(&mut self, span: Span, _error: &mut dyn ErrorSink) -> bool {
        let a = Node {
            val: Val::Array(Vec::new()),
            origin: self.place.at(span.start()),
            form: Form::VALUE,
        };
        self.open.push(Open::Array(a));
        true
    }

    fn array_close(&mut self, _span: Span, error: &mut dyn ErrorSink) {
        if let Some(Open::Array(a)) = self.open.pop() {
            self.deliver(fitted(a), error);
        }
    }

    fn simple_key(&mut self, span: Span, kind: Option<Encoding>, error: &mut dyn ErrorSink) {
        let raw = toml_parser::Raw::new_unchecked(
            &self.source.input()[span.start()..span.end()],
            kind,
            span,
        );
        let mut name = String::new();
        raw.decode_key(&mut name, error);
        self.keys.push(Key {
            name,
            at: span.start(),
        });
    }

    fn key_val_sep(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        let key = std::mem::take(&mut self.keys);
        match self.open.last_mut() {
            Some(Open::Table(_, k)) => *k = key,
            _ => self.doc_key = key,
        }
    }

    fn scalar(&mut self, span: Span, kind: Option<Encoding>, error: &mut dyn ErrorSink) {
        let text = &self.source.input()[span.start()..span.end()];
        let raw = toml_parser::Raw::new_unchecked(text, kind, span);
        let decoded = &mut self.decoded;
        decoded.clear();
        let val = match raw.decode_scalar(decoded, error) {
            ScalarKind::String => Val::Str(std::mem::take(decoded)),
            ScalarKind::Boolean(b) => Val::Bool(b),
            ScalarKind::DateTime => {
                if decoded.parse::<toml_datetime::Datetime>().is_err() {
                    error.report_error(err("invalid date-time", span.start()));
                }
                Val::Other("a date")
            }
            ScalarKind::Float => match decoded.parse::<f64>() {
                Ok(f) if f.is_finite() || decoded.contains("inf") || decoded.contains("nan") => {
                    Val::Float(f)
                }
                _ => {
                    error.report_error(err("the number does not fit a float", span.start()));
                    Val::Float(0.0)
                }
            },
            ScalarKind::Integer(radix) => match i64::from_str_radix(decoded, radix.value()) {
                Ok(i) => Val::Int(i),
                Err(_) => {
                    error.report_error(err(
                        "the integer does not fit 64 bits (-2^63 to 2^63 - 1; a key that takes any number takes it as a float, e.g. 1e20)",
                        span.start(),
                    ));
                    Val::Int(0)
                }
            },
        };
        let node = Node {
            val,
            origin: self.place.at(span.start()),
            form: Form::VALUE,
        };
        self.deliver(node, error);
    }
}
