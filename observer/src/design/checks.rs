//! The conditions of a design, evaluated as it goes: [`Checks`] collects them and ends the design
//! at the first required one that fails; the shared steps every family takes (the sampled
//! report, placement of the detectable pair, refusal naming an unseen mode, stability).

use lti::eig::{continuous_image, eigenvalues, format_list, format_one};
use lti::place::{Method, place_observer};
use lti::staircase::{observability_staircase_at, observable_by_rank_at};
use lti::{C64, Mat, Poles};

use super::report::*;

/// Collects conditions; a failing required one ends the design with a [`DesignError`].
pub(crate) struct Checks {
    kind: &'static str,
    prefix: String,
    list: Vec<Condition>,
    /// The LQE weights (Q, R) at the pair's sizes, when the gain came from a DARE.
    pub(crate) weights: Option<(Mat, Mat)>,
}

impl Checks {
    pub(crate) fn new(kind: &'static str) -> Self {
        Self {
            kind,
            prefix: String::new(),
            list: Vec::new(),
            weights: None,
        }
    }

    /// Checks of the sampled design: names are prefixed so an error says which design failed.
    pub(crate) fn sampled(kind: &'static str, dt: f64) -> Self {
        Self {
            kind,
            prefix: format!("sampled design (dt = {dt}): "),
            list: Vec::new(),
            weights: None,
        }
    }

    /// Records a condition that must hold.
    pub(crate) fn require(
        &mut self,
        name: &str,
        ok: bool,
        detail: impl Into<String>,
    ) -> Result<(), DesignError> {
        let detail = self.in_domain(&detail.into());
        let name = format!("{}{}", self.prefix, self.in_domain(name));
        self.list.push(Condition {
            name: name.clone(),
            ok,
            detail: detail.clone(),
        });
        if ok {
            Ok(())
        } else {
            Err(DesignError {
                unseen_states: Vec::new(),
                kind: self.kind,
                condition: name,
                detail,
                conditions: self.list.clone(),
            })
        }
    }

    /// An error for `name`, carrying the conditions so far.
    pub(crate) fn error(&self, name: &str, detail: impl Into<String>) -> DesignError {
        let condition = format!("{}{}", self.prefix, self.in_domain(name));
        DesignError {
            unseen_states: Vec::new(),
            kind: self.kind,
            condition,
            detail: self.in_domain(&detail.into()),
            conditions: self.list.clone(),
        }
    }

    /// A condition's words in this design's domain: the sampled design works on (Φ, Γ_B, Γ_E),
    /// and says so — "(TΦ, C)", "invariant zeros of (Φ, Γ_E, C)" — where the families, which
    /// run one function for both domains, write the papers' continuous names.
    fn in_domain(&self, text: &str) -> String {
        if self.prefix.is_empty() {
            return text.to_string();
        }
        SAMPLED_NAMES
            .iter()
            .fold(text.to_string(), |t, (from, to)| t.replace(from, to))
    }

    pub(crate) fn into_list(self) -> Vec<Condition> {
        self.list
    }

    /// The LQE weights as report matrices (none for a placed gain).
    pub(crate) fn weight_matrices(&self) -> Vec<(String, Mat)> {
        self.weights
            .iter()
            .flat_map(|(q, r)| {
                [
                    ("Q (LQE)".to_string(), q.clone()),
                    ("R (LQE)".to_string(), r.clone()),
                ]
            })
            .collect()
    }
}

/// The papers' continuous names and their sampled counterparts, longest first where one
/// contains another (Φ = e^{A·dt}, Γ_E = ∫e^{Aτ}dτ·E, the same C).
const SAMPLED_NAMES: [(&str, &str); 18] = [
    ("(A, E, C)", "(Φ, Γ_E, C)"),
    // Hui–Żak: B2 is the unknown input's matrix and A1 the projected A (the "B2" entry runs after
    // the first, which leaves B2 for it).
    ("(A, B2, C, D)", "(Φ, B2, C, D)"),
    ("B2", "Γ_B2"),
    ("A1", "Φ1"),
    ("A − KCA", "Φ − KCΦ"),
    ("rank(CE) = rank(E)", "rank(CΓ_E) = rank(Γ_E)"),
    ("TA − K1C", "TΦ − K1C"),
    ("(TA, C)", "(TΦ, C)"),
    ("LgEd(CEd)g(CEd)", "LᵍΓ_E(CΓ_E)ᵍ(CΓ_E)"),
    ("LgEd", "LᵍΓ_E"),
    ("KCEd", "KCΓ_E"),
    ("max|Ed|", "max|Γ_E|"),
    ("LgAL", "LᵍΦL"),
    ("K0CAL", "K0CΦL"),
    ("KCAL", "KCΦL"),
    ("CAL", "CΦL"),
    ("HAF", "HΦF"),
    ("CAF", "CΦF"),
];

