//! Hints added to clap's errors where the command line was mangled on its way in.

/// Where a command line failed to parse because a `--set` (or `--sbatch-arg`) value was split
/// by the shell at its spaces (`--set group.a.velocity=[0.9, 0, 0]` unquoted): how to quote it,
/// the value joined again.
pub(super) fn quoting_hint(args: &[String]) -> Option<String> {
    let depth =
        |v: &str| v.matches(['[', '{']).count() as i64 - v.matches([']', '}']).count() as i64;
    let flags = ["--set", "--sbatch-arg"];
    (0..args.len()).find_map(|i| {
        let (flag, first, rest) = match args[i].split_once('=') {
            Some((f, v)) if flags.contains(&f) => (f, v, i + 1),
            _ if flags.contains(&args[i].as_str()) => (args[i].as_str(), args.get(i + 1)?.as_str(), i + 2),
            _ => return None,
        };
        if depth(first) <= 0 {
            return None;
        }
        // The pieces the shell made of the value, up to where its brackets close.
        let mut value = first.to_string();
        for piece in args.iter().skip(rest) {
            if depth(&value) <= 0 {
                break;
            }
            value.push(' ');
            value.push_str(piece);
        }
        Some(format!(
            "hint: the shell split the value of {flag} at its spaces; quote it whole: {flag} '{value}'"
        ))
    })
}
