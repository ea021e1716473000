//! Every family on the class of plants, not on the shipped examples: 1200 seeded random plants
//! (n = 3…12, p = 1…n − 1, a general full-row-rank C of short decimals, q = 0…p unknown inputs,
//! some with a rank-deficient CE or a mode no sensor sees), each designed by one family, and each
//! verdict checked against an existence test computed here another way:
//!
//! * ranks from nalgebra's SVD (the design uses faer's), with a gap: σ_min/σ_max ≤ 1e-10 is
//!   deficient, ≥ 1e-7 full, in between the plant is counted as ambiguous and skipped;
//! * the modes no gain can move from the PBH test — eigenvalues λ of the family's pair from
//!   nalgebra's Schur form and σ_min([λI − A₁; C]) on the real embedding of the complex matrix
//!   (the design uses a staircase form, or a Riccati equation that fails);
//! * for the UIOs, A₁ = TΦ with T = I − Γ_E(CΓ_E)⁻ from the normal equations (the design uses
//!   the pseudo-inverse, or Das–Ghosal's reduced coordinates).
//!
//! A design that exists must be made; what it makes is checked on the runtime observer alone
//! (z⁺ = Fz + Gu + Ky, x̂ = Pz + Qy) against the sampled plant: ρ(F) < 1, the u → e Markov
//! parameters vanish (x̂ follows x from a consistent start), and for UIOs the w → e ones too,
//! to 1e-12 of the plant's own response. A design that does not exist must be refused naming
//! the true reason: the rank condition, or the unseen / unstable mode.

use lti::place::Method;
use lti::{C64, Mat, Model, PoleSpec, Poles};
use nalgebra::Complex;
use observer::design::{Gain, Spec, Weights, design};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CASES: u64 = 1200;
const DT: f64 = 0.05;

/// The largest Markov parameter of u → e (w → e for UIOs) relative to the terms x̂ is the sum of
/// (see [`markov_error`]). Measured on these 1200 plants (2026-11-29): at most 8.4e-13 (u → e)
/// and 7.3e-13 (w → e), both a placed UIO (seed 437), most below 2e-13.
const TOL_MARKOV: f64 = 1e-12;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Family {
    Luenberger,
    DasGhosal,
    Cumming,
    ChenPattonLqe,
    DasGhosalUioLqe,
    ChenPattonPlace,
    DasGhosalUioPlace,
    Kalman,
}

const FAMILIES: [Family; 8] = [
    Family::Luenberger,
    Family::DasGhosal,
    Family::Cumming,
    Family::ChenPattonLqe,
    Family::DasGhosalUioLqe,
    Family::ChenPattonPlace,
    Family::DasGhosalUioPlace,
    Family::Kalman,
];

impl Family {
    fn decouples(self) -> bool {
        matches!(
            self,
            Family::ChenPattonLqe
                | Family::DasGhosalUioLqe
                | Family::ChenPattonPlace
                | Family::DasGhosalUioPlace
        )
    }
    fn placed(self) -> bool {
        matches!(
            self,
            Family::Luenberger
                | Family::DasGhosal
                | Family::Cumming
                | Family::ChenPattonPlace
                | Family::DasGhosalUioPlace
        )
    }
    fn reduced(self) -> bool {
        matches!(
            self,
            Family::DasGhosal
                | Family::Cumming
                | Family::DasGhosalUioPlace
                | Family::DasGhosalUioLqe
        )
    }
}

/// A short decimal in [−lim, lim] with one decimal digit (C: two, in steps of 0.05).
fn decimal(rng: &mut ChaCha8Rng, lim: i32, step: f64) -> f64 {
    let k = (lim as f64 / step).round() as i32;
    rng.random_range(-k..=k) as f64 * step
}

fn random_mat(rng: &mut ChaCha8Rng, r: usize, c: usize, lim: i32, step: f64) -> Mat {
    Mat::from_fn(r, c, |_, _| decimal(rng, lim, step))
}

/// Singular values by nalgebra's SVD (independent of the design's faer).
fn sv(m: &Mat) -> Vec<f64> {
    if m.is_empty() {
        return Vec::new();
    }
    let mut s: Vec<f64> = m
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    s.sort_by(|a, b| b.total_cmp(a));
    s
}

enum Verdict {
    Holds,
    Fails,
    Ambiguous,
}

