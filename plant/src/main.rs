//! `plant`: the plant process of a co-simulation (started by the launcher).

fn main() {
    lockstep::die_with_parent();
    let launch = match lockstep::parse_launch("plant", std::env::args().skip(1)) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("{msg}");
            std::process::exit(lockstep::EXIT_USAGE);
        }
    };
    if let Err(e) = plant::shell::run(&launch) {
        eprintln!("plant: {e}");
        std::process::exit(e.exit_code());
    }
}
