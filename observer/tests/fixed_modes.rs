//! Plants whose (A, E, C) has invariant zeros that sampling removes: the user gives the free
//! poles, the continuous design keeps the zeros as fixed modes, and the sampled design places
//! its whole spectrum at e^{s·dt} of the continuous one (the rule of `place_detectable`).
//!
//! The expected spectra are independent of the design code: the free poles are what the test
//! asks for, the zeros are built into each plant by construction (the zero dynamics of a known
//! block form, hidden by a random similarity), and the sampled images are e^{s·dt}.

use lti::eig::{eigenvalues, match_error};
use lti::place::Method;
use lti::{C64, Mat, Model, PoleSpec, Poles};
use observer::design::{Gain, Path, Spec, design};

#[path = "../../fixtures/zero_plants.rs"]
mod zero_plants;

fn real(v: &[f64]) -> Poles {
    Poles::new(v.iter().map(|&x| PoleSpec::Real(x))).unwrap()
}

fn images(s: &[C64], dt: f64) -> Vec<C64> {
    s.iter().map(|z| (z * dt).exp()).collect()
}

/// The DC motor: x = [i, ω, θ], the load torque w enters ω, y = [ω, θ]. The
/// current i reaches the outputs only through ω, where w enters too: s = −2 is an invariant
/// zero of (A, E, C), and (T_dA_d, C) of the exact sampling has none.
fn dc_motor() -> Model {
    Model {
        a: Mat::from_row_slice(3, 3, &[-2.0, -0.02, 0.0, 1.0, -10.0, 0.0, 0.0, 1.0, 0.0]),
        b: Mat::from_row_slice(3, 1, &[2.0, 0.0, 0.0]),
        c: Mat::from_row_slice(2, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
        e: Mat::from_row_slice(3, 1, &[0.0, -100.0, 0.0]),
        d: Mat::zeros(2, 0),
    }
}

#[test]
fn dc_motor_chen_patton_takes_the_free_poles_and_keeps_the_zero() {
    let dt = 1e-3;
    let spec = Spec::ChenPatton {
        gain: Gain::place(real(&[-20.0, -30.0]), Method::YangTits),
    };
    let d = design(&dc_motor(), &spec, dt).unwrap_or_else(|e| panic!("{e}"));
    let want = [
        C64::new(-2.0, 0.0),
        C64::new(-20.0, 0.0),
        C64::new(-30.0, 0.0),
    ];
    assert!(
        match_error(&want, &d.report.poles) < 1e-8,
        "{:?}",
        d.report.poles
    );
    assert!(match_error(&[C64::new(-2.0, 0.0)], &d.report.fixed_modes) < 1e-9);
    assert!(
        match_error(&images(&want, dt), &d.report.discrete_poles) < 1e-10,
        "{:?}",
        d.report.discrete_poles
    );
    // What runs is the sampled F: its eigenvalues, recomputed from the runtime matrices.
    let f: Mat = (&d.runtime.f).into();
    assert!(match_error(&images(&want, dt), &eigenvalues(&f).unwrap()) < 1e-10);
}

#[test]
fn dc_motor_refuses_three_poles_and_says_how_many() {
    let spec = Spec::ChenPatton {
        gain: Gain::place(real(&[-20.0, -30.0, -40.0]), Method::YangTits),
    };
    let e = design(&dc_motor(), &spec, 1e-3).unwrap_err();
    assert!(e.detail.contains("give 2 pole(s)"), "{e}");
    assert!(
        !e.condition.contains("sampled"),
        "the continuous design refuses, not the sampled one: {e}"
    );
}

#[test]
fn dc_motor_hui_zak_designs_with_default_poles() {
    let dt = 1e-3;
    let spec = Spec::HuiZak {
        decay: 1.0,
        gain: None,
        placement: Method::YangTits,
        path: Path::Placement,
    };
    let d = design(&dc_motor(), &spec, dt).unwrap_or_else(|e| panic!("{e}"));
    assert!(match_error(&[C64::new(-2.0, 0.0)], &d.report.fixed_modes) < 1e-9);
    assert!(match_error(&images(&d.report.poles, dt), &d.report.discrete_poles) < 1e-10);
}

#[test]
fn random_plants_with_invariant_zeros_design_the_same_spectrum_in_both_domains() {
    let dt = 1e-3;
    // Seed 7's fourth plant (zeros −0.5 ± j√7) has staircase blocks that should vanish but carry
    // ~20ε‖A‖ of rounding, which an n·ε rank tolerance took for rank: its zeros went unseen.
    for (seed, i, (m, zeros, _)) in [7, 20261124].into_iter().flat_map(|seed| {
        zero_plants::plants(seed)
            .into_iter()
            .enumerate()
            .map(move |(i, p)| (seed, i, p))
    }) {
        let zeros = &zeros[..];
        let i = format!("{seed}/{i}");
        let free: Vec<f64> = (0..m.n() - zeros.len())
            .map(|j| -5.0 - 3.0 * j as f64)
            .collect();
        for (kind, spec) in [
            (
                "chen-patton",
                Spec::ChenPatton {
                    gain: Gain::place(real(&free), Method::YangTits),
                },
            ),
            (
                "hui-zak",
                Spec::HuiZak {
                    decay: 0.0,
                    gain: Some(Gain::place(real(&free), Method::YangTits)),
                    placement: Method::YangTits,
                    path: Path::Placement,
                },
            ),
        ] {
            let d = design(&m, &spec, dt).unwrap_or_else(|e| panic!("case {i} {kind}: {e}"));
            let mut want: Vec<C64> = free.iter().map(|&p| C64::new(p, 0.0)).collect();
            want.extend_from_slice(zeros);
            assert!(
                match_error(zeros, &d.report.fixed_modes) < 1e-7,
                "case {i} {kind}: fixed {:?}",
                d.report.fixed_modes
            );
            assert!(
                match_error(&want, &d.report.poles) < 1e-6,
                "case {i} {kind}: {:?}",
                d.report.poles
            );
            let f: Mat = (&d.runtime.f).into();
            let got = eigenvalues(&f).unwrap();
            assert!(
                match_error(&images(&want, dt), &got) < 1e-9,
                "case {i} {kind}: sampled {got:?}"
            );
        }
    }
}

#[test]
fn empty_pole_list_for_a_pair_with_only_fixed_modes() {
    // das-ghosal-uio on a plant whose reduced-order pair has no observable part: poles = [].
    let m = Model {
        a: Mat::from_row_slice(3, 3, &[-1.0, 0.0, 0.0, 1.0, -2.0, 0.0, 0.0, 1.0, -3.0]),
        b: Mat::from_row_slice(3, 1, &[1.0, 0.0, 0.0]),
        c: Mat::from_row_slice(2, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
        e: Mat::from_row_slice(3, 1, &[0.0, 1.0, 0.0]),
        d: Mat::zeros(2, 0),
    };
    let none = Poles::new([]).unwrap();
    let d = design(
        &m,
        &Spec::DasGhosalUio {
            h: None,
            gain: Some(Gain::place(none, Method::YangTits)),
        },
        1e-3,
    );
    let d = d.unwrap_or_else(|e| panic!("{e}"));
    assert!(
        match_error(&[C64::new(-1.0, 0.0)], &d.report.poles) < 1e-9,
        "{:?}",
        d.report.poles
    );
    // One pole where none fits: the message says what to write.
    let e = design(
        &m,
        &Spec::DasGhosalUio {
            h: None,
            gain: Some(Gain::place(real(&[-5.0]), Method::YangTits)),
        },
        1e-3,
    )
    .unwrap_err();
    assert!(
        e.detail.contains("give 0 pole(s)") && e.detail.contains("poles = []"),
        "{e}"
    );
}
