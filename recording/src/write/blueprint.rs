//! The layout a recording opens with: each state beside every observer's estimate of it, then
//! the errors of all observers on a log10 axis (the only view where a UIO's 1e−15 error and a
//! Luenberger observer's 1e−1 have readable numbers side by side), each observer's errors and
//! residuals on their own axes, then the signals driving the plant, and latency. It opens on
//! the `sim_time` timeline, paused, and every plot shows the whole run at once (its time axis
//! set so by [`super::whole_run`]: the viewer's own default for a run over 60 s is 60 s of it),
//! ticked in the viewer's duration format (+12h, +1d 12h for a two-day run). Plots sit two
//! to a row, and the time panel is open while the blueprint panel is closed: the viewer labels
//! a duration axis only where a plot is wide enough (≈ 60 px a label), and four plots to a row
//! left it a lone "+0s".
//!
//! A plot names the signals it shows ([`crate::signals`] paths, `*` and `**` patterns); an
//! entity of layout 2 holds many signals ([`Layout`]), and a plot picks each out by its element.

use std::collections::BTreeMap;

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ComponentSourceKind, ContainerLike, Grid, SelectionPanel, TimePanel,
    TimeSeriesView, Vertical, Visualizer, VisualizerComponentMapping,
};
use rerun::{Color, SeriesLines};

use scenario::{Named, Scenario};

use super::layout::{Layout, VALUES_COMPONENT};
use crate::globs::Globs;
use crate::signals;

/// The lockstep's hops on their own axis; the followers' batch delays (ms) apart.
fn latency_views(s: &Scenario, layout: &Layout) -> Vec<ContainerLike> {
    let (followers, ring): (Vec<String>, Vec<String>) = layout
        .signals()
        .filter(|p| p.starts_with("/latency/"))
        .map(str::to_string)
        .partition(|p| signals::follower_hop(s, p));
    let mut views = vec![plot("lockstep latency [µs]", &ring, layout)];
    if !followers.is_empty() {
        views.push(plot(
            "followers' batch delay [µs] (observers off the ring)",
            &followers,
            layout,
        ));
    }
    views
}

/// A plot of the recorded signals matching `patterns`: each gets a visualizer that maps element
/// `i` of its entity's values (selector `.[i]` on [`VALUES_COMPONENT`]) to the plotted scalars,
/// with its own legend, colour and width.
fn plot(title: impl Into<String>, patterns: &[String], layout: &Layout) -> ContainerLike {
    let globs = Globs::new(patterns).ok();
    let mut by_entity: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for path in layout
        .signals()
        .filter(|p| globs.as_ref().is_some_and(|g| g.matches(p)))
    {
        if let Some((entity, _, _)) = layout.at(path) {
            by_entity.entry(entity).or_default().push(path);
        }
    }
    let mut view =
        TimeSeriesView::new(title).with_contents(by_entity.keys().map(|e| e.to_string()));
    for (entity, paths) in &by_entity {
        let visualizers = paths
            .iter()
            .filter_map(|p| layout.at(p))
            .map(|(_, i, line)| {
                let [r, g, b] = line.color;
                let style = SeriesLines::new()
                    .with_names([line.legend.clone()])
                    .with_colors([Color::from_rgb(r, g, b)])
                    .with_widths([line.width]);
                let pick = VisualizerComponentMapping::new(
                    "Scalars:scalars",
                    ComponentSourceKind::SourceComponent,
                    Some(VALUES_COMPONENT),
                    Some(format!(".[{i}]")),
                );
                Visualizer::new("SeriesLines")
                    .with_overrides(&style)
                    .with_mappings([pick.into()])
            });
        view = view.with_overrides(entity.to_string(), visualizers.collect::<Vec<_>>());
    }
    view.into()
}

/// "what: a [m], b [V]" for a handful of components, "what" alone for more.
fn titled(what: &str, parts: &[String]) -> String {
    if parts.is_empty() || parts.len() > 4 {
        what.to_string()
    } else {
        format!("{what}: {}", parts.join(", "))
    }
}

fn with_units(v: &[Named]) -> Vec<String> {
    v.iter().map(Named::with_unit).collect()
}

/// "x3 [m]" for a state with its default name, "x3: eta [rad]" for a named one.
fn state_title(i: usize, x: &Named) -> String {
    if x.name == format!("x{}", i + 1) {
        format!(
            "x{}{}",
            i + 1,
            if x.unit.is_empty() {
                String::new()
            } else {
                format!(" [{}]", x.unit)
            }
        )
    } else {
        format!("x{}: {}", i + 1, x.with_unit())
    }
}

