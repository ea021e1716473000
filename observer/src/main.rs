//! `observer`: one observer process of a co-simulation (started by the launcher).

fn main() {
    lockstep::die_with_parent();
    let launch = match lockstep::parse_launch("observer", std::env::args().skip(1)) {
        Ok(l) => l,
        Err(msg) => {
            eprintln!("{msg}");
            std::process::exit(lockstep::EXIT_USAGE);
        }
    };
    if let Err(e) = observer::shell::run(&launch) {
        eprintln!("observer {}: {e}", launch.name);
        std::process::exit(observer::shell::EXIT_FAILED);
    }
}
