//! Every `emray …` command line the documentation shows parses with the real command
//! line of the binary, so that a renamed option or command cannot leave the README or
//! `docs/` telling users something the program refuses.
//!
//! Commands are taken from `sh` code blocks (a line starting with `emray`, with `\`
//! continuations joined and anything after a pipe or redirection dropped) and from
//! the inline code of table rows (`` `emray SUBCOMMAND ARGS…` ``). `bash` blocks are
//! shell scripts with shell variables in their command lines and are not read.

use super::Cli;
use clap::Parser;
use std::path::{Path, PathBuf};

/// One documented command line and where it is.
struct Documented {
    place: String,
    line: String,
}

/// The README and every Markdown file under `docs/`.
fn documents() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace root");
    let mut files = vec![root.join("README.md")];
    let docs = std::fs::read_dir(root.join("docs")).expect("docs/ is readable");
    let mut md: Vec<PathBuf> = docs
        .map(|e| e.expect("a docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    md.sort();
    files.extend(md);
    files
}

/// The command lines of `sh` blocks and table rows in one Markdown text.
fn commands_in(name: &str, text: &str) -> Vec<Documented> {
    let mut found = Vec::new();
    let mut block: Option<String> = None;
    let mut pending: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let place = format!("{name}:{}", i + 1);
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
                        found.push(documented(name, start, &joined));
                    }
                } else if line == "emray" || line.starts_with("emray ") {
                    if line.ends_with('\\') {
                        pending = Some((i + 1, line.trim_end_matches('\\').to_string()));
                    } else {
                        found.push(documented(name, i + 1, line));
                    }
                }
            }
            Some(_) => {}
            None if line.starts_with('|') => {
                for span in line.split('`').skip(1).step_by(2) {
                    let words = span.split_whitespace().count();
                    if span.starts_with("emray ") && words >= 3 {
                        found.push(Documented {
                            place: place.clone(),
                            line: span.to_string(),
                        });
                    }
                }
            }
            None => {}
        }
    }
    found
}

fn documented(name: &str, line: usize, text: &str) -> Documented {
    Documented {
        place: format!("{name}:{line}"),
        line: text.to_string(),
    }
}

/// Split a shell command line into words as `sh` would for these simple lines (single
/// and double quotes, backslash escapes), stopping at a pipe, a redirection, `&&`,
/// `;` or a comment.
fn shell_words(line: &str) -> Vec<String> {
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

#[test]
fn every_documented_command_parses() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace root");
    let mut checked = 0;
    let mut failures = Vec::new();
    for path in documents() {
        let text = std::fs::read_to_string(&path).expect("a readable document");
        let name = path
            .strip_prefix(root)
            .unwrap_or(&path)
            .display()
            .to_string();
        for cmd in commands_in(&name, &text) {
            let words = shell_words(&cmd.line);
            checked += 1;
            if let Err(e) = Cli::try_parse_from(&words) {
                let first = e.to_string().lines().next().unwrap_or("").to_string();
                failures.push(format!("{}: `{}`: {first}", cmd.place, cmd.line));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The README alone shows dozens: finding few means the scanner broke.
    assert!(checked >= 50, "only {checked} documented commands found");
    println!("{checked} documented commands parse");
}

#[test]
fn the_scanner_reads_sh_blocks_tables_and_shell_quoting() {
    let md = "```sh\nemray render a.nff \\\n  --res 4x4\n$ emray gen balls | head\n```\n\
              ```bash\nemray render \"$X\"\n```\n| `emray merge a.exr -o b.exr` | `emray render` only |\n";
    let got: Vec<String> = commands_in("t.md", md)
        .into_iter()
        .map(|c| c.line)
        .collect();
    assert_eq!(
        got,
        [
            "emray render a.nff  --res 4x4",
            "emray gen balls | head",
            "emray merge a.exr -o b.exr"
        ]
    );
    assert_eq!(
        shell_words("emray gen balls | head"),
        ["emray", "gen", "balls"]
    );
    assert_eq!(
        shell_words("emray render 'a b.nff' \"c\\\"d\" x 2>/dev/null"),
        ["emray", "render", "a b.nff", "c\"d", "x"]
    );
    assert!(Cli::try_parse_from(["emray", "render", "--no-such-option"]).is_err());
}