/// Full column rank of M by the σ gap.
fn full_column_rank(m: &Mat) -> Verdict {
    if m.ncols() == 0 {
        return Verdict::Holds;
    }
    let s = sv(m);
    if s.len() < m.ncols() {
        return Verdict::Fails;
    }
    let ratio = s[m.ncols() - 1] / s[0];
    if ratio <= 1e-10 {
        Verdict::Fails
    } else if ratio >= 1e-7 {
        Verdict::Holds
    } else {
        Verdict::Ambiguous
    }
}

/// The modes of (A₁, C) no sensor sees (PBH), or None when one is too close to call.
fn unobservable_modes(a1: &Mat, c: &Mat) -> Option<Vec<C64>> {
    let n = a1.nrows();
    let schur = nalgebra::Schur::try_new(a1.clone(), f64::EPSILON, 100_000)?;
    let ev: Vec<C64> = schur.complex_eigenvalues().iter().copied().collect();
    let scale = a1.norm().max(c.norm()).max(1.0);
    let p = c.nrows();
    let mut out = Vec::new();
    for &l in &ev {
        // [λI − A₁; C] as a real (2n + 2p) × 2n matrix: [[Re, −Im], [Im, Re]].
        let mut m = Mat::zeros(2 * (n + p), 2 * n);
        for i in 0..n {
            for j in 0..n {
                let re = if i == j { l.re } else { 0.0 } - a1[(i, j)];
                let im = if i == j { l.im } else { 0.0 };
                m[(i, j)] = re;
                m[(i, n + j)] = -im;
                m[(n + p + i, j)] = im;
                m[(n + p + i, n + j)] = re;
            }
        }
        for i in 0..p {
            for j in 0..n {
                m[(n + i, j)] = c[(i, j)];
                m[(2 * n + p + i, n + j)] = c[(i, j)];
            }
        }
        let smin = *sv(&m).last().unwrap();
        if smin <= 1e-9 * scale {
            out.push(l);
        } else if smin < 1e-6 * scale {
            return None;
        }
    }
    Some(out)
}

/// Whether a mode is stable in the domain (continuous when `dt` is None).
fn stable(l: C64, sampled: bool) -> bool {
    if sampled {
        l.norm() < 1.0 - 1e-9
    } else {
        l.re < -1e-9
    }
}

/// A₁ and its fixed modes for the family's error pair in one domain: (A, C) for the plain
/// observers, (TA, C) with T = I − E(CE)⁻¹C from the normal equations for the UIOs.
fn fixed_modes(a: &Mat, c: &Mat, e: &Mat, decouples: bool) -> Option<Vec<C64>> {
    if !decouples || e.ncols() == 0 {
        return unobservable_modes(a, c);
    }
    let ce = c * e;
    let gram = ce.transpose() * &ce;
    let ce_left = gram.lu().solve(&ce.transpose())?; // (CE)⁻ = (CEᵀCE)⁻¹CEᵀ
    let t = Mat::identity(a.nrows(), a.nrows()) - e * ce_left * c;
    unobservable_modes(&(t * a), c)
}

struct Case {
    model: Model,
    family: Family,
    /// Why it must be refused, when it must.
    refusal: Option<&'static str>,
    /// The count of free poles (placement), one per movable mode of the continuous pair.
    free: usize,
}

