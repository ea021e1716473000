//! `launcher`: run, design and inspect unknown-input-observer co-simulations.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use launcher::error::{LaunchError, EXIT_BAD_INPUT, EXIT_EXPECT};
use launcher::run::{Mode, Options, Stop};
use launcher::{design_report, plan, run, Scenario};
use lockstep::Wait;

#[derive(Parser)]
#[command(name = "launcher", version, about = "Design and co-simulate unknown input observers for LTI plants")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scenario and record it to DIR/<name>.rrd and DIR/<name>.summary.json.
    Run {
        /// The scenario file.
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
    },
    /// Check the existence conditions and show the designs of a scenario.
    Design {
        /// The scenario file.
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
    },
    /// Export a recording's signals as CSV, one file per entity group.
    Export {
        /// The recording.
        recording: PathBuf,
        /// Output directory.
        #[arg(long)]
        csv: PathBuf,
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

/// The shipped scenarios: ./scenarios, else the repository's.
fn scenarios_dir() -> PathBuf {
    let local = PathBuf::from("scenarios");
    if local.is_dir() { local } else { Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios") }
}

fn fail(e: &LaunchError) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(e.exit_code() as u8)
}

fn load(path: &Path) -> Result<Scenario, LaunchError> {
    Ok(Scenario::load(path)?)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let command = cli.command.unwrap_or_else(|| Command::Run {
        scenario: scenarios_dir().join("seed002-sine.toml"),
        out: "runs".into(),
        mode: "processes".into(),
        wait: None,
        force: true,
        allow_unstable: false,
        pin: "auto".into(),
    });
    match command {
        Command::Run { scenario, out, mode, wait, force, allow_unstable, pin } => {
            let s = match load(&scenario) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let p = match plan::plan(&s) {
                Ok(p) => p,
                Err(e) => return fail(&LaunchError::Scenario(e.error)),
            };
            for w in &p.warnings {
                eprintln!("warning: {w}");
            }
            let mode = if mode == "in-process" { Mode::InProcess } else { Mode::Processes };
            let opts = Options { out, mode, wait: wait.unwrap_or_else(Wait::default_for_machine), force, allow_unstable, record: true, pin: pin == "auto" };
            match run::run(&s, &p, &opts) {
                Ok(o) => {
                    print!("{}", o.summary.table());
                    if let Some(rrd) = &o.rrd {
                        println!("recording: {}   (view it with: rerun {})", rrd.display(), rrd.display());
                    }
                    match o.stop {
                        Stop::Completed if o.summary.expectations_met() => ExitCode::SUCCESS,
                        Stop::Completed => {
                            eprintln!("error: {}: the run missed its [expect] table", s.path.display());
                            ExitCode::from(EXIT_EXPECT as u8)
                        }
                        Stop::Diverged(w) => fail(&LaunchError::Diverged(format!("{}: run stopped: {w}", s.name))),
                        Stop::Interrupted(sig) => fail(&LaunchError::Interrupted(format!("{}: run interrupted by {sig}; recording closed", s.name))),
                        Stop::Failed(w) => fail(&LaunchError::Component(format!("{}: {w}", s.name))),
                    }
                }
                Err(e) => fail(&e),
            }
        }
        Command::Design { scenario, json } => {
            let s = match load(&scenario) {
                Ok(s) => s,
                Err(e) => return fail(&e),
            };
            let r = design_report::report(&s);
            if json {
                println!("{}", serde_json::to_string_pretty(&r.json).expect("serialises"));
            } else {
                print!("{}", r.text);
            }
            if r.ok { ExitCode::SUCCESS } else { ExitCode::from(EXIT_BAD_INPUT as u8) }
        }
        Command::Bench { steps, json, wait, mode, recording, pin } => {
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
            match launcher::bench::bench(&scenarios_dir().join("seed002-sine.toml"), steps, wait, pin == "auto", &modes, &rec) {
                Ok(runs) => {
                    if json {
                        println!("{}", serde_json::to_string_pretty(&serde_json::json!({ "runs": runs })).expect("serialises"));
                    } else {
                        print!("{}", launcher::bench::table(&runs, wait));
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&e),
            }
        }
        Command::List { dir } => {
            let dir = dir.unwrap_or_else(scenarios_dir);
            let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).map(|d| d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect()).unwrap_or_default();
            files.sort();
            for f in files {
                match Scenario::load(&f) {
                    Ok(s) => println!("{:<34} {}", s.name, s.description),
                    Err(e) => println!("{:<34} (invalid: {e})", f.display()),
                }
            }
            ExitCode::SUCCESS
        }
        Command::Inspect { recording, json } => match read_recording(&recording) {
            Ok(r) => {
                let i = launcher::inspect::inspect(&recording.display().to_string(), &r);
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
        Command::Compare { a, b, abs_tol, rel_tol } => {
            let (ra, rb) = match (read_recording(&a), read_recording(&b)) {
                (Ok(ra), Ok(rb)) => (ra, rb),
                (Err(code), _) | (_, Err(code)) => return code,
            };
            for (p, r) in [(&a, &ra), (&b, &rb)] {
                if !r.complete {
                    eprintln!("warning: {}: incomplete recording", p.display());
                }
            }
            match launcher::compare::compare(&ra, &rb, abs_tol, rel_tol) {
                Ok(n) => {
                    println!("same: {n} values of {} signals{}", ra.series.keys().filter(|k| !k.starts_with("/latency")).count(), if abs_tol.is_none() && rel_tol.is_none() { ", bit for bit" } else { ", within tolerance" });
                    ExitCode::SUCCESS
                }
                Err(d) => {
                    println!("differ: {d}");
                    ExitCode::from(1)
                }
            }
        }
        Command::Plot { recording, out } => match read_recording(&recording) {
            Ok(r) => {
                if !r.complete {
                    eprintln!("warning: {}: incomplete recording (its writer did not finish); plotting what it holds", recording.display());
                }
                match launcher::plot::plot(&r, &out) {
                    Ok(files) => {
                        for f in &files {
                            println!("{}", f.display());
                        }
                        ExitCode::SUCCESS
                    }
                    Err(e) => fail(&LaunchError::BadInput(e)),
                }
            }
            Err(code) => code,
        },
        Command::Export { recording, csv } => {
            let r = match read_recording(&recording) {
                Ok(r) => r,
                Err(code) => return code,
            };
            let dt = launcher::tools::recorded_dt(&r);
            if !r.complete {
                eprintln!("warning: {}: incomplete recording (its writer did not finish); exporting what it holds", recording.display());
            }
            match launcher::export::export(&r, &csv, dt) {
                Ok(files) => {
                    println!("{} files in {}", files.len(), csv.display());
                    ExitCode::SUCCESS
                }
                Err(e) => fail(&LaunchError::BadInput(e)),
            }
        }
        Command::Component { kind, args } => component(&kind, args),
    }
}

/// Reads a recording, or reports why not (exit code 2).
fn read_recording(path: &Path) -> Result<launcher::recording::Recording, ExitCode> {
    launcher::recording::read(path).map_err(|e| fail(&LaunchError::BadInput(e.to_string())))
}

/// Runs a component's shell in this process (the fallback when its binary is not installed).
fn component(kind: &str, args: Vec<String>) -> ExitCode {
    if let Ok(name) = std::ffi::CString::new(kind) {
        // SAFETY: PR_SET_NAME copies at most 16 bytes from a valid C string.
        unsafe { libc::prctl(libc::PR_SET_NAME, name.as_ptr()) };
    }
    lockstep::component_main(kind, args, |l| match kind {
        "plant" => plant::shell::run(l).map_err(|e| (e.exit_code(), e.to_string())),
        "observer" => observer::shell::run(l).map_err(|e| (observer::shell::EXIT_FAILED, e.to_string())),
        "controller" => controller::shell::run(l).map_err(|e| (controller::shell::EXIT_FAILED, e.to_string())),
        other => Err((lockstep::EXIT_USAGE, format!("unknown component '{other}'"))),
    })
}
