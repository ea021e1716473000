//! A sweep cut into shards that run anywhere (a Slurm array's tasks, machines sharing nothing
//! but a folder) and merged into the sweep they make together.
//!
//! Shard K of N runs realisations ⌊(K − 1)·R/N⌋ … ⌊K·R/N⌋ − 1 of the R asked for (seeds S + i),
//! keeps its own worst with their recordings, and writes `<name>.shard-K-of-N.json`: the sweep's
//! [`Frame`], the scenario's digest, and one [`Row`] per completed realisation. `uio-launcher sweep
//! merge` checks that the files are the N shards of one sweep, each once and none interrupted,
//! puts their rows back in seed order and gathers them as the unsharded sweep does: the same
//! values in the same order give the same statistics, bit for bit, and the same worst
//! realisations — each of the sweep's k worst is among its own shard's k worst (fewer than k
//! of the whole sweep, so fewer than k of its shard, come before it), and its recording is the
//! same run again, bit for bit. Only the wall time (the shards' summed) and the jobs (the most
//! any shard used) are the merge's own.

use std::io::Read;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::{Failed, Frame, Row, SweepOptions, SweepSummary, gather, keep_worst, realise};
use crate::error::LaunchError;
use crate::plan::Plan;
use scenario::Scenario;

/// Shard K of N (1 ≤ K ≤ N), from `--shard K/N`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// K, from 1.
    pub k: usize,
    /// N.
    pub n: usize,
}

/// Most shards of one sweep.
pub const MAX_SHARDS: usize = 100_000;

/// What a shard file says it is (`format`).
const FORMAT: &str = "uio-observers sweep shard 1";

/// Largest shard file read by `merge`: ~200 bytes a row, a shard of the 100 000 realisations one
/// process may run is ~20 MB.
const MAX_FILE: u64 = 1 << 30;

impl FromStr for Shard {
    type Err = String;

    fn from_str(v: &str) -> Result<Self, Self::Err> {
        let (k, n) = v
            .split_once('/')
            .ok_or_else(|| format!("'{v}': expected K/N, e.g. 3/8"))?;
        let num = |x: &str| {
            x.trim()
                .parse::<usize>()
                .map_err(|_| format!("'{v}': K and N are whole numbers (K/N, e.g. 3/8)"))
        };
        let (k, n) = (num(k)?, num(n)?);
        if n == 0 || n > MAX_SHARDS {
            return Err(format!("'{v}': N must be 1 … {MAX_SHARDS}"));
        }
        if k == 0 || k > n {
            return Err(format!("'{v}': K must be 1 … N ({n})"));
        }
        Ok(Shard { k, n })
    }
}

impl Shard {
    /// The realisations (indices from 0) of this shard among `runs`.
    pub fn range(&self, runs: usize) -> Range<usize> {
        let at = |k: usize| (k as u128 * runs as u128 / self.n as u128) as usize;
        at(self.k - 1)..at(self.k)
    }
}

/// `<name>.shard-K-of-N.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShardFile {
    /// [`FORMAT`].
    pub format: String,
    /// Which shard.
    pub shard: Shard,
    /// XXH64 (seed 0) of the scenario's text, hex: shards of one sweep run one scenario.
    pub scenario_digest: String,
    /// The sweep.
    pub frame: Frame,
    /// Realisations re-run with a recording (`--keep-worst`).
    pub keep_worst: usize,
    /// This shard's realisations (indices from 0).
    pub realisations: [usize; 2],
    /// How many ended, completed or failed.
    pub finished: usize,
    /// The signal that interrupted it.
    pub interrupted_by: Option<String>,
    /// Wall-clock time, s.
    pub wall_s: f64,
    /// Worker threads.
    pub jobs: usize,
    /// The completed realisations, in seed order.
    pub rows: Vec<Row>,
    /// The realisations that did not complete.
    pub failed: Vec<FailedRow>,
    /// The seeds of its worst realisations, recorded in its folder.
    pub kept: Vec<u64>,
}

