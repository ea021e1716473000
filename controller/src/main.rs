//! `controller`: the state-feedback process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component_main("controller", std::env::args().skip(1), |l| {
        controller::shell::run(l).map_err(|e| (controller::shell::EXIT_FAILED, e.to_string()))
    })
}
