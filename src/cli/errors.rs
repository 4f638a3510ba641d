//! How the command prints an error: one line, each cause once.

/// An error and its causes on one line, each cause once: library errors
/// already print their cause ("reading X: No such file"), so a cause whose
/// text is already in the line is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}
