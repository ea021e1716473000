//! The configuration file every component reads from `$UIO_CONFIG` (PROTOCOL.md §3).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// What a component is in the ring (PROTOCOL.md §5): the plant publishes step k from the inputs
/// of step k − 1; observers and the controller publish step k from the inputs of step k.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// The true plant: the ring's one source.
    Plant,
    /// An observer: reads the plant, publishes x̂.
    Observer,
    /// The controller: reads an observer, publishes u.
    Controller,
}

impl Role {
    /// Its name in the configuration and in `UIO_ROLE`.
    pub fn name(self) -> &'static str {
        match self {
            Role::Plant => "plant",
            Role::Observer => "observer",
            Role::Controller => "controller",
        }
    }
}

/// The run's iceoryx2 settings (PROTOCOL.md §2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Iceoryx2Place {
    /// `global.prefix`.
    pub prefix: String,
    /// `global.root_path`.
    pub root: String,
}

/// The service a component publishes on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PublishSpec {
    /// Service name.
    pub service: String,
    /// Values per sample, fixed for the run.
    pub len: usize,
    /// Names of the values (1-based, as everywhere).
    #[serde(default)]
    pub names: Vec<String>,
}

/// A service a component reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReadSpec {
    /// Service name.
    pub service: String,
    /// Values per sample.
    pub len: usize,
    /// How many steps this input may trail (0: exactly the step's sample).
    #[serde(default)]
    pub lag: u64,
    /// Poll with this sleep (µs) instead of the run's wait strategy: a hint that the input is off
    /// the critical path (PROTOCOL.md §3), which a component may ignore.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sleep_us: Option<u32>,
    /// Named ranges [start, end) of the values (the plant's sample layout).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fields: BTreeMap<String, [usize; 2]>,
}

/// The whole configuration (PROTOCOL.md §3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComponentConfig {
    /// Protocol version.
    pub protocol: u32,
    /// Run id.
    pub run: String,
    /// Component name.
    pub name: String,
    /// Its role.
    pub role: Role,
    /// The run's iceoryx2 settings.
    pub iceoryx2: Iceoryx2Place,
    /// The run's wait strategy.
    pub wait: String,
    /// Sample period, s.
    pub dt: f64,
    /// Steps K of the run.
    pub steps: u64,
    /// What it publishes.
    pub publishes: PublishSpec,
    /// What it reads, in order.
    pub reads: Vec<ReadSpec>,
    /// The scenario's design model: A, B, C, D, E (rows) and x0.
    #[serde(default)]
    pub model: serde_json::Value,
    /// The scenario's signals (for plants): disturbances, measurement_disturbances, inputs.
    #[serde(default)]
    pub signals: serde_json::Value,
    /// The component's own parameters.
    #[serde(default)]
    pub params: serde_json::Value,
    /// Real-time pacing (the plant's, with `--realtime`): sample k is published no earlier than
    /// t₀ + k·pace_s, t₀ when sample 0 was (PROTOCOL.md §5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pace_s: Option<f64>,
    /// How long a wait for an input may last before the component gives up (exit 3), s;
    /// 10 s when absent. The launcher sets it above its own stall limit, so that it names a
    /// stall first and a starved peer is waited for as long as the launcher waits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inlet_timeout_s: Option<f64>,
}

impl Iceoryx2Place {
    /// The prefix and root of `space` (PROTOCOL.md §2).
    pub fn of(space: &crate::RunSpace) -> Self {
        Iceoryx2Place {
            prefix: format!("uio{}_", space.id()),
            root: format!("{}/", space.iox2_root().display()),
        }
    }
}

impl ComponentConfig {
    /// The name of its configuration file in the run directory, without `.json`: the role, or
    /// `observer-<name>` for an observer.
    pub fn file(&self) -> String {
        match self.role {
            Role::Observer => format!("observer-{}", self.name),
            r => r.name().to_string(),
        }
    }

    /// The environment a component is started with (PROTOCOL.md §1), its configuration written
    /// in `space` under [`ComponentConfig::file`].
    pub fn launch_env(&self, space: &crate::RunSpace) -> [(&'static str, std::ffi::OsString); 6] {
        [
            ("UIO_PROTOCOL", crate::PROTOCOL_VERSION.to_string().into()),
            ("UIO_RUN", space.id().into()),
            ("UIO_NAME", self.name.clone().into()),
            ("UIO_ROLE", self.role.name().into()),
            ("UIO_CONFIG", space.config_path(&self.file()).into()),
            (
                crate::RUNS_DIR_ENV,
                space.dir().parent().unwrap_or(space.dir()).into(),
            ),
        ]
    }

    /// Index of the input read from `service`, if any.
    pub fn read_index(&self, service: &str) -> Option<usize> {
        self.reads.iter().position(|r| r.service == service)
    }

    /// The `params`, deserialised.
    pub fn params<T: serde::de::DeserializeOwned>(&self) -> Result<T, String> {
        serde_json::from_value(self.params.clone()).map_err(|e| format!("params: {e}"))
    }
}