/// The report of a design that has only its sampled part (an LQE gain, a discrete-time plant): the sampled checks as
/// conditions, ln(z)/dt as continuous poles and fixed modes, the sampled matrices and the weights.
pub(crate) fn sampled_report(
    kind: &'static str,
    sampled: Checks,
    f: &Mat,
    fixed: Vec<C64>,
    mut matrices: Vec<(String, Mat)>,
    mut notes: Vec<String>,
    dt: f64,
) -> Report {
    let discrete = eig(f);
    matrices.extend(sampled.weight_matrices());
    // The families name their matrices and notes as the papers do (HAF − KCAF, LgAL); in a
    // sampled-only report they are the sampled ones.
    for (name, _) in &mut matrices {
        *name = sampled.in_domain(name);
    }
    for note in &mut notes {
        *note = sampled.in_domain(note);
    }
    notes.insert(0, "the sampled design only (gain = lqe, or a discrete-time plant): matrices are the sampled observer's, poles are ln(z)/dt".into());
    let (poles, deadbeat) = continuous_image(&discrete, dt);
    if deadbeat > 0 {
        notes.push(format!(
            "{deadbeat} deadbeat mode(s) z = 0 (no continuous image, left out of the poles)"
        ));
    }
    Report {
        kind,
        conditions: sampled.into_list(),
        matrices,
        poles,
        discrete_poles: discrete,
        fixed_modes: continuous_image(&fixed, dt).0,
        notes,
        sampled_only: true,
    }
}

/// An observer gain for the pair (A, C) placing the requested spectrum on its observable part;
/// the unobservable modes stay where they are and are returned as fixed modes.
///
/// With the staircase Qᵀ A Q = [[A_o, 0], [A₂₁, A_u]], C Q = [C_o, 0], the gain L = Q [L_o; 0]
/// gives Qᵀ(A − LC)Q = [[A_o − L_oC_o, 0], [A₂₁, A_u]]: eig = eig(A_o − L_oC_o) ∪ eig(A_u).
///
/// `scale` is the size of the data the pair was formed from (0: its own; see `Pair::scale`).
/// `free` are the user's continuous poles: one per observable mode of the continuous pair.
/// `carried` are the continuous design's fixed modes (empty for the continuous design itself).
/// The sampled design aims at the same spectrum mapped by z = e^{s·dt}: every free pole p goes
/// to e^{p·dt}, and every continuous fixed mode z_f to e^{z_f·dt} — left alone where the
/// sampled pair keeps a fixed mode of its own there, placed there where sampling made it
/// observable (an invariant zero of (A, E, C) is often not one of (A_d, E_d, C)). Both designs
/// then have the same error dynamics, and the user writes one pole list for both.
/// `plant_coordinates`: the pair's state is the plant's (a refusal names the states).
#[allow(clippy::too_many_arguments)]
pub(crate) fn place_detectable(
    checks: &mut Checks,
    a: &Mat,
    c: &Mat,
    scale: f64,
    free: &Poles,
    carried: &[C64],
    method: Method,
    pair: &str,
    domain: Domain,
    plant_coordinates: bool,
) -> Result<(Mat, Vec<C64>), DesignError> {
    let n = a.nrows();
    // Every state measured (rank C = n) is observable: no staircase, whose SVDs and rotations
    // are a large model's costliest step.
    // `scale`: the size of the data a reduced pair was formed from (see `Pair::scale`).
    let stairs =
        (!observable_by_rank_at(a, c, scale)).then(|| observability_staircase_at(a, c, scale));
    let (no, fixed) = match &stairs {
        Some(s) => (
            s.no,
            s.unobservable_modes()
                .map_err(|e| checks.error(pair, e.to_string()))?,
        ),
        None => (n, Vec::new()),
    };
    if no < n {
        let what = if domain == Domain::Continuous {
            "Re < 0"
        } else {
            "|z| < 1"
        };
        let unstable: Vec<C64> = fixed
            .iter()
            .copied()
            .filter(|&z| !domain.stable(z))
            .collect();
        if !unstable.is_empty() {
            // Named as the Riccati path names it: the mode in s and z and the states that
            // carry it, by the PBH test; the staircase's own words below only where the PBH
            // test at its tolerance does not confirm the mode.
            refuse_unseen(checks, a, c, pair, domain, plant_coordinates)?;
        }
        checks.require(
            &format!("{pair} detectable"),
            unstable.is_empty(),
            if unstable.is_empty() {
                format!("unobservable modes {} have {what}", format_list(&fixed))
            } else {
                format!("{pair} is not detectable: unobservable mode(s) {} not stable (no gain can move them)", format_list(&unstable))
            },
        )?;
    }
    let target = match domain {
        Domain::Continuous => free.clone(),
        Domain::Discrete(dt) => {
            sampled_target(free, carried, &fixed, n, dt).map_err(|e| checks.error("poles", e))?
        }
    };
    if target.len() != no {
        let detail = match domain {
            Domain::Continuous if no == n => {
                format!(
                    "{pair} is observable: give {n} pole(s) (poles = [...]), {} given",
                    free.len()
                )
            }
            Domain::Continuous => format!(
                "{pair} has {} fixed mode(s) {} that no gain moves; give {} pole(s) for the observable part{}, {} given",
                n - no,
                format_list(&fixed),
                no,
                if no == 0 {
                    " (poles = [] or no poles key)"
                } else {
                    ""
                },
                free.len()
            ),
            Domain::Discrete(_) => format!(
                "{pair} needs {} pole(s) but the continuous design's {} free pole(s) and {} fixed mode(s) {} map to {} \
                 (the sampled pair has fixed mode(s) {} that sampling did not carry over)",
                no,
                free.len(),
                carried.len(),
                format_list(carried),
                target.len(),
                format_list(&fixed)
            ),
        };
        return Err(checks.error("poles", detail));
    }
    if no == n {
        let placed =
            place_observer(a, c, &target, method).map_err(|e| placement_refused(checks, e))?;
        return Ok((placed.gain, Vec::new()));
    }
    if no == 0 {
        return Ok((Mat::zeros(n, c.nrows()), fixed));
    }
    let stairs = stairs.expect("a staircase whenever no < n");
    let (ao, co) = stairs.observable_part();
    let placed =
        place_observer(&ao, &co, &target, method).map_err(|e| placement_refused(checks, e))?;
    let l = stairs.q.columns(0, no) * placed.gain;
    Ok((l, fixed))
}