/// Per bank: its residuals, their evaluations against the thresholds (and its GLR statistics
/// against theirs), the alarms, the isolated channel (and which test decided); and the injected
/// faults for reference.
fn diagnosis_views(s: &Scenario, layout: &Layout) -> Vec<ContainerLike> {
    let mut views: Vec<ContainerLike> = Vec::new();
    for d in &s.diagnosers {
        let n = &d.name;
        views.push(plot(
            format!("residuals ({n})"),
            &[format!("/diagnoser/{n}/residual/**")],
            layout,
        ));
        views.push(plot(
            format!("evaluations J and thresholds ({n})"),
            &[
                format!("/diagnosis/{n}/evaluation/**"),
                format!("/diagnosis/{n}/threshold/**"),
            ],
            layout,
        ));
        if d.glr.is_some() {
            views.push(plot(
                format!("GLR statistics g and thresholds ({n})"),
                &[
                    format!("/diagnosis/{n}/glr/**"),
                    format!("/diagnosis/{n}/glr_threshold/**"),
                ],
                layout,
            ));
        }
        let mut decisions = vec![format!("/diagnosis/{n}/alarm/**"), signals::isolated(n)];
        if d.glr.is_some() {
            decisions.push(signals::decided_by(n));
        }
        views.push(plot(
            format!("alarms, isolated channel ({n})"),
            &decisions,
            layout,
        ));
    }
    if !s.faults.is_empty() {
        views.push(plot("injected faults", &["/fault/**".to_string()], layout));
    }
    views
}

/// The blueprint for a scenario's recording laid out as `layout`.
pub fn blueprint(s: &Scenario, layout: &Layout) -> Blueprint {
    let states: Vec<ContainerLike> = s
        .names
        .state
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let mut contents = vec![signals::state(i)];
            contents.extend(
                s.observers
                    .iter()
                    .filter(|o| o.member.is_none())
                    .map(|o| signals::estimate(&o.name, i)),
            );
            plot(state_title(i, x), &contents, layout)
        })
        .collect();
    let mut per_observer: Vec<ContainerLike> = Vec::new();
    let plain: Vec<_> = s.observers.iter().filter(|o| o.member.is_none()).collect();
    if !plain.is_empty() {
        let logs: Vec<String> = plain.iter().map(|o| signals::log_error(&o.name)).collect();
        per_observer.push(plot("log10 max|e|", &logs, layout));
    }
    for o in &plain {
        per_observer.push(plot(
            format!("error e = x − x̂ ({})", o.name),
            &[format!("/observer/{}/error/**", o.name)],
            layout,
        ));
        per_observer.push(plot(
            format!("residual r = y − Cx̂ ({})", o.name),
            &[format!("/observer/{}/residual/**", o.name)],
            layout,
        ));
    }
    let n = &s.names;
    let mut plant_signals: Vec<ContainerLike> = Vec::new();
    if !n.disturbance.is_empty() || !n.measurement_disturbance.is_empty() {
        let parts = [
            with_units(&n.disturbance),
            with_units(&n.measurement_disturbance),
        ]
        .concat();
        // With every UIO's ŵ (recorded only for those whose outputs see Γ_E whole).
        let mut contents = vec![
            "/disturbance/**".to_string(),
            "/measurement_disturbance/**".to_string(),
        ];
        contents.extend(
            s.observers
                .iter()
                .filter(|o| o.spec.as_ref().is_some_and(|sp| sp.decouples()))
                .map(|o| format!("/observer/{}/what/**", o.name)),
        );
        plant_signals.push(plot(
            titled("unknown inputs w, v and estimates ŵ", &parts),
            &contents,
            layout,
        ));
    }
    let inputs_title = if s.controller.is_some() {
        "inputs r and controller u"
    } else {
        "inputs"
    };
    plant_signals.push(plot(
        titled(inputs_title, &with_units(&n.input)),
        &["/input/**".to_string(), "/controller/**".to_string()],
        layout,
    ));
    plant_signals.push(plot(
        titled("outputs", &with_units(&n.output)),
        &["/plant/y/**".to_string()],
        layout,
    ));
    plant_signals.extend(latency_views(s, layout));
    let mut sections: Vec<ContainerLike> = vec![
        Grid::new(states)
            .with_name("states and estimates")
            .with_grid_columns(2)
            .into(),
        Grid::new(per_observer)
            .with_name("errors and residuals")
            .with_grid_columns(2)
            .into(),
    ];
    if !s.diagnosers.is_empty() || !s.faults.is_empty() {
        sections.push(
            Grid::new(diagnosis_views(s, layout))
                .with_name("diagnosis")
                .with_grid_columns(2)
                .into(),
        );
    }
    sections.push(
        Grid::new(plant_signals)
            .with_name("signals")
            .with_grid_columns(2)
            .into(),
    );
    let root = Vertical::new(sections);
    Blueprint::new(root)
        .with_auto_views(false)
        .with_time_panel(
            TimePanel::new()
                .with_timeline("sim_time")
                .with_play_state(PlayState::Paused)
                .with_state(PanelState::Expanded),
        )
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
}
