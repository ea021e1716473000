//! Hui & Żak's projection unknown-input observer with a measurement disturbance (seed 004):
//!
//! ```text
//! ẋ = Ax + B₁u₁ + B₂u₂,   y = Cx + Dv        (u₂, v unknown)
//! M = [B₂ 0][CB₂ D]⁺,     A₁ = (I − MC)A      ((I − MC)B₂ = 0, MD = 0)
//! ż = (I − MC)(Az + AMy + B₁u₁) + L(y − Cx̂),   x̂ = z + My,   LD = 0
//! ė = (A₁ − LC) e
//! ```
//!
//! LD = 0 forces L = L̃N with N spanning the left null space of D, so the error dynamics are
//! A₁ − L̃(NC): the unobservable modes of (A₁, NC) — the invariant zeros of (A, B₂, C, D) — are
//! fixed, and only the observable part can be placed.
//!
//! Two design paths:
//! * [`Path::Placement`] (default, pure Rust): place the free poles on (A₁, NC), then certify the
//!   decay rate α with a Lyapunov function: P solves (A₁ − LC + α/2·I)ᵀP + P(A₁ − LC + α/2·I) = −I,
//!   scaled so P ⪰ 0.01I, and Y = PL satisfies the paper's LMI
//!   A₁ᵀP + PA₁ − CᵀYᵀ − YC + αP ⪯ 0, YD = 0.
//! * [`Path::Lmi`] (cargo feature `lmi`): the paper's LMI solved as a semidefinite feasibility
//!   problem with Clarabel; L = P⁻¹Y.
//!
//! Sampled counterpart: the same projection on (A_d, B₁d, B₂d): with x̂_k = z_k + M_d y_k,
//! z_{k+1} = (I − M_dC)(A_d x̂_k + B₁d u₁) + L_d(y_k − Cx̂_k) gives e_{k+1} = (A₁d − L_dC)e_k;
//! its decay is certified by the discrete Lyapunov equation for (A₁d − L_dC)/ρ, ρ = e^{−α·dt/2}.

use lti::eig::{format_list, sig};
use lti::lyapunov;
use lti::place::Method;
use lti::zeros::decoupling;
use lti::{C64, Discrete, Mat, Model, PoleSpec, Poles};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, eq_detail, free_gain,
    require_stable, sampled_report,
};
use crate::lmi::LmiSolution;
use crate::runtime::LinearObserver;

const KIND: &str = "hui-zak-uio";

/// How L is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    /// Pole placement on the admissible structure plus a Lyapunov certificate.
    Placement,
    /// The paper's LMI, solved with Clarabel (feature `lmi`).
    Lmi,
}

/// Whether this build can solve the LMI.
pub fn lmi_available() -> bool {
    cfg!(feature = "lmi")
}

struct Core {
    m: Mat,
    a1: Mat,
    l: Mat,
    acl: Mat,
    fixed: Vec<C64>,
}

/// Free poles when none are given (continuous): real, twice as fast as the fastest fixed mode so
/// that the fixed modes set the error's decay, faster than the decay rate, and no slower than −1.
fn default_poles(count: usize, fixed: &[C64], decay: f64) -> Poles {
    let fastest = fixed.iter().map(|z| z.re.abs()).fold(0.0, f64::max);
    let base = (2.0 * fastest).max(decay).max(1.0);
    Poles::new((0..count).map(|i| PoleSpec::Real(-base * (1.0 + 0.1 * i as f64)))).expect("finite")
}