/// A [`Failed`] as a shard file holds it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FailedRow {
    /// Its seed.
    pub seed: u64,
    /// "failed" or "diverged".
    pub kind: String,
    /// Why.
    pub reason: String,
}

impl ShardFile {
    /// Its failed realisations as the sweep counts them.
    fn failures(&self) -> Vec<Failed> {
        self.failed
            .iter()
            .map(|f| Failed {
                seed: f.seed,
                kind: if f.kind == "diverged" {
                    "diverged"
                } else {
                    "failed"
                },
                reason: f.reason.clone(),
            })
            .collect()
    }

    /// What the shard did, in a few lines.
    pub fn text(&self) -> String {
        let [lo, hi] = self.realisations;
        let seed = |i: usize| self.frame.seed.wrapping_add(i as u64);
        let mut t = format!(
            "{} sweep, shard {}/{}: realisations {lo}…{} of {} (seeds {}–{}), {} completed, {} failed, {} job(s), {:.1} s wall\n",
            self.frame.scenario,
            self.shard.k,
            self.shard.n,
            hi.saturating_sub(1),
            self.frame.requested,
            seed(lo),
            seed(hi.saturating_sub(1)),
            self.rows.len(),
            self.failed.len(),
            self.jobs,
            self.wall_s
        );
        if let Some(sig) = &self.interrupted_by {
            t += &format!(
                "  PARTIAL: interrupted by {sig} after {} of {} realisations\n",
                self.finished,
                hi - lo
            );
        }
        if !self.kept.is_empty() {
            let kept: Vec<String> = self.kept.iter().map(u64::to_string).collect();
            t += &format!("  kept with recordings: seeds {}\n", kept.join(", "));
        }
        for f in &self.failed {
            t += &format!("  seed {} {}: {}\n", f.seed, f.kind, f.reason);
        }
        t
    }

    /// The shard's failure, if it is one (as a sweep's: interrupted, then a failed
    /// realisation, then a diverged one).
    pub fn verdict(&self) -> Option<LaunchError> {
        let sig: Option<&'static str> = self.interrupted_by.as_deref().map(|s| match s {
            "SIGINT" => "SIGINT",
            "SIGTERM" => "SIGTERM",
            "SIGHUP" => "SIGHUP",
            "SIGQUIT" => "SIGQUIT",
            _ => "a signal",
        });
        super::outcome::verdict(
            &format!(
                "{} shard {}/{}",
                self.frame.scenario, self.shard.k, self.shard.n
            ),
            self.realisations[1] - self.realisations[0],
            self.finished,
            &self.failures(),
            sig,
        )
    }
}

/// The name of shard `sh`'s file for scenario `name`.
pub fn file_name(name: &str, sh: Shard) -> String {
    format!("{name}.shard-{}-of-{}.json", sh.k, sh.n)
}

fn digest(text: &str) -> String {
    format!("{:016x}", twox_hash::XxHash64::oneshot(0, text.as_bytes()))
}

/// Runs shard `opts.shard` of the sweep and writes its file (returned with its path).
pub fn run_shard(
    s: &Scenario,
    plan: &Plan,
    opts: &SweepOptions,
    sh: Shard,
) -> Result<(ShardFile, PathBuf), LaunchError> {
    let r = realise(s, plan, opts)?;
    let kept = if r.interrupted.is_some() {
        Vec::new()
    } else {
        keep_worst(s, plan, opts, &r.rows, opts.keep_worst)?
    };
    let range = sh.range(opts.runs);
    let file = ShardFile {
        format: FORMAT.into(),
        shard: sh,
        scenario_digest: digest(&s.source),
        frame: Frame::of(s, opts),
        keep_worst: opts.keep_worst,
        realisations: [range.start, range.end],
        finished: r.finished,
        interrupted_by: r.interrupted.map(str::to_string),
        wall_s: r.wall_s,
        jobs: r.jobs,
        rows: r.rows,
        failed: r
            .failed
            .into_iter()
            .map(|f| FailedRow {
                seed: f.seed,
                kind: f.kind.into(),
                reason: f.reason,
            })
            .collect(),
        kept,
    };
    let path = opts.out.join(file_name(&s.name, sh));
    let text = serde_json::to_string_pretty(&file).expect("serialises");
    outputs::write_bytes(&path, (text + "\n").as_bytes()).map_err(LaunchError::Component)?;
    Ok((file, path))
}

