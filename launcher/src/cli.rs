//! The command line: every command and its options, typed (clap's derive; enum-like options
//! are `ValueEnum`s, so a wrong value is refused by clap with the list of the right ones).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use launcher::run::Mode;
use lockstep::Wait;

/// `--mode`: where the components run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// One process per component, over iceoryx2.
    Processes,
    /// All step functions in the launcher's process.
    InProcess,
}

impl From<ModeArg> for Mode {
    fn from(m: ModeArg) -> Mode {
        match m {
            ModeArg::Processes => Mode::Processes,
            ModeArg::InProcess => Mode::InProcess,
        }
    }
}

/// `--pin`: place the lockstep ring's processes on CPUs, or leave them to the scheduler.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Pin {
    Auto,
    Off,
}

/// `bench --recording`: only runs with it, or only without.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

/// `export-fmu --fmi`: the FMI version.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FmiArg {
    #[value(name = "2")]
    V2,
    #[value(name = "3")]
    V3,
}

impl From<FmiArg> for fmu_export::Fmi {
    fn from(f: FmiArg) -> fmu_export::Fmi {
        match f {
            FmiArg::V2 => fmu_export::Fmi::V2,
            FmiArg::V3 => fmu_export::Fmi::V3,
        }
    }
}

#[derive(Parser)]
#[command(
    name = "uio-launcher",
    version,
    about = "Design and co-simulate unknown input observers for LTI plants"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand)]
pub enum Command {
    /// Run a scenario and record it to DIR/<name>.rrd and DIR/<name>.summary.json.
    Run(RunArgs),
    /// Run observers on a run's recorded plant samples: its own scenario's (or --scenario's,
    /// same plant sizes), plant replayed from the recording, controller removed (open loop).
    Replay(ReplayArgs),
    /// Monte Carlo: run N noise realisations (seeds S, S+1, …) and write DIR/<name>.sweep.json
    /// with detection delays, isolation accuracy, false-alarm rates and tail errors.
    Sweep(SweepArgs),
    /// Check the existence conditions and show the designs of a scenario.
    Design(DesignArgs),
    /// Benchmark the seed-002 closed loop in one process and across processes.
    Bench(BenchArgs),
    /// One node of the benchmark's floor ring (started by `uio-launcher bench`).
    #[command(hide = true)]
    FloorNode(FloorNodeArgs),
    /// Take part in runs from another host: start the components a launcher places on this
    /// host (`host = NAME` and `[hosts]` in its scenario). Runs `uio-bridge agent` with these
    /// arguments: `agent init` makes the credentials, `agent --host NAME --listen quic/ADDR:PORT`
    /// serves (`uio-launcher agent --help` for all).
    #[command(disable_help_flag = true)]
    Agent(AgentArgs),
    /// List the shipped scenarios.
    List(ListArgs),
    /// Show what a recording holds, and recompute its figures from the recorded data.
    Inspect(InspectArgs),
    /// Compare two recordings signal by signal, step by step (bit for bit without tolerances).
    Compare(CompareArgs),
    /// Draw a recording's views as PNG files.
    Plot(PlotArgs),
    /// Export a recording's signals for other tools: CSV, MCAP, NumPy .npz, MATLAB .mat (one or more).
    #[command(group(clap::ArgGroup::new("format").required(true).multiple(true).args(["csv", "mcap", "npz", "mat"])))]
    Export(ExportArgs),
    /// Write one of a scenario's observers as an FMI co-simulation FMU, DIR/<observer>_fmi<2|3>.fmu.
    ExportFmu(ExportFmuArgs),
    /// The sampled model (Φ, Γ_B, Γ_E, C) of a scenario's FMU plant at its operating point, made
    /// from the FMU: DIR/{Phi,Gamma_B,Gamma_E,C}.npy and DIR/<name>.toml, a scenario that runs.
    Linearize(LinearizeArgs),
    /// Run one component (used by the launcher when the component binaries are not beside it).
    #[command(hide = true, disable_help_flag = true)]
    Component(ComponentArgs),
}

