//! `observer`: one observer process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component::main::<observer::shell::ObserverComponent>("observer")
}