fn make(seed: u64) -> Option<Case> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let family = FAMILIES[(seed % FAMILIES.len() as u64) as usize];
    // Placement with few outputs is ill-conditioned past ~8 states (scipy's place_poles too);
    // the Riccati families take the whole range.
    let n = if family.placed() {
        rng.random_range(3..=8)
    } else {
        rng.random_range(3..=12)
    };
    let p = rng.random_range(1..n);
    let q = if family.decouples() {
        rng.random_range(0..=p)
    } else {
        0
    };
    let c = loop {
        let c = random_mat(&mut rng, p, n, 2, 0.05);
        if matches!(full_column_rank(&c.transpose()), Verdict::Holds) {
            break c;
        }
    };
    let mut a = random_mat(&mut rng, n, n, 2, 0.1);
    let m = 1 + rng.random_range(0..2);
    let b = random_mat(&mut rng, n, m, 2, 0.1);
    let mut e = random_mat(&mut rng, n, q, 2, 0.1);
    let kernel = lti::subspace::null_space(&c); // n×(n − p), orthonormal
    let twist = rng.random_range(0..10);
    if twist == 0 && q > 0 {
        // A disturbance direction no sensor sees: CE loses rank.
        let v = kernel.column(kernel.ncols() - 1).into_owned();
        e.column_mut(q - 1).copy_from(&v);
    } else if twist == 1 {
        // A mode no sensor sees: v ∈ ker C made an eigenvector of A, at λ = −0.7 or +0.4.
        let v = kernel.column(kernel.ncols() - 1).into_owned();
        let lambda = if rng.random_range(0..2) == 0 {
            -0.7
        } else {
            0.4
        };
        let av = &a * &v;
        a -= (av - &v * lambda) * v.transpose();
    }
    let model = Model {
        a,
        b,
        c,
        e,
        d: Mat::zeros(p, 0),
    };
    let dm = model.discretize(DT);
    let decouples = family.decouples();
    if decouples && q > 0 {
        // A Riccati gain is designed on the sampled plant alone; a placed one on both.
        let checked = if family.placed() {
            vec![&model.c * &model.e, &dm.c * &dm.e]
        } else {
            vec![&dm.c * &dm.e]
        };
        for m in checked {
            match full_column_rank(&m) {
                Verdict::Holds => {}
                Verdict::Fails => {
                    return Some(Case {
                        model,
                        family,
                        refusal: Some("rank"),
                        free: 0,
                    });
                }
                Verdict::Ambiguous => return None,
            }
        }
    }
    let sampled = fixed_modes(&dm.a, &dm.c, &dm.e, decouples)?;
    if sampled.iter().any(|&l| !stable(l, true)) {
        return Some(Case {
            model,
            family,
            refusal: Some("mode"),
            free: 0,
        });
    }
    let mut free = 0;
    if family.placed() {
        let cont = fixed_modes(&model.a, &model.c, &model.e, decouples)?;
        if cont.iter().any(|&l| !stable(l, false)) {
            return Some(Case {
                model,
                family,
                refusal: Some("mode"),
                free: 0,
            });
        }
        let order = if family.reduced() { n - p } else { n };
        if cont.len() > order || sampled.len() != cont.len() {
            return None; // sampling made or removed a zero: a different question
        }
        free = order - cont.len();
    }
    Some(Case {
        model,
        family,
        refusal: None,
        free,
    })
}

fn spec(case: &Case) -> Spec {
    let poles = Poles::new((0..case.free).map(|k| PoleSpec::Real(-1.0 - 0.37 * k as f64))).unwrap();
    let place = Gain::place(poles, Method::YangTits);
    let lqe = Gain::Lqe(Weights::default());
    match case.family {
        Family::Luenberger => Spec::Luenberger { gain: place },
        Family::DasGhosal => Spec::DasGhosal { gain: place },
        Family::Cumming => Spec::Cumming {
            gain: place,
            h: None,
        },
        Family::ChenPattonLqe => Spec::ChenPatton { gain: lqe },
        Family::ChenPattonPlace => Spec::ChenPatton { gain: place },
        Family::DasGhosalUioLqe => Spec::DasGhosalUio {
            h: None,
            gain: Some(lqe),
        },
        Family::DasGhosalUioPlace => Spec::DasGhosalUio {
            h: None,
            gain: Some(place),
        },
        Family::Kalman => {
            let n = case.model.a.nrows();
            let p = case.model.c.nrows();
            Spec::Kalman {
                qd: Mat::identity(n, n),
                r: Mat::identity(p, p),
            }
        }
    }
}

/// The largest |e_k| over 40 steps of the sampled plant and the runtime observer from a
/// consistent start (x₀ = 0, z₀ = 0), driven by an impulse in one input column, relative to
/// the terms it is the difference of: max_k(|x_k| + |Pz_k| + |Qy_k|). An error of a few ε of
/// those is rounding of x̂ = Pz + Qy; a design that does not decouple leaves O(1).
#[allow(clippy::too_many_arguments)] // the five observer matrices and the plant's three
fn markov_error(
    f: &Mat,
    g: &Mat,
    k: &Mat,
    pm: &Mat,
    qm: &Mat,
    phi: &Mat,
    gamma: &Mat,
    c: &Mat,
    known: bool,
) -> f64 {
    let (n, r) = (phi.nrows(), f.nrows());
    let mut worst: f64 = 0.0;
    for col in 0..gamma.ncols() {
        let mut x = Mat::zeros(n, 1);
        let mut z = Mat::zeros(r, 1);
        let mut xmax: f64 = 0.0;
        let mut emax: f64 = 0.0;
        for step in 0..40 {
            let y = c * &x;
            let (pz, qy) = (pm * &z, qm * &y);
            emax = emax.max((&x - &pz - &qy).amax());
            // The terms x̂ is the sum of, and those z is: |P|(|F||z| + |K||y|) + |Q||y| + |x|.
            let inner = f.abs() * z.abs() + k.abs() * y.abs();
            let terms = pm.abs() * inner + qm.abs() * y.abs() + x.abs();
            xmax = xmax.max(terms.amax());
            let mut input = Mat::zeros(gamma.ncols(), 1);
            if step == 0 {
                input[(col, 0)] = 1.0;
            }
            let u = if known {
                input.clone()
            } else {
                Mat::zeros(g.ncols(), 1)
            };
            z = f * &z + g * &u + k * &y;
            x = phi * &x + gamma * &input;
        }
        worst = worst.max(emax / xmax.max(f64::MIN_POSITIVE));
    }
    worst
}