// The arguments of `uio-launcher run`.
#[derive(Args)]
pub struct RunArgs {
    /// The scenario file, or the name of a shipped scenario (see `list`).
    pub scenario: PathBuf,
    /// Output directory.
    #[arg(long, default_value = "runs")]
    pub out: PathBuf,
    /// Where the components run.
    #[arg(long, value_enum, default_value = "processes")]
    pub mode: ModeArg,
    /// How components wait for samples: yield (default), block, waitset,
    /// spin-then-block[:µs], spin-then-yield:<ns>, sleep:<µs>.
    #[arg(long)]
    pub wait: Option<Wait>,
    /// Overwrite an existing recording.
    #[arg(long)]
    pub force: bool,
    /// Run even if the closed loop is unstable (the run stops when a state diverges).
    #[arg(long)]
    pub allow_unstable: bool,
    /// Place the lockstep ring's processes on CPUs (auto) or leave it to the scheduler (off).
    #[arg(long, value_enum, default_value = "auto")]
    pub pin: Pin,
    /// Record only every N-th step (steps 0, N, 2N, …); the summary still sees every step.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub record_every: u64,
    /// Record only the entities matching this glob, e.g. '/observer/uio/**' (`*` within a
    /// path segment, `**` across segments); repeat for several.
    #[arg(long = "record", value_name = "GLOB")]
    pub record: Vec<String>,
    /// Write the recording with Rerun's LZ4 chunk compression: about 0.64 × the bytes, for
    /// the recorder's CPU time.
    #[arg(long)]
    pub compress: bool,
    /// The noise generator's seed (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Pace the run in real time: step k starts at k·dt/X of wall time (waits sleep: the
    /// default wait becomes `block`); steps that end late are counted and recorded.
    #[arg(long)]
    pub realtime: bool,
    /// X for --realtime: 2 runs twice as fast as real time, 0.5 half as fast.
    #[arg(long, value_name = "X", requires = "realtime")]
    pub speed: Option<f64>,
    /// How long a component that runs, or waits for a core, may publish nothing before the
    /// run is stopped (default: the scenario's stall_timeout, else 60 s). A stopped or
    /// blocked component is named after 5 s whatever this is.
    #[arg(long, value_name = "S")]
    pub stall_timeout: Option<f64>,
}

// The arguments of `uio-launcher replay`.
#[derive(Args)]
pub struct ReplayArgs {
    /// The run's recording.
    pub recording: PathBuf,
    /// Another scenario whose observers and banks to run (default: the recorded one).
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Output directory (default: `replay/` beside the recording).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Overwrite an existing replay recording.
    #[arg(long)]
    pub force: bool,
}

// The arguments of `uio-launcher sweep`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    pub merge: Option<SweepCommand>,
    /// The scenario file, or the name of a shipped scenario (see `list`).
    #[arg(required = true)]
    pub scenario: Option<PathBuf>,
    /// Realisations (default 100; with --vary, each point runs once).
    #[arg(long)]
    pub runs: Option<usize>,
    /// Worker threads (default: every core; processes mode runs one at a time).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// The first seed (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Where the realisations run.
    #[arg(long, value_enum, default_value = "in-process")]
    pub mode: ModeArg,
    /// Output directory.
    #[arg(long, default_value = "runs")]
    pub out: PathBuf,
    /// Run the K worst realisations again with a recording (DIR/<name>-seed<S>.rrd).
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub keep_worst: usize,
    /// Run only shard K of N (K = 1 … N) of the --runs realisations, the ⌊(K−1)·runs/N⌋-th to
    /// the ⌊K·runs/N⌋-th, and write DIR/<name>.shard-K-of-N.json for `uio-launcher sweep merge`
    /// (a Slurm array: --shard $((SLURM_ARRAY_TASK_ID+1))/$SLURM_ARRAY_TASK_COUNT).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<launcher::sweep::Shard>,
    /// Vary the simulated plant against the design model instead of the noise: an entry or a
    /// whole matrix of A, B, C, E, D scaled (*=) or set (=), over a list [a, b], a grid lo..hi:N
    /// or a distribution U(lo, hi), N(mean, sd), LogU(lo, hi); e.g. 'A[2,3] *= 0.8..1.2:5'.
    /// Also plant.fmu.parameters.NAME, plant.process.params.NAME, the operating point
    /// plant.operating_point.u[i] / w[i], the initial state x0[i] and the sampling interval dt.
    /// Repeat for more (grids make a product). Writes DIR/<name>.vary.csv, .vary.json and PNGs.
    #[arg(long, value_name = "SPEC")]
    pub vary: Vec<launcher::vary::spec::Vary>,
    /// Draws of the --vary distributions.
    #[arg(long, value_name = "N", default_value_t = 20)]
    pub points: usize,
}

