//! The `quadrecomb` command line: parses arguments into validated configurations and calls the
//! library. Nothing imports this.

mod cli;

use std::process::ExitCode;

/// Out of memory is an error with a message and exit code 2, not an abort.
#[global_allocator]
static ALLOC: cli::oom::ExitOnOom = cli::oom::ExitOnOom;

fn main() -> ExitCode {
    match cli::run() {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {}", cli::describe(&err));
            ExitCode::from(cli::exit_code(&err))
        }
    }
}