#[allow(clippy::too_many_arguments)]
fn core(
    a: &Mat,
    c: &Mat,
    b2: &Mat,
    d: &Mat,
    gain: Option<&Gain>,
    carried: &[C64],
    lmi_l: Option<&Mat>,
    domain: Domain,
    checks: &mut Checks,
) -> Result<Core, DesignError> {
    let n = a.nrows();
    let dec = decoupling(a, b2, c, d).map_err(|e| checks.error("decoupling", e.to_string()))?;
    checks.require(
        "rank[CB2 D] = rank(B2) + rank(D)",
        dec.matching(),
        eq_detail(dec.rank_ced, dec.rank_e_plus_d),
    )?;
    let m = dec.m.clone();
    let proj = Mat::identity(n, n) - &m * c;
    let res_b2 = (&proj * b2).amax();
    let res_md = (&m * d).amax();
    checks.require(
        "(I − MC)B2 = 0, MD = 0",
        res_b2 <= 1e-10 && res_md <= 1e-10,
        format!("max |(I − MC)B2| = {res_b2:.1e}, max |MD| = {res_md:.1e}"),
    )?;
    let fixed = dec.zeros.clone();
    let unstable: Vec<C64> = fixed
        .iter()
        .copied()
        .filter(|&z| !domain.stable(z))
        .collect();
    checks.require(
        "invariant zeros of (A, B2, C, D) stable",
        unstable.is_empty(),
        if fixed.is_empty() {
            "none".into()
        } else if unstable.is_empty() {
            format_list(&fixed)
        } else {
            format!(
                "unstable zero(s) {z}: (A1, NC) is not detectable — its unobservable mode(s) {var} = {z} stay in A1 − LC whatever L is",
                z = format_list(&unstable),
                var = if domain == Domain::Continuous { "s" } else { "z" }
            )
        },
    )?;
    let nc = &dec.n * c;
    let l = match (lmi_l, gain) {
        (Some(l), _) => l.clone(),
        (None, Some(g)) => {
            // The pair's output is N·y (N spans the left null space of D): R given for y is NRNᵀ.
            let pair = Pair {
                a: &dec.a1,
                c: &nc,
                name: "(A1, NC)",
                scale: 0.0,
                state_map: None,
                output_map: Some(&dec.n),
            };
            let (lt, _) = free_gain(checks, &pair, g, carried, domain)?;
            lt * &dec.n
        }
        (None, None) => {
            return Err(checks.error(
                "poles",
                "no free poles given (a design bug: the caller supplies the default)",
            ));
        }
    };
    let res_ld = (&l * d).amax();
    checks.require(
        "LD = 0",
        res_ld <= 1e-9 * l.amax().max(1.0),
        format!("max |LD| = {res_ld:.1e}"),
    )?;
    let acl = &dec.a1 - &l * c;
    require_stable(checks, "A1 − LC stable", &eig(&acl), domain)?;
    Ok(Core {
        m,
        a1: dec.a1,
        l,
        acl,
        fixed,
    })
}

/// The decay-rate certificate of the continuous design: P ⪰ 0.01I with
/// A_clᵀP + PA_cl + αP = −cI ⪯ 0. Returns P and the largest eigenvalue of the LMI's left side.
fn certificate(acl: &Mat, decay: f64) -> Result<(Mat, f64), String> {
    let n = acl.nrows();
    let shifted = acl + Mat::identity(n, n) * (decay / 2.0);
    let p = lyapunov::continuous(&shifted, &Mat::identity(n, n)).map_err(|e| e.to_string())?;
    let lmin = lyapunov::min_eigenvalue(&p);
    if lmin <= 0.0 {
        return Err(format!("no Lyapunov certificate: λmin(P) = {}", sig(lmin)));
    }
    let p = &p * (0.01 / lmin).max(1.0);
    let lhs = acl.transpose() * &p + &p * acl + &p * decay;
    let worst = lhs.symmetric_eigen().eigenvalues.max();
    Ok((p, worst))
}

/// The sampled decay certificate: P ≻ 0 with A_dᵀPA_d − ρ²P ⪯ 0; returns ρ and λmax of the left side.
fn discrete_certificate(acl_d: &Mat, decay: f64, dt: f64) -> Result<(f64, f64), String> {
    let n = acl_d.nrows();
    let rho = (-decay * dt / 2.0).exp();
    let p = lyapunov::discrete(&(acl_d / rho), &Mat::identity(n, n)).map_err(|e| e.to_string())?;
    if lyapunov::min_eigenvalue(&p) <= 0.0 {
        return Err("no discrete Lyapunov certificate".into());
    }
    let lhs = acl_d.transpose() * &p * acl_d - &p * (rho * rho);
    Ok((rho, lhs.symmetric_eigen().eigenvalues.max()))
}

