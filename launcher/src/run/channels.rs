//! The recording's series of a run, made once when the recording opens: every signal's entity
//! path, legend, colour and width (by `recording::palette`, which the PNG plots follow too), in
//! the groups of their time stamps.

use std::path::Path;

use lockstep::PlantLayout;
use observer::design::InputEstimator;
use recording::palette;
use recording::signals as sig;
use recording::write::{RrdSink, Selection, SeriesId, blueprint};
use scenario::Scenario;

use crate::error::LaunchError;
use diagnosis::Bank;

/// Series of one observer.
pub(super) struct ObserverChannels {
    pub(super) xhat: Vec<SeriesId>,
    pub(super) error: Vec<SeriesId>,
    pub(super) residual: Vec<SeriesId>,
    /// log10 max_i |e_i| (see [`sig::log_error`]).
    pub(super) log_error: SeriesId,
    /// ŵ, for an observer that estimates the unknown inputs (recorded one row late, at t_{k−1}).
    pub(super) what: Vec<SeriesId>,
}

/// The recording's series, in groups by time stamp: the signals of step k, and the latencies of
/// step k − 1, which complete with row k (the step time and the controller→plant hop; the
/// other hops of step k − 1 wait for them, so that all latencies of a step are one row).
pub(super) struct Channels {
    pub(super) signals: usize,
    /// ŵ_{k−1}, completed by row k (a group only when some observer estimates w).
    pub(super) estimates_late: Option<usize>,
    pub(super) latency: usize,
    pub(super) x: Vec<SeriesId>,
    pub(super) y: Vec<SeriesId>,
    pub(super) w: Vec<SeriesId>,
    pub(super) v: Vec<SeriesId>,
    pub(super) r: Vec<SeriesId>,
    pub(super) u: Vec<SeriesId>,
    /// None for a bank member (recorded under `/diagnoser`).
    pub(super) observers: Vec<Option<ObserverChannels>>,
    /// Per bank: per member, its residual's outputs.
    pub(super) members: Vec<Vec<Vec<SeriesId>>>,
    /// Per bank: (evaluation, threshold, alarm) per member, and the isolation.
    pub(super) decisions: Vec<(Vec<[SeriesId; 3]>, SeriesId)>,
    /// Per bank with a GLR test: (g, threshold) per member, and which test decided.
    pub(super) glr: Vec<Option<(Vec<[SeriesId; 2]>, SeriesId)>>,
    /// Per fault: (active, value).
    pub(super) faults: Vec<[SeriesId; 2]>,
    pub(super) step_latency: SeriesId,
    /// One per hop; the last is controller→plant (late) when there is a controller.
    pub(super) hops: Vec<SeriesId>,
}

/// The entity path of a hop: "plant->observer/uio" becomes "/latency/plant_to_observer_uio".
pub fn hop_entity(hop: &str) -> String {
    format!("/latency/{}", hop.replace("->", "_to_").replace('/', "_"))
}

/// What the recording holds besides the scenario's own signals.
pub(super) struct Wanted<'a> {
    pub(super) layout: PlantLayout,
    pub(super) banks: &'a [Bank],
    /// Per observer, its ŵ estimator (None for those without and for bank members).
    pub(super) estimates: &'a [Option<&'a InputEstimator>],
    pub(super) select: &'a Selection,
    /// The hops whose latencies are recorded (none in one process).
    pub(super) hops: &'a [String],
    /// A paced run (`--realtime`) also records each step's overrun.
    pub(super) paced: bool,
}

/// The recording opened at `path` with its series.
pub(super) struct Opened {
    pub(super) sink: RrdSink,
    pub(super) channels: Channels,
    /// `/latency/overrun`'s group and series (paced runs).
    pub(super) overrun: Option<(usize, SeriesId)>,
}

/// Makes series and remembers their paths (for `--record` patterns that match none).
struct Namer<'a> {
    sink: &'a mut RrdSink,
    observer_names: Vec<String>,
    paths: Vec<String>,
}

