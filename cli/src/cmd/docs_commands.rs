//! Every `emray …` command line the documentation shows parses with the real command
//! line of the binary, so that a renamed option or command cannot leave the README or
//! `docs/` telling users something the program refuses. (`tests/docs_commands.rs` runs
//! them.) The commands are found by [`docs_scan`](super::docs_scan); a line's words
//! end at a pipe or a redirection.

use super::Cli;
use super::docs_scan::{commands_in, documented, shell_words};
use clap::Parser;

#[test]
fn every_documented_command_parses() {
    let mut checked = 0;
    let mut failures = Vec::new();
    for cmd in documented() {
        let words = shell_words(&cmd.line);
        checked += 1;
        if let Err(e) = Cli::try_parse_from(&words) {
            let first = e.to_string().lines().next().unwrap_or("").to_string();
            failures.push(format!("{}: `{}`: {first}", cmd.place, cmd.line));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The README alone shows dozens: finding few means the scanner broke.
    assert!(checked >= 50, "only {checked} documented commands found");
    println!("{checked} documented commands parse");
}

#[test]
fn the_scanner_reads_sh_blocks_tables_sections_and_shell_quoting() {
    let md = "# T\n```sh\nemray render a.nff \\\n  --res 4x4\n$ emray gen balls | head\n```\n\
              ## Two\n```bash\nemray render \"$X\"\n```\n#not a heading\n\
              | `emray merge a.exr -o b.exr` | `emray render` only |\n";
    let got: Vec<(String, String, String)> = commands_in("t.md", md)
        .into_iter()
        .map(|c| (c.place, c.section, c.line))
        .collect();
    let want = [
        ("t.md:3", "t.md T", "emray render a.nff  --res 4x4"),
        ("t.md:5", "t.md T", "emray gen balls | head"),
        ("t.md:12", "t.md Two", "emray merge a.exr -o b.exr"),
    ];
    let want: Vec<(String, String, String)> = want
        .iter()
        .map(|(p, s, l)| (p.to_string(), s.to_string(), l.to_string()))
        .collect();
    assert_eq!(got, want);
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
