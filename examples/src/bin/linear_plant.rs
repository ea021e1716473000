//! The built-in exact linear plant run as an external process through the kit: built from the
//! protocol's configuration alone (`model`, `signals`, as [`plant::PlantConfig::from_protocol`]
//! reads them), it gives a recording equal to the built-in plant's bit for bit — the proof that
//! the protocol carries everything a plant needs and that a kit component runs like ours.

fn main() -> std::process::ExitCode {
    lockstep::component::main::<plant::shell::PlantComponent>("linear_plant")
}