#[test]
fn every_family_designs_exactly_where_an_independent_check_says_it_exists_on_1200_random_plants() {
    let (mut designed, mut refused, mut ambiguous, mut ill) = (0, 0, 0, 0);
    let mut failures = Vec::new();
    for seed in 0..CASES {
        let Some(case) = make(seed) else {
            ambiguous += 1;
            continue;
        };
        let sp = spec(&case);
        let dm = case.model.discretize(DT);
        let got = design(&case.model, &sp, DT);
        let label = format!(
            "seed {seed} {:?} n={} p={} q={}",
            case.family,
            dm.a.nrows(),
            dm.c.nrows(),
            dm.e.ncols()
        );
        match (&case.refusal, got) {
            (None, Ok(d)) => {
                designed += 1;
                let rt = &d.runtime;
                let [f, g, k, pm, qm] = [&rt.f, &rt.g, &rt.k, &rt.p, &rt.q].map(Mat::from);
                let rho = lti::eig::spectral_radius(
                    &nalgebra::Schur::new(f.clone())
                        .complex_eigenvalues()
                        .iter()
                        .map(|z| Complex::new(z.re, z.im))
                        .collect::<Vec<_>>(),
                );
                if rho >= 1.0 {
                    failures.push(format!("{label}: designed with ρ(F) = {rho}"));
                }
                let eu = markov_error(&f, &g, &k, &pm, &qm, &dm.a, &dm.b, &dm.c, true);
                if eu > TOL_MARKOV {
                    failures.push(format!(
                        "{label}: u → e Markov parameters {eu:.2e} of the response"
                    ));
                }
                if case.family.decouples() && dm.e.ncols() > 0 {
                    let ew = markov_error(&f, &g, &k, &pm, &qm, &dm.a, &dm.e, &dm.c, false);
                    if ew > TOL_MARKOV {
                        failures.push(format!(
                            "{label}: w → e Markov parameters {ew:.2e} of the response"
                        ));
                    }
                }
                for cond in &d.report.conditions {
                    if !cond.ok {
                        failures.push(format!(
                            "{label}: designed with a failed condition {}",
                            cond.name
                        ));
                    }
                }
            }
            // Placement of many poles through few outputs can be too ill-conditioned to meet
            // (scipy's place_poles misses there too): refused as such, pointing to the Riccati
            // gain, it is counted, not failed.
            (None, Err(e)) if case.family.placed() && e.to_string().contains("ill-conditioned") => {
                ill += 1
            }
            (None, Err(e)) => failures.push(format!("{label}: exists, refused: {e}")),
            (Some(why), Ok(_)) => failures.push(format!(
                "{label}: designed though {why} says it cannot exist"
            )),
            (Some(why), Err(e)) => {
                refused += 1;
                let text = e.to_string();
                let named = match *why {
                    "rank" => text.contains("rank") || text.contains("eq. 21"),
                    _ => ["zero", "detectable", "unobservable", "no sensor"]
                        .iter()
                        .any(|w| text.contains(w)),
                };
                if !named {
                    failures.push(format!(
                        "{label}: refused for the wrong reason (want {why}): {text}"
                    ));
                }
            }
        }
    }
    eprintln!(
        "{designed} designed, {refused} refused, {ill} placements refused as ill-conditioned, {ambiguous} too close to call"
    );
    assert!(
        ambiguous * 20 < CASES as usize,
        "{ambiguous} of {CASES} cases too close to call"
    );
    assert!(
        ill * 50 < CASES as usize,
        "{ill} of {CASES} placements refused as ill-conditioned"
    );
    assert!(
        refused * 10 > CASES as usize && designed * 2 > CASES as usize,
        "{designed} designed, {refused} refused"
    );
    assert!(
        failures.is_empty(),
        "{} of {CASES} wrong:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