/// A placement that failed; one that missed its poles (ill-conditioned: many poles, few
/// outputs, a stiff model) points to the Riccati gain, which needs no pole list.
fn placement_refused(checks: &Checks, e: lti::LtiError) -> DesignError {
    let hint = if matches!(e, lti::LtiError::PlacementMissed { .. }) {
        "; the placement is ill-conditioned: gain = \"lqe\" (instead of poles) designs this pair from a Riccati equation"
    } else {
        ""
    };
    checks.error("pole placement", format!("{e}{hint}"))
}

/// The sampled design's poles: e^{p·dt} for the free poles, then, while the sampled pair has
/// more movable modes than free poles, e^{z·dt} of the continuous fixed modes z that sampling
/// made movable — those farthest (in the s-plane) from every sampled fixed mode first, a
/// conjugate pair together. The sampled pair's fixed modes are those of (Φ, Γ_E, C), which sit
/// near, not on, e^{z·dt} of the continuous ones (within 1e−6 on seed 004, 7e−3 relative on
/// random plants at dt = 0.05): which continuous mode each one "is" is decided by the count, and
/// the distance only orders the rest. More sampled fixed modes than the continuous design had
/// (a zero that sampling made) leave too few movable modes for the free poles: the count then
/// says the design cannot be had.
fn sampled_target(
    free: &Poles,
    carried: &[C64],
    sampled_fixed: &[C64],
    order: usize,
    dt: f64,
) -> Result<Poles, String> {
    // Conjugates mapped as conjugates, so the list stays exactly closed under conjugation.
    let image = |z: C64| {
        if z.im < 0.0 {
            (z.conj() * dt).exp().conj()
        } else {
            (z * dt).exp()
        }
    };
    let mut values: Vec<C64> = free.to_discrete(dt).values().to_vec();
    let movable = order.saturating_sub(sampled_fixed.len());
    if movable > values.len() {
        // |Δs| between a continuous mode z and a sampled one f: |e^{z·dt} − f| / (dt·|e^{z·dt}|).
        let ds = |z: C64, f: C64| (image(z) - f).norm() / (dt * image(z).norm());
        let nearest = |z: C64| {
            sampled_fixed
                .iter()
                .map(|&f| ds(z, f))
                .fold(f64::INFINITY, f64::min)
        };
        let mut order_by: Vec<C64> = carried.iter().copied().filter(|z| z.im >= 0.0).collect();
        order_by.sort_by(|a, b| nearest(*b).total_cmp(&nearest(*a)));
        for z in order_by {
            let take = if z.im > 0.0 { 2 } else { 1 };
            if values.len() + take <= movable {
                values.push(image(z));
                if z.im > 0.0 {
                    values.push(image(z.conj()));
                }
            }
        }
    }
    Poles::from_values(&values).map_err(|e| e.to_string())
}

