//! The `quadrecomb` command line: parses arguments into validated configurations and calls the
//! library. Nothing imports this.

mod cli;

use std::io::Write as _;
use std::process::ExitCode;

/// Out of memory is an error with a message and exit code 5, not an abort.
#[global_allocator]
static ALLOC: cli::oom::ExitOnOom = cli::oom::ExitOnOom;

fn main() -> ExitCode {
    quiet_mesa_device_select();
    ignore_file_size_signal();
    match cli::run() {
        Ok(code) => match cli::stdout_failure() {
            // What was printed is incomplete: exit 1 (as for any file the system cannot
            // write), unless the command failed otherwise.
            Some(e) if code == ExitCode::SUCCESS => {
                let _ = writeln!(std::io::stderr(), "error: cannot write to stdout: {e}");
                ExitCode::from(1)
            }
            _ => code,
        },
        Err(err) => {
            // A closed stderr must not turn the error into a panic: the exit code says it.
            let _ = writeln!(std::io::stderr(), "error: {}", cli::describe(&err));
            ExitCode::from(cli::exit_code(&err))
        }
    }
}

/// A file-size limit (`ulimit -f`) makes the kernel send SIGXFSZ to a write past it, whose
/// default action kills the process (exit 153) before the write's error is reported, leaving
/// its temporary file behind and the run's figures unprinted. Ignored, such a write fails
/// with EFBIG as on a full disk, and the error path removes the temporary file and reports.
#[cfg(unix)]
#[allow(unsafe_code)]
fn ignore_file_size_signal() {
    // SAFETY: SIG_IGN installs no handler code to run; done before any thread exists.
    unsafe { libc::signal(libc::SIGXFSZ, libc::SIG_IGN) };
}

#[cfg(not(unix))]
fn ignore_file_size_signal() {}

/// Mesa's device-selection layer (an implicit Vulkan layer installed with lavapipe) prints
/// `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` on every instance it
/// joins when that variable is unset (cron, Slurm, containers, CI), on a run that then
/// succeeds. The layer only reorders devices, which `gpu::adapters` ranks itself, so it is
/// disabled in that case through its own switch, `NODEVICE_SELECT=1` (a user's own setting
/// of either variable is left alone). Setting the environment is `unsafe` (no thread may
/// read it meanwhile): done first thing, before any thread exists.
#[allow(unsafe_code)]
fn quiet_mesa_device_select() {
    let runtime_dir_ok =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if !runtime_dir_ok && std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: first thing in main, before any thread exists (nothing reads the
        // environment concurrently).
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
