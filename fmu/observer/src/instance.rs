//! One FMU instance, whatever the FMI version: its mode, its time, the observer and the
//! variables by value reference (fmu_export::variables). fmi2.rs and fmi3.rs translate the two
//! APIs onto it; every failure is one line given to the importer's logger.

use std::path::Path;

use fmu_export::resource::{FILE, ObserverResource};
use fmu_export::variables::{Layout, Role};

use crate::observer::Observer;

/// Where an instance is in the co-simulation life cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// After instantiate (and reset).
    Instantiated,
    /// Between enter and exit initialization mode.
    Initialization,
    /// After exit initialization mode: doStep may be called.
    Step,
    /// After terminate.
    Terminated,
}

/// Reports one line to the importer (its logger, with status Error).
pub type Log = Box<dyn Fn(&str)>;

/// An instance: the observer and its FMI state.
pub struct Instance {
    /// Reports errors.
    pub log: Log,
    layout: Layout,
    observer: Observer,
    dt: f64,
    /// The start time (FMI 2: from fmi2SetupExperiment; both: on entering initialization).
    pub start_time: f64,
    /// Steps taken since the start: time = start_time + steps·dt.
    steps: u64,
    /// Life-cycle mode.
    pub mode: Mode,
}

/// The largest relative difference between a communication step size and dt that is taken as dt.
pub const STEP_TOLERANCE: f64 = 1e-9;

impl Instance {
    /// Reads `resources/observer.json` from `dir` and checks it against the modelDescription's
    /// token.
    pub fn new(dir: &Path, token: &str, log: Log) -> Result<Instance, String> {
        let path = dir.join(FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        let (res, dims) =
            ObserverResource::from_json(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if res.token != token {
            return Err(format!(
                "{}: made for token {}, the modelDescription gives {token}",
                path.display(),
                res.token
            ));
        }
        Ok(Instance {
            log,
            layout: Layout { dims },
            observer: Observer::new(&res),
            dt: res.dt,
            start_time: 0.0,
            steps: 0,
            mode: Mode::Instantiated,
        })
    }

    /// Logs `e` if it is an error; whether all went well.
    pub fn ok(&self, r: Result<(), String>) -> bool {
        r.map_err(|e| (self.log)(&e)).is_ok()
    }

    /// The current communication point.
    pub fn time(&self) -> f64 {
        self.start_time + self.steps as f64 * self.dt
    }

    /// Enter initialization mode at `start_time`.
    pub fn enter_initialization(&mut self, start_time: f64) -> Result<(), String> {
        if self.mode != Mode::Instantiated {
            return Err(
                "enter initialization mode: only right after instantiation or reset".into(),
            );
        }
        if !start_time.is_finite() {
            return Err(format!("the start time {start_time} is not finite"));
        }
        self.start_time = start_time;
        self.mode = Mode::Initialization;
        Ok(())
    }

    /// Exit initialization mode: step mode.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        if self.mode != Mode::Initialization {
            return Err("exit initialization mode: not in initialization mode".into());
        }
        self.mode = Mode::Step;
        Ok(())
    }

    /// Terminate.
    pub fn terminate(&mut self) -> Result<(), String> {
        if self.mode != Mode::Step {
            return Err("terminate: not in step mode".into());
        }
        self.mode = Mode::Terminated;
        Ok(())
    }

    /// Back to the state right after instantiation.
    pub fn reset(&mut self) {
        self.observer.reset();
        self.start_time = 0.0;
        self.steps = 0;
        self.mode = Mode::Instantiated;
    }

    /// The values of the variables `vr` (outputs formed from the current inputs).
    pub fn get(&mut self, vr: &[u32], values: &mut [f64]) -> Result<(), String> {
        let roles = self.roles(vr)?;
        let time = self.time();
        self.observer.outputs();
        let o = &self.observer;
        for (v, role) in values.iter_mut().zip(roles) {
            *v = match role {
                Role::Time => time,
                Role::U(i) => o.u[i],
                Role::Y(j) => o.y[j],
                Role::Xhat(i) => o.xhat()[i],
                Role::R(j) => o.residual()[j],
            };
        }
        Ok(())
    }

    /// Sets inputs; refuses (and sets none) if any is not an input.
    pub fn set(&mut self, vr: &[u32], values: &[f64]) -> Result<(), String> {
        if self.mode == Mode::Terminated {
            return Err("set: the instance is terminated".into());
        }
        let roles = self.roles(vr)?;
        if let Some(&role) = roles.iter().find(|r| !matches!(r, Role::U(_) | Role::Y(_))) {
            return Err(format!(
                "{} (value reference {}) is not an input",
                self.layout.name(role),
                self.layout.vr(role)
            ));
        }
        for (&v, role) in values.iter().zip(roles) {
            match role {
                Role::U(i) => self.observer.u[i] = v,
                Role::Y(j) => self.observer.y[j] = v,
                _ => unreachable!("checked above"),
            }
        }
        Ok(())
    }

