//! Frequency responses of sampled systems: how much of an input reaches an output at each
//! frequency, as engineers read it from a σ (singular-value) plot.
//!
//! For x_{k+1} = A x_k + B u_k, y_k = C x_k + D u_k sampled at Δt, the transfer at the
//! continuous-equivalent frequency ω (rad/s) is
//!
//! ```text
//! G(e^{jωΔt}) = C (e^{jωΔt} I − A)⁻¹ B + D,        0 ≤ ω ≤ ω_N = π/Δt (Nyquist),
//! ```
//!
//! and its largest and smallest singular values σ_max(ω), σ_min(ω) bound the gain from any input
//! direction (Skogestad & Postlethwaite, "Multivariable Feedback Control", 2005, §3.3). The peak
//! of σ_max over 0 … ω_N is the H∞ norm of the sampled system (§4.10.2); at ω = 0, G(1) is its
//! DC gain — the steady response to a constant input. [`Response`] holds σ on a grid, the DC
//! gain, and the peak: the grid's largest σ_max refined by golden-section search between its
//! neighbours on log ω (a single peak is then found to ≈ 1e-10 in ω; a sharper resonance between
//! grid points than the grid resolves is a limit of any gridded H∞ estimate).
//!
//! Precondition: A has no eigenvalue on the unit circle at the frequencies asked (the observers'
//! error systems this is used for are stable; an unstable A still has a transfer, evaluated the
//! same way).

use crate::Mat;
use crate::eig::C64;
use crate::linalg::complex::{CMat, singular_values, solve};

/// A sampled system (A, B, C, D) at sample period `dt`.
#[derive(Debug, Clone)]
pub struct Sampled {
    /// State matrix, r×r.
    pub a: Mat,
    /// Input matrix, r×m.
    pub b: Mat,
    /// Output matrix, p×r.
    pub c: Mat,
    /// Feedthrough, p×m.
    pub d: Mat,
    /// Sample period, s.
    pub dt: f64,
}

/// σ_max and σ_min over a frequency grid, the peak and the DC gain.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Response {
    /// Frequencies, rad/s (continuous-equivalent), ascending.
    pub omega: Vec<f64>,
    /// σ_max(G(e^{jωΔt})) per frequency.
    pub sigma_max: Vec<f64>,
    /// σ_min per frequency: the smallest of G's min(rows, columns) singular values (as
    /// python-control's `singular_values_response` gives them; equal to σ_max for one input or
    /// one output).
    pub sigma_min: Vec<f64>,
    /// The peak of σ_max over 0 … ω_N: the H∞ norm of the sampled system.
    pub hinf: f64,
    /// Where it is, rad/s.
    pub hinf_omega: f64,
    /// G(1), row-major rows (`None` when A has an eigenvalue at 1).
    pub dc: Option<Vec<Vec<f64>>>,
    /// σ_max(G(1)).
    pub dc_sigma_max: Option<f64>,
}

/// Grid points per decade of [`grid`].
pub const PER_DECADE: usize = 50;

/// The frequencies of a σ plot: log-spaced, [`PER_DECADE`] a decade, from `lo` to the Nyquist
/// frequency π/Δt (both included); `lo` is clamped to (0, ω_N / 10].
pub fn grid(dt: f64, lo: f64) -> Vec<f64> {
    let hi = std::f64::consts::PI / dt;
    let lo = lo.clamp(hi * 1e-9, hi / 10.0);
    let decades = (hi / lo).log10();
    let n = ((decades * PER_DECADE as f64).ceil() as usize).max(2);
    (0..=n)
        .map(|i| {
            if i == n {
                hi
            } else {
                lo * 10f64.powf(decades * i as f64 / n as f64)
            }
        })
        .collect()
}

/// B, C and D as complex matrices, made once for all the frequencies of a response.
struct Complexified {
    b: CMat,
    c: CMat,
    d: CMat,
}

