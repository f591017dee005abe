//! Exit codes and error printing at the binary's edge.

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

/// Prints an error (if any) to stderr and returns the exit code.
pub fn report(result: anyhow::Result<()>) -> i32 {
    match result {
        Ok(()) => OK,
        Err(e) => {
            let code = e.downcast_ref::<Coded>().map_or(INTERNAL, |c| c.code);
            eprintln!("error: {e:#}");
            code
        }
    }
}
