//! Standard output for every command. A closed pipe (`towpath verify … | head -1`) is not an
//! error: printing stops quietly and the run goes on (its files are still written and its exit
//! code is unchanged). Any other failure to print (a full disk) is remembered and reported when
//! the command ends.

use std::io::Write;
use std::sync::Mutex;

/// How printing has gone so far.
enum State {
    Open,
    /// The reader went away: nothing more is printed.
    Closed,
    /// Printing failed otherwise; reported at the end.
    Failed(std::io::Error),
}

static STATE: Mutex<State> = Mutex::new(State::Open);

/// Prints formatted text on standard output (use [`outln!`](crate::outln!) / [`out!`](crate::out!)).
pub fn print(args: std::fmt::Arguments<'_>) {
    let mut state = STATE.lock().unwrap_or_else(|p| p.into_inner());
    if !matches!(*state, State::Open) {
        return;
    }
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args).and_then(|()| stdout.flush()) {
        *state = if e.kind() == std::io::ErrorKind::BrokenPipe { State::Closed } else { State::Failed(e) };
    }
}

/// The error printing met, other than a closed pipe, if any.
pub fn failure() -> Option<std::io::Error> {
    let mut state = STATE.lock().unwrap_or_else(|p| p.into_inner());
    match std::mem::replace(&mut *state, State::Closed) {
        State::Failed(e) => Some(e),
        _ => None,
    }
}

/// `println!` that survives a closed pipe.
#[macro_export]
macro_rules! outln {
    () => { $crate::out::print(format_args!("\n")) };
    ($($arg:tt)*) => { $crate::out::print(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `print!` that survives a closed pipe.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::out::print(format_args!($($arg)*)) };
}
