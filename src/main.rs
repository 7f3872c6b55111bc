//! The `quadrecomb` command line: parses arguments into validated configurations and calls the
//! library. Nothing imports this.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    match cli::run() {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {}", cli::describe(&err));
            ExitCode::from(cli::exit_code(&err))
        }
    }
}
