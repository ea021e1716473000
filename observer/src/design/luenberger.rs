//! Full-order Luenberger observer (Luenberger 1964): x̂˙ = Ax̂ + Bu + L(y − Cx̂),
//! error ė = (A − LC)e with eig(A − LC) placed. It ignores the unknown inputs: w and v drive
//! the error, which is what the unknown-input observers are compared against.
//!
//! Sampled counterpart (predictor form): x̂_{k+1} = A_d x̂_k + B_d u_k + L_d(y_k − Cx̂_k),
//! eig(A_d − L_dC) = e^{p·dt}.

use lti::{Discrete, Mat, Model};

use super::{
    Checks, DesignError, Designed, Domain, Gain, Pair, Report, eig, free_gain, require_stable,
    sampled_report,
};
use crate::runtime::LinearObserver;

const KIND: &str = "luenberger";

pub(super) fn design(
    model: Option<&Model>,
    dm: &Discrete,
    gain: &Gain,
) -> Result<Designed, DesignError> {
    let dt = dm.dt;
    let mut checks = Checks::new(KIND);
    // The continuous design (placement only): the report's paper form, and the fixed modes the
    // sampled design carries over.
    let continuous = match (gain, model) {
        (Gain::Lqe(_), _) | (_, None) => None,
        (Gain::Place { .. }, Some(model)) => {
            let (l, fixed) = free_gain(
                &mut checks,
                &Pair::full(&model.a, &model.c, "(A, C)"),
                gain,
                &[],
                Domain::Continuous,
            )?;
            let f = &model.a - &l * &model.c;
            let poles_c = eig(&f);
            require_stable(&mut checks, "A − LC stable", &poles_c, Domain::Continuous)?;
            Some((l, f, poles_c, fixed))
        }
    };
    let carried = continuous.as_ref().map(|c| c.3.clone()).unwrap_or_default();

    let mut sampled = Checks::sampled(KIND, dt);
    let (ld, fixed_d) = free_gain(
        &mut sampled,
        &Pair::full(&dm.a, &dm.c, "(Φ, C)"),
        gain,
        &carried,
        Domain::Discrete(dt),
    )?;
    let fd = &dm.a - &ld * &dm.c;
    let n = dm.a.nrows();
    let runtime = LinearObserver::new(
        &fd,
        &dm.b,
        &ld,
        &Mat::identity(n, n),
        &Mat::zeros(n, dm.c.nrows()),
    );
    let report = match continuous {
        Some((l, f, poles, fixed)) => Report {
            kind: KIND,
            conditions: checks.into_list(),
            matrices: vec![("L".into(), l), ("F".into(), f)],
            poles,
            discrete_poles: eig(&fd),
            fixed_modes: fixed,
            notes: vec![],
            sampled_only: false,
        },
        None => {
            require_stable(
                &mut sampled,
                "Φ − LC stable",
                &eig(&fd),
                Domain::Discrete(dt),
            )?;
            sampled_report(
                KIND,
                sampled,
                &fd,
                fixed_d,
                vec![("L".into(), ld.clone()), ("F".into(), fd.clone())],
                vec![],
                dt,
            )
        }
    };
    Ok(Designed {
        report,
        runtime,
        what: None,
    })
}
