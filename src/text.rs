//! Text from files and requests as messages show it: cut to a line of about 200 characters,
//! its control characters escaped, so that no file's content can write a 20 MB message, set a
//! terminal's title or clear its screen through an error (`shown`); and a whole message made
//! safe for a terminal the same way line by line, as the command line prints it
//! (`terminal_safe`); a line on standard output or error that a closed pipe or a full device
//! does not turn into a panic (`say`, `warn`).

/// Write a line to standard output. A reader that has gone (`rest-embree backends | head -1`)
/// wants no more: the rest is dropped, quietly. Any other failure is said on standard error;
/// neither panics, as `println!` would.
pub(crate) fn say(line: impl std::fmt::Display) {
    use std::io::Write;
    match writeln!(std::io::stdout().lock(), "{line}") {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            warn(format_args!("error: cannot write to standard output: {e}"));
        }
        _ => {}
    }
}

/// Write a line to standard error, as `eprintln!` does, but without its panic where standard
/// error cannot be written (`2>/dev/full`, a closed pipe): the line is lost, the command's exit
/// status stands.
pub(crate) fn warn(line: impl std::fmt::Display) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// The most characters of a file's text an error quotes.
pub const SHOWN_CHARS: usize = 200;

/// The most characters a line of a message printed to a terminal keeps.
const LINE_CHARS: usize = 2000;

/// The most lines of a message printed to a terminal.
const LINES: usize = 200;

/// `s` as an error quotes it: on one line, control characters (and the line breaks) escaped
/// (`\u{1b}` as `\x1b`, a newline as `\n`), cut after `SHOWN_CHARS` characters with the
/// number left out said.
pub fn shown(s: &str) -> String {
    let mut out = String::new();
    for (count, c) in s.chars().enumerate() {
        if count == SHOWN_CHARS {
            let rest = s.chars().count() - count;
            out.push_str(&format!("… ({rest} more characters)"));
            break;
        }
        push_escaped(&mut out, c, true);
    }
    out
}

/// A control character as an escape (`\n`, `\t`, `\x1b`, `\u{9b}`), anything else as itself;
/// with `breaks` false a newline and a tab stay as they are.
fn push_escaped(out: &mut String, c: char, breaks: bool) {
    match c {
        '\n' if !breaks => out.push('\n'),
        '\t' if !breaks => out.push('\t'),
        '\n' => out.push_str("\\n"),
        '\t' => out.push_str("\\t"),
        '\r' => out.push_str("\\r"),
        c if (c as u32) < 0x20 || c == '\u{7f}' => out.push_str(&format!("\\x{:02x}", c as u32)),
        // C1 controls (a terminal may take U+009B as an escape sequence's start), and the
        // characters that reorder text on screen.
        c if ('\u{80}'..='\u{9f}').contains(&c)
            || ('\u{202a}'..='\u{202e}').contains(&c)
            || ('\u{2066}'..='\u{2069}').contains(&c) =>
        {
            out.push_str(&format!("\\u{{{:x}}}", c as u32))
        }
        c => out.push(c),
    }
}

/// A whole message as a terminal is given it: line by line (its own line breaks kept), every
/// other control character escaped, a line cut after `LINE_CHARS` characters and the message
/// after `LINES` lines, each cut said.
pub fn terminal_safe(message: &str) -> String {
    let mut out = String::with_capacity(message.len().min(LINE_CHARS * 4));
    for (k, line) in message.split('\n').enumerate() {
        if k == LINES {
            let rest = message.split('\n').count() - k;
            out.push_str(&format!("… ({rest} more lines)"));
            break;
        }
        if k > 0 {
            out.push('\n');
        }
        for (n, c) in line.chars().enumerate() {
            if n == LINE_CHARS {
                out.push_str(&format!("… ({} more characters)", line.chars().count() - n));
                break;
            }
            push_escaped(&mut out, c, false);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_cuts() {
        assert_eq!(shown("a\u{1b}]0;pwned\u{7}b"), "a\\x1b]0;pwned\\x07b");
        assert_eq!(shown("one\ntwo"), "one\\ntwo");
        let long = "x".repeat(1000);
        let s = shown(&long);
        assert!(s.starts_with(&"x".repeat(SHOWN_CHARS)) && s.ends_with("(800 more characters)"));
        assert_eq!(shown("\u{9b}2J"), "\\u{9b}2J");
        let t = terminal_safe("error: a\nb\u{1b}[2J\tc");
        assert_eq!(t, "error: a\nb\\x1b[2J\tc");
        let many = "y\n".repeat(1000);
        assert!(terminal_safe(&many).ends_with("more lines)"));
        assert!(terminal_safe(&"z".repeat(3_000_000)).len() < 3000);
        assert_eq!(shown("plain ascii and ümlauts"), "plain ascii and ümlauts");
    }
}
