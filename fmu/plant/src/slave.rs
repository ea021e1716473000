//! A running co-simulation instance of an FMU, FMI 2.0 or 3.0, behind the few calls the plant
//! makes: parameters before initialisation, Real/Float64 inputs and outputs, and doStep. Every
//! failed call says which call, at what time, and what the FMU logged about it.

use std::rc::Rc;

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi3::import::Fmi3Import;
use fmi::fmi3::instance::InstanceCS as Cs3;
use fmi::fmi3::{CoSimulation as _, Common as _, Fmi3Model as _, GetSet as _};

use crate::check::Start;
use crate::fmi2::Cs2;
use crate::log_capture;
use crate::version::Version;

/// An extracted FMU, its library ready to instantiate: extracted once however many instances
/// are made of it (`uio-launcher linearize` makes dozens).
#[derive(Clone)]
pub enum Archive {
    Two(Rc<Fmi2Import>),
    Three(Rc<Fmi3Import>),
}

impl Archive {
    /// Extracts the FMU at `path`; an FMU whose library embeds Python gets `python` loaded
    /// first.
    pub fn open(
        path: &str,
        version: Version,
        python: Option<&crate::python::Python>,
    ) -> Result<Self, String> {
        log_capture::install();
        if let Some(py) = python {
            crate::python::load(py)?;
        }
        let cannot = |e: fmi::Error| format!("cannot extract: {e}");
        Ok(match version {
            Version::Two => Archive::Two(Rc::new(fmi::import::from_path(path).map_err(cannot)?)),
            Version::Three => {
                Archive::Three(Rc::new(fmi::import::from_path(path).map_err(cannot)?))
            }
        })
    }

    /// Instantiates the FMU for co-simulation, sets the parameters' and the states' start
    /// values (`x0`, may be empty) and initialises it at t = 0.
    pub fn start(
        &self,
        name: &str,
        parameters: &[(u32, Start)],
        x0: &[(u32, f64)],
    ) -> Result<Slave, String> {
        let mut s = match self {
            Archive::Two(import) => Slave::Two {
                inst: Cs2::instantiate(import, name)?,
                _import: import.clone(),
            },
            Archive::Three(import) => {
                let inst = import
                    .instantiate_cs(name, false, true, false, false, &[])
                    .map_err(|e| {
                        format!(
                            "fmi3InstantiateCoSimulation failed ({e}){}",
                            log_capture::take()
                        )
                    })?;
                Slave::Three {
                    inst,
                    _import: import.clone(),
                }
            }
        };
        let starts: Vec<(u32, Start)> = parameters
            .iter()
            .cloned()
            .chain(x0.iter().map(|&(vr, x)| (vr, Start::Real(x))))
            .collect();
        s.initialise(&starts)?;
        Ok(s)
    }
}

/// An instance; the import (the extracted archive) lives as long as it. Fields drop in order:
/// the instance is freed before its library's folder goes.
#[allow(clippy::large_enum_variant)] // one instance per process, never moved in the step loop
pub enum Slave {
    Two { inst: Cs2, _import: Rc<Fmi2Import> },
    Three { inst: Cs3, _import: Rc<Fmi3Import> },
}

fn failed(call: &str, t: f64, status: impl std::fmt::Debug) -> String {
    format!(
        "{call} at t = {t} returned {status:?}{}",
        log_capture::take()
    )
}

impl Slave {
    fn initialise(&mut self, parameters: &[(u32, Start)]) -> Result<(), String> {
        match self {
            Slave::Two { inst: i, .. } => {
                i.setup_experiment(0.0)?;
                for (vr, v) in parameters {
                    match v {
                        Start::Real(x) => i.set_real(&[*vr], &[*x], 0.0),
                        Start::Integer(x) => i.set_integer(&[*vr], &[*x], 0.0),
                        Start::Boolean(b) => i.set_boolean(&[*vr], &[*b as i32], 0.0),
                    }
                    .map_err(|e| format!("setting a start value: {e}"))?;
                }
                i.enter_initialization_mode()?;
                i.exit_initialization_mode()?;
            }
            Slave::Three { inst: i, .. } => {
                for (vr, v) in parameters {
                    match v {
                        Start::Real(x) => i.set_float64(&[*vr], &[*x]).map(drop),
                        Start::Integer(x) => i.set_int32(&[*vr], &[*x]).map(drop),
                        Start::Boolean(b) => i.set_boolean(&[*vr], &[*b]).map(drop),
                    }
                    .map_err(|e| failed("setting a start value", 0.0, e))?;
                }
                i.enter_initialization_mode(None, 0.0, None)
                    .map_err(|e| failed("fmi3EnterInitializationMode", 0.0, e))?;
                i.exit_initialization_mode()
                    .map_err(|e| failed("fmi3ExitInitializationMode", 0.0, e))?;
            }
        }
        Ok(())
    }

    /// Sets Real/Float64 inputs at time t.
    pub fn set(&mut self, vrs: &[u32], values: &[f64], t: f64) -> Result<(), String> {
        if vrs.is_empty() {
            return Ok(());
        }
        match self {
            Slave::Two { inst: i, .. } => i.set_real(vrs, values, t),
            Slave::Three { inst: i, .. } => i
                .set_float64(vrs, values)
                .map(drop)
                .map_err(|e| failed("fmi3SetFloat64", t, e)),
        }
    }

    /// Reads Real/Float64 variables at time t.
    pub fn get(&mut self, vrs: &[u32], out: &mut [f64], t: f64) -> Result<(), String> {
        if vrs.is_empty() {
            return Ok(());
        }
        match self {
            Slave::Two { inst: i, .. } => i.get_real(vrs, out, t),
            Slave::Three { inst: i, .. } => i
                .get_float64(vrs, out)
                .map(drop)
                .map_err(|e| failed("fmi3GetFloat64", t, e)),
        }
    }

    /// One communication step from t of length h.
    pub fn step(&mut self, t: f64, h: f64) -> Result<(), String> {
        match self {
            Slave::Two { inst: i, .. } => i.do_step(t, h),
            Slave::Three { inst: i, .. } => {
                let (mut event, mut terminate, mut early, mut last) = (false, false, false, t);
                i.do_step(
                    t,
                    h,
                    true,
                    &mut event,
                    &mut terminate,
                    &mut early,
                    &mut last,
                )
                .map_err(|e| failed("fmi3DoStep", t, e))?;
                if terminate {
                    return Err(format!(
                        "fmi3DoStep at t = {t} asked to terminate the simulation{}",
                        log_capture::take()
                    ));
                }
                if early {
                    return Err(format!(
                        "fmi3DoStep at t = {t} returned early at t = {last}: intermediate updates are not supported"
                    ));
                }
                Ok(())
            }
        }
    }
}