impl Namer<'_> {
    fn series(&mut self, group: usize, path: String, legend: String) -> SeriesId {
        let line = palette::line(&path, &self.observer_names);
        let width = palette::viewer_width(&path, &self.observer_names);
        let id = self.sink.series(group, &path, &legend, line.color, width);
        self.paths.push(path);
        id
    }
}

/// Opens the recording at `path` and makes every series of the run `s`.
pub(super) fn open(path: &Path, s: &Scenario, want: &Wanted) -> Result<Opened, LaunchError> {
    let scenario = s.clone();
    let mut sink = RrdSink::create(
        path,
        &s.name,
        move |layout| blueprint(&scenario, layout),
        &s.source,
        want.select.clone(),
    )
    .map_err(LaunchError::BadInput)?;
    let (signals, latency) = (sink.group("signals"), sink.group("latency"));
    let estimates_late = want
        .estimates
        .iter()
        .any(Option::is_some)
        .then(|| sink.group("what"));
    let overrun_group = want.paced.then(|| sink.group("overrun"));
    let mut namer = Namer {
        sink: &mut sink,
        observer_names: s.observers.iter().map(|o| o.name.clone()).collect(),
        paths: Vec::new(),
    };
    let [x, y, w, v, r, u] = plant_series(&mut namer, s, want.layout, signals);
    let observers = observer_series(&mut namer, s, want, signals, estimates_late);
    let (members, decisions) = bank_series(&mut namer, s, want.banks, signals);
    let glr = glr_series(&mut namer, want.banks, signals);
    let faults = s
        .faults
        .iter()
        .map(|f| {
            [
                namer.series(
                    signals,
                    sig::fault_active(&f.name),
                    format!("{} active", f.name),
                ),
                namer.series(
                    signals,
                    sig::fault_value(&f.name),
                    format!("{} value", f.name),
                ),
            ]
        })
        .collect();
    let step_latency = namer.series(latency, "/latency/step".into(), "step".into());
    let overrun = overrun_group.map(|g| {
        (
            g,
            namer.series(g, "/latency/overrun".into(), "overrun".into()),
        )
    });
    let hops = want
        .hops
        .iter()
        .map(|h| namer.series(latency, hop_entity(h), h.clone()))
        .collect();
    for p in want
        .select
        .unmatched(namer.paths.iter().map(String::as_str))
    {
        eprintln!(
            "warning: --record {}: matches no signal of this run, so records nothing",
            scenario::quoted(&p)
        );
    }
    let channels = Channels {
        signals,
        estimates_late,
        latency,
        x,
        y,
        w,
        v,
        r,
        u,
        observers,
        members,
        decisions,
        glr,
        faults,
        step_latency,
        hops,
    };
    Ok(Opened {
        sink,
        channels,
        overrun,
    })
}

/// The plant's and the loop's signals: x (true), y, w, v, r, and u with a controller.
fn plant_series(
    namer: &mut Namer,
    s: &Scenario,
    layout: PlantLayout,
    g: usize,
) -> [Vec<SeriesId>; 6] {
    let names = &s.names;
    let x = (0..layout.n)
        .map(|i| namer.series(g, sig::state(i), format!("{} (true)", names.state[i].name)))
        .collect();
    let y = (0..layout.p)
        .map(|j| namer.series(g, sig::output(j), names.output[j].name.clone()))
        .collect();
    let w = (0..layout.q)
        .map(|k| namer.series(g, sig::disturbance(k), names.disturbance[k].name.clone()))
        .collect();
    let v = (0..layout.r)
        .map(|k| {
            let name = names.measurement_disturbance[k].name.clone();
            namer.series(g, sig::measurement_disturbance(k), name)
        })
        .collect();
    let r = (0..layout.l)
        .map(|k| namer.series(g, sig::input(k), sig::reference_named(s, k).name))
        .collect();
    let u = if s.controller.is_some() {
        (0..layout.l)
            .map(|k| namer.series(g, sig::control(k), sig::control_name(s, k)))
            .collect()
    } else {
        Vec::new()
    };
    [x, y, w, v, r, u]
}

