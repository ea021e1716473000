//! Samples are sized by the run (PROTOCOL.md §4): a plant of 70 states — 213 values a sample,
//! over the old fixed cap of 64 — runs across processes and in one process bit-identically, and
//! so does a run without any observer (the plant's end sample is not a row).

use tests::*;

/// A stable 70-state plant measured whole, with a Luenberger observer (or none).
fn big(s: &Scratch, name: &str, observer: bool) -> std::path::PathBuf {
    let n = 70;
    let mut seed = 3u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let a: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    if i == j {
                        -1.0 - 0.05 * i as f64
                    } else {
                        0.02 * rnd()
                    }
                })
                .collect()
        })
        .collect();
    let col = |r: &mut dyn FnMut() -> f64| -> Vec<Vec<f64>> { (0..n).map(|_| vec![r()]).collect() };
    let (b, e) = (col(&mut rnd), col(&mut rnd));
    let c: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    let x0: Vec<f64> = (0..n).map(|_| rnd()).collect();
    let poles: Vec<f64> = (0..n).map(|i| -2.0 - 0.1 * i as f64).collect();
    let mut text = format!(
        "name = \"{name}\"\ndt = 0.001\nduration = 1.0\n[plant]\nA = {a:?}\nB = {b:?}\nC = {c:?}\nE = {e:?}\nx0 = {x0:?}\n\
         [[disturbance]]\nkind = \"sine\"\namplitude = 1.0\nfrequency_hz = 1.0\n[[input]]\nkind = \"constant\"\nvalue = 0.5\n"
    );
    if observer {
        text += &format!(
            "[[observer]]\nname = \"luenberger\"\nkind = \"luenberger\"\npoles = {poles:?}\n"
        );
    }
    let p = s.join(&format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn same_in_both_modes(name: &str, observer: bool) {
    let s = Scratch::new(name);
    let path = big(&s, name, observer);
    for (out, mode) in [("p", "processes"), ("i", "in-process")] {
        let o = launcher(&s)
            .arg("run")
            .arg(&path)
            .args(["--mode", mode, "--out"])
            .arg(s.join(out))
            .output()
            .unwrap();
        assert!(o.status.success(), "{name} {mode}: {:?}", text(&o));
    }
    let (a, b) = (
        read(&s.join(&format!("p/{name}.rrd"))).unwrap(),
        read(&s.join(&format!("i/{name}.rrd"))).unwrap(),
    );
    let (ta, tb) = (trajectories(&a), trajectories(&b));
    assert_eq!(ta.len(), tb.len());
    assert!(ta.len() >= 70 * 2 + 2, "{} series", ta.len());
    for ((k, x), (_, y)) in ta.iter().zip(&tb) {
        assert_eq!(x.steps, (0..1000).collect::<Vec<i64>>(), "{name}: {k}");
        assert!(
            x.values
                .iter()
                .zip(&y.values)
                .all(|(p, q)| p.to_bits() == q.to_bits()),
            "{name}: {k} differs"
        );
    }
}

#[test]
fn a_plant_of_70_states_runs_in_both_modes_bit_identically() {
    same_in_both_modes("big", true);
}

#[test]
fn a_run_without_observers_runs_in_both_modes() {
    same_in_both_modes("big0", false);
}
