//! `fmu_plant`: an FMU (FMI 2.0 or 3.0 co-simulation) as the true plant of a run, written with
//! the component kit like every plant. `[plant.fmu]` of a scenario names the FMU and which of
//! its variables carry u, w, y and x; the launcher starts this program with that map as
//! `params`. `fmu_plant --check` reads the map from stdin and checks the FMU against it without
//! loading the FMU's library: the launcher's pre-flight, so that a bad FMU exits 2 before
//! anything runs.

mod archive;
mod check;
mod fmi2;
mod log_capture;
mod params;
mod plant;
mod python;
mod slave;

fn main() -> std::process::ExitCode {
    if std::env::args().nth(1).as_deref() == Some("--check") {
        return check::main();
    }
    let code = lockstep::component::main::<plant::FmuPlant>("fmu_plant");
    if fmi2::fatal() {
        // The run's message is written and the kit has left the run; the FMU's libraries are
        // not to run their exit handlers (see fmi2::fatal).
        use std::io::Write as _;
        let _ = std::io::stderr().flush();
        // SAFETY: ends the process at once; nothing of ours is left to flush.
        unsafe { libc::_exit(lockstep::component::EXIT_FAILED) };
    }
    code
}