impl Sampled {
    fn complexified(&self) -> Complexified {
        let cplx = |m: &Mat| m.map(|v| C64::new(v, 0.0));
        Complexified {
            b: cplx(&self.b),
            c: cplx(&self.c),
            d: cplx(&self.d),
        }
    }

    /// G(z).
    pub fn at(&self, z: C64) -> Option<CMat> {
        self.at_with(z, &self.complexified())
    }

    fn at_with(&self, z: C64, k: &Complexified) -> Option<CMat> {
        let r = self.a.nrows();
        let za = CMat::from_fn(r, r, |i, j| {
            let a = C64::new(-self.a[(i, j)], 0.0);
            if i == j { a + z } else { a }
        });
        let x = solve(&za, &k.b)?;
        Some(&k.c * x + &k.d)
    }

    /// (σ_max, σ_min) of G(e^{jωΔt}): its largest and smallest of min(rows, columns) singular
    /// values; ∞ at a pole on the unit circle.
    pub fn sigma(&self, omega: f64) -> (f64, f64) {
        self.sigma_with(omega, &self.complexified())
    }

    fn sigma_with(&self, omega: f64, k: &Complexified) -> (f64, f64) {
        let z = C64::from_polar(1.0, omega * self.dt);
        match self.at_with(z, k) {
            Some(g) => {
                let s = singular_values(&g);
                (
                    s.first().copied().unwrap_or(0.0),
                    s.last().copied().unwrap_or(0.0),
                )
            }
            None => (f64::INFINITY, f64::INFINITY),
        }
    }

    /// G(1) = C(I − A)⁻¹B + D, or `None` when I − A is singular by the one rank rule (A has an
    /// eigenvalue at 1: an integrator), whatever finite numbers an LU would return.
    pub fn dc(&self) -> Option<Mat> {
        let r = self.a.nrows();
        let i_a = Mat::identity(r, r) - &self.a;
        if r > 0 && crate::linalg::svd::rank(&i_a) < r {
            return None;
        }
        self.at(C64::new(1.0, 0.0)).map(|g| g.map(|v| v.re))
    }

    /// The response on `omega` (ascending, within 0 … π/Δt).
    pub fn response(&self, omega: &[f64]) -> Response {
        self.response_with_dc(omega, || None)
    }

    /// [`Sampled::response`], the DC gain from `same` when this realisation has none at z = 1:
    /// that of a realisation of the same transfer without the pole at 1 that cancels from it (an
    /// observer's error system in its own coordinates, where the plant's integrator is not a
    /// state), asked for only then.
    pub fn response_with_dc(
        &self,
        omega: &[f64],
        same: impl FnOnce() -> Option<Sampled>,
    ) -> Response {
        let k = self.complexified();
        let (sigma_max, sigma_min): (Vec<f64>, Vec<f64>) =
            omega.iter().map(|&w| self.sigma_with(w, &k)).unzip();
        let dc = self.dc().or_else(|| same().as_ref().and_then(Sampled::dc));
        let dc_sigma_max = dc.as_ref().map(|g| {
            crate::linalg::svd::singular_values(g)
                .first()
                .copied()
                .unwrap_or(0.0)
        });
        let (mut hinf, mut hinf_omega) = (dc_sigma_max.unwrap_or(0.0), 0.0);
        if let Some(i) = (0..omega.len()).max_by(|&i, &j| sigma_max[i].total_cmp(&sigma_max[j]))
            && sigma_max[i] > hinf
        {
            let (w, s) = self.refine(omega, i, sigma_max[i], &k);
            (hinf, hinf_omega) = (s, w);
        }
        Response {
            omega: omega.to_vec(),
            sigma_max,
            sigma_min,
            hinf,
            hinf_omega,
            dc: dc.map(|g| {
                (0..g.nrows())
                    .map(|i| g.row(i).iter().copied().collect())
                    .collect()
            }),
            dc_sigma_max,
        }
    }