// one job: Hui & Żak's design in the paper's order (the projection, the LMI or the placement, the
// certificate), each step using the last.
pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    decay: f64,
    gain: Option<&Gain>,
    method: Method,
    path: Path,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::new(KIND);
    if !(decay >= 0.0 && decay.is_finite()) {
        return Err(checks.error("decay", format!("{decay} must be finite and ≥ 0")));
    }
    if let Some(g @ Gain::Lqe(_)) = gain {
        if path == Path::Lmi {
            return Err(checks.error(
                "path",
                "gain = lqe computes L from a DARE: it takes no LMI path",
            ));
        }
        return design_sampled(dm, decay, g);
    }
    let Some(model) = model else {
        // A discrete-time plant: no continuous design, so no LMI and no default poles.
        return match (gain, path) {
            (_, Path::Lmi) => Err(checks.error("path", "the LMI is of the continuous-time plant: a discrete-time plant takes gain = lqe or poles")),
            (Some(g), _) => design_sampled(dm, decay, g),
            (None, _) => Err(checks.error("poles", "a discrete-time plant has no continuous fixed modes to default the poles from: give poles or gain = lqe")),
        };
    };
    let poles = match gain {
        Some(Gain::Place { poles, method: m }) => Some((poles, *m)),
        _ => None,
    };
    let method = poles.map_or(method, |p| p.1);
    let poles = poles.map(|p| p.0);
    let (b2, d) = (&model.e, &model.d);
    let mut notes = Vec::new();
    let lmi = match path {
        Path::Placement => None,
        Path::Lmi => Some(solve_lmi(model, decay, &mut checks)?),
    };
    let lmi_l = lmi
        .as_ref()
        .map(|s| s.p.clone().lu().solve(&s.y).expect("P ≻ 0 is invertible"));
    // Without given poles the free ones default from the continuous fixed modes, once, and the
    // sampled design then places their images e^{p·dt}.
    let free_default;
    let poles = match poles {
        Some(p) => Some(p),
        None if lmi.is_none() => {
            let dec = decoupling(&model.a, b2, &model.c, d)
                .map_err(|e| checks.error("decoupling", e.to_string()))?;
            free_default = default_poles(dec.staircase.no, &dec.zeros, decay);
            Some(&free_default)
        }
        None => None,
    };
    let ct = core(
        &model.a,
        &model.c,
        b2,
        d,
        poles.map(|p| Gain::place(p.clone(), method)).as_ref(),
        &[],
        lmi_l.as_ref(),
        Domain::Continuous,
        &mut checks,
    )?;
    let poles_c = eig(&ct.acl);
    let slowest = poles_c
        .iter()
        .map(|z| z.re)
        .fold(f64::NEG_INFINITY, f64::max);
    checks.require(
        &format!("decay rate {decay}: every Re λ(A1 − LC) < −{}", decay / 2.0),
        slowest < -decay / 2.0,
        format!("slowest Re λ = {}", sig(slowest)),
    )?;
    let p = match &lmi {
        Some(s) => {
            notes.push("L = P⁻¹Y from the LMI solved with Clarabel".into());
            s.p.clone()
        }
        None => {
            let (p, worst) =
                certificate(&ct.acl, decay).map_err(|e| checks.error("Lyapunov certificate", e))?;
            checks.require(
                "A1ᵀP + PA1 − CᵀYᵀ − YC + αP ⪯ 0, P ⪰ 0.01I (Y = PL)",
                worst <= 1e-9 * p.amax(),
                format!(
                    "λmax = {}, λmin(P) = {}",
                    sig(worst),
                    sig(lyapunov::min_eigenvalue(&p))
                ),
            )?;
            p
        }
    };

    // Sampled: the LMI path keeps the LMI's continuous poles, mapped to e^{p·dt}.
    let mut sampled = Checks::sampled(KIND, dt);
    let free_poles = match (&lmi, poles) {
        (Some(_), _) => {
            let free: Vec<C64> = poles_c
                .iter()
                .copied()
                .filter(|z| {
                    !ct.fixed
                        .iter()
                        .any(|f| (f - z).norm() < 1e-6 * f.norm().max(1.0))
                })
                .collect();
            Some(Poles::from_values(&free).map_err(|e| sampled.error("poles", e.to_string()))?)
        }
        (None, p) => p.cloned(),
    };
    let free = free_poles.map(|p| Gain::place(p, method));
    let d_core = core(
        &dm.a,
        &dm.c,
        &dm.e,
        d,
        free.as_ref(),
        &ct.fixed,
        None,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let (rho, worst_d) = discrete_certificate(&d_core.acl, decay, dt)
        .map_err(|e| sampled.error("Lyapunov certificate", e))?;
    notes.push(format!(
        "sampled decay certificate: ρ = e^(−α·dt/2) = {}, λmax(FᵀPF − ρ²P) = {} (F = Φ1 − LC)",
        sig(rho),
        sig(worst_d)
    ));
    let runtime = runtime(&d_core, dm);
    Ok(Designed {
        report: Report {
            kind: KIND,
            conditions: checks.into_list(),
            poles: poles_c,
            discrete_poles: eig(&d_core.acl),
            fixed_modes: ct.fixed,
            matrices: vec![
                ("M".into(), ct.m),
                ("A1".into(), ct.a1),
                ("L".into(), ct.l),
                ("P".into(), p),
            ],
            notes,
            sampled_only: false,
        },
        runtime,
        what: None,
    })
}