/// Each observer's x̂, e, r, log10 max|e| and ŵ (ŵ one row late, in `estimates_late`); none for
/// a bank member, recorded under its diagnoser.
fn observer_series(
    namer: &mut Namer,
    s: &Scenario,
    want: &Wanted,
    g: usize,
    estimates_late: Option<usize>,
) -> Vec<Option<ObserverChannels>> {
    let (names, layout) = (&s.names, want.layout);
    s.observers
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let name = &o.name;
            o.member.is_none().then(|| ObserverChannels {
                xhat: (0..layout.n)
                    .map(|i| {
                        let legend = format!("{} ({name})", names.state[i].name);
                        namer.series(g, sig::estimate(name, i), legend)
                    })
                    .collect(),
                error: (0..layout.n)
                    .map(|i| namer.series(g, sig::error(name, i), format!("e{} ({name})", i + 1)))
                    .collect(),
                residual: (0..layout.p)
                    .map(|j| {
                        namer.series(g, sig::residual(name, j), format!("r{} ({name})", j + 1))
                    })
                    .collect(),
                log_error: namer.series(g, sig::log_error(name), format!("log10 max|e| ({name})")),
                what: match (want.estimates[i], estimates_late) {
                    (Some(_), Some(late)) => (0..layout.q)
                        .map(|k| {
                            let legend = format!("{} estimate ({name})", names.disturbance[k].name);
                            namer.series(late, sig::input_estimate(name, k), legend)
                        })
                        .collect(),
                    _ => Vec::new(),
                },
            })
        })
        .collect()
}

/// Per diagnoser bank: each member's residual outputs, and (J, threshold, alarm) per member
/// with the isolated channel.
#[allow(clippy::type_complexity)] // Channels' own two fields, made together
fn bank_series(
    namer: &mut Namer,
    s: &Scenario,
    banks: &[Bank],
    g: usize,
) -> (Vec<Vec<Vec<SeriesId>>>, Vec<(Vec<[SeriesId; 3]>, SeriesId)>) {
    let names = &s.names;
    let members = banks
        .iter()
        .map(|b| {
            let d = &b.spec.name;
            b.members
                .iter()
                .enumerate()
                .map(|(i, mb)| {
                    mb.outputs
                        .iter()
                        .map(|&j| {
                            let legend = format!("r{} {} ({d})", i + 1, names.output[j].name);
                            namer.series(g, sig::member_residual(d, i, j), legend)
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let decisions = banks
        .iter()
        .map(|b| {
            let d = &b.spec.name;
            let per = (0..b.members.len())
                .map(|i| {
                    [
                        namer.series(g, sig::evaluation(d, i), format!("J{} ({d})", i + 1)),
                        namer.series(
                            g,
                            sig::threshold(d, i),
                            format!("threshold {} ({d})", i + 1),
                        ),
                        namer.series(g, sig::alarm(d, i), format!("alarm {} ({d})", i + 1)),
                    ]
                })
                .collect();
            let isolated = namer.series(g, sig::isolated(d), format!("isolated channel ({d})"));
            (per, isolated)
        })
        .collect();
    (members, decisions)
}

/// Per diagnoser bank with a GLR test: (g, its threshold) per member, and which test decided.
fn glr_series(
    namer: &mut Namer,
    banks: &[Bank],
    g: usize,
) -> Vec<Option<(Vec<[SeriesId; 2]>, SeriesId)>> {
    banks
        .iter()
        .map(|b| {
            if b.members.iter().all(|mb| mb.glr.is_none()) {
                return None;
            }
            let d = &b.spec.name;
            let per = (0..b.members.len())
                .map(|i| {
                    [
                        namer.series(g, sig::glr(d, i), format!("GLR g{} ({d})", i + 1)),
                        namer.series(
                            g,
                            sig::glr_threshold(d, i),
                            format!("GLR threshold {} ({d})", i + 1),
                        ),
                    ]
                })
                .collect();
            let by = namer.series(g, sig::decided_by(d), format!("decided by ({d})"));
            Some((per, by))
        })
        .collect()
}
