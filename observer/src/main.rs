//! `observer`: one observer process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component_main("observer", std::env::args().skip(1), |l| {
        observer::shell::run(l).map_err(|e| (observer::shell::EXIT_FAILED, e.to_string()))
    })
}
