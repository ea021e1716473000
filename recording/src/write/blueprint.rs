//! The layout a recording opens with: each state beside every observer's estimate of it, then
//! the errors of all observers on a log10 axis (the only view where a UIO's 1e−15 error and a
//! Luenberger observer's 1e−1 have readable numbers side by side), each observer's errors and
//! residuals on their own axes, then the signals driving the plant, and latency. It opens on
//! the `sim_time` timeline, paused, so every plot shows the whole run at once.

use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{Blueprint, ContainerLike, Grid, Horizontal, SelectionPanel, TimePanel, TimeSeriesView, Vertical};

use scenario::{Named, Scenario};

use crate::signals;

/// "what: a [m], b [V]" for a handful of components, "what" alone for more.
fn titled(what: &str, parts: &[String]) -> String {
    if parts.is_empty() || parts.len() > 4 { what.to_string() } else { format!("{what}: {}", parts.join(", ")) }
}

fn with_units(v: &[Named]) -> Vec<String> {
    v.iter().map(Named::with_unit).collect()
}

/// "x3 [m]" for a state with its default name, "x3: eta [rad]" for a named one.
fn state_title(i: usize, x: &Named) -> String {
    if x.name == format!("x{}", i + 1) { format!("x{}{}", i + 1, if x.unit.is_empty() { String::new() } else { format!(" [{}]", x.unit) }) } else { format!("x{}: {}", i + 1, x.with_unit()) }
}

/// Per bank: its residuals, their evaluations against the thresholds, the alarms and the
/// isolated channel; and the injected faults for reference.
fn diagnosis_views(s: &Scenario) -> Vec<ContainerLike> {
    let mut views: Vec<ContainerLike> = Vec::new();
    for d in &s.diagnosers {
        let n = &d.name;
        views.push(TimeSeriesView::new(format!("residuals ({n})")).with_contents([format!("/diagnoser/{n}/residual/**")]).into());
        views.push(TimeSeriesView::new(format!("evaluations J and thresholds ({n})")).with_contents([format!("/diagnosis/{n}/evaluation/**"), format!("/diagnosis/{n}/threshold/**")]).into());
        views.push(TimeSeriesView::new(format!("alarms, isolated channel ({n})")).with_contents([format!("/diagnosis/{n}/alarm/**"), signals::isolated(n)]).into());
    }
    if !s.faults.is_empty() {
        views.push(TimeSeriesView::new("injected faults").with_contents(["/fault/**"]).into());
    }
    views
}

/// The blueprint for a scenario's recording.
pub fn blueprint(s: &Scenario) -> Blueprint {
    let states: Vec<ContainerLike> = s
        .names
        .state
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let mut contents = vec![signals::state(i)];
            contents.extend(s.observers.iter().filter(|o| o.member.is_none()).map(|o| signals::estimate(&o.name, i)));
            TimeSeriesView::new(state_title(i, x)).with_contents(contents).into()
        })
        .collect();
    let mut per_observer: Vec<ContainerLike> = Vec::new();
    let plain: Vec<_> = s.observers.iter().filter(|o| o.member.is_none()).collect();
    if !plain.is_empty() {
        let logs: Vec<String> = plain.iter().map(|o| signals::log_error(&o.name)).collect();
        per_observer.push(TimeSeriesView::new("log10 max|e|").with_contents(logs).into());
    }
    for o in &plain {
        per_observer.push(TimeSeriesView::new(format!("error e = x − x̂ ({})", o.name)).with_contents([format!("/observer/{}/error/**", o.name)]).into());
        per_observer.push(TimeSeriesView::new(format!("residual r = y − Cx̂ ({})", o.name)).with_contents([format!("/observer/{}/residual/**", o.name)]).into());
    }
    let n = &s.names;
    let mut plant_signals: Vec<ContainerLike> = Vec::new();
    if !n.disturbance.is_empty() || !n.measurement_disturbance.is_empty() {
        let parts = [with_units(&n.disturbance), with_units(&n.measurement_disturbance)].concat();
        // With every UIO's ŵ (recorded only for those whose outputs see Γ_E whole).
        let mut contents = vec!["/disturbance/**".to_string(), "/measurement_disturbance/**".to_string()];
        contents.extend(s.observers.iter().filter(|o| o.spec.as_ref().is_some_and(|sp| sp.decouples())).map(|o| format!("/observer/{}/what/**", o.name)));
        plant_signals.push(TimeSeriesView::new(titled("unknown inputs w, v and estimates ŵ", &parts)).with_contents(contents).into());
    }
    let inputs_title = if s.controller.is_some() { "inputs r and controller u" } else { "inputs" };
    plant_signals.push(TimeSeriesView::new(titled(inputs_title, &with_units(&n.input))).with_contents(["/input/**", "/controller/**"]).into());
    plant_signals.push(TimeSeriesView::new(titled("outputs", &with_units(&n.output))).with_contents(["/plant/y/**"]).into());
    plant_signals.push(TimeSeriesView::new("latency [ns]").with_contents(["/latency/**"]).into());
    let mut sections: Vec<ContainerLike> = vec![
        Grid::new(states).with_name("states and estimates").into(),
        Grid::new(per_observer).with_name("errors and residuals").into(),
    ];
    if !s.diagnosers.is_empty() || !s.faults.is_empty() {
        sections.push(Grid::new(diagnosis_views(s)).with_name("diagnosis").into());
    }
    sections.push(Horizontal::new(plant_signals).with_name("signals").into());
    let root = Vertical::new(sections);
    Blueprint::new(root)
        .with_auto_views(false)
        .with_time_panel(TimePanel::new().with_timeline("sim_time").with_play_state(PlayState::Paused).with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
}
