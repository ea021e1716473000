//! Every plot opens on the whole run. The viewer's default time (X) axis of a plot over a
//! duration timeline spanning more than 60 s is the time cursor ± 30 s (Rerun 0.36,
//! `re_view_time_series`'s fallback for `TimeAxis.view_range`, chosen for hour-long live
//! streams): a two-day run opened on 60 s of it, a 600 s run on its first 30 s. A recorded run
//! is read as a whole, so each plot's `TimeAxis` is set to the whole timeline.
//!
//! The Rust SDK's `TimeSeriesView` has no setter for its time axis (the Python SDK's `axis_x`),
//! and a view's blueprint path `view/<id>` is private to it: the blueprint is therefore made
//! into its messages on a memory stream, every view path is read from them, and a `TimeAxis`
//! archetype is logged at `view/<id>/TimeAxis` in the same blueprint store, before the
//! activation command that makes the viewer use it.

use rerun::blueprint::{Blueprint, BlueprintActivation};
use rerun::datatypes::TimeRange;
use rerun::external::re_log_types::{BlueprintActivationCommand, StoreKind};
use rerun::external::re_sdk_types::blueprint::archetypes::TimeAxis;
use rerun::log::{Chunk, LogMsg};
use rerun::{RecordingStream, RecordingStreamBuilder};

/// Sends `blueprint` to `rec` with each of its plots' time axis on the whole timeline.
pub fn send(
    blueprint: &Blueprint,
    rec: &RecordingStream,
    activation: BlueprintActivation,
) -> Result<(), String> {
    let app = rec
        .store_info()
        .map(|i| i.application_id().clone())
        .ok_or("the recording has no store info")?;
    let (capture, storage) = RecordingStreamBuilder::new(app.clone())
        .memory()
        .map_err(|e| e.to_string())?;
    blueprint
        .send(&capture, activation)
        .map_err(|e| e.to_string())?;
    capture.flush_blocking().map_err(|e| e.to_string())?;
    let mut msgs = Vec::new();
    let mut activate: Option<BlueprintActivationCommand> = None;
    let mut views: Vec<String> = Vec::new();
    for msg in storage.take() {
        if msg.store_id().kind() != StoreKind::Blueprint {
            continue; // the capture stream's own recording
        }
        match &msg {
            LogMsg::BlueprintActivationCommand(cmd) => {
                activate = Some(cmd.clone());
                continue;
            }
            LogMsg::ArrowMsg(_, arrow) => {
                let chunk = Chunk::from_arrow_msg(arrow).map_err(|e| e.to_string())?;
                let path = chunk.entity_path().to_string();
                if let Some(view) = view_path(&path)
                    && !views.iter().any(|v| v == view)
                {
                    views.push(view.to_string());
                }
            }
            LogMsg::SetStoreInfo(_) => {}
        }
        msgs.push(msg);
    }
    let activate = activate.ok_or("the blueprint sent no activation command")?;
    msgs.extend(time_axes(&activate, &views)?);
    rec.send_blueprint(msgs, activate);
    Ok(())
}

/// `view/<id>` of a path in a view's subtree (`view/<id>`, `view/<id>/ViewContents`, …).
fn view_path(path: &str) -> Option<&str> {
    let rest = path.strip_prefix("/view/").or(path.strip_prefix("view/"))?;
    let id_len = rest.find('/').unwrap_or(rest.len());
    let start = path.len() - rest.len() - "view/".len();
    (id_len > 0).then(|| &path[start..start + "view/".len() + id_len])
}

/// The `TimeAxis` messages of `views`, in the blueprint store `activate` names.
fn time_axes(
    activate: &BlueprintActivationCommand,
    views: &[String],
) -> Result<Vec<LogMsg>, String> {
    let id = &activate.blueprint_id;
    let (bp, storage) = RecordingStreamBuilder::new(id.application_id().clone())
        .recording_id(id.recording_id().clone())
        .blueprint()
        .memory()
        .map_err(|e| e.to_string())?;
    bp.set_time_sequence("blueprint", 0);
    let axis = TimeAxis::new().with_view_range(TimeRange::EVERYTHING);
    for view in views {
        bp.log(format!("{view}/TimeAxis"), &axis)
            .map_err(|e| e.to_string())?;
    }
    bp.flush_blocking().map_err(|e| e.to_string())?;
    Ok(storage
        .take()
        .into_iter()
        .filter(|m| matches!(m, LogMsg::ArrowMsg(..)))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rerun::blueprint::{TimeSeriesView, Vertical};

    /// Each view of the blueprint gets one `TimeAxis` at its own path, in the blueprint's store,
    /// sent before the activation command, which comes last.
    #[test]
    fn every_view_gets_a_whole_run_time_axis_before_the_activation() {
        let (rec, storage) = RecordingStreamBuilder::new("whole-run").memory().unwrap();
        let views = ["a", "b", "c"].map(|n| TimeSeriesView::new(n).into());
        let bp = Blueprint::new(Vertical::new(views));
        let activation = BlueprintActivation {
            make_active: true,
            make_default: true,
        };
        send(&bp, &rec, activation).unwrap();
        rec.flush_blocking().unwrap();
        let msgs: Vec<LogMsg> = storage
            .take()
            .into_iter()
            .filter(|m| m.store_id().kind() == StoreKind::Blueprint)
            .collect();
        assert!(matches!(
            msgs.last(),
            Some(LogMsg::BlueprintActivationCommand(_))
        ));
        let (mut blueprints, mut axes) = (Vec::new(), Vec::new());
        for m in &msgs {
            if let LogMsg::ArrowMsg(_, arrow) = m {
                let chunk = Chunk::from_arrow_msg(arrow).unwrap();
                let path = chunk.entity_path().to_string();
                let has = |c: &str| chunk.components().keys().any(|d| d.as_str() == c);
                if has("ViewBlueprint:class_identifier") {
                    blueprints.push(path);
                } else if has("TimeAxis:view_range") {
                    axes.push(path.trim_end_matches("/TimeAxis").to_string());
                }
            }
        }
        blueprints.sort();
        axes.sort();
        assert_eq!(blueprints.len(), 3, "{blueprints:?}");
        assert_eq!(axes, blueprints);
    }

    #[test]
    fn a_views_path_is_read_from_any_path_in_its_subtree() {
        use super::view_path;
        assert_eq!(view_path("/view/abc"), Some("view/abc"));
        assert_eq!(view_path("/view/abc/ViewContents"), Some("view/abc"));
        assert_eq!(view_path("view/abc/x/y"), Some("view/abc"));
        assert_eq!(view_path("/container/abc"), None);
        assert_eq!(view_path("/view/"), None);
        assert_eq!(view_path("/viewport"), None);
    }
}
