//! Every recorded signal's entity path and label, in one place: the writer, the blueprint and
//! every tool that reads a recording agree on them. Paths number components from 1, the way the
//! labels (x1, y1, w1) and the papers do: `/plant/x/1` is x1.

use scenario::{Named, Scenario};

/// `/plant/x/<i+1>`: the true state x_i (0-based `i`).
pub fn state(i: usize) -> String {
    format!("/plant/x/{}", i + 1)
}

/// `/plant/y/<j+1>`: the measured output.
pub fn output(j: usize) -> String {
    format!("/plant/y/{}", j + 1)
}

/// `/disturbance/<k+1>`: the unknown input w (column of E).
pub fn disturbance(k: usize) -> String {
    format!("/disturbance/{}", k + 1)
}

/// `/measurement_disturbance/<k+1>`: v (column of D).
pub fn measurement_disturbance(k: usize) -> String {
    format!("/measurement_disturbance/{}", k + 1)
}

/// `/input/<k+1>`: the known input / reference r (column of B).
pub fn input(k: usize) -> String {
    format!("/input/{}", k + 1)
}

/// `/controller/u/<k+1>`: the controller's u.
pub fn control(k: usize) -> String {
    format!("/controller/u/{}", k + 1)
}

/// `/observer/<name>/xhat/<i+1>`.
pub fn estimate(observer: &str, i: usize) -> String {
    format!("/observer/{observer}/xhat/{}", i + 1)
}

/// `/observer/<name>/error/<i+1>`: x_i − x̂_i.
pub fn error(observer: &str, i: usize) -> String {
    format!("/observer/{observer}/error/{}", i + 1)
}

/// `/observer/<name>/residual/<j+1>`: y_j − (Cx̂)_j.
pub fn residual(observer: &str, j: usize) -> String {
    format!("/observer/{observer}/residual/{}", j + 1)
}

/// `/observer/<name>/what/<k>`: the observer's estimate ŵ_k of unknown input k, recorded at t_k
/// (it completes one sample later).
pub fn input_estimate(observer: &str, k: usize) -> String {
    format!("/observer/{observer}/what/{}", k + 1)
}

/// `/observer/<name>/log10_max_abs_error`: log10 of max_i |e_i|, a zero error recorded as
/// log10 of [`LOG_FLOOR`]. Derived from the errors, so that a viewer without log axes still
/// shows rounding-level and large errors with readable numbers on one axis.
pub fn log_error(observer: &str) -> String {
    format!("/observer/{observer}/log10_max_abs_error")
}

/// Where an error of exactly zero is drawn on a log axis (log10 of 0 has no value).
pub const LOG_FLOOR: f64 = 1e-18;

/// The observers a recording holds (from its `/observer/<name>/…` entities), in the scenario's
/// order where it is known — the order that gives each observer its colour — else by name.
pub fn observers_of<'a>(
    paths: impl IntoIterator<Item = &'a String>,
    s: Option<&Scenario>,
) -> Vec<String> {
    let mut names: Vec<String> = paths
        .into_iter()
        .filter_map(|p| {
            p.strip_prefix("/observer/")
                .and_then(|x| x.split_once('/'))
                .map(|(n, _)| n.to_string())
        })
        .collect();
    names.sort();
    names.dedup();
    let order: Vec<&str> = s
        .map(|s| s.observers.iter().map(|o| o.name.as_str()).collect())
        .unwrap_or_default();
    names.sort_by_key(|n| order.iter().position(|o| o == n).unwrap_or(usize::MAX));
    names
}

/// A figure that may be missing, for tables: "—" where there is none (a run of fewer than 4
/// steps has no tail).
pub fn figure(v: Option<f64>) -> String {
    v.map_or_else(|| "—".to_string(), |v| format!("{v:.3e}"))
}

/// log10 of a max |e|, zeros at the floor (NaN stays NaN: a diverged run shows as a gap).
pub fn log10_floored(v: f64) -> f64 {
    if v.is_nan() {
        v
    } else {
        v.max(LOG_FLOOR).log10()
    }
}

