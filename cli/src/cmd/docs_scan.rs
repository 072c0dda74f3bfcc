//! The `emray …` command lines the documentation shows (the README and every Markdown
//! file under `docs/`), with where each is and the section it is in. Two tests read
//! them: the binary's own (`docs_commands`), which parses every one with the real
//! command line, and `tests/docs_commands.rs`, which runs them; this file is shared by
//! both and depends on nothing else.
//!
//! Commands are taken from `sh` code blocks (a line starting with `emray`, with `\`
//! continuations joined) and from the inline code of table rows
//! (`` `emray SUBCOMMAND ARGS…` ``). `bash` blocks are shell scripts with shell
//! variables in their command lines and are not read. A section is the text under one
//! heading, of any level: its commands may use what the ones before them wrote.

use std::path::{Path, PathBuf};

/// One documented command line and where it is.
pub struct Documented {
    /// `file:line`.
    pub place: String,
    /// `file` and the heading the command is under.
    pub section: String,
    /// The command line as shown (a shell line: it may have a pipe or a redirection).
    pub line: String,
}

/// The repository's root (the workspace, above the command line's package).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the command line's package lies in the workspace")
}

/// The README and every Markdown file under `docs/`.
pub fn documents() -> Vec<PathBuf> {
    let mut files = vec![root().join("README.md")];
    let docs = std::fs::read_dir(root().join("docs")).expect("docs/ is readable");
    let mut md: Vec<PathBuf> = docs
        .map(|e| e.expect("a docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    md.sort();
    files.extend(md);
    files
}

/// Every documented command, document by document, in order.
pub fn documented() -> Vec<Documented> {
    let mut all = Vec::new();
    for path in documents() {
        let text = std::fs::read_to_string(&path).expect("a readable document");
        let name = path
            .strip_prefix(root())
            .unwrap_or(&path)
            .display()
            .to_string();
        all.extend(commands_in(&name, &text));
    }
    all
}

/// The command lines of `sh` blocks and table rows in one Markdown text.
pub fn commands_in(name: &str, text: &str) -> Vec<Documented> {
    let mut found = Vec::new();
    let mut block: Option<String> = None;
    let mut pending: Option<(usize, String)> = None;
    let mut section = name.to_string();
    for (i, line) in text.lines().enumerate() {
        let at = |line: usize, text: &str| Documented {
            place: format!("{name}:{line}"),
            section: section.clone(),
            line: text.to_string(),
        };
        if let Some(fence) = line.trim_start().strip_prefix("```") {
            block = if block.is_some() {
                None
            } else {
                Some(fence.trim().to_string())
            };
            continue;
        }
        match block.as_deref() {
            Some("sh") => {
                let line = line.trim();
                let line = line.strip_prefix("$ ").unwrap_or(line);
                if let Some((start, mut joined)) = pending.take() {
                    joined.push(' ');
                    joined.push_str(line.trim_end_matches('\\'));
                    if line.ends_with('\\') {
                        pending = Some((start, joined));
                    } else {
                        found.push(at(start, &joined));
                    }
                } else if line == "emray" || line.starts_with("emray ") {
                    if line.ends_with('\\') {
                        pending = Some((i + 1, line.trim_end_matches('\\').to_string()));
                    } else {
                        found.push(at(i + 1, line));
                    }
                }
            }
            Some(_) => {}
            None if line.starts_with('#') && line.trim_start_matches('#').starts_with(' ') => {
                section = format!("{name} {}", line.trim_start_matches('#').trim());
            }
            None if line.starts_with('|') => {
                for span in line.split('`').skip(1).step_by(2) {
                    let words = span.split_whitespace().count();
                    if span.starts_with("emray ") && words >= 3 {
                        found.push(at(i + 1, span));
                    }
                }
            }
            None => {}
        }
    }
    found
}

/// Split a shell command line into words as `sh` would for these simple lines (single
/// and double quotes, backslash escapes), stopping at a pipe, a redirection, `&&`,
/// `;` or a comment.
pub fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_word = true;
                for q in chars.by_ref() {
                    if q == '\'' {
                        break;
                    }
                    word.push(q);
                }
            }
            '"' => {
                in_word = true;
                while let Some(q) = chars.next() {
                    match q {
                        '"' => break,
                        '\\' => word.extend(chars.next()),
                        _ => word.push(q),
                    }
                }
            }
            '\\' => {
                in_word = true;
                word.extend(chars.next());
            }
            '|' | '>' | '<' | ';' | '&' | '#' if !in_word => break,
            c if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            c => {
                in_word = true;
                word.push(c);
            }
        }
    }
    if in_word {
        words.push(word);
    }
    // A redirection glued to the word before it (`2>/dev/null`) ends the command too.
    if let Some(at) = words.iter().position(|w| w.starts_with("2>")) {
        words.truncate(at);
    }
    words
}
