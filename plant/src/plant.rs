//! Exact sampled-data integration of the plant over each step.
//!
//! Over a stretch [t₀, t₀ + h] in which u and the piecewise-constant parts c(t) of the
//! disturbances are constant, each disturbance is w_i(t) = a_i sin(ω_i t + φ_i) + c_i, and the
//! generator g_i = [sin(ω_i t + φ_i), cos(ω_i t + φ_i)] obeys ġ_i = [0 ω_i; −ω_i 0] g_i. With
//! ξ = [u; c; g₁; …] the augmented input,
//!
//! ```text
//! x(t₀ + h) = Φ_h x(t₀) + Γ_h ξ(t₀),    [Φ_h Γ_h] = top rows of exp([[A, G], [0, W]] h),
//! G = [B, E, a₁E₁ e₁ᵀ, …],  W = blockdiag(0, 0, Ω₁, …)
//! ```
//!
//! (Φ_h and the B, E columns are computed by [`lti::Model::discretize`], exactly as the observer
//! designs compute them; each generator's columns by its own block exponential.)
//!
//! is exact: nothing inside the step is approximated. A step that contains a switching time of
//! some c(t) strictly inside it is split there; its pieces' exponentials and held values are
//! computed once, at construction. Whether a switching time is on a sample or inside a step is
//! decided exactly, on the decimals the scenario writes ([`lti::signal::locate`]): no tolerance.
//! The generator is re-evaluated from t at every step rather than propagated, so it cannot drift.
//!
//! A discrete-time plant (`PlantConfig::discrete`, an identified model) is given per step:
//! x_{k+1} = Φx_k + Γ_Bu_k + Γ_Ew(t_k), the unknown inputs sampled at t_k and held — the same
//! recursion with Φ_h = Φ, Γ_h = [Γ_B, Γ_E, a_iΓ_E,i e₁ᵀ …] and no step split.

use lockstep::PlantLayout;
use lti::discretize::exp_upper;
use lti::kernel::{copy, mul_acc, mul_into};
use lti::sampled::SampledSignal;
use lti::signal::{Switch, locate};
use nalgebra::{DMatrix, DVector};

use crate::config::PlantConfig;
use crate::fault::Target;
use crate::noise::{Gaussian, PROCESS};
use crate::sensing::Sensing;

/// A stretch of a step with its transition matrices.
#[derive(Debug, Clone)]
struct Piece {
    /// Offset of the stretch from t_k, s.
    offset: f64,
    phi: DMatrix<f64>,
    gamma: DMatrix<f64>,
    /// c(t) of each disturbance on this piece of a split step (empty for the whole step, whose
    /// held values are those of its first sample).
    held: Vec<f64>,
}

/// A state left its bound or became non-finite.
#[derive(Debug, Clone, PartialEq)]
pub struct Divergence {
    /// The step whose result diverged (x_{step+1}).
    pub step: u64,
    /// The index of the state that diverged (from 0; messages name it x{state + 1}, the
    /// project's 1-based numbering of signals).
    pub state: usize,
    /// Its value.
    pub value: f64,
    /// The bound it exceeded.
    pub bound: f64,
}

impl std::fmt::Display for Divergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.value.is_finite() {
            write!(
                f,
                "x{} = {:.6e} left the bound ±{:.3e} at step {}",
                self.state + 1,
                self.value,
                self.bound,
                self.step + 1
            )
        } else {
            write!(
                f,
                "x{} = {} at step {}",
                self.state + 1,
                self.value,
                self.step + 1
            )
        }
    }
}

/// The plant as a step function.
#[derive(Debug, Clone)]
pub struct Plant {
    dt: f64,
    bound: f64,
    disturbances: Vec<SampledSignal>,
    measurement: Vec<SampledSignal>,
    inputs: Vec<SampledSignal>,
    /// (disturbance index, ω, φ) of each sinusoidal part.
    sines: Vec<(usize, f64, f64)>,
    /// (sin, cos) of each generator at the last sampled t_k, shared by the sample and the step.
    generators: Vec<(f64, f64)>,
    c: DMatrix<f64>,
    d: DMatrix<f64>,
    full: Piece,
    /// Steps split at switching times, sorted by step.
    splits: Vec<(u64, Vec<Piece>)>,
    next_split: usize,
    layout: PlantLayout,
    x: DVector<f64>,
    x_next: DVector<f64>,
    xi: DVector<f64>,
    out: Vec<f64>,
    /// Faults and measurement noise (shared with every plant that applies them).
    sensing: Sensing,
    /// Per fault acting through the state equation: (fault index, Γ₀ column, Γ₁ column).
    state_faults: Vec<(usize, DVector<f64>, DVector<f64>)>,
    process_noise: Option<Gaussian>,
    /// The input applied over the step (the commanded one changed by actuator faults).
    u_applied: Vec<f64>,
}

