//! Exit codes and error printing at the binary's edge, decided in one place by the error's type:
//!
//! | code | when |
//! |---|---|
//! | 0 | success (also when the reader of standard output went away) |
//! | 2 | anything the user gave was refused: files, arguments, output paths, permissions, a full disk |
//! | 3 | a check failed: an answer or a rewritten program did not verify |
//! | 70 | a bug in towpath |
//!
//! Commands mark what only they can tell ([`bad_input`], [`check_failed`]); library errors and
//! I/O errors are classified here by [`code`], so a command that forgets to mark an error cannot
//! report a user's mistake as a bug.

use std::io::Write;

/// Exit code: success.
pub const OK: i32 = 0;
/// Exit code: the input was refused (bad file, bad arguments, infeasible problem).
pub const BAD_INPUT: i32 = 2;
/// Exit code: a check failed (a solution or program did not verify).
pub const CHECK_FAILED: i32 = 3;
/// Exit code: an internal error.
pub const INTERNAL: i32 = 70;

/// An error that carries its own exit code.
#[derive(Debug)]
pub struct Coded {
    /// Exit code to return.
    pub code: i32,
    /// What went wrong.
    pub error: anyhow::Error,
}

impl std::fmt::Display for Coded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:#}", self.error)
    }
}

impl std::error::Error for Coded {}

/// Marks an error as bad input (exit code 2).
pub fn bad_input(error: impl Into<anyhow::Error>) -> anyhow::Error {
    anyhow::Error::new(Coded { code: BAD_INPUT, error: error.into() })
}

/// Marks an error as a failed check (exit code 3).
pub fn check_failed(error: impl Into<anyhow::Error>) -> anyhow::Error {
    anyhow::Error::new(Coded { code: CHECK_FAILED, error: error.into() })
}

/// The exit code of an error: its own mark if it has one, else by the type of what caused it.
pub fn code(e: &anyhow::Error) -> i32 {
    for cause in e.chain() {
        if let Some(c) = cause.downcast_ref::<Coded>() {
            return c.code;
        }
        if let Some(code) = code_of_type(cause) {
            return code;
        }
    }
    INTERNAL
}

/// The exit code that an error's type implies, if it implies one.
fn code_of_type(cause: &(dyn std::error::Error + 'static)) -> Option<i32> {
    use towpath_nc::{NcError, VerifyError};
    match cause {
        c if c.is::<NcError>() => Some(match c.downcast_ref::<NcError>() {
            Some(NcError::SelfCheck(_)) => CHECK_FAILED,
            _ => BAD_INPUT,
        }),
        c if c.is::<VerifyError>() => Some(match c.downcast_ref::<VerifyError>() {
            Some(VerifyError::Original(_) | VerifyError::Optimized(_) | VerifyError::Setup(_)) => BAD_INPUT,
            _ => CHECK_FAILED,
        }),
        // Files and folders the user named, permissions, a full disk; and every reader's and
        // model's refusal of what it was given: the user's to fix.
        c if c.is::<std::io::Error>()
            || c.is::<towpath_formats::FormatError>()
            || c.is::<towpath_geom::MeshError>()
            || c.is::<towpath_geom::surface::ParseError>()
            || c.is::<towpath_geom::surface::NurbsError>()
            || c.is::<towpath_geom::surface::TessellationError>()
            || c.is::<towpath_layup::input::CsvError>()
            || c.is::<towpath_layup::ply::PlyError>()
            || c.is::<towpath_machine::MachineError>()
            || c.is::<towpath_machine::CostError>()
            || c.is::<towpath_coverage::InstanceError>()
            || c.is::<towpath_coverage::ReadError>()
            || c.is::<towpath_coverage::BuildError>()
            || c.is::<towpath_coverage::GenerateError>()
            || c.is::<towpath_formats::ExportError>()
            || c.is::<towpath_seq::ModelError>()
            || c.is::<towpath_seq::SolveError>()
            || c.is::<towpath_baselines::BaselineError>() =>
        {
            Some(BAD_INPUT)
        }
        // An answer that does not check out.
        c if c.is::<towpath_coverage::RouteError>() || c.is::<towpath_seq::Violation>() => Some(CHECK_FAILED),
        _ => None,
    }
}

/// Prints an error (if any) to stderr and returns the exit code.
pub fn report(result: anyhow::Result<()>) -> i32 {
    let result = result.and_then(|()| match crate::out::failure() {
        Some(e) => Err(bad_input(anyhow::Error::new(e).context("cannot write to standard output"))),
        None => Ok(()),
    });
    match result {
        Ok(()) => OK,
        Err(e) => {
            let code = code(&e);
            let note = if code == INTERNAL { " (this is a bug in towpath; please report it)" } else { "" };
            // A closed stderr must not turn an error into a panic.
            let _ = writeln!(std::io::stderr().lock(), "error: {e:#}{note}");
            code
        }
    }
}