    /// One communication step of h = m·dt from `t` (m ≥ 1 whole, to [`STEP_TOLERANCE`]
    /// relative): m samples z ← F z + G u + K y with the inputs held, as FMI holds them over a
    /// step. A master that samples every 2^j·dt (FMPy's default output interval for a long
    /// experiment) gets the run's x̂ at its points.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), String> {
        if self.mode != Mode::Step {
            return Err("doStep: not in step mode".into());
        }
        let m = (h / self.dt).round();
        // NaN h fails this too.
        let within = m >= 1.0 && (h - m * self.dt).abs() <= STEP_TOLERANCE * h;
        if !within {
            return Err(format!(
                "doStep(t = {t}, h = {h}): this observer was sampled with dt = {}; it takes steps of whole multiples of dt only",
                self.dt
            ));
        }
        for _ in 0..m as u64 {
            self.observer.advance();
        }
        self.steps += m as u64;
        Ok(())
    }

    fn roles(&self, vr: &[u32]) -> Result<Vec<Role>, String> {
        vr.iter()
            .map(|&v| {
                self.layout.role(v).ok_or_else(|| {
                    format!(
                        "unknown value reference {v} (this FMU has 0 … {})",
                        self.layout.len() - 1
                    )
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lti::MatData;

    fn instance() -> (Instance, std::path::PathBuf) {
        let one = |v: f64| MatData {
            rows: 1,
            cols: 1,
            data: vec![v],
        };
        let res = ObserverResource::new(
            "o",
            0.1,
            one(0.5),
            one(1.0),
            one(1.0),
            one(1.0),
            one(2.0),
            one(1.0),
            None,
        )
        .unwrap();
        let dir = std::env::temp_dir().join(format!(
            "fmu-observer-test-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(FILE), res.to_json()).unwrap();
        (
            Instance::new(&dir, &res.token, Box::new(|_| ())).unwrap(),
            dir,
        )
    }

    #[test]
    fn refuses_a_wrong_token_a_garbled_file_and_a_missing_one() {
        let (_, dir) = instance();
        assert!(
            Instance::new(&dir, "{other}", Box::new(|_| ()))
                .err()
                .unwrap()
                .contains("token")
        );
        std::fs::write(dir.join(FILE), "{\"format\": 1").unwrap();
        assert!(
            Instance::new(&dir, "", Box::new(|_| ()))
                .err()
                .unwrap()
                .contains("not an observer resource")
        );
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(
            Instance::new(&dir, "", Box::new(|_| ()))
                .err()
                .unwrap()
                .contains("cannot read")
        );
    }

    #[test]
    fn steps_by_whole_multiples_of_dt_and_sets_only_inputs() {
        let (mut inst, dir) = instance();
        std::fs::remove_dir_all(&dir).unwrap();
        // Value references: 0 time, 1 u, 2 y, 3 x̂, 4 r.
        assert!(inst.do_step(0.0, 0.1).is_err()); // not in step mode yet
        inst.enter_initialization(0.0).unwrap();
        inst.set(&[1, 2], &[10.0, 3.0]).unwrap();
        assert!(inst.set(&[3], &[1.0]).is_err());
        assert!(inst.get(&[9], &mut [0.0]).is_err());
        inst.exit_initialization().unwrap();
        let mut v = [0.0; 2];
        inst.get(&[3, 4], &mut v).unwrap();
        assert_eq!(v, [6.0, -3.0]);
        assert!(inst.do_step(0.0, 0.25).unwrap_err().contains("dt = 0.1"));
        assert!(
            inst.do_step(0.0, 0.04)
                .unwrap_err()
                .contains("whole multiples")
        );
        inst.do_step(0.0, 0.1 * (1.0 + 1e-12)).unwrap();
        inst.set(&[2], &[1.0]).unwrap();
        inst.get(&[0, 3], &mut v).unwrap();
        assert_eq!(v, [0.1, 15.0]);
        // Two samples in one step, the inputs held: z2 = 0.5·13 + 10 + 1, z3 = 0.5·17.5 + 11.
        inst.do_step(0.1, 0.2).unwrap();
        inst.get(&[0, 3], &mut v).unwrap();
        assert_eq!(v, [0.30000000000000004, 19.75 + 2.0]);
        inst.terminate().unwrap();
        inst.reset();
        assert_eq!(inst.mode, Mode::Instantiated);
        inst.get(&[3], &mut v[..1]).unwrap();
        assert_eq!(v[0], 0.0);
    }
}