fn bad(path: &Path, why: impl std::fmt::Display) -> LaunchError {
    LaunchError::BadInput(format!("{}: {why}", path.display()))
}

/// Opens `path` to read if it is a regular file, never through a link nor waiting on a FIFO.
fn open_regular(path: &Path) -> Result<(std::fs::File, std::fs::Metadata), LaunchError> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| bad(path, format!("cannot read: {e}")))?;
    let meta = file.metadata().map_err(|e| bad(path, e))?;
    if !meta.is_file() {
        return Err(bad(path, "not a regular file"));
    }
    Ok((file, meta))
}

/// Reads one shard file (a regular file of at most [`MAX_FILE`] bytes, never through a link).
fn read(path: &Path) -> Result<ShardFile, LaunchError> {
    let (file, meta) = open_regular(path)?;
    if meta.len() > MAX_FILE {
        return Err(bad(
            path,
            format!(
                "{} bytes, more than a shard file holds ({MAX_FILE})",
                meta.len()
            ),
        ));
    }
    let mut text = String::new();
    file.take(MAX_FILE)
        .read_to_string(&mut text)
        .map_err(|e| bad(path, format!("cannot read: {e}")))?;
    let f: ShardFile = serde_json::from_str(&text).map_err(|e| {
        bad(
            path,
            format!("not a sweep shard file (`uio-launcher sweep … --shard K/N` writes them): {e}"),
        )
    })?;
    if f.format != FORMAT {
        return Err(bad(
            path,
            format!(
                "format '{}' is not '{FORMAT}'",
                scenario::untrusted::one_line(&f.format)
            ),
        ));
    }
    Ok(f)
}