// `uio-launcher sweep merge`.
#[derive(Subcommand)]
pub enum SweepCommand {
    /// Merge the N shard files of one sweep into DIR/<name>.sweep.json, equal to the unsharded
    /// sweep's (statistics, worst realisations and their recordings; not the wall time).
    Merge(MergeArgs),
}

// The arguments of `uio-launcher sweep merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// The shard files (<name>.shard-K-of-N.json), all N of them, in any order.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Output directory (the kept recordings are copied here from their shards' folders).
    #[arg(long, default_value = "runs")]
    pub out: PathBuf,
}

// The arguments of `uio-launcher design`.
#[derive(Args)]
pub struct DesignArgs {
    /// The scenario file, or the name of a shipped scenario (see `list`).
    pub scenario: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also the frequency responses of every observer and bank member: σ of w → e, v → e,
    /// w → r, v → r and f → r over 0 … Nyquist, with H∞ norms, DC gains and fault-to-noise ratios.
    #[arg(long)]
    pub freq: bool,
    /// With --freq: write a σ plot per observer and member into this folder.
    #[arg(long, value_name = "DIR", requires = "freq")]
    pub out: Option<PathBuf>,
}

// The arguments of `uio-launcher bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Steps per run.
    #[arg(long, default_value_t = 100_000)]
    pub steps: u64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// How components wait for samples: yield (default), block, waitset,
    /// spin-then-block[:µs], spin-then-yield:<ns>, sleep:<µs>.
    #[arg(long)]
    pub wait: Option<Wait>,
    /// Only this mode (default: both).
    #[arg(long, value_enum)]
    pub mode: Option<ModeArg>,
    /// Only runs with (on) or without (off) recording (default: both).
    #[arg(long, value_enum)]
    pub recording: Option<OnOff>,
    /// Place the lockstep ring's processes on CPUs (auto) or not (off).
    #[arg(long, value_enum, default_value = "auto")]
    pub pin: Pin,
    /// Repetitions (each: the floor, then every configuration); ratios are given as medians.
    #[arg(long, default_value_t = 1)]
    pub repeat: usize,
    /// Each repetition also runs a 32-sensor plant with and without a 32-member bank, for a bank
    /// member's cost in each mode (on) or not (off).
    #[arg(long, value_enum, default_value = "on")]
    pub bank: OnOff,
    /// Instead: how a step's cost grows with the model, for random stable plants of these
    /// sizes with a UIO and a Luenberger observer in closed loop (e.g. 3,10,30).
    #[arg(long, value_name = "N[,N…]", value_delimiter = ',')]
    pub states: Vec<usize>,
}

// The arguments of `launcher floor-node`.
#[derive(Args)]
pub struct FloorNodeArgs {
    pub run: String,
    pub index: usize,
    pub steps: u64,
    pub len_plant: usize,
    pub len_observer: usize,
    pub len_controller: usize,
    pub wait: Wait,
}

// The arguments of `uio-launcher agent`.
#[derive(Args)]
pub struct AgentArgs {
    /// Passed to `uio-bridge agent`.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<String>,
}

