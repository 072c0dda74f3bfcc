//! `emray gen`: write a Standard Procedural Database scene as NFF (the module is not
//! called `gen`, a reserved word since edition 2024).

use super::Error;
use super::args::LogArgs;
use super::error::print;
use anyhow::Context;
use emray::spd::Database;

/// `emray gen`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Database: balls, gears, jacks, lattice, mount, rings, shells, sombrero, teapot,
    /// tetra, tree.
    #[arg(value_name = "DATABASE")]
    pub database: String,
    /// Size factor (default: the SPD program's default for the database).
    #[arg(short, long)]
    pub size: Option<u32>,
    /// Output file (default: standard output).
    #[arg(short, long, value_name = "FILE.nff")]
    pub output: Option<std::path::PathBuf>,
    /// `-q` and `-v`.
    #[command(flatten)]
    pub log: LogArgs,
}

/// Generate the database at its size, to the file or to standard output.
pub fn run(g: Args) -> Result<(), Error> {
    let Some(db) = Database::from_name(&g.database) else {
        let names: Vec<&str> = Database::ALL.iter().map(|d| d.name()).collect();
        return Err(Error::usage(format!(
            "unknown database '{}' (one of {})",
            g.database,
            names.join(", ")
        )));
    };
    let size = g.size.unwrap_or_else(|| db.default_size());
    db.check_size(size).map_err(Error::usage)?;
    super::outputs::prepare(g.output.as_deref())?;
    let text = db.generate(size);
    match &g.output {
        None => print(format_args!("{text}"))
            .context("cannot write to standard output")
            .map_err(Error::Failed),
        Some(path) => Ok(emray::output::write_text(path, &text)?),
    }
}
