//! The configuration each component receives, built from the scenario and its designs. The
//! same values drive the in-process loop, so both modes compute with identical numbers.

use controller::{ControllerConfig, FeedforwardConfig, IntegralConfig};
use lockstep::PlantLayout;
use observer::LinearObserver;
use plant::PlantConfig;

use crate::plan::Plan;
use scenario::Scenario;

/// Every component's configuration.
#[derive(Debug, Clone)]
pub struct Configs {
    /// The plant's (the built-in plant reads the same from the protocol's fields).
    pub plant: PlantConfig,
    /// Per observer, whether it may trail the plant (a follower: off the ring's critical path).
    pub followers: Vec<bool>,
    /// Whether a controller, built in or external, closes the loop.
    pub closed_loop: bool,
    /// (name, sampled observer) per observer; none for an external observer.
    pub observers: Vec<(String, Option<LinearObserver>)>,
    /// The observer processes across processes, each the observers it steps
    /// ([`scenario::observer_processes`]: a bank's members share one).
    pub processes: Vec<scenario::ObserverProcess>,
    /// The built-in controller's (none without one, or for an external one).
    pub controller: Option<ControllerConfig>,
    /// The plant sample layout.
    pub layout: PlantLayout,
    /// Real-time pacing period, s (dt / speed), with `--realtime`.
    pub pace_s: Option<f64>,
}

/// How long a follower sleeps between batches. Each wake-up takes a core from the ring while
/// the batch is worked through, so wake rarely: at ~150k steps/s, 5 ms is ~750 samples, well
/// within [`lockstep::FOLLOWER_LAG`] (measured: 1 ms batches put the step's p99 at ~26 µs,
/// 5 ms batches at ~8 µs).
pub const FOLLOWER_SLEEP_US: u32 = 5000;

/// Observers the controller does not read are off the critical path: in closed loop every one
/// but the controller's; in open loop, where the plant reads no estimate, every one but the
/// first. That one keeps the plant in step with the ring, so that the launcher, which reads
/// every sample but paces no one, cannot fall more than its buffer
/// ([`lockstep::RECORDER_BUFFER`]) behind a plant only followers would hold back
/// ([`lockstep::FOLLOWER_LAG`] steps ahead of them).
pub fn is_follower(s: &Scenario, observer: &str) -> bool {
    s.ring_observer().is_some_and(|r| r != observer)
}

/// The plant's noise: the scenario's covariances and seed; a run with only noise-burst faults
/// still needs the seed.
pub fn noise(s: &Scenario) -> Option<plant::Noise> {
    let bursts = s.faults.iter().any(|f| f.kind == plant::fault::Kind::Noise);
    let (n, p) = (s.model.n(), s.model.p());
    match &s.noise {
        Some(z) => Some(plant::Noise {
            seed: s.seed,
            qd: (&z.qd).into(),
            r: (&z.r).into(),
        }),
        None if bursts => Some(plant::Noise {
            seed: s.seed,
            qd: (&lti::Mat::zeros(n, n)).into(),
            r: (&lti::Mat::zeros(p, p)).into(),
        }),
        None => None,
    }
}

/// Builds the configurations.
pub fn configs(s: &Scenario, plan: &Plan) -> Configs {
    let m = &s.model;
    let layout = PlantLayout {
        n: m.n(),
        p: m.p(),
        q: m.e.ncols(),
        r: m.d.ncols(),
        l: m.l(),
        f: s.faults.len(),
    };
    let plant = PlantConfig {
        a: (&m.a).into(),
        b: (&m.b).into(),
        c: (&m.c).into(),
        e: (&m.e).into(),
        d: (&m.d).into(),
        x0: s.x0.clone(),
        disturbances: s.disturbances.clone(),
        measurement_disturbances: s.measurement_disturbances.clone(),
        inputs: s.inputs.clone(),
        dt: s.dt,
        steps: s.steps,
        state_bound: s.state_bound,
        ff: (&s.ff).into(),
        faults: s.faults.clone(),
        noise: noise(s),
        discrete: s.discrete,
    };
    let followers = s
        .observers
        .iter()
        .map(|o| is_follower(s, &o.name))
        .collect();
    let observers = plan
        .observers
        .iter()
        .map(|(name, d)| (name.clone(), d.as_ref().map(|d| d.runtime.clone())))
        .collect();
    let controller = match (&s.controller, &plan.feedback) {
        (Some(c), Some(fb)) => Some(ControllerConfig {
            g: (&fb.g).into(),
            n: (&fb.n).into(),
            references: s.inputs.clone(),
            dt: s.dt,
            observer: c.observer.clone(),
            integral: fb.integral.as_ref().map(|(gi, ct, m)| match m {
                Some(m) => IntegralConfig {
                    gi: gi.into(),
                    ct: m.into(),
                    y: Some([layout.y().start, layout.y().end]),
                    references: integrated(fb),
                },
                None => IntegralConfig {
                    gi: gi.into(),
                    ct: ct.into(),
                    y: None,
                    references: integrated(fb),
                },
            }),
            feedforward: fb.feedforward.as_ref().map(|[mw, a, b]| FeedforwardConfig {
                mw: mw.into(),
                mw_c_phi: a.into(),
                mw_c_gamma_b: b.into(),
                y: [layout.y().start, layout.y().end],
                u_prev: [layout.u_prev().start, layout.u_prev().end],
                offset: s
                    .operating_point
                    .as_ref()
                    .filter(|op| !op.is_origin())
                    .map(|op| {
                        // M(c − w_op) = −M(W y_op − WCΦ x_op − WCΓ_B u_op): what cancels Mδŵ.
                        lti::input_estimate::at_rest(mw, a, b, &op.x, &op.u, &op.y)
                            .iter()
                            .map(|v| -v)
                            .collect()
                    }),
            }),
            offset: s
                .operating_point
                .as_ref()
                .filter(|op| !op.is_origin())
                .map(|op| fb.offset_at(c.track.as_ref(), op)),
        }),
        _ => None,
    };
    Configs {
        plant,
        followers,
        closed_loop: s.controller.is_some(),
        observers,
        processes: s.observer_processes(),
        controller,
        layout,
        pace_s: None,
    }
}

/// The references the integrators compare with: the commanded inputs' (all, as an empty list,
/// without measured disturbances).
fn integrated(fb: &controller::design::FeedbackDesign) -> Vec<usize> {
    if fb.measured.is_empty() {
        Vec::new()
    } else {
        controller::design::measured::commanded(fb.g.nrows(), &fb.measured)
    }
}
