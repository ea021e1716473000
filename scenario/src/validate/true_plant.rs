//! What the run simulates as the plant — the built-in one, an external process, an FMU or
//! replayed data — with its faults, noise and operating point, and what each of them excludes.

use std::path::{Path, PathBuf};

use crate::check::{Bad, bad};
use crate::limits::MAX_FAULTS;
use crate::raw::RawScenario;
use crate::{NoiseSpec, ProcessSpec};

/// What the true plant is and what acts on it.
pub(super) struct TruePlant {
    pub noise: Option<NoiseSpec>,
    pub faults: Vec<plant::Fault>,
    pub fmu: Option<(PathBuf, ProcessSpec)>,
    pub replay: Option<(PathBuf, ProcessSpec)>,
    pub operating_point: Option<lti::OperatingPoint>,
}

// one job: who simulates the true plant (built-in, process, FMU or replay), validated with the
// operating point they share.
pub(super) fn true_plant(
    raw: &RawScenario,
    plant: &super::plant::Plant,
    dt: f64,
    steps: u64,
    dir: Option<&Path>,
) -> Result<TruePlant, Bad> {
    let p = &raw.plant;
    let (model, ff, discrete) = (&plant.model, &plant.ff, plant.discrete);
    let (n, x0, layout_names) = (model.n(), &plant.x0, &plant.names);
    if discrete {
        // What needs the continuous A: a continuous noise intensity (Van Loan), an external
        // plant (PROTOCOL.md §3 sends A), the banks' structure from Markov parameters.
        if raw.noise.as_ref().is_some_and(|z| z.process.is_some()) {
            return Err(bad(
                "noise.process",
                "a discrete-time plant takes process_discrete (Q_d per step), not a continuous intensity",
            ));
        }
        if p.process.is_some() {
            return Err(bad(
                "plant.process",
                "time = \"discrete\" is for the built-in plant: an external plant simulates itself",
            ));
        }
        if !raw.diagnoser.is_empty() {
            return Err(bad(
                "diagnoser[1]",
                "diagnosis banks need a continuous-time plant (time = \"discrete\" does not take [[diagnoser]] yet)",
            ));
        }
    }
    let noise = crate::fault_diagnosis::noise(&raw.noise, model, dt)?;
    if raw.fault.len() > MAX_FAULTS {
        return Err(bad(
            format!("fault[{}]", MAX_FAULTS + 1),
            format!(
                "{} faults: at most {MAX_FAULTS} (each adds two values to every plant sample and two recorded signals)",
                raw.fault.len()
            ),
        ));
    }
    let faults = crate::fault_diagnosis::faults(&raw.fault, model, ff, dt)?;
    if p.process.is_some()
        && let Some(what) = [
            (!raw.fault.is_empty(), "fault"),
            (raw.noise.is_some(), "noise"),
        ]
        .iter()
        .find(|w| w.0)
        .map(|w| w.1)
    {
        return Err(bad(
            what,
            "faults and noise are applied by the built-in plant: an external plant (plant.process) models its own",
        ));
    }
    if p.fmu.is_some() {
        // Actuator faults act on the FMU's inputs and sensor faults and measurement noise on its
        // outputs; what acts inside (F_f, process noise) is the FMU's own.
        if p.process.is_some() {
            return Err(bad(
                "plant.fmu",
                "one true plant: [plant.process] or [plant.fmu], not both",
            ));
        }
        if let Some(i) = faults
            .iter()
            .position(|f| matches!(f.target, plant::fault::Target::Component(_)))
        {
            return Err(bad(
                format!("fault[{}].target", i + 1),
                "a component fault acts through F_f of the built-in plant: an FMU plant takes actuator and sensor faults",
            ));
        }
        if raw
            .noise
            .as_ref()
            .is_some_and(|z| z.process.is_some() || z.process_discrete.is_some())
        {
            return Err(bad(
                "noise.process",
                "process noise enters the state, which an FMU plant keeps to itself: an FMU plant takes measurement noise only",
            ));
        }
    }
    let sizes = crate::plant_file::Sizes {
        n,
        p: model.c.nrows(),
        l: model.b.ncols(),
        q: model.e.ncols(),
    };
    let fmu = crate::fmu_plant::plant_fmu(&p.fmu, dir, &sizes, x0.as_deref())?;
    if p.replay.is_some() {
        // Recorded data holds its own faults and noise: [[fault]] and [noise] then describe
        // them (for the design and the scoring), and nothing is applied.
        if p.process.is_some() || p.fmu.is_some() {
            return Err(bad(
                "plant.replay",
                "one true plant: [plant.process], [plant.fmu] or [plant.replay]",
            ));
        }
        if raw.controller.is_some() {
            return Err(bad(
                "controller",
                "the plant is replayed from recorded data, which cannot react to a controller: a replay is open loop",
            ));
        }
    }
    let builtin = p.process.is_none() && p.fmu.is_none() && p.replay.is_none();
    let operating_point = crate::operating_point::operating_point(
        &p.operating_point,
        model,
        discrete,
        builtin,
        layout_names,
    )?;
    let replay = crate::replay_plant::plant_replay(
        &p.replay,
        dir,
        &sizes,
        model.d.ncols(),
        dt,
        steps,
        operating_point.as_ref().map(|op| &op.u[..]),
    )?;

    Ok(TruePlant {
        noise,
        faults,
        fmu,
        replay,
        operating_point,
    })
}
