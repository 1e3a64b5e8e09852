//! A long scene file read on every thread: cut before some of its `[[group]]` headers into runs
//! of about equal length, each run parsed on its own (toml_tree.rs) and the runs joined in
//! order: their groups appended to the first run's, the tables after them (a `[[light]]`, a
//! `[film]`) added to the document. A scene of 100,000 groups is mostly such tables, and its
//! parse is most of its load.
//!
//! The cuts are found by text alone (a line that starts with `[[group]]`), so a cut may fall
//! inside a value: a multi-line string or array holding such a line. Then the run before it ends
//! inside that value and does not parse. A run that does not parse, or a table that runs would
//! share (one defined twice, an array of tables in two runs), sends the whole file back to the
//! reader in one piece, whose tree (or first error) is the file's; so the tree made here is
//! always the one that reader makes, or none.

use super::node::{Form, Lines, Node, Val};
use super::toml_tree::parse_part;
use rayon::prelude::*;

/// Files shorter than this are read in one piece: splitting them is not worth the threads.
pub(crate) const RUNS_FROM: usize = 1 << 20;

/// What a cut goes before: a `[[group]]` header at the start of a line.
const HEADER: &[u8] = b"\n[[group]]";

/// The tree of `text` (the file `lines` counts) read in about `runs` runs in parallel; None
/// where the file has no cut to make or a run does not parse as a run of groups (then the
/// file is read in one piece).
pub(crate) fn in_runs(text: &str, lines: &Lines, runs: usize) -> Option<Node> {
    let cuts = cuts(text, runs);
    if cuts.len() < 3 {
        return None;
    }
    let parts: Vec<Option<Node>> = cuts
        .par_windows(2)
        .map(|w| parse_part(&text[w[0]..w[1]], lines, w[0]).ok())
        .collect();
    let mut parts = parts.into_iter();
    let mut root = parts.next()??;
    let Val::Table(entries) = &mut root.val else {
        return None;
    };
    // The groups before the first cut, if any: they must be an array of tables (else a
    // `[[group]]` after the cut is an error the reader in one piece reports).
    let mut groups = entries.iter().position(|(k, _)| k == "group");
    if groups.is_some_and(|i| !entries[i].1.form.has(Form::ARRAY_OF_TABLES)) {
        return None;
    }
    for part in parts {
        let Val::Table(more) = part?.val else {
            return None;
        };
        let mut more = more.into_iter();
        // A run starts with a `[[group]]` header, so its first entry is its groups.
        let (key, Node { val, origin, form }) = more.next()?;
        let Val::Array(items) = val else {
            return None;
        };
        if key != "group" || !form.has(Form::ARRAY_OF_TABLES) {
            return None;
        }
        match groups {
            Some(i) => match &mut entries[i].1.val {
                Val::Array(all) => all.extend(items),
                _ => return None,
            },
            None => {
                let val = Val::Array(items);
                entries.push((key, Node { val, origin, form }));
                groups = Some(entries.len() - 1);
            }
        }
        // Tables after its groups (a `[[light]]`, a `[film]`) are the document's where no
        // earlier run made that key; else the reader in one piece decides (a table defined
        // twice is an error, an array of tables is extended).
        for (key, node) in more {
            if entries.iter().any(|(k, _)| *k == key) {
                return None;
            }
            entries.push((key, node));
        }
    }
    Some(root)
}

