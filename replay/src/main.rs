//! `uio-replay-plant`: recorded data (a CSV or MCAP log or a run's `.rrd`) as the true plant of a run,
//! written with the component kit like every plant. `[plant.replay]` of a scenario names the
//! file and its column map; the launcher starts this program with them as `params`.
//! `uio-replay-plant --check` reads the same parameters from stdin, reads the whole file and prints
//! what the summary says of it (JSON on stdout), or one line on stderr and exit 2: the
//! launcher's pre-flight, so that bad data is refused before anything runs.

mod check;
mod plant;

fn main() -> std::process::ExitCode {
    if std::env::args().nth(1).as_deref() == Some("--check") {
        return check::main();
    }
    lockstep::component::main::<plant::ReplayPlant>(lockstep::programs::REPLAY_PLANT)
}
