//! Figures of merit, accumulated step by step: per observer the largest |x − x̂| and |y − Cx̂|
//! over the last quarter of the steps completed (the "tail", after transients; see [`super::tail`]),
//! and between observers the largest difference of their estimates at any step.

use lockstep::PlantLayout;
use lti::Mat;
use lti::kernel::mul_into;

use super::StepRow;
use super::tail::{BlockMax, tail_start};
use super::what::InputEstimate;
use crate::nan::nan_max;

/// The figures of one observer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObserverFigures {
    /// max_k≥tail max_i |x_i − x̂_i|; `None` when the run has no tail (fewer than 4 steps).
    pub tail_max_abs_error: Option<f64>,
    /// max_k≥tail max_j |y_j − (Cx̂)_j|.
    pub tail_max_abs_residual: Option<f64>,
    /// max over the whole run of max_i |x_i − x̂_i|.
    pub max_abs_error: f64,
    /// max_i |x_i − x̂_i| at the last step.
    pub final_abs_error: f64,
    /// max over the tail of max_j |w_j − ŵ_j|, for an observer that estimates w.
    pub tail_max_abs_input_error: Option<f64>,
    /// The same figures over the fault-free stretch before the first fault, in a run with faults
    /// that completed at least four of those steps.
    pub fault_free: Option<FaultFree>,
}

/// An observer's figures over the steps [0, F) before the first fault (F its first step): its
/// tail is that stretch's last quarter, [F − ⌊F/4⌋, F).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct FaultFree {
    /// F·dt: how long the stretch is, s.
    pub until: f64,
    /// max |x − x̂| over its last quarter.
    pub tail_max_abs_error: f64,
    /// max |y − Cx̂| over its last quarter.
    pub tail_max_abs_residual: f64,
    /// max |x − x̂| over the stretch.
    pub max_abs_error: f64,
}

/// Accumulates [`ObserverFigures`] and pairwise differences.
#[derive(Debug, Clone)]
pub struct Metrics {
    layout: PlantLayout,
    c: Mat,
    planned: u64,
    /// First step of the tail of a run that completes: [K − ⌊K/4⌋, K), or [K − L, K).
    planned_tail: u64,
    /// The tail's length L where the scenario sets it.
    tail: Option<u64>,
    /// Per observer, max |e| and max |r| from `planned_tail` on: exact for a completed run.
    exact: Vec<[f64; 2]>,
    /// Per observer, block maxima of max_i |e_i| and max_j |r_j| (the tail of an early stop).
    blocks: Vec<[BlockMax; 2]>,
    /// Per observer.
    pub observers: Vec<ObserverFigures>,
    /// max_k max_i |x̂_a − x̂_b| for each pair (a, b), a < b.
    pub differences: Vec<((usize, usize), f64)>,
    /// Steps seen.
    pub steps: u64,
    /// e_k and r_k of the last row, per observer (for the recording).
    pub error: Vec<Vec<f64>>,
    /// Residuals of the last row.
    pub residual: Vec<Vec<f64>>,
    /// Per observer, its unknown-input estimate ŵ when it has one.
    pub what: Vec<Option<InputEstimate>>,
    /// The first step a fault acts in, its time, and per observer [tail max|e|, tail max|r|,
    /// max|e|] over the steps before it ([`FaultFree`]).
    fault_free: Option<(u64, f64, Vec<[f64; 3]>)>,
    /// c_r = y_op − C x_op where it is not zero ([`Metrics::residual_offset`]).
    c_r: Option<Vec<f64>>,
}

