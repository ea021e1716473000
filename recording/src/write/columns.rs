//! The recorder's second thread: it turns each batch of rows into the digest of every signal
//! and into Rerun columns, and sends them, so that the loop that fills the rows (the launcher's,
//! on the run's critical path in one process) only writes values into buffers.
//!
//! A batch is a group's rows since its last send: its steps and times and, per entity, the
//! values row-major. The channel is bounded ([`DEPTH`] batches): a recorder that falls behind
//! holds the loop back instead of growing without bound.

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use rerun::external::arrow::array::{Float64Array, ListArray};
use rerun::external::arrow::buffer::{OffsetBuffer, ScalarBuffer};
use rerun::external::arrow::datatypes::{DataType, Field, FieldRef};
use rerun::time::Timeline;
use rerun::{ComponentDescriptor, RecordingStream, SerializedComponentColumn, TimeColumn};

use super::layout::VALUES_COMPONENT;
use crate::digest::{Rows, Running};

/// Batches in flight between the loop and the recorder's thread.
const DEPTH: usize = 4;

/// One group's rows since its last send.
pub struct Batch {
    pub steps: Vec<i64>,
    /// sim_time in nanoseconds.
    pub times_ns: Vec<i64>,
    /// Per entity of the group: its index and its values, row-major.
    pub values: Vec<(usize, Vec<f64>)>,
}

/// An entity as the thread writes it: its path and the signal behind each element.
pub struct Entity {
    pub path: String,
    pub signals: Vec<String>,
}

/// The thread, and the end of its channel.
pub struct Columns {
    tx: Option<SyncSender<Batch>>,
    thread: Option<JoinHandle<Result<BTreeMap<String, Running>, String>>>,
}

impl Columns {
    /// Starts the thread writing `entities` to `rec`.
    pub fn start(rec: RecordingStream, entities: Vec<Entity>) -> Result<Self, String> {
        let (tx, rx) = sync_channel(DEPTH);
        let thread = std::thread::Builder::new()
            .name("uio-recorder".into())
            .spawn(move || write_all(&rec, &entities, rx))
            .map_err(|e| format!("cannot start the recorder's thread: {e}"))?;
        Ok(Columns {
            tx: Some(tx),
            thread: Some(thread),
        })
    }

    /// Hands a batch over (waits while [`DEPTH`] are in flight); fails with the thread's error
    /// once it has stopped.
    pub fn send(&mut self, batch: Batch) -> Result<(), String> {
        if let Some(tx) = &self.tx
            && tx.send(batch).is_ok()
        {
            return Ok(());
        }
        // The thread has gone: its own error says why.
        self.finish()
            .and(Err("the recorder's thread has stopped".into()))
    }

    /// Waits for every batch to be written; returns each signal's digest.
    pub fn finish(&mut self) -> Result<BTreeMap<String, Running>, String> {
        self.tx = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err("the recorder's thread panicked".into()),
            None => Err("the recorder's thread has stopped".into()),
        }
    }
}

fn write_all(
    rec: &RecordingStream,
    entities: &[Entity],
    rx: Receiver<Batch>,
) -> Result<BTreeMap<String, Running>, String> {
    let inner: FieldRef = Arc::new(Field::new("item", DataType::Float64, true));
    let outer: FieldRef = Arc::new(Field::new("item", DataType::List(inner.clone()), true));
    let mut digests: BTreeMap<String, Running> = BTreeMap::new();
    for batch in rx {
        let rows = batch.steps.len();
        let (step_values, time_values) = (
            ScalarBuffer::from(batch.steps),
            ScalarBuffer::from(batch.times_ns),
        );
        let steps = TimeColumn::new(
            Some(true),
            Timeline::new_sequence("step"),
            step_values.clone(),
        );
        let times = TimeColumn::new(
            Some(true),
            Timeline::new_duration("sim_time"),
            time_values.clone(),
        );
        let mut digest_rows = Rows::new(&step_values, Some(&time_values));
        for (e, values) in batch.values {
            let entity = &entities[e];
            let width = entity.signals.len();
            if values.len() != rows * width {
                return Err(format!(
                    "{}: {} values for {rows} rows of {width}",
                    entity.path,
                    values.len()
                ));
            }
            for (j, signal) in entity.signals.iter().enumerate() {
                digests.entry(signal.clone()).or_default().update_rows(
                    &mut digest_rows,
                    values.iter().skip(j).step_by(width).copied(),
                );
            }
            let lists = ListArray::new(
                inner.clone(),
                OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(width, rows)),
                Arc::new(Float64Array::from(values)),
                None,
            );
            let column = ListArray::new(
                outer.clone(),
                OffsetBuffer::<i32>::from_lengths(std::iter::repeat_n(1, rows)),
                Arc::new(lists),
                None,
            );
            let column = SerializedComponentColumn::new(
                column,
                ComponentDescriptor::partial(VALUES_COMPONENT),
            );
            rec.send_columns(
                entity.path.as_str(),
                [steps.clone(), times.clone()],
                [column],
            )
            .map_err(|e| e.to_string())?;
        }
    }
    Ok(digests)
}
