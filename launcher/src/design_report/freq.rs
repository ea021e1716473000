//! `uio-launcher design --freq`: the frequency responses of every observer and bank member
//! ([`diagnosis::freq`]) on one grid, as numbers in the report, JSON and σ plots.
//!
//! Per observer: w → e and v → e (what of the unknown inputs and of sensor noise reaches the
//! estimate), w → r and v → r for its residual y − Cx̂; per bank member, f → r for each watched
//! channel, with the steady (DC) signature and — with `[noise]` — the fault-to-noise ratio: the
//! steady residual of a unit constant fault, σ_max(G_fr(1)), over the residual's noise standard
//! deviation along its widest direction, √λ_max(Σ_r). The grid ([`lti::freq::grid`]) runs from
//! a hundredth of the slowest observer mode's rate to the Nyquist frequency π/Δt, on the
//! continuous-equivalent axis ω (rad/s).

use std::path::{Path, PathBuf};

use diagnosis::freq::ErrorSystems;
use lti::eig::sig;
use lti::freq::{Response, grid};
use recording::palette::{Line, THIN, color};
use recording::plot::{Curve, Figure, Scale};
use serde_json::{Value, json};

use super::sections::{DesignReport, ObserverSection};
use scenario::Scenario;

/// One observer's (or member's) responses.
pub struct Responses {
    pub name: String,
    /// w → e (none without unknown inputs).
    pub w_e: Option<Response>,
    pub v_e: Response,
    pub w_r: Option<Response>,
    pub v_r: Response,
    /// The observer decouples w (its w → e is rounding).
    pub w_decoupled: bool,
    /// A bank member's f → r per watched channel: (label, response, fault-to-noise ratio).
    pub faults: Vec<(String, Response, Option<f64>)>,
}

/// The frequency responses of a scenario's designs.
pub struct FreqReport {
    /// The grid, rad/s.
    pub omega: Vec<f64>,
    /// Observers, then bank members (an external observer, not designed here, has none).
    pub systems: Vec<Responses>,
}

/// An observer's or member's systems: its name, its error systems, and a member's fault
/// systems (channel, f → r, the residual's noise standard deviation).
type Made = (
    String,
    ErrorSystems,
    Vec<(
        String,
        lti::freq::Sampled,
        Option<f64>,
        diagnosis::structure::FaultInput,
    )>,
);

/// The responses of every designed observer and bank member of `r` (made from `s`).
pub fn freq(s: &Scenario, r: &DesignReport) -> FreqReport {
    let dm = s.sampled_model();
    let p = dm.c.nrows();
    let all: Vec<usize> = (0..p).collect();
    let mut made: Vec<Made> = Vec::new();
    for o in &r.observers {
        if let ObserverSection::Designed { name, designed, .. } = o {
            let e = ErrorSystems::new(&dm.a, &dm.e, &dm.c, &designed.runtime, &all, dm.dt);
            made.push((name.clone(), e, Vec::new()));
        }
    }
    if let Some(Ok(banks)) = &r.banks {
        for b in banks {
            for m in &b.members {
                let e =
                    ErrorSystems::new(&dm.a, &dm.e, &dm.c, &m.designed.runtime, &m.outputs, dm.dt);
                let noise = m.covariance.as_ref().map(|cov| {
                    lti::linalg::svd::singular_values(cov)
                        .first()
                        .copied()
                        .unwrap_or(0.0)
                        .sqrt()
                });
                let faults = b
                    .channels
                    .iter()
                    .zip(&b.inputs)
                    .map(|(label, input)| (label.clone(), e.fault(input), noise, input.clone()))
                    .collect();
                made.push((m.name.clone(), e, faults));
            }
        }
    }
    let slowest = made
        .iter()
        .map(|(_, e, _)| e.slowest_rate())
        .fold(f64::INFINITY, f64::min);
    let omega = grid(
        dm.dt,
        if slowest.is_finite() {
            slowest / 100.0
        } else {
            0.0
        },
    );
    let systems = made
        .into_iter()
        .map(|(name, e, faults)| {
            // The DC gain from the observer's own coordinates, asked for only where the plant's
            // integrator leaves the joint realisation without one.
            let resp = |sys: &lti::freq::Sampled, which: usize| {
                sys.response_with_dc(&omega, || e.reduced().and_then(|r| r[which].clone()))
            };
            Responses {
                name,
                w_e: e.w_e.as_ref().map(|sys| resp(sys, 0)),
                v_e: resp(&e.v_e, 1),
                w_r: e.w_r.as_ref().map(|sys| resp(sys, 2)),
                v_r: resp(&e.v_r, 3),
                w_decoupled: e.w_decoupled,
                faults: faults
                    .into_iter()
                    .map(|(label, sys, noise, input)| {
                        let resp = sys.response_with_dc(&omega, || e.reduced_fault(&input));
                        let fnr = noise
                            .filter(|&n| n > 0.0)
                            .and_then(|n| resp.dc_sigma_max.map(|d| d / n));
                        (label, resp, fnr)
                    })
                    .collect(),
            }
        })
        .collect();
    FreqReport { omega, systems }
}

