//! A plant at an operating point. The design model is in deviations there,
//! the plant speaks absolute units, and the observers and the controller add the point's offsets.
//! The check is the definition: on seeded random plants at random equilibria, a scenario written
//! in absolute units with `[plant.operating_point]` and the same scenario written by hand in
//! deviations (x0 − x_op, w − w_op, references − r_op) give the same signals, each shifted by its
//! operating value — the plant's x, every observer's x̂ (Luenberger, Chen–Patton, Das–Ghosal,
//! Cumming: full and reduced order, Q = 0 and Q ≠ 0), the UIO's ŵ and the controller's u — to
//! rounding of the absolute values, in one process and across processes.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use lti::{Mat, Model};
use observer::design::{Gain, Spec, Weights, design};
use tests::*;

const DT: f64 = 0.01;

/// xorshift64*: the test's own seeded numbers (no dependency, the same on every machine).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// A short decimal in [−1, 1] (two places).
    fn entry(&mut self) -> f64 {
        ((self.next() * 2.0 - 1.0) * 100.0).round() / 100.0
    }
    fn below(&mut self, k: usize) -> usize {
        (self.next() * k as f64) as usize % k
    }
    fn mat(&mut self, r: usize, c: usize) -> Mat {
        Mat::from_fn(r, c, |_, _| self.entry())
    }
}

/// A plant and its point: A stable (its eigenvalues shifted left of −0.5), x_op = −A⁻¹(B u_op +
/// E w_op) — an equilibrium to rounding.
struct Case {
    model: Model,
    x_op: Vec<f64>,
    u_op: Vec<f64>,
    w_op: Vec<f64>,
    x0: Vec<f64>,
    observers: Vec<(&'static str, &'static str)>,
}

fn make(seed: u64) -> Case {
    let mut g = Rng(0x9E37_79B9_7F4A_7C15 ^ (seed + 1).wrapping_mul(0x1000_0000_01B3));
    let n = 3 + g.below(3);
    let l = 1 + g.below(2);
    let p = 2 + g.below(n - 2);
    let mut a = g.mat(n, n);
    let shift = lti::eig::eigenvalues(&a)
        .unwrap()
        .iter()
        .map(|z| z.re)
        .fold(f64::MIN, f64::max)
        + 0.5;
    let shift = (shift.max(0.0) * 100.0).ceil() / 100.0;
    a -= Mat::identity(n, n) * shift;
    let (b, c, e) = (g.mat(n, l), g.mat(p, n), g.mat(n, 1));
    let model = Model {
        a,
        b,
        c,
        e,
        d: Mat::zeros(p, 0),
    };
    let u_op: Vec<f64> = (0..l).map(|_| 5.0 * g.entry()).collect();
    let w_op = vec![3.0 * g.entry()];
    let rhs = &model.b * Mat::from_column_slice(l, 1, &u_op)
        + &model.e * Mat::from_column_slice(1, 1, &w_op);
    let x_op: Vec<f64> = model
        .a
        .clone()
        .lu()
        .solve(&(-rhs))
        .unwrap()
        .iter()
        .copied()
        .collect();
    let x0 = (0..n).map(|_| g.entry()).collect();
    // The families that exist on this plant (a UIO needs rank CE = 1 and stable zeros).
    let lqe = || Gain::Lqe(Weights { q: None, r: None });
    let mut observers = vec![("lu", "luenberger")];
    for (name, kind, spec) in [
        ("uio", "chen-patton-uio", Spec::ChenPatton { gain: lqe() }),
        ("dg", "das-ghosal", Spec::DasGhosal { gain: lqe() }),
        (
            "cum",
            "cumming",
            Spec::Cumming {
                gain: lqe(),
                h: None,
            },
        ),
    ] {
        if design(&model, &spec, DT).is_ok() {
            observers.push((name, kind));
        }
    }
    Case {
        model,
        x_op,
        u_op,
        w_op,
        x0,
        observers,
    }
}

