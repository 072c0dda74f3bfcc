//! The arguments every command takes: `-q` and `-v`. (What a render asks for is
//! declared once, in the library: [`emray::job::RenderOptions`], which the commands
//! that render flatten into their own arguments.)

use clap::Args;

/// `-q` and `-v`, which every command takes.
#[derive(Args, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LogArgs {
    /// No progress bars and no messages but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// More log output (repeat for more).
    #[arg(short, long, action = clap::ArgAction::Count)]
    pub verbose: u8,
}
