//! How a command fails, and the one place that turns that into what is printed and
//! the process's exit status.
//!
//! | status | when |
//! |---|---|
//! | 0 | success (`compare`: within the thresholds) |
//! | 1 | [`Error::Failed`]: an input, render or output error; `batch`: a job failed |
//! | 1 | [`Error::CheckFailed`]: `compare` over a threshold, `stress` outside a bound |
//! | 2 | [`Error::Usage`]: bad arguments, found before any work (clap's own errors too); `compare`: an unreadable image |
//! | 130 | [`Error::Interrupted`]: Ctrl-C or SIGTERM stopped the command (`interrupt.rs`) |
//!
//! A command whose standard output is closed early (`emray gen teapot | head`) stops
//! quietly with status 0, as other command-line tools do.

use std::fmt::Display;
use std::process::ExitCode;

/// Why a command did not succeed.
#[derive(Debug)]
pub enum Error {
    /// Bad arguments or a request that cannot be met, found before any work: exit 2.
    Usage(anyhow::Error),
    /// The work failed (unreadable input, a failed render or write): exit 1.
    Failed(anyhow::Error),
    /// A check the command makes did not pass and says so itself (`compare`'s
    /// thresholds, `stress`'s bounds): exit 1, nothing more printed.
    CheckFailed,
    /// Ctrl-C or SIGTERM stopped the command (a batch, with the error of the jobs that
    /// failed before if any): exit 130.
    Interrupted(Option<anyhow::Error>),
}

impl Error {
    /// A usage error saying `message`.
    pub fn usage(message: impl Display + std::fmt::Debug + Send + Sync + 'static) -> Self {
        Error::Usage(anyhow::Error::msg(message))
    }

    /// A failure saying `message`.
    pub fn failed(message: impl Display + std::fmt::Debug + Send + Sync + 'static) -> Self {
        Error::Failed(anyhow::Error::msg(message))
    }

    /// The process's exit status.
    pub fn exit_code(&self) -> u8 {
        if self.is_closed_pipe() {
            return 0;
        }
        match self {
            Error::Usage(_) => 2,
            Error::Failed(_) | Error::CheckFailed => 1,
            Error::Interrupted(_) => 130,
        }
    }

    /// What to print, if anything.
    fn message(&self) -> Option<&anyhow::Error> {
        match self {
            Error::Usage(e) | Error::Failed(e) | Error::Interrupted(Some(e)) => Some(e),
            Error::CheckFailed | Error::Interrupted(None) => None,
        }
    }

    /// Whether the command stopped because its standard output was closed.
    pub fn is_closed_pipe(&self) -> bool {
        self.message().is_some_and(is_closed_pipe)
    }

    /// Print the error (once, one line, no backtrace) and give the exit status.
    pub fn report(&self) -> ExitCode {
        if self.is_closed_pipe() {
            return ExitCode::SUCCESS;
        }
        if let Some(e) = self.message() {
            eprintln!("{}", error_line(e));
        }
        ExitCode::from(self.exit_code())
    }
}

/// Any library error is a failure (exit 1) unless the command says otherwise.
impl<E: std::error::Error + Send + Sync + 'static> From<E> for Error {
    fn from(e: E) -> Self {
        Error::Failed(e.into())
    }
}

/// A job's failure: a usage error (exit 2) when the job was asked something it cannot
/// do, else a failure (exit 1).
pub fn job_error(e: emray::job::JobError) -> Error {
    if e.is_usage() {
        Error::Usage(e.into())
    } else {
        Error::Failed(e.into())
    }
}

/// Whether `e` comes from writing to a pipe whose reader has gone.
pub fn is_closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Write `text` to standard output; unlike `print!`, a closed pipe is an error the
/// caller returns (and the process then ends quietly) rather than a panic.
pub fn print(text: std::fmt::Arguments) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_fmt(text)?;
    out.flush()
}

/// The line an error is printed as: `emray: error: ` and the error with its causes
/// (every error the command prints goes through here). Control characters, which a
/// malformed input can put in a message (a garbled keyword, a file name), are
/// escaped (`\u{1b}`, `\n`), so the message stays one line and cannot drive the
/// terminal.
pub fn error_line(e: impl Display) -> String {
    let text = format!("{e:#}");
    let mut line = String::from("emray: error: ");
    for c in text.chars() {
        if c.is_control() {
            line.extend(c.escape_default());
        } else {
            line.push(c);
        }
    }
    line
}

/// The usage error of a command this build lacks for want of `feature`.
#[cfg(not(feature = "quality"))]
pub fn lacks_feature(command: &str, feature: &str) -> Error {
    Error::usage(format!(
        "this emray was built without the `{feature}` feature, which `emray {command}` needs \
         (build it with the default features or with `--features {feature}`)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statuses_follow_the_variant() {
        assert_eq!(Error::usage("x").exit_code(), 2);
        assert_eq!(Error::failed("x").exit_code(), 1);
        assert_eq!(Error::CheckFailed.exit_code(), 1);
        assert_eq!(Error::Interrupted(None).exit_code(), 130);
        let e = anyhow::anyhow!("inner").context("outer");
        assert_eq!(error_line(&e), "emray: error: outer: inner");
    }

    #[test]
    fn an_error_line_escapes_control_characters() {
        let e = anyhow::anyhow!("a.nff:1:1: unknown entity 'x\u{1b}[2Jy\nz'");
        assert_eq!(
            error_line(&e),
            "emray: error: a.nff:1:1: unknown entity 'x\\u{1b}[2Jy\\nz'"
        );
        assert_eq!(error_line("é ✓"), "emray: error: é ✓");
    }

    #[test]
    fn a_closed_pipe_exits_quietly() {
        let pipe = std::io::Error::from(std::io::ErrorKind::BrokenPipe);
        let e = Error::Failed(anyhow::Error::new(pipe).context("cannot write"));
        assert!(e.is_closed_pipe());
        assert_eq!(e.exit_code(), 0);
        assert!(!Error::failed("other").is_closed_pipe());
    }
}
