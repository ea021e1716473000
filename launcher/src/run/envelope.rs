//! The configuration file of every component of a run (PROTOCOL.md §3), and who runs it: one
//! of our binaries, with its designed matrices as `params`, or the scenario's command.

use std::collections::BTreeMap;

use controller::ControllerConfig;
use lockstep::component::{ComponentConfig, Iceoryx2Place, PublishSpec, ReadSpec, Role};
use lockstep::{FOLLOWER_LAG, PROTOCOL_VERSION, PlantLayout, RunSpace, Wait};
use scenario::{Named, ProcessSpec, Scenario};
use serde_json::{Value, json};

use observer::shell::ObserverRun;

use super::configs::{Configs, is_follower};

/// Who runs a component.
#[derive(Debug, Clone)]
pub enum Program {
    /// Our binary of this name (`plant`, `observer`, `controller`).
    Builtin(&'static str),
    /// The scenario's command.
    External(ProcessSpec),
    /// Our binary of this name on another host, through its agent: the launcher starts the
    /// bridge's proxy (`uio-bridge remote`) in its place.
    Remote(&'static str, scenario::Remote),
}

/// The bridge's binary (`uio-bridge`), built beside the launcher: it carries components to
/// other hosts, so that Zenoh stays out of the launcher.
pub fn bridge_path() -> std::path::PathBuf {
    std::env::current_exe()
        .unwrap_or_else(|_| lockstep::programs::LAUNCHER.into())
        .with_file_name(lockstep::programs::BRIDGE)
}

/// A component ready to be started.
#[derive(Debug, Clone)]
pub struct Launchable {
    /// How messages name it: `plant`, `observer 'uio'`, `controller`.
    pub label: String,
    /// Who runs it.
    pub program: Program,
    /// Its configuration.
    pub config: ComponentConfig,
}

impl Launchable {
    /// The configuration's file name in the run directory (without `.json`).
    pub fn file(&self) -> String {
        self.config.file()
    }
}

fn names(list: &[Named]) -> Vec<String> {
    list.iter().map(|n| n.name.clone()).collect()
}

fn rows(m: &lti::Mat) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

/// The named ranges of the plant's sample (PROTOCOL.md §4).
fn fields(l: PlantLayout) -> BTreeMap<String, [usize; 2]> {
    [
        ("x", l.x()),
        ("y", l.y()),
        ("w", l.w()),
        ("v", l.v()),
        ("r", l.r()),
        ("u_prev", l.u_prev()),
        ("faults", l.faults()),
    ]
    .into_iter()
    .filter(|(k, r)| *k != "faults" || !r.is_empty())
    .map(|(k, r)| (k.to_string(), [r.start, r.end]))
    .collect()
}

/// How one observer process ([`scenario::ObserverProcess`]) is started: a scenario's observer,
/// or a bank's members together.
struct ObserverLaunch {
    name: String,
    label: String,
    program: Program,
    params: Value,
    publishes: PublishSpec,
    follower: bool,
}

/// The observer processes ([`Configs::processes`]). An observer publishes its x̂ on
/// `observer/<name>`; a bank's process publishes its members' x̂ side by side on
/// `observer/<bank>`, member i's at values i·n … (i+1)·n.
fn observer_launches(s: &Scenario, cfg: &Configs) -> Vec<ObserverLaunch> {
    let lay = cfg.layout;
    let run = |members: &[usize]| {
        let observers: Vec<_> = members
            .iter()
            .map(|&i| {
                cfg.observers[i]
                    .1
                    .clone()
                    .expect("a designed observer has a runtime")
            })
            .collect();
        serde_json::to_value(ObserverRun {
            observers,
            layout: lay,
        })
        .expect("serialises")
    };
    cfg.processes
        .iter()
        .map(|process| {
            let members = &process.observers[..];
            let first = &s.observers[members[0]];
            let follower = members
                .iter()
                .all(|&i| is_follower(s, &s.observers[i].name));
            match process.bank {
                Some(d) => {
                    let bank = &s.diagnosers[d].name;
                    let names = members
                        .iter()
                        .flat_map(|&i| {
                            s.names
                                .state
                                .iter()
                                .map(move |x| format!("{} ({})", x.name, s.observers[i].name))
                        })
                        .collect();
                    ObserverLaunch {
                        name: bank.clone(),
                        label: format!(
                            "bank '{bank}' ({} member{})",
                            members.len(),
                            if members.len() == 1 { "" } else { "s" }
                        ),
                        program: Program::Builtin("observer"),
                        params: run(members),
                        publishes: PublishSpec {
                            service: format!("observer/{bank}"),
                            len: lay.n * members.len(),
                            names,
                        },
                        follower,
                    }
                }
                None => {
                    let (program, params) = match &first.process {
                        Some(p) => (Program::External(p.clone()), p.params.clone()),
                        None => (Program::Builtin("observer"), run(members)),
                    };
                    ObserverLaunch {
                        name: first.name.clone(),
                        label: format!("observer '{}'", first.name),
                        program,
                        params,
                        publishes: PublishSpec {
                            service: format!("observer/{}", first.name),
                            len: lay.n,
                            names: names(&s.names.state),
                        },
                        follower,
                    }
                }
            }
        })
        .collect()
}

/// Every component of the run, in start order: plant, observer processes, controller.
// one job: the launch envelopes of a run's components in start order, one arm per kind of component
// over the same layout.
pub fn envelopes(s: &Scenario, cfg: &Configs, space: &RunSpace, wait: Wait) -> Vec<Launchable> {
    let lay = cfg.layout;
    let m = &s.model;
    let base = |name: &str,
                role: Role,
                publishes: PublishSpec,
                reads: Vec<ReadSpec>,
                params: Value| ComponentConfig {
        protocol: PROTOCOL_VERSION,
        run: space.id().to_string(),
        name: name.to_string(),
        role,
        iceoryx2: Iceoryx2Place::of(space),
        wait: wait.to_string(),
        dt: s.dt,
        steps: s.steps,
        publishes,
        reads,
        model: {
            let mut model = json!({ "A": rows(&m.a), "B": rows(&m.b), "C": rows(&m.c), "D": rows(&m.d), "E": rows(&m.e), "Ff": rows(&s.ff), "x0": s.x0 });
            if s.discrete {
                model["time"] = json!("discrete");
            }
            // The point the model is linearised at (PROTOCOL.md §3): the signals stay absolute.
            if let Some(op) = &s.operating_point {
                model["operating_point"] = json!(op);
            }
            model
        },
        signals: Value::Null,
        params,
        pace_s: None,
        // Set below for the components on this host.
        inlet_timeout_s: None,
    };
    let plant_read = |sleep_us| ReadSpec {
        service: "plant".into(),
        len: lay.len(),
        lag: 0,
        sleep_us,
        fields: fields(lay),
    };
    let processes = observer_launches(s, cfg);
    let mut out = Vec::new();

    // The plant reads every observer process (a follower may trail) and the controller.
    let mut reads: Vec<ReadSpec> = processes
        .iter()
        .map(|p| ReadSpec {
            service: format!("observer/{}", p.name),
            len: p.publishes.len,
            lag: if p.follower { FOLLOWER_LAG } else { 0 },
            sleep_us: None,
            fields: BTreeMap::new(),
        })
        .collect();
    if s.controller.is_some() {
        reads.push(ReadSpec {
            service: "controller".into(),
            len: lay.l,
            lag: 0,
            sleep_us: None,
            fields: BTreeMap::new(),
        });
    }
    let mut sample_names: Vec<String> = [
        &s.names.state,
        &s.names.output,
        &s.names.disturbance,
        &s.names.measurement_disturbance,
        &s.names.input,
        &s.names.input,
    ]
    .iter()
    .flat_map(|l| names(l))
    .collect();
    sample_names.extend(
        s.faults
            .iter()
            .flat_map(|f| [format!("{}.active", f.name), format!("{}.value", f.name)]),
    );
    let publishes = PublishSpec {
        service: "plant".into(),
        len: lay.len(),
        names: sample_names,
    };
    let (program, params) = match &s.plant_process {
        Some(p) => (Program::External(p.clone()), p.params.clone()),
        // The built-in plant reads what every plant reads: `model` and `signals`.
        None => (Program::Builtin("plant"), json!({})),
    };
    let mut plant = base("plant", Role::Plant, publishes, reads, params);
    plant.pace_s = cfg.pace_s;
    plant.signals = json!({
        "disturbances": s.disturbances,
        "measurement_disturbances": s.measurement_disturbances,
        "inputs": s.inputs,
        "state_bound": s.state_bound,
        "faults": s.faults,
        "noise": cfg.plant.noise,
    });
    // An FMU plant is named with its file: what fails is most likely the FMU's library.
    let label = match &s.plant_fmu {
        Some(f) => format!(
            "plant (FMU {})",
            f.file_name().map_or_else(
                || f.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            )
        ),
        None => "plant".into(),
    };
    out.push(Launchable {
        label,
        program,
        config: plant,
    });

    for p in processes {
        let sleep = p.follower.then_some(super::configs::FOLLOWER_SLEEP_US);
        let config = base(
            &p.name,
            Role::Observer,
            p.publishes,
            vec![plant_read(sleep)],
            p.params,
        );
        out.push(Launchable {
            label: p.label,
            program: p.program,
            config,
        });
    }

    if let Some(c) = &s.controller {
        let publishes = PublishSpec {
            service: "controller".into(),
            len: lay.l,
            names: names(&s.names.input)
                .iter()
                .enumerate()
                .map(|(i, _)| format!("u{}", i + 1))
                .collect(),
        };
        let mut reads = vec![ReadSpec {
            service: format!("observer/{}", c.observer),
            len: lay.n,
            lag: 0,
            sleep_us: None,
            fields: BTreeMap::new(),
        }];
        // ŵ is made from the plant's y_k and u_{k−1}, and measured tracked outputs from its y_k.
        if cfg
            .controller
            .as_ref()
            .is_some_and(ControllerConfig::reads_plant)
        {
            reads.push(plant_read(None));
        }
        let (program, params) = match (&c.process, &cfg.controller) {
            (Some(p), _) => (Program::External(p.clone()), p.params.clone()),
            (None, Some(cc)) => (
                Program::Builtin("controller"),
                serde_json::to_value(cc).expect("serialises"),
            ),
            (None, None) => unreachable!("a designed controller has a configuration"),
        };
        let mut config = base("controller", Role::Controller, publishes, reads, params);
        config.signals = json!({ "inputs": s.inputs });
        out.push(Launchable {
            label: "controller".into(),
            program,
            config,
        });
    }
    for c in &mut out {
        if let (Program::Builtin(kind), Some(r)) = (&c.program, s.remote.get(&c.config.name)) {
            c.label = format!("{} (on host {})", c.label, r.host);
            c.program = Program::Remote(kind, r.clone());
        } else {
            // Above the launcher's stall limit: it names a stall first, and a component waits
            // for a starved peer as long as the launcher does. Not on another host: the
            // launcher cannot see that host's kernel, names a stall there after 5 s, and a
            // component left waiting there (its run gone) would spin the default 10 s only.
            c.config.inlet_timeout_s =
                Some(s.stall_timeout + super::stall::STALL_BLOCKED.as_secs_f64());
        }
    }
    out
}
