//! `uio-bridge`: a run across hosts over Zenoh (see the crate's modules). The launcher starts
//! `uio-bridge remote` in place of a component that runs on another host; `uio-launcher agent` is
//! `uio-bridge agent` on that host; the agent starts `uio-bridge worker`s.

/// One line on stderr in a single write: the agent and its workers (processes of their own)
/// share one stderr, and `eprintln!` writes a line in pieces that another process's line can
/// split (the two-host test once read "worker for worker for luenberger: …").
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let mut line = format!($($arg)*);
        line.push('\n');
        let _ = std::io::stderr().write_all(line.as_bytes());
    }};
}

mod access;
mod agent;
mod beat;
mod clock;
mod credentials;
mod keys;
mod proxy;
mod pump;
mod seal;
mod sealed;
mod session;
mod wire;
mod worker;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "uio-bridge", about = "A run across hosts, over Zenoh")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Take part in runs on this host: listen on one Zenoh endpoint and start components on
    /// request (`agent init` makes the credentials first).
    #[command(args_conflicts_with_subcommands = true)]
    Agent {
        #[command(subcommand)]
        init: Option<Init>,
        /// This host's name, as scenarios' `[hosts]` tables call it.
        #[arg(long, required = false)]
        host: Option<String>,
        /// The one endpoint to listen on: quic/10.0.0.2:7447 (mutual TLS with the credentials),
        /// or tcp/… with --insecure.
        #[arg(long)]
        listen: Option<String>,
        /// The credentials directory (default: $UIO_CREDENTIALS, else
        /// ~/.config/uio-observers/credentials).
        #[arg(long)]
        credentials: Option<PathBuf>,
        /// Accept a plain tcp/… endpoint: anyone who reaches it can start components here.
        #[arg(long)]
        insecure: bool,
        /// Components this agent runs at once, over all runs.
        #[arg(long, default_value_t = 16)]
        max_workers: usize,
        /// Accept a wildcard listen address (0.0.0.0, ::): the agent is then reachable on
        /// every interface of the host, not only the one the launcher uses.
        #[arg(long)]
        all_interfaces: bool,
    },
    /// Stand in for a component on another host (started by the launcher).
    Remote {
        /// The host's name.
        #[arg(long)]
        host: String,
        /// Its agent's endpoint.
        #[arg(long)]
        connect: String,
        /// Which built-in component to start there.
        #[arg(long)]
        builtin: String,
    },
    /// Run one component for an agent (started by the agent).
    #[command(hide = true)]
    Worker {
        /// The agent's endpoint.
        #[arg(long)]
        connect: String,
        /// The agent's credentials directory (a quic/ endpoint).
        #[arg(long)]
        credentials: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Init {
    /// Make the credentials of runs across hosts: a CA, an agent's and a launcher's certificate.
    Init {
        /// Where (default: $UIO_CREDENTIALS, else ~/.config/uio-observers/credentials).
        #[arg(long)]
        dir: Option<PathBuf>,
        /// Replace existing credentials.
        #[arg(long)]
        force: bool,
    },
}

fn main() {
    // Zenoh's own reports (a refused handshake, a closed link) only when RUST_LOG asks for them.
    zenoh::try_init_log_from_env();
    let cli = Cli::parse();
    let code = match cli.command {
        Cmd::Agent {
            init: Some(Init::Init { dir, force }),
            ..
        } => {
            let dir = dir.unwrap_or_else(credentials::default_dir);
            match credentials::init(&dir, force) {
                Ok(()) => {
                    println!(
                        "credentials in {}: ca.pem, agent.pem/.key (for agents), launcher.pem/.key (for launchers)",
                        dir.display()
                    );
                    println!(
                        "copy ca.pem and the agent's pair to each agent's host, and ca.pem and the launcher's pair to each launcher's host (same directory, or set UIO_CREDENTIALS / --credentials); ca.key stays here"
                    );
                    0
                }
                Err(e) => {
                    say!("agent init: {e}");
                    2
                }
            }
        }
        Cmd::Agent {
            init: None,
            host,
            listen,
            credentials: dir,
            insecure,
            max_workers,
            all_interfaces,
        } => {
            let (Some(host), Some(listen)) = (host, listen) else {
                say!("agent: --host and --listen are required (or `agent init`)");
                std::process::exit(2);
            };
            agent::run(&agent::Options {
                host,
                listen,
                credentials: dir.unwrap_or_else(credentials::default_dir),
                insecure,
                max_workers,
                all_interfaces,
            })
        }
        Cmd::Remote {
            host,
            connect,
            builtin,
        } => proxy::run(&host, &connect, &builtin),
        Cmd::Worker {
            connect,
            credentials,
        } => worker::run(&connect, credentials.as_deref()),
    };
    std::process::exit(code);
}
