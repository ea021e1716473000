//! `uio-bridge`: a run across hosts over Zenoh (see the crate's modules). The launcher starts
//! `uio-bridge remote` in place of a component that runs on another host; `launcher agent` is
//! `uio-bridge agent` on that host; the agent starts `uio-bridge worker`s.

mod agent;
mod clock;
mod keys;
mod proxy;
mod pump;
mod session;
mod wire;
mod worker;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "uio-bridge", about = "A run across hosts, over Zenoh")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Take part in runs on this host: listen on one Zenoh endpoint and start components on request.
    Agent {
        /// This host's name, as scenarios' `[hosts]` tables call it.
        #[arg(long)]
        host: String,
        /// The one endpoint to listen on, e.g. tcp/10.0.0.2:7447 (tls/… with Zenoh's TLS settings).
        #[arg(long)]
        listen: String,
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
    },
}

fn main() {
    let cli = Cli::parse();
    let code = match cli.command {
        Cmd::Agent { host, listen } => agent::run(&host, &listen),
        Cmd::Remote { host, connect, builtin } => proxy::run(&host, &connect, &builtin),
        Cmd::Worker { connect } => worker::run(&connect),
    };
    std::process::exit(code);
}
