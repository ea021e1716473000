//! A recording of a run at an operating point in deviations (`uio-launcher export --deviations`,
//! `uio-launcher plot --deviations`): every recorded signal is in the plant's own (absolute) units,
//! and this shifts each by its value at the point,
//!
//! ```text
//! δx = x − x_op,  δx̂ = x̂ − x_op,  δy = y − y_op,  δu = u − u_op,  δw = w − w_op,  δŵ = ŵ − w_op,
//! ```
//!
//! a reference by its level at the point (r_op = C_t x_op for a tracked output, u_op for an
//! input driven directly or a measured disturbance). Errors x − x̂, residuals, faults and every
//! diagnosis signal are differences already and stay as recorded.

use crate::read::Recording;
use crate::tools::recorded_scenario;

/// `r` with its signals shifted to deviations from the recorded scenario's operating point; an
/// error when the recording holds no scenario or its scenario no point.
pub fn in_deviations(r: &Recording) -> Result<Recording, String> {
    let s = recorded_scenario(r).ok_or(
        "the recording holds no scenario that can be read, so no operating point to subtract",
    )?;
    let op = s
        .operating_point
        .as_ref()
        .filter(|op| !op.is_origin())
        .ok_or("its scenario has no [plant.operating_point]: its signals are deviations already")?;
    let references = reference_levels(&s, op);
    let mut out = r.clone();
    for (path, series) in &mut out.series {
        if let Some(level) = level(path, op, &references) {
            for v in &mut series.values {
                *v -= level;
            }
        }
    }
    Ok(out)
}

/// r_op per input: C_t x_op for a commanded input under a controller with tracked outputs, else
/// u_op (the input's own level).
fn reference_levels(s: &scenario::Scenario, op: &lti::OperatingPoint) -> Vec<f64> {
    let mut levels = op.u.clone();
    if let Some(ct) = s
        .controller
        .as_ref()
        .and_then(|c| c.track.as_ref().map(|t| (c, t)))
    {
        let (c, ct) = ct;
        let z = ct * lti::Mat::from_column_slice(op.x.len(), 1, &op.x);
        let commanded = (0..op.u.len()).filter(|j| !c.measured.contains(j));
        for (i, j) in commanded.enumerate() {
            levels[j] = z[i];
        }
    }
    levels
}

/// The level at the point of the signal at `path` (1-based index last), if it has one.
fn level(path: &str, op: &lti::OperatingPoint, references: &[f64]) -> Option<f64> {
    let (group, index) = path.rsplit_once('/')?;
    let i = index.parse::<usize>().ok()?.checked_sub(1)?;
    let kind = group
        .strip_prefix("/observer/")
        .and_then(|g| g.split_once('/'))
        .map_or(group, |(_, kind)| kind);
    match kind {
        "/plant/x" | "xhat" => op.x.get(i).copied(),
        "/plant/y" => op.y.get(i).copied(),
        "/disturbance" | "what" => op.w.get(i).copied(),
        "/controller/u" => op.u.get(i).copied(),
        "/input" => references.get(i).copied(),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_signal_takes_its_own_level_and_differences_none() {
        let op = lti::OperatingPoint {
            x: vec![1.0, 2.0],
            u: vec![3.0],
            w: vec![4.0],
            y: vec![5.0],
        };
        let refs = [6.0];
        assert_eq!(level("/plant/x/2", &op, &refs), Some(2.0));
        assert_eq!(level("/observer/uio/xhat/1", &op, &refs), Some(1.0));
        assert_eq!(level("/observer/uio/what/1", &op, &refs), Some(4.0));
        assert_eq!(level("/plant/y/1", &op, &refs), Some(5.0));
        assert_eq!(level("/controller/u/1", &op, &refs), Some(3.0));
        assert_eq!(level("/input/1", &op, &refs), Some(6.0));
        for path in [
            "/observer/uio/error/1",
            "/observer/uio/residual/1",
            "/diagnoser/b/residual/1/1",
            "/fault/f/value",
            "/latency/step",
        ] {
            assert_eq!(level(path, &op, &refs), None, "{path}");
        }
    }
}
