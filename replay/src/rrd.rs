//! A run's own `.rrd` as plant samples: its recorded x, y, w, v and r are the plant's samples
//! exactly as the run recorded them (f64 for f64, so that a replay through the same observers
//! records the same bits), and u_{k−1} is what the plant held over the step: the controller's
//! recorded u_{k−1} in a closed-loop run, else the input r(t_{k−1}).

use std::path::Path;

use recording::digest::Integrity;
use recording::read::{Series, read};
use recording::signals;

use crate::Params;
use crate::table::{Facts, Table, enough};

/// Reads the recording the parameters name.
pub fn load(p: &Params) -> Result<Table, String> {
    let file = p.file();
    let rec = read(Path::new(&p.path)).map_err(|e| format!("{file}: {}", e.reason))?;
    if let Integrity::Damaged(why) = &rec.integrity {
        return Err(format!("{file}: damaged recording: {why}"));
    }
    if let Some(dt) = recording::tools::recorded_dt(&rec)
        && dt != p.dt
    {
        return Err(format!(
            "{file}: recorded at dt = {dt}; the scenario's dt = {}: a replay keeps the run's grid",
            p.dt
        ));
    }
    let count = |path: fn(usize) -> String| {
        (0..)
            .take_while(|&i| rec.series.contains_key(&path(i)))
            .count()
    };
    let have = (
        count(signals::state),
        count(signals::output),
        count(signals::input),
        count(signals::disturbance),
        count(signals::measurement_disturbance),
    );
    let want = (p.n, p.p, p.l, p.q, p.r);
    if have != want {
        let sizes = |(n, pp, l, q, r): (usize, usize, usize, usize, usize)| {
            format!("n = {n}, p = {pp}, l = {l}, q = {q}, r = {r}")
        };
        return Err(format!(
            "{file}: the recorded plant has {}; the scenario's plant has {}: a replay needs the same sizes",
            sizes(have),
            sizes(want)
        ));
    }
    let closed = rec.series.contains_key(&signals::control(0));
    let get = |path: String| -> Result<&Series, String> {
        rec.series
            .get(&path)
            .ok_or_else(|| format!("{file}: {path} is not recorded"))
    };
    let group = |path: fn(usize) -> String, m: usize| -> Result<Vec<&Series>, String> {
        (0..m).map(|i| get(path(i))).collect()
    };
    let x = group(signals::state, p.n)?;
    let y = group(signals::output, p.p)?;
    let w = group(signals::disturbance, p.q)?;
    let v = group(signals::measurement_disturbance, p.r)?;
    let r = group(signals::input, p.l)?;
    let u = if closed {
        group(signals::control, p.l)?
    } else {
        r.clone()
    };
    let recorded = x[0].steps.len();
    // Every step of the run, in order, in every signal: a run recorded with --record-every or
    // --record has gaps no replay can fill.
    for (s, name) in x
        .iter()
        .chain(&y)
        .chain(&w)
        .chain(&v)
        .chain(&r)
        .chain(&u)
        .zip(names(p, closed))
    {
        if s.steps.len() != recorded || s.values.len() != recorded {
            return Err(format!(
                "{file}: {name} has {} rows, {} has {recorded}: the run was recorded in part (--record)",
                s.steps.len(),
                signals::state(0)
            ));
        }
        if let Some(i) = s.steps.iter().enumerate().position(|(i, &k)| k != i as i64) {
            return Err(format!(
                "{file}: {name}: row {} is step {}, not {i}: a replay needs every step (the run was recorded with --record-every)",
                i + 1,
                s.steps[i]
            ));
        }
    }
    enough(&file, recorded as u64, "recorded steps", p.steps)?;
    let samples = recorded.min(p.steps as usize + 1);
    let width = p.n + p.p + p.q + p.r + 2 * p.l;
    let mut data = Vec::with_capacity(samples * width);
    for k in 0..samples {
        for s in x.iter().chain(&y).chain(&w).chain(&v).chain(&r) {
            data.push(s.values[k]);
        }
        data.extend(u.iter().map(|s| if k == 0 { 0.0 } else { s.values[k - 1] }));
    }
    let facts = Facts {
        file,
        rows: recorded as u64,
        samples: samples as u64,
        held_rows: 0,
        held_cells: 0,
        states: true,
        disturbances: true,
    };
    Ok(Table { width, data, facts })
}

/// The entity paths read, in the order `load` checks them.
fn names(p: &Params, closed: bool) -> Vec<String> {
    let mut out: Vec<String> = (0..p.n).map(signals::state).collect();
    out.extend((0..p.p).map(signals::output));
    out.extend((0..p.q).map(signals::disturbance));
    out.extend((0..p.r).map(signals::measurement_disturbance));
    out.extend((0..p.l).map(signals::input));
    out.extend((0..p.l).map(if closed {
        signals::control
    } else {
        signals::input
    }));
    out
}
