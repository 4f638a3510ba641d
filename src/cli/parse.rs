//! Reading the command line: the arguments, with a nearer suggestion for a
//! mistyped flag, and comma-separated lists of numbers.

/// Parses the command line like `T::parse()`, except that an unknown
/// `--flag` is answered with the subcommand's flag nearest by edit distance
/// (a swap of two neighbours counts as one edit): `--pgn` suggests `--png`.
/// Clap ranks by Jaro similarity, which matches letters only within a window
/// that is empty for three-letter words, so it found no letter of `pgn` in
/// `png` beyond the first and suggested `--ga-n` instead.
pub fn parse_args<T: clap::Parser>() -> T {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    T::try_parse_from(&args).unwrap_or_else(|e| nearer_suggestion(e, T::command(), &args).exit())
}

/// `e` with the suggestion of [`parse_args`] when it names an unknown flag
/// and a flag is within a third of its length in edits; otherwise `e`.
fn nearer_suggestion(mut e: clap::Error, mut cmd: clap::Command, args: &[std::ffi::OsString]) -> clap::Error {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::UnknownArgument {
        return e;
    }
    let Some(ContextValue::String(given)) = e.get(ContextKind::InvalidArg) else { return e };
    let Some(given) = given.strip_prefix("--").map(str::to_string) else { return e };
    cmd.build();
    // The subcommand is the first argument naming one (flags of `cablemap` itself come before it).
    let Some(name) = args.iter().skip(1).filter_map(|a| a.to_str()).find(|a| cmd.find_subcommand(a).is_some()) else { return e };
    let Some(sub) = cmd.find_subcommand_mut(name) else { return e };
    let longs: Vec<String> = sub.get_arguments().filter(|a| !a.is_hide_set()).filter_map(|a| a.get_long().map(str::to_string)).collect();
    let Some((distance, nearest)) = longs.iter().map(|l| (edit_distance(&given, l), l)).min_by_key(|(d, _)| *d) else { return e };
    let clap_choice = match e.get(ContextKind::SuggestedArg) {
        Some(ContextValue::String(s)) => s.strip_prefix("--").map(str::to_string),
        _ => None,
    };
    let tied_with_clap = clap_choice.as_deref().is_some_and(|c| edit_distance(&given, c) == distance);
    if distance > (given.chars().count() / 3).max(1) || tied_with_clap {
        return e;
    }
    if clap_choice.is_none() {
        // Clap's "to pass '--x' as a value, use '-- --x'", which it gives only when it has no flag to suggest.
        e.remove(ContextKind::Suggested);
    }
    e.insert(ContextKind::SuggestedArg, ContextValue::String(format!("--{nearest}")));
    // Clap's usage line shows its own suggestion as if given; show the plain usage.
    e.insert(ContextKind::Usage, ContextValue::StyledStr(sub.render_usage()));
    e
}

/// Edits (insert, delete, substitute, swap two neighbours) from `a` to `b`:
/// the optimal string alignment distance.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // d[i][j]: distance between the first i letters of a and the first j of b.
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for j in 0..=b.len() {
        d[0][j] = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            d[i][j] = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d[i][j] = d[i][j].min(d[i - 2][j - 2] + 1);
            }
        }
    }
    d[a.len()][b.len()]
}

/// Parses "a,b,c" into numbers, naming the offending item.
pub fn parse_list(text: &str, what: &str) -> anyhow::Result<Vec<f64>> {
    text.split(',')
        .map(|item| {
            item.trim()
                .parse::<f64>()
                .map_err(|_| anyhow::anyhow!("{what}: '{}' is not a number (expected a comma-separated list like 1,-2,0.5,0,3)", item.trim()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::edit_distance;

    #[test]
    fn a_swap_of_neighbours_is_one_edit() {
        assert_eq!(edit_distance("pgn", "png"), 1);
        assert_eq!(edit_distance("pgn", "ga-n"), 3);
        assert_eq!(edit_distance("tension", "tension-n"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }
}