// The arguments of `uio-launcher list`.
#[derive(Args)]
pub struct ListArgs {
    /// Directory of scenarios.
    #[arg(long)]
    pub dir: Option<PathBuf>,
}

// The arguments of `uio-launcher inspect`.
#[derive(Args)]
pub struct InspectArgs {
    /// The recording.
    pub recording: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

// The arguments of `uio-launcher compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// First recording.
    pub a: PathBuf,
    /// Second recording.
    pub b: PathBuf,
    /// Absolute tolerance.
    #[arg(long)]
    pub abs_tol: Option<f64>,
    /// Relative tolerance (of the first recording's value).
    #[arg(long)]
    pub rel_tol: Option<f64>,
}

// The arguments of `uio-launcher plot`.
#[derive(Args)]
pub struct PlotArgs {
    /// The recording.
    pub recording: PathBuf,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Only entities matching this glob, e.g. '/observer/uio/**' (`*` within a path
    /// segment, `**` across segments); repeat for several.
    #[arg(long = "signals", value_name = "GLOB")]
    pub signals: Vec<String>,
    /// Start of the time window: s, or with a unit ("24 h"; steps for a recording without its
    /// scenario).
    #[arg(long, value_name = "T", allow_negative_numbers = true, value_parser = time_arg)]
    pub from: Option<f64>,
    /// End of the time window: s, or with a unit ("36 h").
    #[arg(long, value_name = "T", allow_negative_numbers = true, value_parser = time_arg)]
    pub to: Option<f64>,
    /// A run at an operating point in deviations from it (x − x_op, u − u_op, …) instead of
    /// the plant's own units.
    #[arg(long)]
    pub deviations: bool,
}

// The arguments of `uio-launcher export`.
#[derive(Args)]
pub struct ExportArgs {
    /// The recording.
    pub recording: PathBuf,
    /// Output directory: one CSV per entity group.
    #[arg(long, value_name = "DIR")]
    pub csv: Option<PathBuf>,
    /// MCAP file (Foxglove, PlotJuggler): one JSON channel per entity group.
    #[arg(long, value_name = "FILE")]
    pub mcap: Option<PathBuf>,
    /// NumPy .npz file: `t`, `step` and one steps × members array per entity group.
    #[arg(long, value_name = "FILE")]
    pub npz: Option<PathBuf>,
    /// MATLAB level-5 .mat file: the arrays of --npz.
    #[arg(long, value_name = "FILE")]
    pub mat: Option<PathBuf>,
    /// A run at an operating point in deviations from it (x − x_op, u − u_op, …) instead of
    /// the plant's own units.
    #[arg(long)]
    pub deviations: bool,
    /// Replace export files that already exist (without it they are refused, exit 2).
    #[arg(long)]
    pub force: bool,
}

// The arguments of `uio-launcher export-fmu`.
#[derive(Args)]
pub struct ExportFmuArgs {
    /// The scenario file, or the name of a shipped scenario (see `list`).
    pub scenario: PathBuf,
    /// The observer's name.
    #[arg(long)]
    pub observer: String,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// FMI version.
    #[arg(long, value_enum, default_value = "3")]
    pub fmi: FmiArg,
}

// The arguments of `uio-launcher linearize`.
#[derive(Args)]
pub struct LinearizeArgs {
    /// The scenario file: dt, [plant.fmu] and [plant.operating_point] are read.
    pub scenario: PathBuf,
    /// First find the equilibrium x_op for the operating point's u and w (Newton's method;
    /// the given x is the first guess).
    #[arg(long)]
    pub trim: bool,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

// The arguments of `uio-launcher component`.
#[derive(Args)]
pub struct ComponentArgs {
    /// plant, observer or controller.
    pub kind: String,
    /// The component's own arguments.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<String>,
}

/// A time on the command line: seconds, or with its unit ("24 h", [`lti::units::seconds`]). A
/// bare number is taken as written, NaN too: the window's own check names what is wrong with it.
fn time_arg(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .or_else(|_| lti::units::seconds(text))
}