/// The name and unit of the signal at `path` in a run of `s`, for CSV headers and axis labels:
/// a state estimate is named after its state, an error `e<i>` and a residual `r<j>` carry the
/// unit of their state or output (as in the README: e = x − x̂, r = y − Cx̂), an unknown-input
/// estimate ŵ_k the name and unit of w_k. Without the
/// scenario, the default names (x1, y1, w1, …) and no unit. `None` for paths that are not a
/// numbered signal (latency).
pub fn named(s: Option<&Scenario>, path: &str) -> Option<Named> {
    let (group, index) = path.rsplit_once('/')?;
    let i = index.parse::<usize>().ok()?.checked_sub(1)?;
    let kind = group
        .strip_prefix("/observer/")
        .and_then(|g| g.split_once('/'))
        .map_or(group, |(_, kind)| kind);
    let Some(s) = s else {
        let letter = match kind {
            "/plant/x" | "xhat" => "x",
            "/plant/y" => "y",
            "/disturbance" | "what" => "w",
            "/measurement_disturbance" => "v",
            "/input" | "residual" => "r",
            "/controller/u" => "u",
            "error" => "e",
            _ => return None,
        };
        return Some(Named {
            name: format!("{letter}{}", i + 1),
            unit: String::new(),
        });
    };
    let n = &s.names;
    let get = |v: &[Named]| v.get(i).cloned();
    match kind {
        "/plant/x" | "xhat" => get(&n.state),
        "/plant/y" => get(&n.output),
        // ŵ_k is named after w_k, as x̂_i after x_i: its group tells them apart.
        "/disturbance" | "what" => get(&n.disturbance),
        "/measurement_disturbance" => get(&n.measurement_disturbance),
        "/input" => (i < n.input.len()).then(|| reference_named(s, i)),
        "/controller/u" => n.input.get(i).map(|r| Named {
            name: control_name(s, i),
            unit: r.unit.clone(),
        }),
        "error" => n.state.get(i).map(|x| Named {
            name: format!("e{}", i + 1),
            unit: x.unit.clone(),
        }),
        "residual" => n.output.get(i).map(|y| Named {
            name: format!("r{}", i + 1),
            unit: y.unit.clone(),
        }),
        _ => None,
    }
}

/// What `[[input]]` k is and its unit. Open loop, and for a measured disturbance, the known
/// input itself. In a closed loop the other inputs' signals are references: with `track`, the
/// setpoint of the tracked z_j = C_t[j]·x (j counting the commanded inputs), named and measured
/// as the state or output that row picks ("T1 ref [°C]"; "z2 ref" for another combination);
/// without it, u = r − G x̂ and r is a reference in the input's own unit ("Qh1 ref [kW]").
pub fn reference_named(s: &Scenario, k: usize) -> Named {
    let n = &s.names;
    let own = n.input.get(k).cloned().unwrap_or_default();
    let Some(c) = s.controller.as_ref().filter(|c| !c.measured.contains(&k)) else {
        return own;
    };
    let reference = |m: &Named| Named {
        name: format!("{} ref", m.name),
        unit: m.unit.clone(),
    };
    let Some(track) = &c.track else {
        return reference(&own);
    };
    let j = (0..k).filter(|i| !c.measured.contains(i)).count();
    if j >= track.nrows() {
        return reference(&own);
    }
    let row = track.row(j);
    let unit_vector = row.iter().filter(|&&v| v != 0.0).count() == 1;
    if let Some(m) = row.iter().position(|&v| v == 1.0).filter(|_| unit_vector)
        && let Some(x) = n.state.get(m)
    {
        return reference(x);
    }
    let c_rows = s.model.c.nrows();
    if let Some(y) = (0..c_rows)
        .find(|&q| s.model.c.row(q) == row)
        .and_then(|q| n.output.get(q))
    {
        return reference(y);
    }
    Named {
        name: format!("z{} ref", j + 1),
        unit: String::new(),
    }
}