/// Refuses the pair (A₁, C₁) if a mode on or outside the stability boundary is one no output
/// sees ([`lti::unseen`], the PBH test at those eigenvalues), naming it in s and z and, when the
/// pair's state is the plant's (`plant_coordinates`), the states that carry it. Passes silently
/// otherwise: the condition it adds is the family's own detectability one, already listed.
pub(crate) fn refuse_unseen(
    checks: &mut Checks,
    a1: &Mat,
    c1: &Mat,
    pair: &str,
    domain: Domain,
    plant_coordinates: bool,
) -> Result<(), DesignError> {
    let found = lti::unseen::unseen_modes(a1, c1, |z| !domain.stable(z))
        .map_err(|e| checks.error(pair, e.to_string()))?;
    let Some(first) = found.first() else {
        return Ok(());
    };
    let both = |m: &lti::unseen::Unseen| {
        let times = if m.multiplicity > 1 {
            format!(" (×{})", m.multiplicity)
        } else {
            String::new()
        };
        match domain {
            Domain::Continuous => format!("s = {}{times}", format_one(m.value, true)),
            Domain::Discrete(dt) => {
                // z carries rounding of ~1e-12 at best, ln(z)/dt that over dt: below 1e-9/dt, s is 0.
                let snap = |s: C64| {
                    if s.norm() * dt < 1e-9 {
                        C64::new(0.0, 0.0)
                    } else {
                        s
                    }
                };
                let s = continuous_image(&[m.value], dt)
                    .0
                    .first()
                    .map(|s| format_one(snap(*s), true))
                    .unwrap_or_else(|| "none".into());
                format!("z = {} (s = {s}){times}", format_one(m.value, true))
            }
        }
    };
    let modes: Vec<String> = found.iter().map(both).collect();
    let carried = if plant_coordinates {
        let names: Vec<String> = first
            .states
            .iter()
            .map(|(i, _)| format!("x{}", i + 1))
            .collect();
        format!(", carried by {}", names.join(", "))
    } else {
        String::new()
    };
    let detail = format!(
        "mode {}{carried}: no sensor sees it, no observer can estimate it",
        modes.join("; ")
    );
    let mut err = match checks.require(&format!("{pair} detectable"), false, detail) {
        Err(e) => e,
        Ok(()) => unreachable!("a failed condition is an error"),
    };
    if plant_coordinates {
        err.unseen_states = first.states.iter().map(|(i, _)| *i).collect();
    }
    Err(err)
}

/// Sorted eigenvalues; NaNs where the Schur iteration failed (see below).
pub(crate) fn eig(m: &Mat) -> Vec<C64> {
    // A failure gives NaNs, which no stability check passes: never an "ok" over an empty list.
    eigenvalues(m).unwrap_or_else(|_| vec![C64::new(f64::NAN, f64::NAN); m.nrows()])
}

/// "rank X = r" style details.
pub(crate) fn eq_detail(a: usize, b: usize) -> String {
    format!("{a} {} {b}", if a == b { "=" } else { "≠" })
}

/// Checks that every eigenvalue is stable in `domain`.
pub(crate) fn require_stable(
    checks: &mut Checks,
    name: &str,
    ev: &[C64],
    domain: Domain,
) -> Result<(), DesignError> {
    let bad: Vec<String> = ev
        .iter()
        .filter(|&&z| !domain.stable(z))
        .map(|&z| format_one(z, true))
        .collect();
    if bad.is_empty() {
        checks.require(name, true, format_list(ev))
    } else {
        checks.require(
            name,
            false,
            format!("unstable eigenvalue(s) {}", bad.join(", ")),
        )
    }
}
