//! A sweep cut into shards (`--shard K/N`, each in a folder of its own, as a Slurm array's tasks
//! would run them) and merged (`uio-launcher sweep merge`) is the unsharded sweep: the same
//! statistics bit for bit (every field of `<name>.sweep.json` but the wall time), the same worst
//! realisations, and their recordings the same runs (`uio-launcher compare`: bit for bit). Shard
//! files that do not make one whole sweep are refused with one line and exit 2.

use std::path::{Path, PathBuf};

use tests::*;

const SCENARIO: &str = "seed002-actuator-faults";
const RUNS: usize = 7;
const KEEP: usize = 2;

fn sweep(s: &Scratch, out: &Path, extra: &[&str]) {
    let o = launcher(s)
        .args(["sweep", SCENARIO, "--runs", &RUNS.to_string()])
        .args(["--keep-worst", &KEEP.to_string(), "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "sweep {extra:?}: {err}");
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(
        &std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display())),
    )
    .unwrap()
}

fn shard_file(dir: &Path, k: usize, n: usize) -> PathBuf {
    dir.join(format!("{SCENARIO}.shard-{k}-of-{n}.json"))
}

fn merge(s: &Scratch, files: &[PathBuf], out: &Path) -> std::process::Output {
    launcher(s)
        .args(["sweep", "merge"])
        .args(files)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn a_sweep_in_shards_merges_to_the_unsharded_sweep_bit_for_bit() {
    let s = Scratch::new("shards");
    let whole = s.join("whole");
    sweep(&s, &whole, &[]);
    let want = json(&whole.join(format!("{SCENARIO}.sweep.json")));
    // 8 shards of 7 realisations: one shard is empty.
    for n in [2, 3, 8] {
        let mut files = Vec::new();
        for k in 1..=n {
            let dir = s.join(&format!("n{n}-k{k}"));
            sweep(&s, &dir, &["--shard", &format!("{k}/{n}")]);
            files.push(shard_file(&dir, k, n));
        }
        files.reverse(); // any order
        let out = s.join(&format!("merged-{n}"));
        let o = merge(&s, &files, &out);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(0), "{n} shards: {err}");
        let got = json(&out.join(format!("{SCENARIO}.sweep.json")));
        for (key, value) in want.as_object().unwrap() {
            if key == "wall_s" || key == "jobs" {
                continue;
            }
            assert_eq!(&got[key], value, "{n} shards: '{key}' differs");
        }
        let kept = want["kept"].as_array().unwrap();
        assert_eq!(kept.len(), KEEP);
        for seed in kept {
            let name = format!("{SCENARIO}-seed{seed}.rrd");
            let c = launcher(&s)
                .arg("compare")
                .arg(whole.join(&name))
                .arg(out.join(&name))
                .output()
                .unwrap();
            let (said, err) = text(&c);
            assert_eq!(c.status.code(), Some(0), "{n} shards, {name}: {said}{err}");
            assert!(said.contains("bit for bit"), "{said}");
        }
    }
}

#[test]
fn shard_files_that_do_not_make_one_sweep_are_refused_with_one_line() {
    let s = Scratch::new("shards-bad");
    let dirs: Vec<PathBuf> = (1..=3).map(|k| s.join(&format!("k{k}"))).collect();
    for (k, dir) in dirs.iter().enumerate() {
        sweep(&s, dir, &["--shard", &format!("{}/3", k + 1)]);
    }
    let files: Vec<PathBuf> = (1..=3).map(|k| shard_file(&dirs[k - 1], k, 3)).collect();
    // Another sweep's shard: other runs.
    let other = s.join("other");
    let o = launcher(&s)
        .args(["sweep", SCENARIO, "--runs", "9", "--shard", "3/3", "--out"])
        .arg(&other)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o).1);
    // An interrupted shard, as its file says.
    let partial = s.join("partial.json");
    let mut v = json(&files[1]);
    v["interrupted_by"] = "SIGTERM".into();
    std::fs::write(&partial, v.to_string()).unwrap();
    // A link to a shard file, and a file that is no shard file.
    let link = s.join("link.json");
    std::os::unix::fs::symlink(&files[2], &link).unwrap();
    let summary = s.join("not-a-shard.json");
    std::fs::write(&summary, "{\"scenario\": \"x\"}").unwrap();

    let f = |i: usize| files[i].clone();
    for (given, says) in [
        (vec![f(0), f(1)], "shard(s) 3/3 missing"),
        (vec![f(0), f(1), f(1), f(2)], "shard 2/3 is also"),
        (
            vec![f(0), f(1), shard_file(&other, 3, 3)],
            "a shard of another sweep",
        ),
        (
            vec![f(0), partial.clone(), f(2)],
            "was interrupted by SIGTERM",
        ),
        (vec![f(0), f(1), link.clone()], "cannot read"),
        (vec![f(0), f(1), summary.clone()], "not a sweep shard file"),
    ] {
        let out = s.join("merged");
        let o = merge(&s, &given, &out);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{says}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(says), "wanted '{says}': {err}");
        assert!(
            !out.exists(),
            "{says}: a refused merge wrote {}",
            out.display()
        );
    }
    for bad in ["0/3", "4/3", "a/3", "3"] {
        let o = launcher(&s)
            .args(["sweep", SCENARIO, "--runs", "3", "--shard", bad])
            .output()
            .unwrap();
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--shard"), "{bad}: {err}");
    }
}
