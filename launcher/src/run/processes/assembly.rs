//! The launcher's side of the samples: a queue per component, checked against the protocol
//! (PROTOCOL.md §6) as it is assembled into the rows of the recording, in step order.

use std::collections::VecDeque;

use lockstep::{Header, PROTOCOL_VERSION, Reader, WireHeader};

use super::super::envelope::Launchable;
use super::super::session::Session;
use crate::error::LaunchError;
use recording::write::StepRow;

/// The samples received from one component, in order. Their value buffers are recycled, so
/// once the queue has been as deep as it gets, receiving allocates nothing.
pub(super) struct Queue {
    /// How messages name the component.
    label: String,
    /// Names of its values (1-based), for messages.
    names: Vec<String>,
    items: VecDeque<(WireHeader, Vec<f64>)>,
    free: Vec<Vec<f64>>,
    /// The highest step any of its samples carried.
    pub(super) last: Option<u64>,
    /// The host it runs on, when not this one: its times are of that host's clock.
    host: Option<String>,
}

impl Queue {
    pub(super) fn new(c: &Launchable) -> Self {
        let host = match &c.program {
            super::super::envelope::Program::Remote(_, r) => Some(r.host.clone()),
            _ => None,
        };
        Queue {
            label: c.label.clone(),
            names: c.config.publishes.names.clone(),
            items: VecDeque::new(),
            free: Vec::new(),
            last: None,
            host,
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Moves every pending sample of `reader` in; returns how many there were. A sample of a
    /// component on this host cannot have been sent after the launcher received it: its
    /// `sent_ns` is checked against the clock read once the batch is in (another host's clock
    /// is moved onto this one only to within half a round trip, so its samples are not).
    pub(super) fn drain(&mut self, reader: &Reader, max: usize) -> Result<usize, LaunchError> {
        let (items, free, last) = (&mut self.items, &mut self.free, &mut self.last);
        let mut latest: Option<(u64, u64)> = None;
        let got = reader
            .drain_up_to(max, |h, v| {
                let mut buf = free.pop().unwrap_or_default();
                buf.clear();
                buf.extend_from_slice(v);
                *last = Some(last.map_or(h.step, |l| l.max(h.step)));
                if latest.is_none_or(|(sent, _)| h.sent_ns > sent) {
                    latest = Some((h.sent_ns, h.step));
                }
                items.push_back((*h, buf));
            })
            .map_err(|e| LaunchError::Component(format!("{}: {e}", self.label)))?;
        if let Some((sent, step)) = latest
            && self.host.is_none()
        {
            let now = lockstep::now_ns();
            if sent > now {
                return Err(LaunchError::Component(format!(
                    "{} broke the protocol at step {step}: its sample says it was sent at {sent} ns, after the launcher received it ({now} ns, CLOCK_MONOTONIC)",
                    self.label
                )));
            }
        }
        Ok(got)
    }

    /// The first queued sample that breaks the protocol by itself (its version, its number of
    /// values, a non-finite value), whether or not its step is complete: when a component stops
    /// because of another's sample, the launcher names the one that broke the protocol.
    fn violation(&self, width: usize) -> Option<LaunchError> {
        self.items.iter().find_map(|(h, values)| {
            let broken = |why: String| {
                Some(LaunchError::Component(format!(
                    "{} broke the protocol at step {}: {why}",
                    self.label, h.step
                )))
            };
            if h.protocol != PROTOCOL_VERSION {
                return broken(format!(
                    "its sample says protocol version {}, the run speaks {PROTOCOL_VERSION}",
                    h.protocol
                ));
            }
            if values.len() != width {
                return broken(format!(
                    "its sample has {} values, the run's configuration says {width}",
                    values.len()
                ));
            }
            let i = values.iter().position(|v| !v.is_finite())?;
            let name = self.names.get(i).map_or(String::new(), |n| {
                format!(" ({})", scenario::untrusted::quoted(n))
            });
            broken(format!("value {}{name} is {}", i + 1, values[i]))
        })
    }

    /// Takes the sample of step `k` into `out`, checking it against the protocol (PROTOCOL.md
    /// §6): the step, the protocol version, its stamps (a finite sim_time, taken no later than
    /// sent), the number of values, and that each is finite.
    pub(super) fn take(&mut self, k: u64, out: &mut [f64]) -> Result<Header, LaunchError> {
        let (h, values) = self.items.pop_front().expect("non-empty");
        let broken = |why: String| {
            LaunchError::Component(format!(
                "{} broke the protocol at step {k}: {why}",
                self.label
            ))
        };
        if h.protocol != PROTOCOL_VERSION {
            return Err(broken(format!(
                "its sample says protocol version {}, the run speaks {PROTOCOL_VERSION}",
                h.protocol
            )));
        }
        if h.step != k {
            return Err(broken(format!("its sample is of step {}", h.step)));
        }
        if let Some(why) = h.stamp_violation() {
            return Err(broken(why));
        }
        if values.len() != out.len() {
            return Err(broken(format!(
                "its sample has {} values, the run's configuration says {}",
                values.len(),
                out.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            let name = self.names.get(i).map_or(String::new(), |n| {
                format!(" ({})", scenario::untrusted::quoted(n))
            });
            return Err(broken(format!("value {}{name} is {}", i + 1, values[i])));
        }
        out.copy_from_slice(&values);
        self.free.push(values);
        Ok(Header::of(&h, 0))
    }

    /// Checks that the sample of step k was made from its input's sample k: it cannot have taken
    /// its input (`taken_ns`) before that input was sent. A component that publishes without
    /// reading would otherwise go unnoticed until its full subscriber buffer blocks the plant.
    /// Two hosts' CLOCK_MONOTONIC have unrelated origins, so a hop between hosts is not checked.
    pub(super) fn made_after(
        &self,
        k: u64,
        own: &Header,
        input: &Header,
        input_label: &str,
        input_host: &Option<String>,
    ) -> Result<(), LaunchError> {
        if self.host == *input_host && own.taken_ns < input.sent_ns {
            return Err(LaunchError::Component(format!(
                "{} broke the protocol at step {k}: it published the step before {input_label}'s sample {k} was sent (it does not read its input)",
                self.label
            )));
        }
        Ok(())
    }
}

/// Per-component queues of received samples, assembled into rows in step order.
pub(super) struct Assembly {
    pub(super) plant: Queue,
    /// One per observer process.
    pub(super) observers: Vec<Queue>,
    pub(super) controller: Option<Queue>,
    pub(super) next: u64,
    /// Steps K of the run: the plant's end sample (step K) is not a row.
    pub(super) steps: u64,
    /// Sample period: the recording's time is k·dt, whatever a plant's header says.
    pub(super) dt: f64,
    /// The observer the controller reads, and the observer process that publishes it.
    pub(super) controller_observer: Option<(usize, usize)>,
    /// Per observer process, the observers whose x̂ its sample holds, side by side.
    members: Vec<Vec<usize>>,
    /// Per observer process of several, its sample of the step being assembled.
    scratch: Vec<Vec<f64>>,
}

impl Assembly {
    /// The queues of `components` (plant, observer processes, controller), as the launcher
    /// spawns them.
    pub(super) fn new(
        components: &[Launchable],
        cfg: &super::super::configs::Configs,
        steps: u64,
        dt: f64,
        controller_observer: Option<usize>,
    ) -> Self {
        let nproc = cfg.processes.len();
        let members: Vec<Vec<usize>> = cfg.processes.iter().map(|p| p.observers.clone()).collect();
        let controller_observer = controller_observer.map(|c| {
            (
                c,
                members
                    .iter()
                    .position(|m| m.contains(&c))
                    .expect("every observer has a process"),
            )
        });
        Assembly {
            plant: Queue::new(&components[0]),
            observers: components[1..1 + nproc].iter().map(Queue::new).collect(),
            controller: components.get(1 + nproc).map(Queue::new),
            next: 0,
            steps,
            dt,
            controller_observer,
            scratch: members
                .iter()
                .map(|m| {
                    if m.len() > 1 {
                        vec![0.0; m.len() * cfg.layout.n]
                    } else {
                        Vec::new()
                    }
                })
                .collect(),
            members,
        }
    }

    /// The component whose sample for the next step is missing, first in the order samples flow
    /// within a step (plant, observers, controller): the others wait on it. Indices as the
    /// launcher spawns them.
    pub(super) fn missing(&self) -> Option<usize> {
        if self.plant.is_empty() {
            return Some(0);
        }
        if let Some(i) = self.observers.iter().position(|q| q.is_empty()) {
            return Some(1 + i);
        }
        self.controller
            .as_ref()
            .filter(|q| q.is_empty())
            .map(|_| 1 + self.observers.len())
    }

    /// A queued sample that breaks the protocol (see [`Queue::violation`]), with the widths of
    /// `row`: the plant's first, then the observers', then the controller's.
    pub(super) fn queued_violation(&self, row: &StepRow) -> Option<LaunchError> {
        self.plant
            .violation(row.plant.len())
            .or_else(|| {
                self.observers
                    .iter()
                    .zip(&self.members)
                    .find_map(|(q, m)| q.violation(m.len() * row.xhat.first().map_or(0, Vec::len)))
            })
            .or_else(|| {
                self.controller
                    .as_ref()
                    .and_then(|q| q.violation(row.u.len()))
            })
    }

    /// Moves every complete step into the session.
    pub(super) fn assemble(
        &mut self,
        row: &mut StepRow,
        session: &mut Session,
    ) -> Result<usize, LaunchError> {
        let mut done = 0;
        loop {
            if self.next >= self.steps {
                return Ok(done);
            }
            let ready = !self.plant.is_empty()
                && self.observers.iter().all(|q| !q.is_empty())
                && self.controller.as_ref().is_none_or(|q| !q.is_empty());
            if !ready {
                return Ok(done);
            }
            let k = self.next;
            row.plant_hdr = self.plant.take(k, &mut row.plant)?;
            row.k = k;
            row.t = k as f64 * self.dt;
            for ((q, members), buf) in self
                .observers
                .iter_mut()
                .zip(&self.members)
                .zip(&mut self.scratch)
            {
                if let [i] = members[..] {
                    row.xhat_hdr[i] = q.take(k, &mut row.xhat[i])?;
                    q.made_after(
                        k,
                        &row.xhat_hdr[i],
                        &row.plant_hdr,
                        "the plant",
                        &self.plant.host,
                    )?;
                    continue;
                }
                // A bank's process: its members' x̂ side by side.
                let h = q.take(k, buf)?;
                q.made_after(k, &h, &row.plant_hdr, "the plant", &self.plant.host)?;
                for (&i, x) in members
                    .iter()
                    .zip(buf.chunks_exact(row.xhat[members[0]].len()))
                {
                    row.xhat[i].copy_from_slice(x);
                    row.xhat_hdr[i] = h;
                }
            }
            if let Some(q) = &mut self.controller {
                row.u_hdr = q.take(k, &mut row.u)?;
                if let Some((c, p)) = self.controller_observer {
                    let o = &self.observers[p];
                    q.made_after(k, &row.u_hdr, &row.xhat_hdr[c], &o.label, &o.host)?;
                }
            }
            session.record(row)?;
            self.next += 1;
            done += 1;
        }
    }

    /// The plant's end sample (step K), checked like every other, once every step was assembled.
    pub(super) fn end(&mut self, row: &mut StepRow) -> Result<Option<Header>, LaunchError> {
        if self.plant.is_empty() {
            return Ok(None);
        }
        self.plant.take(self.steps, &mut row.plant).map(Some)
    }

    /// Whether component `i` (spawn order) has published its last sample: step K for the plant
    /// (its end sample), K − 1 for the others.
    pub(super) fn published_all(&self, i: usize) -> bool {
        let nobs = self.observers.len();
        let (q, last) = match i {
            0 => (&self.plant, self.steps),
            i if i <= nobs => (&self.observers[i - 1], self.steps.saturating_sub(1)),
            _ => (
                self.controller.as_ref().expect("a controller"),
                self.steps.saturating_sub(1),
            ),
        };
        q.last.is_some_and(|l| l >= last)
    }

    pub(super) fn queue(&self, i: usize) -> &Queue {
        let nobs = self.observers.len();
        match i {
            0 => &self.plant,
            i if i <= nobs => &self.observers[i - 1],
            _ => self.controller.as_ref().expect("a controller"),
        }
    }
}

/// The launcher's recording subscribers, one per topic.
pub(super) struct Readers<'a> {
    pub(super) plant: &'a Reader,
    pub(super) observers: &'a [Reader],
    pub(super) controller: Option<&'a Reader>,
}

impl Readers<'_> {
    /// Moves every pending sample into its queue; returns how many there were.
    pub(super) fn drain_all(&self, asm: &mut Assembly) -> Result<usize, LaunchError> {
        self.drain_up_to(asm, usize::MAX)
    }

    /// At most `max` samples of each service.
    pub(super) fn drain_up_to(&self, asm: &mut Assembly, max: usize) -> Result<usize, LaunchError> {
        let mut got = asm.plant.drain(self.plant, max)?;
        for (r, q) in self.observers.iter().zip(asm.observers.iter_mut()) {
            got += q.drain(r, max)?;
        }
        if let (Some(r), Some(q)) = (self.controller, asm.controller.as_mut()) {
            got += q.drain(r, max)?;
        }
        Ok(got)
    }
}