/// "H∞ 1.23 at 4.5 rad/s, DC 0.98" (or "decoupled" for a UIO's w).
fn summary(r: &Response, decoupled: bool) -> String {
    let dc = r.dc_sigma_max.map_or(
        "— (the plant has a pole at z = 1: an integrator)".to_string(),
        |d| sig(d).to_string(),
    );
    if decoupled {
        return format!("decoupled (σ_max ≤ {} at rounding level)", sig(r.hinf));
    }
    if r.hinf == 0.0 {
        return "none (the residual does not use this channel)".into();
    }
    format!("H∞ {} at {} rad/s, DC {dc}", sig(r.hinf), sig(r.hinf_omega))
}

impl FreqReport {
    /// The report's text section.
    pub fn text(&self, dt: f64) -> String {
        let (lo, hi) = (self.omega[0], self.omega[self.omega.len() - 1]);
        let mut t = format!(
            "\nfrequency responses: σ over ω = {} … {} rad/s (Nyquist π/Δt at Δt = {}), {} points; H∞ the peak of σ_max, DC the steady gain σ_max(G(1))\n",
            sig(lo),
            sig(hi),
            sig(dt),
            self.omega.len()
        );
        for s in &self.systems {
            t += &format!("  {}\n", s.name);
            if let Some(w) = &s.w_e {
                t += &format!("    w → e   {}\n", summary(w, s.w_decoupled));
            }
            t += &format!("    v → e   {}\n", summary(&s.v_e, false));
            if let Some(w) = &s.w_r {
                t += &format!("    w → r   {}\n", summary(w, s.w_decoupled));
            }
            t += &format!("    v → r   {}\n", summary(&s.v_r, false));
            for (label, f, fnr) in &s.faults {
                let fnr = fnr.map_or(String::new(), |x| format!(", fault-to-noise {}", sig(x)));
                t += &format!("    {label} → r  {}{fnr}\n", summary(f, false));
            }
        }
        t
    }

    /// The JSON section.
    pub fn json(&self) -> Value {
        let systems: Vec<Value> = self
            .systems
            .iter()
            .map(|s| {
                let faults: Vec<Value> = s
                    .faults
                    .iter()
                    .map(|(label, r, fnr)| json!({ "channel": label, "f_r": r, "fault_to_noise": fnr }))
                    .collect();
                json!({
                    "name": s.name,
                    "w_e": s.w_e,
                    "v_e": s.v_e,
                    "w_r": s.w_r,
                    "v_r": s.v_r,
                    "w_decoupled": s.w_decoupled,
                    "faults": faults,
                })
            })
            .collect();
        json!({ "omega": self.omega, "systems": systems })
    }

    /// One σ plot per observer and member into `dir`: σ_max solid and σ_min dashed of each
    /// transfer, log-log; the files written.
    pub fn plots(&self, dir: &Path, scenario: &str) -> Result<Vec<PathBuf>, String> {
        let mut written = Vec::new();
        for s in &self.systems {
            // σ below 1e-13 of the plot's largest is rounding (a decoupled or rank-deficient
            // transfer): drawn at that floor, so that the axis spans what can be read.
            let peak = [&s.w_e, &s.w_r]
                .into_iter()
                .flatten()
                .chain([&s.v_e, &s.v_r])
                .chain(s.faults.iter().map(|(_, r, _)| r))
                .flat_map(|r| r.sigma_max.iter().copied())
                .filter(|v| v.is_finite())
                .fold(0.0, f64::max);
            let floor = (peak * 1e-13).max(1e-300);
            let mut curves = Vec::new();
            let mut add = |label: String, r: &Response, k: usize, min: bool| {
                let line = Line {
                    color: color(k),
                    width: THIN + 0.5,
                };
                let pts = |v: &[f64]| -> Vec<(f64, f64)> {
                    r.omega
                        .iter()
                        .zip(v)
                        .map(|(w, s)| (w.log10(), s.max(floor).log10()))
                        .collect()
                };
                curves.push(Curve {
                    label: format!("{label} σ_max"),
                    line,
                    points: pts(&r.sigma_max),
                    dashed: false,
                });
                // One input or one output: σ_min is σ_max, not drawn twice.
                let differs = r.sigma_max.iter().zip(&r.sigma_min).any(|(a, b)| a != b);
                if min && differs {
                    curves.push(Curve {
                        label: format!("{label} σ_min"),
                        line,
                        points: pts(&r.sigma_min),
                        dashed: true,
                    });
                }
            };
            let rounding = |d: bool| if d { " (rounding: decoupled)" } else { "" };
            if let Some(w) = &s.w_e {
                add(format!("w → e{}", rounding(s.w_decoupled)), w, 0, true);
            }
            add("v → e".into(), &s.v_e, 1, true);
            if let Some(w) = &s.w_r {
                add(format!("w → r{}", rounding(s.w_decoupled)), w, 2, false);
            }
            add("v → r".into(), &s.v_r, 3, false);
            // A channel the member's residual does not use has no curve.
            for (k, (label, f, _)) in s.faults.iter().enumerate() {
                if f.hinf > 0.0 {
                    add(format!("{label} → r"), f, 4 + k, false);
                }
            }
            let fig = Figure {
                title: format!("{scenario}: {} — singular values over frequency", s.name),
                y_label: "σ (gain; below 1e-13 of the largest: rounding, at that floor)".into(),
                x_label: "ω [rad/s] (continuous-equivalent, up to Nyquist)".into(),
                scale: Scale::Log,
                x_scale: Scale::Log,
                curves,
            };
            let path = dir.join(format!("freq_{}.png", recording::plot::sanitize(&s.name)));
            if recording::plot::draw(&path, &fig)? {
                written.push(path);
            }
        }
        Ok(written)
    }
}