    /// The peak of σ_max near grid point i (where it is `at_i`): golden-section search on log ω
    /// between its neighbours; (ω, σ_max) of the best point seen, the grid's own included.
    fn refine(&self, omega: &[f64], i: usize, at_i: f64, k: &Complexified) -> (f64, f64) {
        let lo = omega[i.saturating_sub(1)].ln();
        let hi = omega[(i + 1).min(omega.len() - 1)].ln();
        let f = |l: f64| self.sigma_with(l.exp(), k).0;
        let g = (5f64.sqrt() - 1.0) / 2.0;
        let (mut a, mut b) = (lo, hi);
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (f(c), f(d));
        let mut best = (omega[i], at_i);
        for _ in 0..60 {
            if fc > fd {
                b = d;
                (d, fd) = (c, fc);
                c = b - g * (b - a);
                fc = f(c);
            } else {
                a = c;
                (c, fc) = (d, fd);
                d = a + g * (b - a);
                fd = f(d);
            }
            for (x, fx) in [(c, fc), (d, fd)] {
                if fx > best.1 {
                    best = (x.exp(), fx);
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A first-order lag sampled exactly, x⁺ = a x + (1 − a) u: G(z) = (1 − a)/(z − a), whose gain
    /// at ω is (1 − a)/|e^{jωΔt} − a|; DC gain 1, and the peak is at ω = 0.
    #[test]
    fn a_sampled_lag_has_its_textbook_gain_and_a_dc_gain_of_one() {
        let (a, dt) = (0.9, 0.01);
        let sys = Sampled {
            a: Mat::from_element(1, 1, a),
            b: Mat::from_element(1, 1, 1.0 - a),
            c: Mat::from_element(1, 1, 1.0),
            d: Mat::zeros(1, 1),
            dt,
        };
        let omega = grid(dt, 0.1);
        assert_eq!(*omega.last().unwrap(), std::f64::consts::PI / dt);
        let r = sys.response(&omega);
        for (&w, &s) in omega.iter().zip(&r.sigma_max) {
            let want = (1.0 - a) / (C64::from_polar(1.0, w * dt) - a).norm();
            assert!((s - want).abs() <= 1e-14 * want, "{w}: {s} {want}");
        }
        assert_eq!(r.sigma_max, r.sigma_min);
        assert!((r.dc_sigma_max.unwrap() - 1.0).abs() < 1e-14);
        assert!((r.hinf - 1.0).abs() < 1e-14 && r.hinf_omega == 0.0, "{r:?}");
    }

    /// A lightly damped resonance: the refined peak is |G| at the analytic resonance of the
    /// sampled system, found between grid points.
    #[test]
    fn the_peak_is_found_between_grid_points() {
        // Poles at ρe^{±jθ}: the gain of 1/((z − p)(z − p̄)) peaks near e^{jθ}.
        let (rho, theta, dt) = (0.99_f64, 0.3_f64, 0.01);
        let a = Mat::from_row_slice(2, 2, &[2.0 * rho * theta.cos(), -rho * rho, 1.0, 0.0]);
        let sys = Sampled {
            a,
            b: Mat::from_column_slice(2, 1, &[1.0, 0.0]),
            c: Mat::from_row_slice(1, 2, &[0.0, 1.0]),
            d: Mat::zeros(1, 1),
            dt,
        };
        let r = sys.response(&grid(dt, 1.0));
        // A dense scan of the analytic gain.
        let gain = |w: f64| {
            let z = C64::from_polar(1.0, w * dt);
            let p = C64::from_polar(rho, theta);
            1.0 / ((z - p) * (z - p.conj())).norm()
        };
        let best = (0..2_000_000)
            .map(|i| 25.0 + i as f64 * 1e-5)
            .map(gain)
            .fold(0.0, f64::max);
        assert!((r.hinf - best).abs() <= 1e-8 * best, "{} {best}", r.hinf);
        assert!(r.hinf >= r.sigma_max.iter().copied().fold(0.0, f64::max));
    }
}
