//! The layout a recording opens with: each state beside every observer's estimate of it, then
//! each observer's errors and residuals on their own axes (a UIO's 1e−12 error would be a flat
//! line on a Luenberger observer's scale), then the signals driving the plant, and latency.

use rerun::blueprint::{Blueprint, ContainerLike, Grid, Horizontal, TimeSeriesView, Vertical};

use crate::scenario::Scenario;

/// The blueprint for a scenario's recording.
pub fn blueprint(s: &Scenario) -> Blueprint {
    let n = s.model.n();
    let states: Vec<ContainerLike> = (0..n)
        .map(|i| {
            let unit = &s.state_units[i];
            let title = if unit.is_empty() { s.state_names[i].clone() } else { format!("{} [{unit}]", s.state_names[i]) };
            let mut contents = vec![format!("/plant/x/{i}")];
            contents.extend(s.observers.iter().map(|o| format!("/observer/{}/xhat/{i}", o.name)));
            TimeSeriesView::new(title).with_contents(contents).into()
        })
        .collect();
    let mut per_observer: Vec<ContainerLike> = Vec::new();
    for o in &s.observers {
        per_observer.push(TimeSeriesView::new(format!("error e = x − x̂ ({})", o.name)).with_contents([format!("/observer/{}/error/**", o.name)]).into());
        per_observer.push(TimeSeriesView::new(format!("residual r = y − Cx̂ ({})", o.name)).with_contents([format!("/observer/{}/residual/**", o.name)]).into());
    }
    let mut signals: Vec<ContainerLike> = Vec::new();
    if !s.disturbances.is_empty() || !s.measurement_disturbances.is_empty() {
        signals.push(TimeSeriesView::new("unknown inputs").with_contents(["/disturbance/**", "/measurement_disturbance/**"]).into());
    }
    signals.push(TimeSeriesView::new("inputs").with_contents(["/input/**", "/controller/**"]).into());
    signals.push(TimeSeriesView::new("outputs y").with_contents(["/plant/y/**"]).into());
    signals.push(TimeSeriesView::new("latency [ns]").with_contents(["/latency/**"]).into());
    let root = Vertical::new([
        Grid::new(states).with_name("states and estimates").into(),
        Grid::new(per_observer).with_name("errors and residuals").into(),
        Horizontal::new(signals).with_name("signals").into(),
    ]);
    Blueprint::new(root).with_auto_views(false)
}