impl Plant {
    /// Precomputes the transition matrices; fails on inconsistent sizes.
    // one job: the plant's precomputed transition matrices, built once from a config whose every size
    // is checked where it is used.
    pub fn new(cfg: &PlantConfig) -> Result<Self, String> {
        let a: DMatrix<f64> = (&cfg.a).into();
        let b: DMatrix<f64> = (&cfg.b).into();
        let c: DMatrix<f64> = (&cfg.c).into();
        let e: DMatrix<f64> = (&cfg.e).into();
        let d: DMatrix<f64> = (&cfg.d).into();
        let (n, l, q, p, r) = (a.nrows(), b.ncols(), e.ncols(), c.nrows(), d.ncols());
        let consistent = a.ncols() == n
            && b.nrows() == n
            && e.nrows() == n
            && c.ncols() == n
            && d.nrows() == p
            && cfg.x0.len() == n
            && cfg.disturbances.len() == q
            && cfg.measurement_disturbances.len() == r
            && cfg.inputs.len() == l;
        if !consistent {
            return Err("plant configuration: matrix and signal sizes do not conform".into());
        }
        let sines: Vec<(usize, f64, f64)> = cfg
            .disturbances
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.sine().map(|(_, w, ph)| (i, w, ph)))
            .collect();
        let m = l + q + 2 * sines.len();
        let model = lti::Model {
            a: a.clone(),
            b: b.clone(),
            c: c.clone(),
            e: e.clone(),
            d: d.clone(),
        };
        // Φ, B_d and E_d exactly as the observer designs compute them (Model::discretize), so
        // plant and observers share the same sampled model to the last bit; only the sine
        // generators' columns need the larger exponential.
        let piece = |offset: f64, h: f64| {
            let dm = model.discretize(h);
            let mut gamma = DMatrix::<f64>::zeros(n, m);
            gamma.columns_mut(0, l).copy_from(&dm.b);
            gamma.columns_mut(l, q).copy_from(&dm.e);
            for (j, &(i, omega, _)) in sines.iter().enumerate() {
                let amp = cfg.disturbances[i].sine().map_or(0.0, |s| s.0);
                let mut g = DMatrix::<f64>::zeros(n, 2);
                g.set_column(0, &(e.column(i) * amp));
                let w = DMatrix::from_row_slice(2, 2, &[0.0, omega, -omega, 0.0]);
                let (_, gj) = exp_upper(&a, &g, &w, h);
                gamma.columns_mut(l + q + 2 * j, 2).copy_from(&gj);
            }
            Piece {
                offset,
                phi: dm.a,
                gamma,
                held: Vec::new(),
            }
        };
        let (full, splits) = if cfg.discrete {
            // Φ, Γ_B, Γ_E as given; a sine enters through its value at t_k: a_i·sin(ω_it_k + φ_i)·Γ_E,i.
            let mut gamma = DMatrix::<f64>::zeros(n, m);
            gamma.columns_mut(0, l).copy_from(&b);
            gamma.columns_mut(l, q).copy_from(&e);
            for (j, &(i, _, _)) in sines.iter().enumerate() {
                let amp = cfg.disturbances[i].sine().map_or(0.0, |s| s.0);
                gamma.set_column(l + q + 2 * j, &(e.column(i) * amp));
            }
            (
                Piece {
                    offset: 0.0,
                    phi: a.clone(),
                    gamma,
                    held: Vec::new(),
                },
                Vec::new(),
            )
        } else {
            (piece(0.0, cfg.dt), split_steps(cfg, &piece))
        };
        let layout = PlantLayout {
            n,
            p,
            q,
            r,
            l,
            f: cfg.faults.len(),
        };
        let ff: DMatrix<f64> = (&cfg.ff).into();
        for f in &cfg.faults {
            let fits = match f.target {
                Target::Actuator(i) => i < l,
                Target::Sensor(j) => j < p,
                Target::Component(j) => j < ff.ncols() && ff.nrows() == n,
            };
            if !fits {
                return Err(format!(
                    "fault '{}': its target does not exist in this plant",
                    f.name
                ));
            }
        }
        // [Γ₀ Γ₁] of a column f: exp([[A, f, 0], [0, 0, 1], [0, 0, 0]]·dt), see crate::fault.
        let ramp_generator = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let state_faults = cfg
            .faults
            .iter()
            .enumerate()
            .filter(|(_, f)| f.through_state())
            .map(|(i, f)| {
                let column = match f.target {
                    Target::Actuator(j) => b.column(j).into_owned(),
                    Target::Component(j) => ff.column(j).into_owned(),
                    Target::Sensor(_) => unreachable!("sensor faults act at the sample"),
                };
                if cfg.discrete {
                    // Γ₀ is the column itself (a per-step distribution); f is held at f(t_k).
                    return (i, column.clone(), DVector::zeros(n));
                }
                let mut g = DMatrix::<f64>::zeros(n, 2);
                g.set_column(0, &column);
                let (_, gamma) = exp_upper(&a, &g, &ramp_generator, cfg.dt);
                (
                    i,
                    gamma.column(0).into_owned(),
                    gamma.column(1).into_owned(),
                )
            })
            .collect();
        let process_noise = match &cfg.noise {
            Some(z) if (z.qd.rows, z.qd.cols) != (n, n) => {
                return Err("plant configuration: the noise covariances do not conform".into());
            }
            Some(z) => Gaussian::new(&z.qd, z.seed, PROCESS),
            None => None,
        };
        let sensing = Sensing::new(cfg)?;
        Ok(Self {
            dt: cfg.dt,
            bound: cfg.state_bound,
            disturbances: SampledSignal::all(&cfg.disturbances, cfg.dt),
            measurement: SampledSignal::all(&cfg.measurement_disturbances, cfg.dt),
            inputs: SampledSignal::all(&cfg.inputs, cfg.dt),
            generators: vec![(0.0, 1.0); sines.len()],
            sines,
            c,
            d,
            full,
            splits,
            next_split: 0,
            layout,
            x: DVector::from_column_slice(&cfg.x0),
            x_next: DVector::zeros(n),
            xi: DVector::zeros(m),
            out: vec![0.0; layout.len()],
            sensing,
            state_faults,
            process_noise,
            u_applied: vec![0.0; l],
        })
    }

    /// Where each signal sits in [`Plant::sample`]'s output.
    pub fn layout(&self) -> PlantLayout {
        self.layout
    }

    /// t_k = k·dt.
    pub fn time(&self, k: u64) -> f64 {
        k as f64 * self.dt
    }

    /// The sample of step k: [x_k | y_k | w(t_k) | v(t_k) | r(t_k) | u_{k−1}].
    pub fn sample(&mut self, k: u64) -> &[f64] {
        let t = self.time(k);
        let lay = self.layout;
        for (g, &(_, omega, phase)) in self.generators.iter_mut().zip(&self.sines) {
            *g = (omega * t + phase).sin_cos();
        }
        let out = &mut self.out;
        copy(&mut out[lay.x()], self.x.as_slice());
        let mut next_sine = 0;
        for (i, (o, s)) in out[lay.w()].iter_mut().zip(&self.disturbances).enumerate() {
            *o = match self.sines.get(next_sine) {
                Some(&(d, _, _)) if d == i => {
                    let amplitude = s.sine().map_or(0.0, |a| a.0);
                    next_sine += 1;
                    amplitude * self.generators[next_sine - 1].0 + s.held_at_step(k)
                }
                _ => s.sample_step(k),
            };
        }
        for (o, s) in out[lay.v()].iter_mut().zip(&self.measurement) {
            *o = s.sample_step(k);
        }
        for (o, s) in out[lay.r()].iter_mut().zip(&self.inputs) {
            *o = s.sample_step(k);
        }
        // y = C x + D v, written in place.
        let (head, tail) = out.split_at_mut(lay.w().start);
        let y = &mut head[lay.y()];
        mul_into(y, &self.c, self.x.as_slice());
        mul_acc(
            y,
            &self.d,
            &tail[lay.v().start - lay.w().start..lay.v().end - lay.w().start],
        );
        let slots = lay.faults().start - lay.w().start;
        self.sensing.sense(k, y, &mut tail[slots..]);
        &self.out
    }

    /// The input signals r(t_k) of the last [`Plant::sample`] (the open-loop u_k).
    pub fn reference(&self) -> &[f64] {
        &self.out[self.layout.r()]
    }

    /// x_k → x_{k+1} with u_k held over the step (as commanded: actuator faults change what
    /// acts on the plant, not what the observers are told).
    pub fn advance(&mut self, k: u64, u: &[f64]) -> Result<(), Divergence> {
        let t = self.time(k);
        let lay = self.layout;
        copy(&mut self.out[lay.u_prev()], u);
        // Additive actuator faults act through the state equation below, integrated exactly.
        self.sensing.actuate(k, u, &mut self.u_applied, false);
        let u = self.u_applied.as_slice();
        let pieces: &[Piece] = match self.splits.get(self.next_split) {
            Some((s, pieces)) if *s == k => {
                self.next_split += 1;
                pieces
            }
            _ => std::slice::from_ref(&self.full),
        };
        for piece in pieces {
            let at_tk = (piece.offset == 0.0).then_some(self.generators.as_slice());
            let (l, q) = (u.len(), self.disturbances.len());
            // c(t) on the piece: precomputed for a split step; the first sample's otherwise.
            let held = &mut self.xi.as_mut_slice()[l..l + q];
            if piece.held.is_empty() {
                for (c, s) in held.iter_mut().zip(&self.disturbances) {
                    *c = s.held_at_step(k);
                }
            } else {
                copy(held, &piece.held);
            }
            integrate(
                piece,
                t,
                u,
                &self.sines,
                at_tk,
                &mut self.xi,
                &mut self.x,
                &mut self.x_next,
            );
        }
        // Faults through the state equation, over the whole step (superposition: the split of
        // a step at a disturbance's switching time does not concern them).
        for (i, g0, g1) in &self.state_faults {
            let (phi, slope) = self.sensing.faults[*i].magnitude(k, self.dt);
            if phi != 0.0 || slope != 0.0 {
                self.x.axpy(phi, g0, 1.0);
                self.x.axpy(slope, g1, 1.0);
            }
        }
        if let Some(g) = &mut self.process_noise {
            g.add_to(self.x.as_mut_slice());
        }
        for (i, &v) in self.x.as_slice().iter().enumerate() {
            if !v.is_finite() || v.abs() > self.bound {
                return Err(Divergence {
                    step: k,
                    state: i,
                    value: v,
                    bound: self.bound,
                });
            }
        }
        Ok(())
    }
}