impl Metrics {
    /// For a run of `steps` steps with `observers` observers, whose tail is its last `tail`
    /// steps (`None`: its last quarter; [`super::tail`]).
    pub fn new(
        layout: PlantLayout,
        c: Mat,
        observers: usize,
        steps: u64,
        tail: Option<u64>,
    ) -> Self {
        let mut differences = Vec::new();
        for a in 0..observers {
            for b in a + 1..observers {
                differences.push(((a, b), 0.0));
            }
        }
        Metrics {
            layout,
            c,
            planned: steps,
            planned_tail: tail_start(steps, steps, tail).unwrap_or(steps),
            tail,
            exact: vec![[0.0; 2]; observers],
            blocks: (0..observers)
                .map(|_| [BlockMax::new(steps), BlockMax::new(steps)])
                .collect(),
            observers: vec![ObserverFigures::default(); observers],
            differences,
            steps: 0,
            error: vec![vec![0.0; layout.n]; observers],
            residual: vec![vec![0.0; layout.p]; observers],
            what: vec![None; observers],
            fault_free: None,
            c_r: None,
        }
    }

    /// At an operating point whose y_op is not C x_op (an output map that is not linear), the
    /// residual is formed in deviations, r = (y − y_op) − C(x̂ − x_op) = y − C x̂ − c_r with
    /// c_r = y_op − C x_op; a zero c_r changes nothing.
    pub fn residual_offset(&mut self, c_r: Vec<f64>) {
        self.c_r = c_r.iter().any(|&v| v != 0.0).then_some(c_r);
    }

    /// The run's first fault acts from step `first` (of period dt): figures are kept for the
    /// steps before it too.
    pub fn fault_free_until(&mut self, first: u64, dt: f64) {
        self.fault_free = Some((
            first,
            first as f64 * dt,
            vec![[0.0; 3]; self.observers.len()],
        ));
    }

    /// Observer `o` estimates the unknown inputs: ŵ_k = W y_{k+1} − (WCΦ) x̂_k − (WCΓ_B) u_k
    /// (+ c at an operating point, `offset`).
    pub fn estimate_inputs(
        &mut self,
        o: usize,
        w: Mat,
        w_c_phi: &Mat,
        w_c_gamma_b: &Mat,
        offset: Option<Vec<f64>>,
    ) {
        self.what[o] = Some(InputEstimate::new(
            w,
            w_c_phi,
            w_c_gamma_b,
            offset,
            self.planned,
            self.planned_tail,
        ));
    }

    /// The first step of the tail of the steps completed so far.
    pub fn tail_start(&self) -> Option<u64> {
        tail_start(self.steps, self.planned, self.tail)
    }

    /// Sets each observer's tail figures from the steps completed; call once the run has ended.
    /// A run that completed has its exact tail; one stopped early the block maxima's.
    pub fn finish(&mut self) {
        let start = self.tail_start();
        let completed = self.steps >= self.planned;
        for (((f, [e, r]), exact), what) in self
            .observers
            .iter_mut()
            .zip(&self.blocks)
            .zip(&self.exact)
            .zip(&self.what)
        {
            f.tail_max_abs_error = start.map(|s| if completed { exact[0] } else { e.max_from(s) });
            f.tail_max_abs_residual =
                start.map(|s| if completed { exact[1] } else { r.max_from(s) });
            f.tail_max_abs_input_error = what
                .as_ref()
                .and_then(|w| start.map(|s| w.tail_max_abs_error(s, completed)));
        }
        if let Some((first, until, ff)) = &self.fault_free
            && *first / 4 > 0
            && self.steps >= *first
        {
            for (f, m) in self.observers.iter_mut().zip(ff) {
                f.fault_free = Some(FaultFree {
                    until: *until,
                    tail_max_abs_error: m[0],
                    tail_max_abs_residual: m[1],
                    max_abs_error: m[2],
                });
            }
        }
    }