/// The merge of the shard files at `paths` into the sweep they make: checked to be the N
/// shards of one sweep, each once, none interrupted, their rows in seed order.
pub fn merge(paths: &[PathBuf]) -> Result<(SweepSummary, Vec<(u64, PathBuf)>), LaunchError> {
    let mut files: Vec<(PathBuf, ShardFile)> = paths
        .iter()
        .map(|p| read(p).map(|f| (p.clone(), f)))
        .collect::<Result<_, _>>()?;
    // In shard order from here on (each checked below to be there once).
    files.sort_by_key(|(_, f)| f.shard.k);
    let files = files;
    let Some((first_path, first)) = files.first() else {
        return Err(LaunchError::BadInput(
            "sweep merge: no shard files given".into(),
        ));
    };
    let n = first.shard.n;
    let mut seen: Vec<Option<&Path>> = vec![None; n];
    for (p, f) in &files {
        let differs = |what: &str| {
            bad(
                p,
                format!(
                    "a shard of another sweep: its {what} differs from {}'s",
                    first_path.display()
                ),
            )
        };
        if f.shard.n != n {
            return Err(differs("shard count N"));
        }
        if f.scenario_digest != first.scenario_digest || f.frame.scenario != first.frame.scenario {
            return Err(differs("scenario"));
        }
        if f.frame != first.frame {
            return Err(differs("runs, first seed or mode"));
        }
        if f.keep_worst != first.keep_worst {
            return Err(differs("--keep-worst"));
        }
        let k = f.shard.k;
        if k == 0 || k > n {
            return Err(bad(p, format!("shard {k}/{n} does not exist")));
        }
        if let Some(other) = seen[k - 1] {
            return Err(bad(p, format!("shard {k}/{n} is also {}", other.display())));
        }
        seen[k - 1] = Some(p);
        if let Some(sig) = &f.interrupted_by {
            return Err(bad(
                p,
                format!(
                    "shard {k}/{n} was interrupted by {} after {} realisations: run it again",
                    scenario::untrusted::one_line(sig),
                    f.finished
                ),
            ));
        }
        let want = f.shard.range(f.frame.requested);
        let counted = f.rows.len() + f.failed.len();
        if f.realisations != [want.start, want.end]
            || counted != want.len()
            || f.finished != counted
        {
            return Err(bad(
                p,
                format!(
                    "shard {k}/{n} should hold realisations {}…{} ({} of them); it holds {counted}",
                    want.start,
                    want.end.saturating_sub(1),
                    want.len()
                ),
            ));
        }
    }
    let missing: Vec<usize> = (1..=n).filter(|k| seen[k - 1].is_none()).collect();
    if !missing.is_empty() {
        let mut list: Vec<String> = missing
            .iter()
            .take(20)
            .map(|k| format!("{k}/{n}"))
            .collect();
        if missing.len() > 20 {
            list.push(format!("and {} more", missing.len() - 20));
        }
        return Err(LaunchError::BadInput(format!(
            "sweep merge: shard(s) {} missing",
            list.join(", ")
        )));
    }
    let rows: Vec<Row> = files.iter().flat_map(|(_, f)| f.rows.clone()).collect();
    let failed: Vec<Failed> = files.iter().flat_map(|(_, f)| f.failures()).collect();
    let jobs = files.iter().map(|(_, f)| f.jobs).max().unwrap_or(1);
    let mut out = gather(&first.frame, jobs, &rows);
    out.finished = files.iter().map(|(_, f)| f.finished).sum();
    out.failed = failed;
    out.wall_s = files.iter().map(|(_, f)| f.wall_s).sum();
    out.kept = super::row::worst(&rows, first.keep_worst);
    // Where each kept realisation's recording is: the folder of the shard that ran it.
    let mut sources = Vec::new();
    for &seed in &out.kept {
        let (p, _) = files
            .iter()
            .find(|(_, f)| f.kept.contains(&seed))
            .ok_or_else(|| {
                LaunchError::BadInput(format!(
                    "sweep merge: seed {seed} is among the {} worst but no shard kept its recording",
                    first.keep_worst
                ))
            })?;
        let dir = p
            .parent()
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        let dir = if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir
        };
        sources.push((seed, dir));
    }
    Ok((out, sources))
}

/// [`merge`], then its result in `out`: the kept realisations' recordings copied there from their
/// shards' folders and `<name>.sweep.json` written (its path returned).
pub fn merge_into(paths: &[PathBuf], out: &Path) -> Result<(SweepSummary, PathBuf), LaunchError> {
    let (sw, sources) = merge(paths)?;
    crate::run::create_output_dir(out)?;
    for (seed, dir) in &sources {
        copy_kept(&sw.scenario, *seed, dir, out)?;
    }
    let path = sw.write(out).map_err(LaunchError::Component)?;
    Ok((sw, path))
}

/// Copies realisation `seed`'s recording and summary (`<name>-seed<S>.rrd`, `.summary.json`)
/// from `from` to `to`, unless they are one folder; a source is read only as a regular file of
/// its own (never through a link).
fn copy_kept(name: &str, seed: u64, from: &Path, to: &Path) -> Result<(), LaunchError> {
    let same = std::fs::canonicalize(from)
        .ok()
        .zip(std::fs::canonicalize(to).ok())
        .is_some_and(|(a, b)| a == b);
    if same {
        return Ok(());
    }
    for ext in ["rrd", "summary.json"] {
        let file = format!("{name}-seed{seed}.{ext}");
        let src = from.join(&file);
        let (mut input, _) = open_regular(&src)?;
        let target = to.join(&file);
        let (staged, mut w) = outputs::Staged::create(&target).map_err(LaunchError::Component)?;
        std::io::copy(&mut input, &mut w)
            .map_err(|e| LaunchError::Component(outputs::cannot_write(&target, &e)))?;
        staged.commit(w).map_err(LaunchError::Component)?;
    }
    Ok(())
}
