//! Writing to standard output and standard error without panicking.
//!
//! `print!` panics when the reader of a pipe has gone (`tadslc check DIR | head`). Every
//! subcommand writes through [`out`] and [`err`] instead (the [`outln!`](crate::outln)
//! family of macros). A closed pipe is not a failure of the run: from then on that stream
//! is quiet (nothing more is written to it) and the run goes on to the status it reaches,
//! its files written. Any other write error (a full disk) is reported on standard error,
//! if it can be, and returns [`Closed`], which stops the subcommand with status 2
//! (`spec/output.md`).
//!
//! Subcommands return `Result<Status, CliError>` ([`finish`] reports the error); those not
//! yet converted raise a `&mut Status` inside [`run`] (tidy lists them, a list that shrinks).

use crate::Status;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// A standard stream could not be written for another reason than a closed pipe (a full
/// disk): stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Closed {
    /// What the failure adds to the run's status: [`Status::Usage`].
    pub status: Status,
}

impl Closed {
    /// `status`, the status the run had reached, with this failure's.
    pub fn merge(self, status: Status) -> Status {
        status.max(self.status)
    }
}

/// Whether the reader of standard output, or of standard error, has gone.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
static STDERR_GONE: AtomicBool = AtomicBool::new(false);

/// The outcome of a write to `stream`: a closed pipe quiets the stream (`Ok`), any other
/// error is reported and stops the run.
fn written(stream: &str, gone: &AtomicBool, result: std::io::Result<()>) -> Result<(), Closed> {
    match result {
        Ok(()) => Ok(()),
        Err(error) if error.kind() == std::io::ErrorKind::BrokenPipe => {
            gone.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(error) => {
            // best effort: standard error may be the stream that failed
            if !STDERR_GONE.load(Ordering::Relaxed) {
                let _ = writeln!(std::io::stderr().lock(), "error: cannot write to {stream}: {error}");
            }
            Err(Closed { status: Status::Usage })
        }
    }
}

/// Write to standard output.
pub fn out(args: std::fmt::Arguments<'_>) -> Result<(), Closed> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    written("standard output", &STDOUT_GONE, std::io::stdout().lock().write_fmt(args))
}

/// Write raw bytes to standard output, then flush it.
pub fn out_bytes(bytes: &[u8]) -> Result<(), Closed> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut stdout = std::io::stdout().lock();
    written("standard output", &STDOUT_GONE, stdout.write_all(bytes).and_then(|()| stdout.flush()))
}

/// Flush standard output (what a `print!` without a newline left in its buffer).
pub fn flush() -> Result<(), Closed> {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    written("standard output", &STDOUT_GONE, std::io::stdout().lock().flush())
}

/// Write to standard error.
pub fn err(args: std::fmt::Arguments<'_>) -> Result<(), Closed> {
    if STDERR_GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    written("standard error", &STDERR_GONE, std::io::stderr().lock().write_fmt(args))
}

/// `print!` that returns [`Closed`] instead of panicking.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::output::out(format_args!($($arg)*)) };
}

/// `println!` that returns [`Closed`] instead of panicking.
#[macro_export]
macro_rules! outln {
    () => { $crate::output::out(format_args!("\n")) };
    ($($arg:tt)*) => { $crate::output::out(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `eprint!` that returns [`Closed`] instead of panicking.
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => { $crate::output::err(format_args!($($arg)*)) };
}

/// `eprintln!` that returns [`Closed`] instead of panicking.
#[macro_export]
macro_rules! errln {
    () => { $crate::output::err(format_args!("\n")) };
    ($($arg:tt)*) => { $crate::output::err(format_args!("{}\n", format_args!($($arg)*))) };
}

/// Run `body` with a status it raises as it goes; if it stops because a stream was
/// closed, the status reached so far is returned, merged with the failure's.
pub fn run(body: impl FnOnce(&mut Status) -> Result<(), Closed>) -> Status {
    let mut status = Status::Ok;
    match body(&mut status).and_then(|()| flush()) {
        Ok(()) => status,
        Err(closed) => closed.merge(status),
    }
}

/// Ctrl-C as a request to stop, for a command whose finished work is worth keeping: the
/// first sets the flag returned (nothing new is started, what is under way finishes, and
/// the command keeps what finished) and says so on standard error; a second exits at once
/// with status 130.
pub fn on_interrupt(under_way: &'static str) -> std::sync::Arc<AtomicBool> {
    let stop = std::sync::Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let watch = async move {
        if tokio::signal::ctrl_c().await.is_ok() {
            flag.store(true, Ordering::SeqCst);
            let _ = crate::errln!("\ninterrupted: finishing the {under_way} under way (Ctrl-C again to abort)");
            if tokio::signal::ctrl_c().await.is_ok() {
                std::process::exit(130);
            }
        }
    };
    // a thread of its own, so that any command can be interrupted, async or not
    // without the thread (none could be made), Ctrl-C stops the command as it always did
    let _ = std::thread::Builder::new().name("ctrl-c".into()).spawn(move || {
        if let Ok(runtime) = tokio::runtime::Builder::new_current_thread().enable_all().build() {
            runtime.block_on(watch);
        }
    });
    stop
}

/// The progress bar of every long command, on standard error, shown at a terminal only:
/// `total` units named `unit` (`episodes`, `steps`); a message follows the count.
pub fn progress(total: usize, unit: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(total as u64);
    let template = format!("{{bar:30}} {{pos}}/{{len}} {unit} {{msg}} [{{elapsed}}, eta {{eta}}]");
    bar.set_style(
        indicatif::ProgressStyle::with_template(&template).unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Why a subcommand stopped: a message for standard error and the exit status it ends with.
/// A subcommand returns `Result<Status, CliError>`: the status of what it did (1 when some
/// inputs had errors), or the failure that ended it; [`finish`] reports it.
#[derive(Debug)]
pub enum CliError {
    /// The run ends with this status, saying why.
    Exit(Status, String),
    /// A standard stream could not be written (already reported where it could be).
    Closed(Closed),
}

impl CliError {
    /// Usage or I/O (status 2).
    pub fn usage(message: impl std::fmt::Display) -> CliError {
        CliError::Exit(Status::Usage, message.to_string())
    }

    /// The input has errors, or the work failed (status 1).
    pub fn failed(message: impl std::fmt::Display) -> CliError {
        CliError::Exit(Status::Failed, message.to_string())
    }
}

impl From<Closed> for CliError {
    fn from(closed: Closed) -> CliError {
        CliError::Closed(closed)
    }
}

/// The exit status of a subcommand's result, its error reported on standard error.
pub fn finish(result: Result<Status, CliError>) -> Status {
    let (status, message) = match result {
        Ok(status) => return flush().map_or_else(|closed| closed.merge(status), |()| status),
        Err(CliError::Exit(status, message)) => (status, message),
        Err(CliError::Closed(closed)) => return closed.merge(Status::Ok),
    };
    match err(format_args!("error: {message}\n")) {
        Ok(()) => status,
        Err(closed) => closed.merge(status),
    }
}
