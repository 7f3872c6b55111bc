//! `quadrecomb completions SHELL`: the shell's completion script, generated from the same
//! clap definition as the parser (so it never lists a flag that does not exist), on stdout.

use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The shell to complete in (bash, zsh, fish; elvish and powershell too).
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

/// Writes the completion script of `cmd` (the whole command line) for `args.shell`.
pub fn run(args: Args, mut cmd: clap::Command) -> anyhow::Result<ExitCode> {
    // Generated into memory first: clap_complete panics when its writer fails (a full disk,
    // `> /dev/full`); the write's error is then reported as any stdout error is.
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, "quadrecomb", &mut script);
    outln!(
        "{}",
        String::from_utf8_lossy(&script).trim_end_matches('\n')
    );
    Ok(ExitCode::SUCCESS)
}