/// x ← Φ_h x + Γ_h ξ(t₀) for one piece starting at t_k + offset; ξ's held part c is set by the
/// caller.
#[allow(clippy::too_many_arguments)]
fn integrate(
    piece: &Piece,
    tk: f64,
    u: &[f64],
    sines: &[(usize, f64, f64)],
    generators_at_tk: Option<&[(f64, f64)]>,
    xi: &mut DVector<f64>,
    x: &mut DVector<f64>,
    x_next: &mut DVector<f64>,
) {
    let t0 = tk + piece.offset;
    let l = u.len();
    let q = xi.len() - l - 2 * sines.len();
    copy(&mut xi.as_mut_slice()[..l], u);
    for (j, &(_, omega, phase)) in sines.iter().enumerate() {
        let (sin, cos) = match generators_at_tk {
            Some(g) => g[j],
            None => (omega * t0 + phase).sin_cos(),
        };
        xi[l + q + 2 * j] = sin;
        xi[l + q + 2 * j + 1] = cos;
    }
    mul_into(x_next.as_mut_slice(), &piece.phi, x.as_slice());
    mul_acc(x_next.as_mut_slice(), &piece.gamma, xi.as_slice());
    std::mem::swap(x, x_next);
}

/// The steps that contain a switching time strictly inside them, with their pieces: each piece
/// holds, for every disturbance, the value of its first sample changed by the switches in the
/// step up to the piece's start.
fn split_steps(cfg: &PlantConfig, piece: &dyn Fn(f64, f64) -> Piece) -> Vec<(u64, Vec<Piece>)> {
    let dt = cfg.dt;
    let inside = |tb: f64| match locate(tb, dt) {
        Switch::Inside { step, offset } if step < cfg.steps && offset > 0.0 && offset < dt => {
            Some((step, offset))
        }
        _ => None, // on a sample (the sampling rule makes it there) or outside the run
    };
    let mut cuts: Vec<(u64, f64)> = cfg
        .disturbances
        .iter()
        .flat_map(|s| s.breakpoints())
        .filter_map(inside)
        .collect();
    cuts.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    cuts.dedup();
    let mut out: Vec<(u64, Vec<Piece>)> = Vec::new();
    let mut i = 0;
    while i < cuts.len() {
        let k = cuts[i].0;
        let mut offsets = vec![0.0];
        while i < cuts.len() && cuts[i].0 == k {
            offsets.push(cuts[i].1);
            i += 1;
        }
        offsets.push(dt);
        let pieces = offsets
            .windows(2)
            .map(|w| {
                let mut p = piece(w[0], w[1] - w[0]);
                p.held = cfg
                    .disturbances
                    .iter()
                    .map(|s| {
                        let switched = s.breakpoints().iter().rposition(|&tb| {
                            inside(tb).is_some_and(|(st, off)| st == k && off <= w[0])
                        });
                        switched.map_or_else(|| s.held_at_step(k, dt), |j| s.held_after(j))
                    })
                    .collect();
                p
            })
            .collect();
        out.push((k, pieces));
    }
    out
}