/// The runtime form of the sampled design: x̂ = z + My,
/// z⁺ = (A1d − LC)z + (I − MC)B_d u + (A1d M + L(I − CM)) y.
fn runtime(d: &Core, dm: &Discrete) -> LinearObserver {
    let (n, p) = (dm.a.nrows(), dm.c.nrows());
    let proj = Mat::identity(n, n) - &d.m * &dm.c;
    let k = &d.a1 * &d.m + &d.l * (Mat::identity(p, p) - &dm.c * &d.m);
    LinearObserver::new(&d.acl, &(&proj * &dm.b), &k, &Mat::identity(n, n), &d.m)
}

/// The sampled design alone (`gain = "lqe"`, or a discrete-time plant): L from the DARE of the
/// sampled pair (A1d, NC), or placed there at e^{p·dt}; the decay rate is certified on the sampled
/// error dynamics only.
fn design_sampled(dm: &Discrete, decay: f64, gain: &Gain) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut sampled = Checks::sampled(KIND, dt);
    let d_core = core(
        &dm.a,
        &dm.c,
        &dm.e,
        &dm.d,
        Some(gain),
        &[],
        None,
        Domain::Discrete(dt),
        &mut sampled,
    )?;
    let (rho, worst_d) = discrete_certificate(&d_core.acl, decay, dt)
        .map_err(|e| sampled.error("Lyapunov certificate", e))?;
    sampled.require(
        &format!("decay rate {decay}: FᵀPF − ρ²P ⪯ 0 (F = Φ1 − LC) with ρ = e^(−α·dt/2)"),
        worst_d <= 1e-9,
        format!("ρ = {}, λmax = {}", sig(rho), sig(worst_d)),
    )?;
    let runtime = runtime(&d_core, dm);
    let matrices = vec![
        ("M".into(), d_core.m.clone()),
        ("A1".into(), d_core.a1.clone()),
        ("L".into(), d_core.l.clone()),
    ];
    let report = sampled_report(
        KIND,
        sampled,
        &d_core.acl,
        d_core.fixed.clone(),
        matrices,
        vec![],
        dt,
    );
    Ok(Designed {
        report,
        runtime,
        what: None,
    })
}

#[cfg(feature = "lmi")]
fn solve_lmi(model: &Model, decay: f64, checks: &mut Checks) -> Result<LmiSolution, DesignError> {
    let dec = decoupling(&model.a, &model.e, &model.c, &model.d)
        .map_err(|e| checks.error("decoupling", e.to_string()))?;
    let sol = crate::lmi::solve(&dec.a1, &model.c, &model.d, decay)
        .map_err(|e| checks.error("LMI", e))?;
    let lhs = dec.a1.transpose() * &sol.p + &sol.p * &dec.a1
        - model.c.transpose() * sol.y.transpose()
        - &sol.y * &model.c
        + &sol.p * decay;
    let worst = lhs.symmetric_eigen().eigenvalues.max();
    checks.require(
        "A1ᵀP + PA1 − CᵀYᵀ − YC + αP ⪯ 0, P ⪰ 0.01I, YD = 0 (LMI)",
        worst <= 1e-7 * sol.p.amax() && lyapunov::min_eigenvalue(&sol.p) >= 0.01 * (1.0 - 1e-6),
        format!(
            "λmax = {}, λmin(P) = {}",
            sig(worst),
            sig(lyapunov::min_eigenvalue(&sol.p))
        ),
    )?;
    Ok(sol)
}

#[cfg(not(feature = "lmi"))]
fn solve_lmi(_: &Model, _: f64, checks: &mut Checks) -> Result<LmiSolution, DesignError> {
    Err(checks.error("LMI", "this build has no LMI solver: rebuild with `--features observer/lmi` (needs a system BLAS/LAPACK)"))
}