/// Where the runs start: byte 0, then before a `[[group]]` header at or after each multiple of
/// the file's length over `runs`; last the file's end.
fn cuts(text: &str, runs: usize) -> Vec<usize> {
    let bytes = text.as_bytes();
    let find = memchr::memmem::Finder::new(HEADER);
    let step = (text.len() / runs.max(1)).max(1);
    let mut cuts = vec![0];
    let mut from = step;
    while from < bytes.len() {
        let Some(i) = find.find(&bytes[from..]) else {
            break;
        };
        // The header's `[`, after the newline (a character boundary).
        let cut = from + i + 1;
        cuts.push(cut);
        from = cut + step;
    }
    cuts.push(text.len());
    cuts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree of `text` read in one piece.
    fn whole(text: &str) -> Result<Node, String> {
        parse_part(text, &Lines::new(text), 0).map_err(|e| e.message)
    }

    /// Many groups, each with an object, a worldline array over lines and a comment.
    fn groups(n: usize) -> String {
        let mut s = String::new();
        for i in 0..n {
            s += &format!(
                "[[group]]\nname = \"g{i}\"\nvelocity = [0.1, 0, 0] # c\n\
                 [[group.object]]\ntype = \"box\"\nmin = [\n  {i}, 0, 0,\n]\nmax = [{i}.5, 1, 1]\n\n"
            );
        }
        s
    }

    /// Every way of cutting a file gives the tree read in one piece, line numbers included.
    #[test]
    fn runs_make_the_same_tree() {
        let head = "[camera]\nposition = [0, -5, 0]\n[image]\nwidth = 8\n";
        for text in [
            format!("{head}{}", groups(40)),
            // No group before the first cut.
            groups(40),
            // Groups, then other tables in the last run.
            format!("{}[light]\nposition = [0, 0, 9]\n", groups(40)),
            // An array of tables among the groups, and a table of tables after them.
            format!(
                "{}[[light]]\nposition = [0, 0, 9]\n{}[film.a.b]\nc = 1\n",
                groups(20),
                groups(20)
            ),
            format!("{}\r\n", groups(40).replace('\n', "\r\n")),
        ] {
            let expected = whole(&text).expect("valid");
            for runs in [2, 3, 7, 40, 500] {
                if let Some(tree) = in_runs(&text, &Lines::new(&text), runs) {
                    assert_eq!(tree, expected, "{runs} runs");
                }
            }
            assert!(
                in_runs(&text, &Lines::new(&text), 7).is_some(),
                "the runs were used"
            );
        }
    }

    /// A cut that falls inside a value, or tables that runs would share, send the file back to
    /// the reader in one piece (which gives the tree or the first error).
    #[test]
    fn what_runs_cannot_join_reads_in_one_piece() {
        let g = groups(20);
        let in_string = format!("{g}[[group]]\nname = \"s\"\nnote = \"\"\"\n{g}\"\"\"\n{g}");
        let in_literal = format!("{g}[[group]]\nname = \"s\"\nnote = \'\'\'\n{g}\'\'\'\n{g}");
        let in_array = format!("{g}[[group]]\nname = \"a\"\nlist = [\n{g}]\n{g}");
        let redefined = format!("{g}[camera]\nx = 1\n{g}[camera]\ny = 2\n{g}");
        let not_tables = format!("group = 5\n{g}");
        let lights_twice = format!("[[light]]\nx = 1\n{g}[[light]]\nx = 2\n{g}");
        for (text, valid) in [
            (in_string, true),
            (in_literal, true),
            (in_array, false),
            (redefined, false),
            (not_tables, false),
            (lights_twice, true),
        ] {
            let lines = Lines::new(&text);
            let one = whole(&text);
            assert_eq!(one.is_ok(), valid, "{text:.60}");
            let mut cut_inside = false;
            for runs in [2, 3, 5, 11, 60] {
                match in_runs(&text, &lines, runs) {
                    Some(tree) => assert_eq!(Ok(tree), one, "{runs}"),
                    None => cut_inside = true,
                }
            }
            assert!(cut_inside, "some cuts could not be joined: {text:.60}");
        }
    }

    /// A file long enough to be read in runs is, on more than one thread, and its tree and its
    /// errors are the reader's in one piece.
    #[test]
    fn a_long_file_reads_in_runs() {
        let text = groups(RUNS_FROM / 100);
        assert!(text.len() > RUNS_FROM);
        let lines = Lines::new(&text);
        let tree = in_runs(&text, &lines, 8).expect("read in runs");
        assert_eq!(Ok(tree), whole(&text));
        let read = super::super::toml_tree::parse_document(&text, &lines).map_err(|e| e.message);
        assert_eq!(read, whole(&text));
        // An error in the last run: the same message, pointing at the same byte.
        let bad = format!("{text}[[group]]\nname = \"x\"\nx = [1, 2\n");
        let lines = Lines::new(&bad);
        assert!(in_runs(&bad, &lines, 8).is_none());
        let e = super::super::toml_tree::parse_document(&bad, &lines).unwrap_err();
        let one = parse_part(&bad, &lines, 0).unwrap_err();
        assert_eq!((e.message, e.at), (one.message, one.at));
    }
}