fn rows(m: &Mat) -> String {
    let r: Vec<String> = m
        .row_iter()
        .map(|r| {
            format!(
                "[{}]",
                r.iter()
                    .map(|v| format!("{v:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    format!("[{}]", r.join(", "))
}

fn list(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter()
            .map(|v| format!("{v:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The scenario: `absolute` with the operating point and every signal shifted, else in
/// deviations. The controller (an LQR on the Luenberger estimate) tracks the first l outputs.
fn scenario(dir: &Path, name: &str, c: &Case, absolute: bool) -> PathBuf {
    let (n, l) = (c.model.n(), c.model.b.ncols());
    let shift = |v: f64, op: f64| if absolute { v + op } else { v };
    let track = c.model.c.rows(0, l).into_owned();
    let r_op: Vec<f64> = (&track * Mat::from_column_slice(n, 1, &c.x_op))
        .iter()
        .copied()
        .collect();
    let x0: Vec<f64> =
        c.x0.iter()
            .zip(&c.x_op)
            .map(|(x, o)| shift(*x, *o))
            .collect();
    let mut t = format!("name = \"{name}\"\ndt = {DT}\nduration = 3.0\n[plant]\n");
    writeln!(
        t,
        "A = {}\nB = {}\nC = {}\nE = {}\nx0 = {}",
        rows(&c.model.a),
        rows(&c.model.b),
        rows(&c.model.c),
        rows(&c.model.e),
        list(&x0)
    )
    .unwrap();
    if absolute {
        writeln!(
            t,
            "[plant.operating_point]\nx = {}\nu = {}\nw = {}",
            list(&c.x_op),
            list(&c.u_op),
            list(&c.w_op)
        )
        .unwrap();
    }
    writeln!(
        t,
        "[[disturbance]]\nkind = \"sine\"\namplitude = 0.7\nfrequency_hz = 0.4\noffset = {:?}",
        shift(0.0, c.w_op[0])
    )
    .unwrap();
    for r in &r_op {
        writeln!(
            t,
            "[[input]]\nkind = \"step\"\ntime = 1.0\nbefore = {:?}\nafter = {:?}",
            shift(0.0, *r),
            shift(0.2, *r)
        )
        .unwrap();
    }
    for (name, kind) in &c.observers {
        writeln!(
            t,
            "[[observer]]\nname = \"{name}\"\nkind = \"{kind}\"\ngain = \"lqe\""
        )
        .unwrap();
    }
    writeln!(
        t,
        "[controller]\nkind = \"lqr\"\nobserver = \"lu\"\ntrack = {}",
        rows(&track)
    )
    .unwrap();
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, t).unwrap();
    path
}

/// Every signal of the absolute run, less its operating value, against the deviation run's.
fn compare(seed: u64, mode: &str) {
    let c = make(seed);
    let s = Scratch::new(&format!("op-{seed}-{mode}"));
    let runs: Vec<Recording> = [(false, "dev"), (true, "abs")]
        .iter()
        .map(|&(absolute, name)| {
            let path = scenario(&s.0, name, &c, absolute);
            let out = run(&s, &path, &["--mode", mode]);
            assert!(
                out.status.success(),
                "seed {seed} {name}: {:?}\n{}",
                text(&out),
                std::fs::read_to_string(&path).unwrap()
            );
            read(&s.join("out").join(format!("{name}.rrd"))).unwrap()
        })
        .collect();
    let (dev, abs) = (&runs[0], &runs[1]);
    let mut groups: Vec<(String, &[f64])> = vec![
        ("/plant/x/".into(), &c.x_op),
        ("/controller/u/".into(), &c.u_op),
    ];
    for (name, _) in &c.observers {
        groups.push((format!("/observer/{name}/xhat/"), &c.x_op));
    }
    if c.observers.iter().any(|(n, _)| *n == "uio") {
        groups.push(("/observer/uio/what/".into(), &c.w_op));
    }
    let mut compared = 0;
    for (prefix, op) in &groups {
        for (i, &o) in op.iter().enumerate() {
            let path = format!("{prefix}{}", i + 1);
            let (d, a) = (&dev.series[&path].values, &abs.series[&path].values);
            assert_eq!(d.len(), a.len(), "seed {seed}: {path}");
            // Rounding of the absolute values: a few ε of their size, through the gains.
            let scale = a
                .iter()
                .chain(d.iter())
                .fold(1.0_f64, |m, v| m.max(v.abs()));
            for (k, (dv, av)) in d.iter().zip(a).enumerate() {
                let off = (av - o - dv).abs();
                assert!(
                    off <= 1e-9 * scale,
                    "seed {seed} {mode}: {path} at step {k}: absolute {av} − {o} vs deviation {dv} ({off:e}, scale {scale})"
                );
            }
            compared += 1;
        }
    }
    assert!(
        compared >= 2 * c.model.n(),
        "seed {seed}: {compared} signals compared"
    );
    let big = c.x_op.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    eprintln!(
        "seed {seed} {mode}: n = {}, {} signals, observers {:?}, max|x_op| = {big:.3}",
        c.model.n(),
        compared,
        c.observers.iter().map(|o| o.0).collect::<Vec<_>>()
    );
}

#[test]
fn a_scenario_at_its_operating_point_gives_the_deviation_scenarios_signals_shifted_on_random_plants()
 {
    let mut uios = 0;
    for seed in 0..16 {
        compare(seed, "in-process");
        uios += usize::from(make(seed).observers.iter().any(|(n, _)| *n == "uio"));
    }
    // The property is about the UIOs above all: enough of the random plants must have one.
    assert!(
        uios >= 4,
        "only {uios} of 16 random plants have a Chen–Patton UIO"
    );
}

#[test]
fn the_offsets_reach_the_observer_and_controller_processes() {
    compare(3, "processes");
}

#[test]
fn a_point_that_is_not_an_equilibrium_of_the_built_in_plant_is_refused_naming_the_residual() {
    let c = make(0);
    let s = Scratch::new("op-refused");
    let path = scenario(&s.0, "abs", &c, true);
    let text0 = std::fs::read_to_string(&path).unwrap();
    // x_op moved by 0.1 in its first state: A x + B u + E w = 0.1·A e₁.
    let moved = text0.replacen(
        &format!("x = {}", list(&c.x_op)),
        &format!(
            "x = {}",
            list(&[&[c.x_op[0] + 0.1][..], &c.x_op[1..]].concat())
        ),
        1,
    );
    assert_ne!(moved, text0);
    std::fs::write(&path, moved).unwrap();
    let out = run(&s, &path, &["--mode", "in-process"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("plant.operating_point")
            && err.contains("is not an equilibrium")
            && err.contains("A x + B u + E w"),
        "{err}"
    );
    assert!(
        !s.join("out").join("abs.rrd").exists(),
        "no recording for a refused scenario"
    );
    // A y that is not C x at the point.
    let with_y = text0.replacen(
        "[plant.operating_point]\n",
        &format!(
            "[plant.operating_point]\ny = {}\n",
            list(&vec![1.0; c.model.c.nrows()])
        ),
        1,
    );
    std::fs::write(&path, with_y).unwrap();
    let out = run(&s, &path, &["--mode", "in-process"]);
    let (_, err) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("plant.operating_point.y") && err.contains("is not C x"),
        "{err}"
    );
}

#[test]
fn the_summary_carries_the_operating_point() {
    let c = make(1);
    let s = Scratch::new("op-summary");
    let path = scenario(&s.0, "abs", &c, true);
    let out = run(&s, &path, &["--mode", "in-process"]);
    assert!(out.status.success(), "{:?}", text(&out));
    let op = &summary(&s, "abs")["operating_point"];
    let got: Vec<f64> = op["x"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(got, c.x_op);
    // y defaults to C x_op.
    let y: Vec<f64> = op["y"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let cx = &c.model.c * Mat::from_column_slice(c.model.n(), 1, &c.x_op);
    assert_eq!(y, cx.iter().copied().collect::<Vec<_>>());
}
