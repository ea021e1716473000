//! `--mode in-process`: the same step functions, called in lockstep order in one process.

use controller::Controller;
use lockstep::now_ns;
use lti::kernel::copy;
use observer::ObserverState;
use plant::Plant;

use super::configs::Configs;
use super::session::Session;
use super::{Stop, interrupt};
use crate::error::LaunchError;
use recording::write::StepRow;

/// Runs every step; returns how it ended.
pub fn run(cfg: &Configs, session: &mut Session) -> Result<Stop, LaunchError> {
    let mut plant = Plant::new(&cfg.plant).map_err(LaunchError::Component)?;
    // External components were refused before the run (`run::run`): every observer is ours.
    let mut observers: Vec<ObserverState> = cfg
        .observers
        .iter()
        .map(|(_, o)| o.as_ref().expect("built-in").instantiate())
        .collect();
    let mut controller = cfg
        .controller
        .as_ref()
        .map(Controller::new)
        .transpose()
        .map_err(LaunchError::Component)?;
    let ctrl_obs = cfg
        .controller
        .as_ref()
        .and_then(|c| cfg.observers.iter().position(|(n, _)| *n == c.observer));
    let lay = cfg.layout;
    let mut row = StepRow::new(lay, observers.len(), controller.is_some());
    let mut u = vec![0.0; lay.l];
    // Real-time pacing: step k starts at t₀ + k·period.
    let pace = cfg.pace_s.map(|p| (p * 1e9).round() as u64);
    let mut t0 = 0;
    if pace.is_some() {
        lockstep::tight_timers();
        t0 = now_ns();
        session.pace_start(t0);
    }
    for k in 0..cfg.plant.steps {
        if let Some(p) = pace {
            lockstep::sleep_until_ns(t0 + k * p);
        }
        if k % 1024 == 0
            && let Some(sig) = interrupt::received()
        {
            return Ok(Stop::Interrupted(sig));
        }
        // Timing every step would cost two clock reads per ~0.2 µs step: sample one in 16.
        let timed = k % 16 == 0;
        let start = if timed { now_ns() } else { 0 };
        row.k = k;
        row.t = plant.time(k);
        row.plant.copy_from_slice(plant.sample(k));
        for (i, obs) in observers.iter_mut().enumerate() {
            let xhat = obs.step(&row.plant[lay.y()], &row.plant[lay.u_prev()]);
            copy(&mut row.xhat[i], xhat);
        }
        match (&mut controller, ctrl_obs) {
            (Some(c), Some(o)) => {
                copy(&mut u, c.step(k, &row.xhat[o], &row.plant));
                copy(&mut row.u, &u);
            }
            _ => copy(&mut u, plant.reference()),
        }
        let diverged = plant.advance(k, &u);
        let step_ns = if timed { Some(now_ns() - start) } else { None };
        session.record_in_process(&row, step_ns)?;
        if pace.is_some() {
            session.step_ended(k, now_ns())?;
        }
        if let Err(d) = diverged {
            return Ok(Stop::Diverged(d.to_string()));
        }
        if let Some(w) = session.diverged.take() {
            return Ok(Stop::Diverged(w));
        }
    }
    Ok(Stop::Completed)
}
