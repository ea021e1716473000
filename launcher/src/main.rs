//! `launcher`: run, design and inspect unknown-input-observer co-simulations.
//!
//! `main` → [`try_main`] → one function per command (`commands/`, one file each), with the
//! options typed in [`cli`]. Every command returns its exit code or a [`LaunchError`]; [`fail`]
//! prints that as one line and exits with its code (`launcher::error`, the one list of codes).

use std::process::ExitCode;

use clap::Parser;
use launcher::eprintln;
use launcher::error::LaunchError;

mod cli;
mod commands;

use cli::{Cli, Command};

fn main() -> ExitCode {
    match try_main(Cli::parse()) {
        Ok(code) => code,
        Err(e) => fail(&e),
    }
}

fn try_main(cli: Cli) -> Result<ExitCode, LaunchError> {
    let command = cli
        .command
        .unwrap_or_else(|| Command::Run(commands::run::default_args()));
    if matches!(
        command,
        Command::Run(_) | Command::Sweep(_) | Command::Bench(_) | Command::Agent(_)
    ) {
        // Dead runs of ours in the machine's /dev/shm go first; then this process and all it
        // starts move to a /dev/shm of their own, before any thread or segment exists.
        lockstep::cleanup_dead_runs();
        if let lockstep::private_shm::Shm::Shared(why) = lockstep::private_shm::enter()
            && !why.starts_with(lockstep::private_shm::SHARED_ENV)
        {
            // The kernel refused the namespaces (a container without CAP_SYS_ADMIN, user
            // namespaces switched off): the run goes on, and says what that leaves open.
            eprintln!(
                "warning: shared memory in the machine's /dev/shm ({why}): another local user could open this run's node-counter segment (docs/security.md)"
            );
        }
    }
    use commands as c;
    match command {
        Command::Run(a) => c::run::command(a),
        Command::Replay(a) => c::replay::command(a),
        Command::Sweep(a) => c::sweep::command(a),
        Command::Design(a) => c::design::command(a),
        Command::Bench(a) => c::bench::command(a),
        Command::FloorNode(a) => c::floor_node::command(a),
        Command::Agent(a) => c::agent::command(a),
        Command::List(a) => c::list::command(a),
        Command::Inspect(a) => c::inspect::command(a),
        Command::Compare(a) => c::compare::command(a),
        Command::Plot(a) => c::plot::command(a),
        Command::Export(a) => c::export::command(a),
        Command::ExportFmu(a) => c::export_fmu::command(a),
        Command::Linearize(a) => c::linearize::command(a),
        Command::Component(a) => c::component::command(a),
    }
}

/// The one line of a failure, and its exit code.
fn fail(e: &LaunchError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code() as u8)
}
