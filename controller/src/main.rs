//! `controller`: the state-feedback process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component::main::<controller::shell::ControllerComponent>("controller")
}
