//! Full-order Luenberger observer (Luenberger 1964): x̂˙ = Ax̂ + Bu + L(y − Cx̂),
//! error ė = (A − LC)e with eig(A − LC) placed. It ignores the unknown inputs: w and v drive
//! the error, which is what the unknown-input observers are compared against.
//!
//! Sampled counterpart (predictor form): x̂_{k+1} = A_d x̂_k + B_d u_k + L_d(y_k − Cx̂_k),
//! eig(A_d − L_dC) = e^{p·dt}.

use lti::place::Method;
use lti::{Mat, Model, Poles};

use super::{eig, place_detectable, require_stable, Checks, Designed, DesignError, Domain, Report};
use crate::runtime::LinearObserver;

const KIND: &str = "luenberger";

fn gain(a: &Mat, c: &Mat, poles: &Poles, carried: &[lti::C64], method: Method, domain: Domain, checks: &mut Checks) -> Result<(Mat, Vec<lti::C64>), DesignError> {
    place_detectable(checks, a, c, poles, carried, method, "(A, C)", domain)
}

pub(super) fn design(model: &Model, poles: &Poles, method: Method, dt: f64) -> Result<Designed, DesignError> {
    let mut checks = Checks::new(KIND);
    let (l, fixed) = gain(&model.a, &model.c, poles, &[], method, Domain::Continuous, &mut checks)?;
    let f = &model.a - &l * &model.c;
    let poles_c = eig(&f);
    require_stable(&mut checks, "A − LC stable", &poles_c, Domain::Continuous)?;

    let dm = model.discretize(dt);
    let mut sampled = Checks::sampled(KIND, dt);
    let (ld, _) = gain(&dm.a, &dm.c, poles, &fixed, method, Domain::Discrete(dt), &mut sampled)?;
    let fd = &dm.a - &ld * &dm.c;
    let n = model.n();
    let runtime = LinearObserver::new(&fd, &dm.b, &ld, &Mat::identity(n, n), &Mat::zeros(n, model.p()));
    Ok(Designed {
        report: Report {
            kind: KIND,
            conditions: checks.into_list(),
            matrices: vec![("L".into(), l), ("F".into(), f)],
            poles: poles_c,
            discrete_poles: eig(&fd),
            fixed_modes: fixed,
            notes: vec![],
        },
        runtime,
    })
}