    /// Adds one step.
    pub fn push(&mut self, row: &StepRow) {
        let k = row.k;
        let lay = self.layout;
        let (x, y) = (&row.plant[lay.x()], &row.plant[lay.y()]);
        let in_tail = k >= self.planned_tail;
        // When step k is in the fault-free stretch [0, F): whether in its last quarter.
        let fault_free = match &self.fault_free {
            Some((first, _, _)) if k < *first => Some(k >= *first - *first / 4),
            _ => None,
        };
        for o in 0..self.observers.len() {
            let xhat = &row.xhat[o][..x.len()];
            let error = &mut self.error[o][..x.len()];
            let mut emax = 0.0;
            for i in 0..x.len() {
                error[i] = x[i] - xhat[i];
                emax = nan_max(emax, error[i].abs());
            }
            let res = &mut self.residual[o][..y.len()];
            mul_into(res, &self.c, xhat);
            // One pass: r = y − Cx̂ (− c_r at a point whose output map is not linear).
            let mut rmax = 0.0;
            match &self.c_r {
                None => {
                    for j in 0..y.len() {
                        res[j] = y[j] - res[j];
                        rmax = nan_max(rmax, res[j].abs());
                    }
                }
                Some(c_r) => {
                    for j in 0..y.len() {
                        res[j] = y[j] - res[j] - c_r[j];
                        rmax = nan_max(rmax, res[j].abs());
                    }
                }
            }
            if let Some(what) = &mut self.what[o] {
                what.push(k, y, &row.plant[lay.u_prev()], &row.plant[lay.w()], xhat);
            }
            let f = &mut self.observers[o];
            f.max_abs_error = nan_max(f.max_abs_error, emax);
            f.final_abs_error = emax;
            let [be, br] = &mut self.blocks[o];
            be.push(k, emax);
            br.push(k, rmax);
            if in_tail {
                let exact = &mut self.exact[o];
                exact[0] = nan_max(exact[0], emax);
                exact[1] = nan_max(exact[1], rmax);
            }
            if let (Some(last_quarter), Some((_, _, ff))) = (fault_free, &mut self.fault_free) {
                let m = &mut ff[o];
                if last_quarter {
                    m[0] = nan_max(m[0], emax);
                    m[1] = nan_max(m[1], rmax);
                }
                m[2] = nan_max(m[2], emax);
            }
        }
        for ((a, b), d) in self.differences.iter_mut() {
            for (xa, xb) in row.xhat[*a].iter().zip(&row.xhat[*b]) {
                *d = nan_max(*d, (xa - xb).abs());
            }
        }
        self.steps += 1;
    }

    /// max_i |x_i − x̂_i| of observer `o` at the last step (NaN when x̂ is not finite).
    #[inline]
    pub fn last_max_abs_error(&self, o: usize) -> f64 {
        self.observers[o].final_abs_error
    }

    /// max |x̂_a − x̂_b| for observers a and b.
    pub fn difference(&self, a: usize, b: usize) -> Option<f64> {
        let key = (a.min(b), a.max(b));
        self.differences
            .iter()
            .find(|(p, _)| *p == key)
            .map(|(_, d)| *d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::write::StepRow;

    #[test]
    fn a_residual_at_an_operating_point_is_formed_in_deviations() {
        // n = 1, p = 1: y = 2.5 at x = 1 where C = 2 gives 2, so c_r = y_op − C x_op = 0.5 for a
        // point (x_op, y_op) = (1, 2.5); x̂ = 1 at y = 2.5 is then no residual at all.
        let layout = PlantLayout {
            n: 1,
            p: 1,
            q: 0,
            r: 0,
            l: 0,
            f: 0,
        };
        let c = Mat::from_element(1, 1, 2.0);
        let op = lti::OperatingPoint {
            x: vec![1.0],
            u: vec![],
            w: vec![],
            y: vec![2.5],
        };
        let mut row = StepRow::new(layout, 1, false);
        row.plant[layout.x()][0] = 1.0;
        row.plant[layout.y()][0] = 2.5;
        row.xhat[0][0] = 1.0;
        let mut without = Metrics::new(layout, c.clone(), 1, 4, None);
        without.push(&row);
        assert_eq!(without.residual[0], [0.5]);
        let mut with = Metrics::new(layout, c.clone(), 1, 4, None);
        with.residual_offset(op.output_offset(&c));
        with.push(&row);
        assert_eq!(with.residual[0], [0.0]);
        // A linear output map leaves y − C x̂ untouched (c_r = 0 is not applied).
        let mut linear = Metrics::new(layout, c, 1, 4, None);
        linear.residual_offset(vec![0.0]);
        assert!(linear.c_r.is_none());
    }
}