/// Whether the latency entity at `path` is a follower's: an observer off the ring (one the
/// controller does not read; in open loop, all but the first) trails the plant in batches (`lockstep::FOLLOWER_LAG`), so its "hop" is a batch delay
/// of milliseconds, not a lockstep hop of microseconds, and is shown apart from them.
pub fn follower_hop(s: &Scenario, path: &str) -> bool {
    let ring = s.ring_observer().map(|r| r.replace('/', "_"));
    path.strip_prefix("/latency/plant_to_observer_")
        .is_some_and(|o| ring.as_deref() != Some(o))
}

/// u's name: `u<k>`, or "<input name> (u)" when the inputs are named.
pub fn control_name(s: &Scenario, k: usize) -> String {
    match s.names.input.get(k) {
        Some(r) if r.name != format!("r{}", k + 1) => format!("{} (u)", r.name),
        _ => format!("u{}", k + 1),
    }
}

/// `/fault/<name>/active`: 1 while the fault acts, 0 otherwise.
pub fn fault_active(name: &str) -> String {
    format!("/fault/{name}/active")
}

/// `/fault/<name>/value`: its magnitude while it acts (0 otherwise).
pub fn fault_value(name: &str) -> String {
    format!("/fault/{name}/value")
}

/// `/diagnoser/<d>/residual/<i+1>/<j+1>`: member i's residual on output j.
pub fn member_residual(diagnoser: &str, i: usize, j: usize) -> String {
    format!("/diagnoser/{diagnoser}/residual/{}/{}", i + 1, j + 1)
}

/// `/diagnosis/<d>/evaluation/<i+1>`: J_i, residual i's evaluation.
pub fn evaluation(diagnoser: &str, i: usize) -> String {
    format!("/diagnosis/{diagnoser}/evaluation/{}", i + 1)
}

/// `/diagnosis/<d>/threshold/<i+1>`: residual i's threshold.
pub fn threshold(diagnoser: &str, i: usize) -> String {
    format!("/diagnosis/{diagnoser}/threshold/{}", i + 1)
}

/// `/diagnosis/<d>/alarm/<i+1>`: 1 while residual i is in alarm.
pub fn alarm(diagnoser: &str, i: usize) -> String {
    format!("/diagnosis/{diagnoser}/alarm/{}", i + 1)
}

/// `/diagnosis/<d>/glr/<i+1>`: g_i, residual i's GLR statistic (a bank with a GLR test).
pub fn glr(diagnoser: &str, i: usize) -> String {
    format!("/diagnosis/{diagnoser}/glr/{}", i + 1)
}

/// `/diagnosis/<d>/glr_threshold/<i+1>`: residual i's GLR threshold.
pub fn glr_threshold(diagnoser: &str, i: usize) -> String {
    format!("/diagnosis/{diagnoser}/glr_threshold/{}", i + 1)
}

/// `/diagnosis/<d>/decided_by`: which test's alarms made the isolation: 0 none, 1 the
/// evaluation's, 2 the GLR's, 3 each alone, 4 only both together.
pub fn decided_by(diagnoser: &str) -> String {
    format!("/diagnosis/{diagnoser}/decided_by")
}

/// `/diagnosis/<d>/isolated`: the channel isolated (1-based), 0 without alarm, −1 unknown.
pub fn isolated(diagnoser: &str) -> String {
    format!("/diagnosis/{diagnoser}/isolated")
}

/// The entity a signal is stored in (layout 2, [`crate::write::LAYOUT`]): the component that
/// publishes it, so that one row of an entity holds all of that component's scalars of a step
/// (`/plant` holds x, y, w, v, r and the faults; `/observer/<name>` x̂, e, r, ŵ and log10 max|e|;
/// `/controller` u; `/diagnoser/<d>` and `/diagnosis/<d>` a bank's residuals and decisions;
/// `/latency` the step and hop times). The signal's own path stays its name in every reader.
pub fn entity_of(path: &str) -> String {
    let mut parts = path.trim_start_matches('/').split('/');
    let first = parts.next().unwrap_or("");
    match first {
        "observer" | "diagnoser" | "diagnosis" => match parts.next() {
            Some(name) => format!("/{first}/{name}"),
            None => format!("/{first}"),
        },
        "plant" | "disturbance" | "measurement_disturbance" | "input" | "fault" => {
            "/plant".to_string()
        }
        _ => format!("/{first}"),
    }
}
