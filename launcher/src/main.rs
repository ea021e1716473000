//! `launcher`: run, design and inspect unknown-input-observer co-simulations.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use launcher::error::{EXIT_BAD_INPUT, EXIT_EXPECT, LaunchError};
// Printing that neither panics on a closed stdout nor passes control characters through.
use launcher::run::{Mode, Options, Stop};
use launcher::{design_report, plan, run};
use launcher::{eprintln, print, println};
use launcher::{limits, shipped};
use lockstep::Wait;
use scenario::Scenario;

mod export_fmu;
mod linearize;

#[derive(Parser)]
#[command(
    name = "launcher",
    version,
    about = "Design and co-simulate unknown input observers for LTI plants"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario and record it to DIR/<name>.rrd and DIR/<name>.summary.json.
    Run {
        /// The scenario file, or the name of a shipped scenario (see `list`).
        scenario: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "runs")]
        out: PathBuf,
        /// Where the components run.
        #[arg(long, value_parser = ["processes", "in-process"], default_value = "processes")]
        mode: String,
        /// How components wait for samples: yield (default), block, waitset,
        /// spin-then-block[:µs], spin-then-yield:<ns>, sleep:<µs>.
        #[arg(long)]
        wait: Option<Wait>,
        /// Overwrite an existing recording.
        #[arg(long)]
        force: bool,
        /// Run even if the closed loop is unstable (the run stops when a state diverges).
        #[arg(long)]
        allow_unstable: bool,
        /// Place the lockstep ring's processes on CPUs (auto) or leave it to the scheduler (off).
        #[arg(long, value_parser = ["auto", "off"], default_value = "auto")]
        pin: String,
        /// Record only every N-th step (steps 0, N, 2N, …); the summary still sees every step.
        #[arg(long, value_name = "N", default_value_t = 1)]
        record_every: u64,
        /// Record only the entities matching this glob, e.g. '/observer/uio/**' (`*` within a
        /// path segment, `**` across segments); repeat for several.
        #[arg(long = "record", value_name = "GLOB")]
        record: Vec<String>,
        /// Write the recording with Rerun's LZ4 chunk compression: about 0.64 × the bytes, for
        /// the recorder's CPU time.
        #[arg(long)]
        compress: bool,
        /// The noise generator's seed (default: the scenario's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Pace the run in real time: step k starts at k·dt/X of wall time (waits sleep: the
        /// default wait becomes `block`); steps that end late are counted and recorded.
        #[arg(long)]
        realtime: bool,
        /// X for --realtime: 2 runs twice as fast as real time, 0.5 half as fast.
        #[arg(long, value_name = "X", requires = "realtime")]
        speed: Option<f64>,
        /// How long a component that runs, or waits for a core, may publish nothing before the
        /// run is stopped (default: the scenario's stall_timeout, else 60 s). A stopped or
        /// blocked component is named after 5 s whatever this is.
        #[arg(long, value_name = "S")]
        stall_timeout: Option<f64>,
    },
    /// Run observers on a run's recorded plant samples: its own scenario's (or --scenario's,
    /// same plant sizes), plant replayed from the recording, controller removed (open loop).
    Replay {
        /// The run's recording.
        recording: PathBuf,
        /// Another scenario whose observers and banks to run (default: the recorded one).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Output directory (default: `replay/` beside the recording).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Overwrite an existing replay recording.
        #[arg(long)]
        force: bool,
    },
    /// Monte Carlo: run N noise realisations (seeds S, S+1, …) and write DIR/<name>.sweep.json
    /// with detection delays, isolation accuracy, false-alarm rates and tail errors.
    Sweep {
        /// The scenario file, or the name of a shipped scenario (see `list`).
        scenario: PathBuf,
        /// Realisations.
        #[arg(long, default_value_t = 100)]
        runs: usize,
        /// Worker threads (default: every core; processes mode runs one at a time).
        #[arg(long)]
        jobs: Option<usize>,
        /// The first seed (default: the scenario's `seed`).
        #[arg(long)]
        seed: Option<u64>,
        /// Where the realisations run.
        #[arg(long, value_parser = ["processes", "in-process"], default_value = "in-process")]
        mode: String,
        /// Output directory.
        #[arg(long, default_value = "runs")]
        out: PathBuf,
        /// Run the K worst realisations again with a recording (DIR/<name>-seed<S>.rrd).
        #[arg(long, value_name = "K", default_value_t = 0)]
        keep_worst: usize,
    },
    /// Check the existence conditions and show the designs of a scenario.
    Design {
        /// The scenario file, or the name of a shipped scenario (see `list`).
        scenario: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Benchmark the seed-002 closed loop in one process and across processes.
    Bench {
        /// Steps per run.
        #[arg(long, default_value_t = 100_000)]
        steps: u64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// How components wait for samples: yield (default), block, waitset,
        /// spin-then-block[:µs], spin-then-yield:<ns>, sleep:<µs>.
        #[arg(long)]
        wait: Option<Wait>,
        /// Only this mode (default: both).
        #[arg(long, value_parser = ["processes", "in-process"])]
        mode: Option<String>,
        /// Only runs with (on) or without (off) recording (default: both).
        #[arg(long, value_parser = ["on", "off"])]
        recording: Option<String>,
        /// Place the lockstep ring's processes on CPUs (auto) or not (off).
        #[arg(long, value_parser = ["auto", "off"], default_value = "auto")]
        pin: String,
        /// Repetitions (each: the floor, then every configuration); ratios are given as medians.
        #[arg(long, default_value_t = 1)]
        repeat: usize,
        /// Instead: how a step's cost grows with the model, for random stable plants of these
        /// sizes with a UIO and a Luenberger observer in closed loop (e.g. 3,10,30).
        #[arg(long, value_name = "N[,N…]", value_delimiter = ',')]
        states: Vec<usize>,
    },
    /// One node of the benchmark's floor ring (started by `launcher bench`).
    #[command(hide = true)]
    FloorNode {
        run: String,
        index: usize,
        steps: u64,
        len_plant: usize,
        len_observer: usize,
        len_controller: usize,
        wait: Wait,
    },
    /// Take part in runs from another host: start the components a launcher places on this
    /// host (`host = NAME` and `[hosts]` in its scenario). Runs `uio-bridge agent` with these
    /// arguments: `agent init` makes the credentials, `agent --host NAME --listen quic/ADDR:PORT`
    /// serves (`launcher agent --help` for all).
    #[command(disable_help_flag = true)]
    Agent {
        /// Passed to `uio-bridge agent`.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// List the shipped scenarios.
    List {
        /// Directory of scenarios.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Show what a recording holds, and recompute its figures from the recorded data.
    Inspect {
        /// The recording.
        recording: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Compare two recordings signal by signal, step by step (bit for bit without tolerances).
    Compare {
        /// First recording.
        a: PathBuf,
        /// Second recording.
        b: PathBuf,
        /// Absolute tolerance.
        #[arg(long)]
        abs_tol: Option<f64>,
        /// Relative tolerance (of the first recording's value).
        #[arg(long)]
        rel_tol: Option<f64>,
    },
    /// Draw a recording's views as PNG files.
    Plot {
        /// The recording.
        recording: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Only entities matching this glob, e.g. '/observer/uio/**' (`*` within a path
        /// segment, `**` across segments); repeat for several.
        #[arg(long = "signals", value_name = "GLOB")]
        signals: Vec<String>,
        /// Start of the time window, s (steps for a recording without its scenario).
        #[arg(long, value_name = "T", allow_negative_numbers = true)]
        from: Option<f64>,
        /// End of the time window, s.
        #[arg(long, value_name = "T", allow_negative_numbers = true)]
        to: Option<f64>,
        /// A run at an operating point in deviations from it (x − x_op, u − u_op, …) instead of
        /// the plant's own units.
        #[arg(long)]
        deviations: bool,
    },
    /// Export a recording's signals for other tools: CSV, MCAP, NumPy .npz, MATLAB .mat (one or more).
    #[command(group(clap::ArgGroup::new("format").required(true).multiple(true).args(["csv", "mcap", "npz", "mat"])))]
    Export {
        /// The recording.
        recording: PathBuf,
        /// Output directory: one CSV per entity group.
        #[arg(long, value_name = "DIR")]
        csv: Option<PathBuf>,
        /// MCAP file (Foxglove, PlotJuggler): one JSON channel per entity group.
        #[arg(long, value_name = "FILE")]
        mcap: Option<PathBuf>,
        /// NumPy .npz file: `t`, `step` and one steps × members array per entity group.
        #[arg(long, value_name = "FILE")]
        npz: Option<PathBuf>,
        /// MATLAB level-5 .mat file: the arrays of --npz.
        #[arg(long, value_name = "FILE")]
        mat: Option<PathBuf>,
        /// A run at an operating point in deviations from it (x − x_op, u − u_op, …) instead of
        /// the plant's own units.
        #[arg(long)]
        deviations: bool,
        /// Replace export files that already exist (without it they are refused, exit 2).
        #[arg(long)]
        force: bool,
    },
    /// Write one of a scenario's observers as an FMI co-simulation FMU, DIR/<observer>_fmi<2|3>.fmu.
    ExportFmu {
        /// The scenario file, or the name of a shipped scenario (see `list`).
        scenario: PathBuf,
        /// The observer's name.
        #[arg(long)]
        observer: String,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// FMI version.
        #[arg(long, value_parser = ["2", "3"], default_value = "3")]
        fmi: String,
    },
    /// The sampled model (Φ, Γ_B, Γ_E, C) of a scenario's FMU plant at its operating point, made
    /// from the FMU: DIR/{Phi,Gamma_B,Gamma_E,C}.npy and DIR/<name>.toml, a scenario that runs.
    Linearize {
        /// The scenario file: dt, [plant.fmu] and [plant.operating_point] are read.
        scenario: PathBuf,
        /// First find the equilibrium x_op for the operating point's u and w (Newton's method;
        /// the given x is the first guess).
        #[arg(long)]
        trim: bool,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Run one component (used by the launcher when the component binaries are not beside it).
    #[command(hide = true, disable_help_flag = true)]
    Component {
        /// plant, observer or controller.
        kind: String,
        /// The component's own arguments.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

fn fail(e: &LaunchError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code() as u8)
}

/// Loads the scenario a command-line argument names (a path, or a shipped scenario's name).
/// A scenario loaded, with `seed` in place of its own, designed, and its calibrated thresholds set.
fn prepared(arg: &Path, seed: Option<u64>) -> Result<(Scenario, plan::Plan), LaunchError> {
    let mut s = shipped::load(arg)?;
    if let Some(seed) = seed {
        s.seed = seed;
    }
    let p = launcher::calibrate::planned(&s)?;
    Ok((s, p))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or_else(|| Command::Run {
        scenario: shipped::dir().join("seed002-sine.toml"),
        out: "runs".into(),
        mode: "processes".into(),
        wait: None,
        force: true,
        allow_unstable: false,
        pin: "auto".into(),
        record_every: 1,
        record: Vec::new(),
        compress: false,
        seed: None,
        realtime: false,
        speed: None,
        stall_timeout: None,
    });
    if matches!(
        command,
        Command::Run { .. } | Command::Sweep { .. } | Command::Bench { .. } | Command::Agent { .. }
    ) {
        // Dead runs of ours in the machine's /dev/shm go first; then this process and all it
        // starts move to a /dev/shm of their own, before any thread or segment exists (issue 32).
        lockstep::cleanup_dead_runs();
        let _ = lockstep::private_shm::enter();
    }
    match command {
        Command::Run {
            scenario,
            out,
            mode,
            wait,
            force,
            allow_unstable,
            pin,
            record_every,
            record,
            compress,
            seed,
            realtime,
            speed,
            stall_timeout,
        } => {
            let speed = speed.unwrap_or(1.0);
            if let Err(e) = limits::speed(speed) {
                return fail(&e);
            }
            let realtime = realtime.then_some(speed);
            // A paced run sleeps while it waits, unless told otherwise.
            let wait = wait.or(realtime.map(|_| Wait::Block));
            let select = match recording::write::Selection::new(record_every, &record) {
                Ok(x) => x.compressed(compress),
                Err(e) => return fail(&LaunchError::BadInput(e)),
            };
            let (mut s, p) = match prepared(&scenario, seed) {
                Ok(x) => x,
                Err(e) => return fail(&e),
            };
            if let Some(t) = stall_timeout {
                match scenario::limits::stall_timeout(t) {
                    Ok(t) => s.stall_timeout = t,
                    Err(e) => return fail(&LaunchError::BadInput(format!("--stall-timeout: {e}"))),
                }
            }
            if let Some(x) = realtime
                && let Err(e) = limits::schedule(x, s.dt, s.steps)
            {
                return fail(&e);
            }
            for w in &p.warnings {
                eprintln!("warning: {w}");
            }
            let mode = if mode == "in-process" {
                Mode::InProcess
            } else {
                Mode::Processes
            };
            if mode == Mode::InProcess && !s.remote.is_empty() {
                eprintln!(
                    "note: --mode in-process runs every component here; the scenario's [hosts] placements apply across processes"
                );
            }
            let opts = Options {
                out,
                mode,
                wait: wait.unwrap_or_else(Wait::default_for_machine),
                force,
                allow_unstable,
                record: true,
                pin: pin == "auto",
                select,
                progress: true,
                realtime,
            };
            match run::run(&s, &p, &opts) {
                Ok(o) => {
                    print!("{}", o.summary.table());
                    if let Some(rrd) = &o.rrd {
                        println!(
                            "recording: {}   (view it with: rerun {})",
                            rrd.display(),
                            rrd.display()
                        );
                    }
                    match o.stop {
                        Stop::Completed if o.summary.expectations_met() => ExitCode::SUCCESS,
                        Stop::Completed => {
                            eprintln!(
                                "error: {}: the run missed its [expect] table",
                                s.path.display()
                            );
                            ExitCode::from(EXIT_EXPECT as u8)
                        }
                        Stop::Diverged(w) => fail(&LaunchError::Diverged(format!(
                            "{}: run stopped: {w}",
                            s.name
                        ))),
                        Stop::Interrupted(sig) => fail(&LaunchError::Interrupted(format!(
                            "{}: run interrupted by {sig}; recording closed",
                            s.name
                        ))),
                        Stop::Failed(w) => {
                            fail(&LaunchError::Component(format!("{}: {w}", s.name)))
                        }
                    }
                }
                Err(e) => fail(&e),
            }
        }
        Command::Replay {
            recording,
            scenario,
            out,
            force,
        } => {
            let out =
                out.unwrap_or_else(|| recording.parent().unwrap_or(Path::new(".")).join("replay"));
            let prepared =
                launcher::replay::scenario(&recording, scenario.as_deref()).and_then(|s| {
                    launcher::replay::refuse_overwrite(&recording, &out, &s.name)?;
                    let p = launcher::calibrate::planned(&s)?;
                    Ok((s, p))
                });
            let (s, p) = match prepared {
                Ok(x) => x,
                Err(e) => return fail(&e),
            };
            let opts = Options {
                force,
                progress: true,
                pin: true,
                ..Options::quiet(&out, Mode::Processes, Wait::default_for_machine(), true)
            };
            match run::run(&s, &p, &opts) {
                Ok(o) => {
                    print!("{}", o.summary.table());
                    if let Some(rrd) = &o.rrd {
                        println!("recording: {}", rrd.display());
                    }
                    match o.stop {
                        Stop::Completed if o.summary.expectations_met() => ExitCode::SUCCESS,
                        Stop::Completed => fail(&LaunchError::Expect(format!(
                            "{}: the replay missed its [expect] table",
                            s.path.display()
                        ))),
                        Stop::Diverged(w) => fail(&LaunchError::Diverged(format!(
                            "{}: replay stopped: {w}",
                            s.name
                        ))),
                        Stop::Interrupted(sig) => fail(&LaunchError::Interrupted(format!(
                            "{}: replay interrupted by {sig}; recording closed",
                            s.name
                        ))),
                        Stop::Failed(w) => {
                            fail(&LaunchError::Component(format!("{}: {w}", s.name)))
                        }
                    }
                }
                Err(e) => fail(&e),
            }
        }
        Command::Sweep {
            scenario,
            runs,
            jobs,
            seed,
            mode,
            out,
            keep_worst,
        } => {
            let jobs = jobs.unwrap_or_else(|| {
                std::thread::available_parallelism()
                    .map_or(1, |n| n.get())
                    .min(limits::MAX_JOBS)
            });
            if let Err(e) = limits::sweep_runs(runs).and_then(|_| limits::jobs(jobs)) {
                return fail(&e);
            }
            // One calibration for every realisation, from the first seed.
            let (s, p) = match prepared(&scenario, seed) {
                Ok(x) => x,
                Err(e) => return fail(&e),
            };
            let mode = if mode == "processes" {
                Mode::Processes
            } else {
                Mode::InProcess
            };
            let opts = launcher::sweep::SweepOptions {
                runs,
                jobs,
                seed: s.seed,
                mode,
                out: out.clone(),
                keep_worst,
                wait: Wait::default_for_machine(),
            };
            run::interrupt::install();
            match launcher::sweep::sweep(&s, &p, &opts) {
                Ok(sw) => {
                    print!("{}", sw.table());
                    match sw.write(&out) {
                        Ok(path) => {
                            println!("sweep summary: {}", path.display());
                            sw.verdict().map_or(ExitCode::SUCCESS, |e| fail(&e))
                        }
                        Err(e) => fail(&LaunchError::Component(e)),
                    }
                }
                Err(e) => fail(&e),
            }
        }
        Command::Design { scenario, json } => {
            let s = match shipped::load(&scenario) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let r = design_report::report(&s);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&r.json).expect("serialises")
                );
            } else {
                print!("{}", r.text);
            }
            if r.ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(EXIT_BAD_INPUT as u8)
            }
        }
        Command::FloorNode {
            run,
            index,
            steps,
            len_plant,
            len_observer,
            len_controller,
            wait,
        } => {
            match launcher::bench::floor::node(
                &run,
                index.min(2),
                steps,
                [len_plant, len_observer, len_controller],
                wait,
            ) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => fail(&LaunchError::Component(format!("floor node {index}: {e}"))),
            }
        }
        Command::Bench {
            steps,
            json,
            wait,
            mode,
            recording,
            pin,
            repeat,
            states,
        } => {
            if let Err(e) = limits::bench(steps, repeat).and_then(|_| limits::states(&states)) {
                return fail(&e);
            }
            let wait = wait.unwrap_or_else(Wait::default_for_machine);
            let modes: Vec<Mode> = match mode.as_deref() {
                Some("processes") => vec![Mode::Processes],
                Some(_) => vec![Mode::InProcess],
                None => vec![Mode::InProcess, Mode::Processes],
            };
            let rec: Vec<bool> = match recording.as_deref() {
                Some("on") => vec![true],
                Some(_) => vec![false],
                None => vec![false, true],
            };
            if !states.is_empty() {
                return match launcher::bench::states::states(
                    &states,
                    steps,
                    wait,
                    pin == "auto",
                    &modes,
                    &rec,
                ) {
                    Ok(runs) => {
                        if json {
                            println!(
                                "{}",
                                serde_json::to_string_pretty(
                                    &serde_json::json!({ "states": runs })
                                )
                                .expect("serialises")
                            );
                        } else {
                            print!("{}", launcher::bench::states::table(&runs));
                        }
                        ExitCode::SUCCESS
                    }
                    Err(e) => fail(&e),
                };
            }
            match launcher::bench::bench(
                &shipped::dir().join("seed002-sine.toml"),
                steps,
                wait,
                pin == "auto",
                &modes,
                &rec,
                repeat,
            ) {
                Ok(runs) => {
                    if json {
                        println!("{}", serde_json::to_string_pretty(&serde_json::json!({ "runs": runs, "ratios": launcher::bench::ratios(&runs).into_iter().map(|(n, v)| (n, serde_json::json!({"min": v.0, "median": v.1, "max": v.2, "repetitions": v.3}))).collect::<serde_json::Map<_, _>>() })).expect("serialises"));
                    } else {
                        print!("{}", launcher::bench::table(&runs, wait));
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::Agent { args } => {
            use std::os::unix::process::CommandExt;
            let bridge = launcher::run::bridge_path();
            let e = std::process::Command::new(&bridge)
                .arg("agent")
                .args(&args)
                .exec();
            eprintln!(
                "error: cannot run {}: {e} (build it with `cargo build --release --workspace`)",
                bridge.display()
            );
            ExitCode::from(3)
        }
        Command::List { dir } => match shipped::list(&dir.unwrap_or_else(shipped::dir)) {
            Ok(entries) => {
                for e in &entries {
                    println!("{}", e.line());
                }
                ExitCode::SUCCESS
            }
            Err(e) => fail(&e),
        },
        Command::Inspect { recording, json } => match read_recording(&recording) {
            Ok(r) => {
                let i = recording::inspect::inspect(&recording.display().to_string(), &r);
                if json {
                    println!("{}", serde_json::to_string_pretty(&i).expect("serialises"));
                } else {
                    print!("{}", i.text());
                }
                for w in &i.warnings {
                    eprintln!("warning: {w}");
                }
                ExitCode::SUCCESS
            }
            Err(code) => code,
        },
        Command::Compare {
            a,
            b,
            abs_tol,
            rel_tol,
        } => {
            let (ra, rb) = match (read_recording(&a), read_recording(&b)) {
                (Ok(ra), Ok(rb)) => (ra, rb),
                (Err(code), _) | (_, Err(code)) => return code,
            };
            for (p, r) in [(&a, &ra), (&b, &rb)] {
                if !r.complete {
                    eprintln!("warning: {}: incomplete recording", p.display());
                }
            }
            match recording::compare::compare(&ra, &rb, abs_tol, rel_tol) {
                Ok(n) => {
                    println!(
                        "same: {n} values of {} signals{}",
                        ra.series
                            .keys()
                            .filter(|k| !k.starts_with("/latency"))
                            .count(),
                        if abs_tol.is_none() && rel_tol.is_none() {
                            ", bit for bit"
                        } else {
                            ", within tolerance"
                        }
                    );
                    ExitCode::SUCCESS
                }
                Err(d) => {
                    println!("differ: {d}");
                    ExitCode::from(1)
                }
            }
        }
        Command::Plot {
            recording,
            out,
            signals,
            from,
            to,
            deviations,
        } => {
            let selection = recording::plot::PlotSelection { signals, from, to };
            if let Err(e) = selection.validate() {
                return fail(&LaunchError::BadInput(e));
            }
            let r =
                match read_recording(&recording).and_then(|r| shifted(&recording, r, deviations)) {
                    Ok(r) => r,
                    Err(code) => return code,
                };
            if !r.complete {
                eprintln!(
                    "warning: {}: incomplete recording (its writer did not finish); plotting what it holds",
                    recording.display()
                );
            }
            match recording::plot::plot(&r, &out, &selection) {
                Ok(files) => {
                    for f in &files {
                        println!("{}", f.display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&LaunchError::BadInput(format!(
                    "{}: {e}",
                    recording.display()
                ))),
            }
        }
        Command::Export {
            recording,
            csv,
            mcap,
            npz,
            mat,
            deviations,
            force,
        } => {
            // An export written over its own recording would replace the data it was made from.
            if let Some(p) = [&mcap, &npz, &mat]
                .into_iter()
                .flatten()
                .find(|p| same_file(p, &recording))
            {
                return fail(&LaunchError::BadInput(format!(
                    "{}: is the recording being exported ({}); refusing to write over it",
                    p.display(),
                    recording.display()
                )));
            }
            let r =
                match read_recording(&recording).and_then(|r| shifted(&recording, r, deviations)) {
                    Ok(r) => r,
                    Err(code) => return code,
                };
            // Existing files are replaced only when asked, as `run` replaces its outputs.
            let csv_files = csv.iter().flat_map(|d| {
                recording::export::csv::planned(&r)
                    .into_iter()
                    .map(move |f| d.join(f))
            });
            if !force
                && let Some(p) = [&mcap, &npz, &mat]
                    .into_iter()
                    .flatten()
                    .cloned()
                    .chain(csv_files)
                    .find(|p| p.symlink_metadata().is_ok())
            {
                return fail(&LaunchError::BadInput(format!(
                    "{}: already exists (pass --force to overwrite)",
                    p.display()
                )));
            }
            let dt = recording::tools::recorded_dt(&r);
            if !r.complete {
                eprintln!(
                    "warning: {}: incomplete recording (its writer did not finish); exporting what it holds",
                    recording.display()
                );
            }
            use recording::export as ex;
            let done = (|| -> Result<(), String> {
                if let Some(d) = &csv {
                    println!("{} files in {}", ex::export(&r, d, dt)?.len(), d.display());
                }
                if let Some(p) = &mcap {
                    println!("{}: {} channels", p.display(), ex::mcap::export(&r, p, dt)?);
                }
                if let Some(p) = &npz {
                    println!("{}: {} arrays", p.display(), ex::npz::export(&r, p, dt)?);
                }
                if let Some(p) = &mat {
                    println!("{}: {} variables", p.display(), ex::mat::export(&r, p, dt)?);
                }
                Ok(())
            })();
            match done {
                Ok(_) => ExitCode::SUCCESS,
                Err(e) => fail(&LaunchError::BadInput(e)),
            }
        }
        Command::ExportFmu {
            scenario,
            observer,
            out,
            fmi,
        } => {
            let fmi = if fmi == "2" {
                fmu_export::Fmi::V2
            } else {
                fmu_export::Fmi::V3
            };
            match shipped::load(&scenario)
                .and_then(|s| export_fmu::export_fmu(&s, &observer, &out, fmi))
            {
                Ok(path) => {
                    println!("{}", path.display());
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::Linearize {
            scenario,
            trim,
            out,
        } => match linearize::linearize(&scenario, trim, &out) {
            Ok(path) => {
                println!("wrote {}", path.display());
                ExitCode::SUCCESS
            }
            Err(e) => fail(&e),
        },
        Command::Component { kind, args } => component(&kind, args),
    }
}

/// Reads a recording, or reports why not: exit code 2 when it cannot be read at all, 6 when
/// it does not match the digest written with it (nothing is then written from it).
fn read_recording(path: &Path) -> Result<recording::Recording, ExitCode> {
    let r = recording::read(path).map_err(|e| fail(&LaunchError::BadInput(e.to_string())))?;
    if let recording::Integrity::Damaged(what) = &r.integrity {
        let why = if what.starts_with('/') || what == recording::digest::SCENARIO_KEY {
            format!(
                "{}: its data does not match the digest written with the recording",
                scenario::quoted(what)
            )
        } else {
            what.clone()
        };
        return Err(fail(&LaunchError::Damaged(format!(
            "{}: damaged: {why}",
            path.display()
        ))));
    }
    Ok(r)
}

/// Whether `a` and `b` name one existing file (the same device and inode: links and `..` alike).
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

/// `r` in deviations from its operating point when asked (`--deviations`), else as recorded.
fn shifted(
    path: &Path,
    r: recording::Recording,
    deviations: bool,
) -> Result<recording::Recording, ExitCode> {
    if !deviations {
        return Ok(r);
    }
    recording::deviations::in_deviations(&r).map_err(|e| {
        fail(&LaunchError::BadInput(format!(
            "{}: --deviations: {e}",
            path.display()
        )))
    })
}

/// Runs a component's shell in this process (the fallback when its binary is not installed).
fn component(kind: &str, args: Vec<String>) -> ExitCode {
    if let Ok(name) = std::ffi::CString::new(kind) {
        // SAFETY: PR_SET_NAME copies at most 16 bytes from a valid C string.
        unsafe { libc::prctl(libc::PR_SET_NAME, name.as_ptr()) };
    }
    use lockstep::component::main_with_args;
    match kind {
        "plant" => main_with_args::<plant::shell::PlantComponent>(kind, args),
        "observer" => main_with_args::<observer::shell::ObserverComponent>(kind, args),
        "controller" => main_with_args::<controller::shell::ControllerComponent>(kind, args),
        other => {
            eprintln!("unknown component {}", scenario::untrusted::quoted(other));
            ExitCode::from(lockstep::EXIT_USAGE as u8)
        }
    }
}
