//! `plant`: the plant process of a co-simulation (started by the launcher).

fn main() -> std::process::ExitCode {
    lockstep::component::main::<plant::shell::PlantComponent>("plant")
}
