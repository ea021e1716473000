//! Banks of any size. A bank's members share one observer process, so a
//! dedicated bank of 32 members on a 32-sensor plant runs across processes (it was refused: a
//! service has 8 subscribers) and in-process, bit-identical, with the decisions of the
//! structure: a bias on sensor j is found by residual j alone and isolated as channel j.

use tests::*;

/// A 2-state plant read by `p` sensors y_j = x1 + a_j x2 (each alone observes it: a_j ∉ {½, 1},
/// the zeros of det [c_j; c_j A]), a bias on `fault` from 2 s, a dedicated Luenberger bank.
fn sensors(p: usize, fault: usize) -> String {
    let c: Vec<String> = (0..p)
        .map(|j| format!("[1.0, {:?}]", 0.03 * (j + 1) as f64 + 0.01))
        .collect();
    format!(
        r#"name = "bank{p}"
dt = 0.01
duration = 3.0

[plant]
A = [[0.0, 1.0], [-2.0, -3.0]]
B = [[0.0], [1.0]]
C = [{}]
x0 = [1.0, 0.0]

[[input]]
kind = "sine"
amplitude = 1.0
frequency_hz = 0.5

[[fault]]
name = "bias"
target = "sensor"
channel = {fault}
kind = "bias"
value = 0.5
start = 2.0

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-4.0, -5.0]

[[diagnoser]]
name = "dos"
scheme = "dedicated"
faults = "sensor"
observer = "luenberger"
poles = [-6.0, -7.0]
evaluation = "norm"
threshold = 0.05
persistence = 3
ignore_before = 1.0
"#,
        c.join(", ")
    )
}

#[test]
fn a_32_member_bank_runs_across_processes_bit_identical_to_in_process() {
    let s = Scratch::new("bank32");
    let (p, fault) = (32, 21);
    let path = s.join("bank32.toml");
    std::fs::write(&path, sensors(p, fault)).unwrap();
    let mut recordings = Vec::new();
    for mode in ["in-process", "processes"] {
        let dir = s.join(mode);
        let out = launcher(&s)
            .args(["run", "--mode", mode, "--out"])
            .arg(&dir)
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{mode}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let sum: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join("bank32.summary.json")).unwrap(),
        )
        .unwrap();
        let bias = &sum["diagnosis"]["faults"][0];
        assert_eq!(bias["isolated_as"], "bias", "{mode}: {bias}");
        let r = recording::read::read(&dir.join("bank32.rrd")).unwrap();
        // Residual j reacts to sensor j alone: only the faulty sensor's member alarms.
        for j in 1..=p {
            let alarm = &r.series[&format!("/diagnosis/dos/alarm/{j}")].values;
            assert_eq!(alarm.contains(&1.0), j == fault, "{mode}: member {j}");
        }
        assert!(
            r.series["/diagnosis/dos/isolated"]
                .values
                .contains(&(fault as f64)),
            "{mode}"
        );
        assert_eq!(
            r.series
                .keys()
                .filter(|k| k.starts_with("/diagnoser/dos/residual/"))
                .count(),
            p,
            "{mode}: one residual per member"
        );
        recordings.push(dir.join("bank32.rrd"));
    }
    let out = launcher(&s)
        .arg("compare")
        .args(&recordings)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(0), "{stdout}{stderr}");
    assert!(stdout.contains("bit for bit"), "{stdout}");
}

/// The cap counts processes: 7 of its own observers and a bank make 8, one past the 7 a
/// service's subscribers allow beside the recorder; the bank is named.
#[test]
fn the_subscriber_cap_counts_a_bank_once() {
    let s = Scratch::new("bank-cap");
    // `extra` more observers of its own beside the scenario's one, and a bank of 4 members.
    let with = |extra: usize| {
        let more: String = (1..=extra).map(|i| format!("[[observer]]\nname = \"l{i}\"\nkind = \"luenberger\"\npoles = [-4.0, -{i}.5]\n\n")).collect();
        let path = s.join(&format!("cap{extra}.toml"));
        std::fs::write(
            &path,
            sensors(4, 2).replace("[[diagnoser]]", &format!("{more}[[diagnoser]]")),
        )
        .unwrap();
        path
    };
    let out = launcher(&s).arg("design").arg(with(6)).output().unwrap();
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stdout}{stderr}");
    assert!(stderr.contains("diagnoser[1]") && stderr.contains("8 observer processes (7 [[observer]] + 1 for bank members, one per bank); at most 7"), "{stderr}");
    // 6 of its own and the bank's 4 members, 10 observers in 7 processes: runs.
    let out = launcher(&s)
        .arg("run")
        .arg(with(5))
        .arg("--out")
        .arg(s.join("out"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out).1);
}
