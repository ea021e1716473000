//! `plant`: the plant process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component_main("plant", std::env::args().skip(1), |l| plant::shell::run(l).map_err(|e| (e.exit_code(), e.to_string())))
}
