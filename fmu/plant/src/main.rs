//! `uio-fmu-plant`: an FMU (FMI 2.0 or 3.0 co-simulation) as the true plant of a run, written with
//! the component kit like every plant. `[plant.fmu]` of a scenario names the FMU and which of
//! its variables carry u, w, y and x; the launcher starts this program with that map as
//! `params`. `uio-fmu-plant --check` reads the map from stdin and checks the FMU against it without
//! loading the FMU's library: the launcher's pre-flight, so that a bad FMU exits 2 before
//! anything runs. `uio-fmu-plant --linearize` makes the sampled model at an operating point from
//! the FMU (`uio-launcher linearize`, module `linearize`).

mod archive;
mod check;
mod exit;
mod fmi2;
mod library;
mod linearize;
mod log_capture;
mod params;
mod plant;
mod python;
mod request;
mod slave;
mod version;

use exit::end;

fn main() -> std::process::ExitCode {
    match std::env::args().nth(1).as_deref() {
        Some("--check") => return check::main(),
        Some("--linearize") => return linearize::main(),
        _ => {}
    }
    let code = lockstep::component::exit_status::<plant::FmuPlant>(
        lockstep::programs::FMU_PLANT,
        std::env::args().skip(1),
    );
    end(code)
}
