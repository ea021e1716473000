//! Plants whose (A, E, C) has invariant zeros that sampling removes design and
//! run in both modes, bit-identically, with the UIO error converging at the fixed modes' rate.

use lti::Model;
use tests::*;

#[path = "../../../../fixtures/zero_plants.rs"]
mod zero_plants;

fn toml_matrix(m: &lti::Mat) -> String {
    let rows: Vec<Vec<f64>> = (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect();
    format!("{rows:?}")
}

/// A scenario for `m`: a sine with an offset as the unknown input, a Chen–Patton UIO with the
/// free poles and a Luenberger observer, state feedback on the UIO's estimate (the random plants
/// are often unstable), long enough for the slowest fixed mode to settle.
fn scenario_for(s: &Scratch, i: usize, m: &Model, zeros: usize, x0: &[f64]) -> std::path::PathBuf {
    let n = m.n();
    let free: Vec<f64> = (0..n - zeros).map(|j| -5.0 - 3.0 * j as f64).collect();
    let all: Vec<f64> = (0..n).map(|j| -5.0 - 3.0 * j as f64).collect();
    let feedback: Vec<f64> = (0..n).map(|j| -1.0 - 0.5 * j as f64).collect();
    let text = format!(
        r#"name = "zeros-{i}"
description = "random plant with invariant zeros"
dt = 0.001
duration = 40.0
[plant]
A = {a}
B = {b}
C = {c}
E = {e}
x0 = {x0:?}
[[disturbance]]
kind = "sine"
amplitude = 1.0
frequency_hz = 0.3
offset = 0.5
[[input]]
kind = "step"
time = 1.0
after = 1.0
[[observer]]
name = "uio"
kind = "chen-patton-uio"
poles = {free:?}
[[observer]]
name = "luenberger"
kind = "luenberger"
poles = {all:?}
[controller]
kind = "state-feedback"
observer = "uio"
poles = {feedback:?}
"#,
        a = toml_matrix(&m.a),
        b = toml_matrix(&m.b),
        c = toml_matrix(&m.c),
        e = toml_matrix(&m.e),
    );
    let p = s.join(&format!("zeros-{i}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn tail(sum: &serde_json::Value, name: &str) -> f64 {
    sum["observers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == name)
        .unwrap()["tail_max_abs_error"]
        .as_f64()
        .unwrap()
}

/// Runs `path` in both modes; asserts bit-identical trajectories; returns the summary.
fn both_modes(path: &std::path::Path, name: &str) -> serde_json::Value {
    let (a, b) = (
        Scratch::new(&format!("{name}-p")),
        Scratch::new(&format!("{name}-i")),
    );
    for (s, mode) in [(&a, "processes"), (&b, "in-process")] {
        let out = run(s, path, &["--mode", mode]);
        assert!(out.status.success(), "{name} {mode}: {:?}", text(&out));
    }
    let (ra, rb) = (
        read(&a.join(&format!("out/{name}.rrd"))).unwrap(),
        read(&b.join(&format!("out/{name}.rrd"))).unwrap(),
    );
    let (ta, tb) = (trajectories(&ra), trajectories(&rb));
    assert_eq!(ta.len(), tb.len());
    for ((k, sa), (_, sb)) in ta.iter().zip(&tb) {
        assert!(
            sa.values.len() == sb.values.len()
                && sa
                    .values
                    .iter()
                    .zip(&sb.values)
                    .all(|(x, y)| x.to_bits() == y.to_bits()),
            "{name}: {k} differs between modes"
        );
    }
    summary(&a, name)
}

#[test]
fn dc_motor_runs_in_both_modes_and_the_uios_converge() {
    let sum = both_modes(&scenario("dc-motor-load-torque"), "dc-motor-load-torque");
    let (uio, hz, lu) = (
        tail(&sum, "uio"),
        tail(&sum, "hui-zak"),
        tail(&sum, "luenberger"),
    );
    eprintln!("dc motor tail max|e|: uio {uio:e}, hui-zak {hz:e}, luenberger {lu:e}");
    // The error decays like e^{−2t} (the fixed mode) from ~1 at t = 0: by the tail (7.5 s) ≲ 1e-6.
    assert!(uio < 1e-5 && hz < 1e-5, "uio {uio}, hui-zak {hz}");
    assert!(
        lu > 1e3 * uio,
        "luenberger {lu} should follow the load torque"
    );
}

#[test]
fn random_plants_with_invariant_zeros_run_and_converge() {
    let s = Scratch::new("zeros");
    for (i, (m, zeros, x0)) in zero_plants::plants(7).into_iter().enumerate() {
        let path = scenario_for(&s, i, &m, zeros.len(), &x0);
        let sum = both_modes(&path, &format!("zeros-{i}"));
        let (uio, lu) = (tail(&sum, "uio"), tail(&sum, "luenberger"));
        // Slowest fixed mode −0.5: from |e(0)| ≲ 3 the error is ≲ 3e^{−0.5·30} ≈ 1e-6 by the tail.
        eprintln!("case {i} zeros {zeros:?}: tail max|e| uio {uio:e}, luenberger {lu:e}");
        assert!(uio < 1e-5, "case {i}: uio tail {uio}");
        assert!(lu > 100.0 * uio, "case {i}: luenberger {lu} vs uio {uio}");
    }
}
