//! `controller`: the state-feedback process of a co-simulation (started by the launcher).

fn main() {
    lockstep::die_with_parent();
    let launch = match lockstep::parse_launch("controller", std::env::args().skip(1)) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("{msg}");
            std::process::exit(lockstep::EXIT_USAGE);
        }
    };
    if let Err(e) = controller::shell::run(&launch) {
        eprintln!("controller: {e}");
        std::process::exit(controller::shell::EXIT_FAILED);
    }
}
