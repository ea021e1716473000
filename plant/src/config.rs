//! What the launcher tells the plant.

use lti::MatData;
use lti::signal::Signal;

use crate::fault::Fault;
use crate::noise::Noise;
use serde::{Deserialize, Serialize};

/// The plant's model, signals and run length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlantConfig {
    /// State matrix A.
    pub a: MatData,
    /// Known-input matrix B.
    pub b: MatData,
    /// Output matrix C.
    pub c: MatData,
    /// Unknown-input distribution E (may have no columns).
    pub e: MatData,
    /// Measurement-disturbance distribution D (may have no columns).
    pub d: MatData,
    /// Initial state.
    pub x0: Vec<f64>,
    /// Unknown inputs w, one per column of E.
    pub disturbances: Vec<Signal>,
    /// Measurement disturbances v, one per column of D.
    pub measurement_disturbances: Vec<Signal>,
    /// Known inputs (open loop) or references (closed loop), one per column of B.
    pub inputs: Vec<Signal>,
    /// Sample period, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// A state whose magnitude exceeds this stops the run.
    pub state_bound: f64,
    /// Fault distribution F_f, n×m (component faults act through its columns; may be empty).
    pub ff: MatData,
    /// Injected faults.
    pub faults: Vec<Fault>,
    /// Process and measurement noise, if any.
    pub noise: Option<Noise>,
    /// A discrete-time plant: `a`, `b`, `e` (and `ff`) are Φ, Γ_B, Γ_E (Γ_F) of one step, and
    /// x_{k+1} = Φx_k + Γ_Bu_k + Γ_Ew(t_k) (+ Γ_F f(t_k)).
    #[serde(default)]
    pub discrete: bool,
}

#[derive(Deserialize)]
#[allow(non_snake_case)]
struct ProtocolModel {
    A: Vec<Vec<f64>>,
    B: Vec<Vec<f64>>,
    C: Vec<Vec<f64>>,
    D: Vec<Vec<f64>>,
    E: Vec<Vec<f64>>,
    x0: Vec<f64>,
    #[serde(default)]
    Ff: Vec<Vec<f64>>,
    /// "discrete" when A, B, E are a discrete-time plant's Φ, Γ_B, Γ_E.
    #[serde(default)]
    time: Option<String>,
}

#[derive(Deserialize)]
struct ProtocolSignals {
    disturbances: Vec<Signal>,
    measurement_disturbances: Vec<Signal>,
    inputs: Vec<Signal>,
    state_bound: f64,
    #[serde(default)]
    faults: Vec<Fault>,
    #[serde(default)]
    noise: Option<Noise>,
}

/// Rows as a matrix of `nrows` rows (an empty matrix keeps its rows, PROTOCOL.md §3).
fn rows(r: &[Vec<f64>], nrows: usize) -> MatData {
    let cols = r.first().map_or(0, Vec::len);
    MatData {
        rows: nrows,
        cols,
        data: r.iter().flat_map(|row| row.iter().copied()).collect(),
    }
}

impl PlantConfig {
    /// The plant a component's configuration describes, from the protocol's public fields
    /// alone — `model`, `signals`, `dt`, `steps` (PROTOCOL.md §3) — as any plant must read it.
    pub fn from_protocol(cfg: &lockstep::component::ComponentConfig) -> Result<Self, String> {
        let m: ProtocolModel =
            serde_json::from_value(cfg.model.clone()).map_err(|e| format!("model: {e}"))?;
        let s: ProtocolSignals =
            serde_json::from_value(cfg.signals.clone()).map_err(|e| format!("signals: {e}"))?;
        let (n, p) = (m.A.len(), m.C.len());
        let ragged = [&m.A, &m.B, &m.C, &m.D, &m.E]
            .iter()
            .any(|x| x.iter().any(|r| r.len() != x[0].len()));
        let ff_bad =
            !m.Ff.is_empty() && (m.Ff.len() != n || m.Ff.iter().any(|r| r.len() != m.Ff[0].len()));
        if ragged
            || ff_bad
            || [&m.B, &m.E].iter().any(|x| x.len() != n)
            || m.D.len() != p
            || m.A.iter().chain(&m.C).any(|r| r.len() != n)
        {
            return Err("model: the matrices do not conform".into());
        }
        Ok(PlantConfig {
            a: rows(&m.A, n),
            b: rows(&m.B, n),
            c: rows(&m.C, p),
            e: rows(&m.E, n),
            d: rows(&m.D, p),
            x0: m.x0,
            disturbances: s.disturbances,
            measurement_disturbances: s.measurement_disturbances,
            inputs: s.inputs,
            dt: cfg.dt,
            steps: cfg.steps,
            state_bound: s.state_bound,
            ff: rows(&m.Ff, n),
            faults: s.faults,
            noise: s.noise,
            discrete: m.time.as_deref() == Some("discrete"),
        })
    }
}
