//! Ports on the bus: an [`Outlet`] publishes one sample per step, an [`Inlet`] waits for the
//! sample of a given step, a [`Reader`] drains everything (the launcher's recorder).

use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;
use iceoryx2::waitset::WaitSetGuard;

use crate::clock::now_ns;
use crate::error::LockstepError;
use crate::run::RunSpace;
use crate::sample::{Header, PROTOCOL_VERSION, WireHeader};
use crate::service::Service as Ipc;
use crate::wait::Wait;

use crate::settings::*;
pub use crate::settings::{FOLLOWER_LAG, RECORDER_BUFFER};

/// A process's node on the run's bus.
pub struct Bus {
    node: Node<Ipc>,
    wait: Wait,
}

impl Bus {
    /// Joins the run's bus as `name` (a node name for diagnostics).
    pub fn join(space: &RunSpace, name: &str, wait: Wait) -> Result<Self, LockstepError> {
        crate::quiet_iceoryx2();
        let node = NodeBuilder::new()
            .name(&NodeName::new(name).map_err(LockstepError::ipc)?)
            .config(space.config())
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(LockstepError::ipc)?;
        Ok(Self { node, wait })
    }

    fn service(&self, topic: &str) -> Result<PortFactory<Ipc, [f64], WireHeader>, LockstepError> {
        // Every port opens the service with the same settings (PROTOCOL.md §4), so any of them
        // may create it.
        self.node
            .service_builder(&ServiceName::new(topic).map_err(LockstepError::ipc)?)
            .publish_subscribe::<[f64]>()
            .user_header::<WireHeader>()
            .max_publishers(MAX_PUBLISHERS)
            .max_subscribers(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .history_size(HISTORY)
            .subscriber_max_buffer_size(SUBSCRIBER_MAX_BUFFER)
            .enable_safe_overflow(false)
            .open_or_create()
            .map_err(LockstepError::ipc)
    }

    fn event(
        &self,
        topic: &str,
    ) -> Result<iceoryx2::service::port_factory::event::PortFactory<Ipc>, LockstepError> {
        self.node
            .service_builder(
                &ServiceName::new(&format!("{topic}/wake")).map_err(LockstepError::ipc)?,
            )
            .event()
            .max_notifiers(MAX_NOTIFIERS)
            .max_listeners(MAX_LISTENERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(LockstepError::ipc)
    }

    /// The publishing end of `topic`, whose samples hold `len` values each.
    pub fn outlet(&self, topic: &str, len: usize) -> Result<Outlet, LockstepError> {
        let publisher = self
            .service(topic)?
            .publisher_builder()
            .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
            .max_loaned_samples(1)
            .initial_max_slice_len(len.max(1))
            .create()
            .map_err(LockstepError::ipc)?;
        let notifier = if self.wait.needs_events() {
            Some(
                self.event(topic)?
                    .notifier_builder()
                    .create()
                    .map_err(LockstepError::ipc)?,
            )
        } else {
            None
        };
        Ok(Outlet {
            publisher,
            notifier,
            len,
        })
    }

    /// A lockstep reading end of `topic`.
    pub fn inlet(&self, topic: &str) -> Result<Inlet, LockstepError> {
        let subscriber = self
            .service(topic)?
            .subscriber_builder()
            .buffer_size(LOCKSTEP_BUFFER)
            .create()
            .map_err(LockstepError::ipc)?;
        let mut listener = if self.wait.needs_events() {
            Some(
                self.event(topic)?
                    .listener_builder()
                    .create()
                    .map_err(LockstepError::ipc)?,
            )
        } else {
            None
        };
        let waitset = if self.wait == Wait::WaitSet {
            // The WaitSet borrows the listener it watches; both live as long as the process (an
            // inlet is made once per component), so they are leaked to 'static.
            let listener: &'static Listener<Ipc> = Box::leak(Box::new(
                listener.take().expect("waitset waits have a listener"),
            ));
            let ws: &'static WaitSet<Ipc> = Box::leak(Box::new(
                WaitSetBuilder::new()
                    .signal_handling_mode(SignalHandlingMode::Disabled)
                    .create::<Ipc>()
                    .map_err(LockstepError::ipc)?,
            ));
            let guard = ws
                .attach_notification(listener)
                .map_err(LockstepError::ipc)?;
            Some(WaitSetWait {
                ws,
                listener,
                _guard: guard,
            })
        } else {
            None
        };
        Ok(Inlet {
            subscriber,
            listener,
            waitset,
            topic: topic.to_string(),
            wait: self.wait,
            timeout: Duration::from_secs(10),
            streak: std::cell::Cell::new(0),
        })
    }

    /// A recording end of `topic` that never makes the publisher drop a sample.
    pub fn reader(&self, topic: &str) -> Result<Reader, LockstepError> {
        let subscriber = self
            .service(topic)?
            .subscriber_builder()
            .buffer_size(RECORDER_BUFFER)
            .create()
            .map_err(LockstepError::ipc)?;
        Ok(Reader { subscriber })
    }
}

/// Publishes one sample per step.
pub struct Outlet {
    publisher: Publisher<Ipc, [f64], WireHeader>,
    notifier: Option<Notifier<Ipc>>,
    len: usize,
}

impl Outlet {
    /// The number of values every sample holds.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Never: a sample holds at least one value (kept for the `len` convention).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Loans a sample, writes header and values in place, sends it; returns the send time.
    pub fn send(
        &self,
        step: u64,
        sim_time: f64,
        taken_ns: u64,
        values: &[f64],
    ) -> Result<u64, LockstepError> {
        if values.len() != self.len {
            return Err(LockstepError::Length {
                topic: "own output".into(),
                expected: self.len,
                got: values.len(),
            });
        }
        self.send_header(
            WireHeader {
                step,
                sim_time,
                sent_ns: 0,
                taken_ns,
                protocol: PROTOCOL_VERSION,
                reserved: 0,
            },
            values,
        )
    }

    /// Sends a sample another host published, header and all (its `sent_ns` kept: the bridge
    /// between hosts is not a publisher of its own, and the hop it adds shows in the receiver's
    /// latency instead).
    pub fn forward(&self, header: &WireHeader, values: &[f64]) -> Result<(), LockstepError> {
        self.publish(values, || *header)
    }

    /// Sends `values` behind `header` as given (its `sent_ns` set to now), without checking
    /// either against the protocol: for a component that fills its headers itself — or a test
    /// that breaks the protocol on purpose. Returns the send time.
    pub fn send_header(
        &self,
        mut header: WireHeader,
        values: &[f64],
    ) -> Result<u64, LockstepError> {
        let mut sent_ns = 0;
        self.publish(values, || {
            sent_ns = now_ns();
            header.sent_ns = sent_ns;
            header
        })?;
        Ok(sent_ns)
    }

    /// Loans a sample, writes the header `header()` gives once the loan is had (a send time is
    /// taken as late as it can be) and the values, sends it, and notifies when the wait needs it.
    fn publish(
        &self,
        values: &[f64],
        header: impl FnOnce() -> WireHeader,
    ) -> Result<(), LockstepError> {
        let mut sample = self
            .publisher
            .loan_slice_uninit(values.len())
            .map_err(LockstepError::ipc)?;
        *sample.user_header_mut() = header();
        let sample = sample.write_from_slice(values);
        sample.send().map_err(LockstepError::ipc)?;
        if let Some(notifier) = &self.notifier {
            notifier.notify().map_err(LockstepError::ipc)?;
        }
        Ok(())
    }
}

/// A WaitSet watching an inlet's listener.
struct WaitSetWait {
    ws: &'static WaitSet<Ipc>,
    listener: &'static Listener<Ipc>,
    _guard: WaitSetGuard<'static, 'static, Ipc>,
}

/// Waits for the sample of a given step.
pub struct Inlet {
    subscriber: Subscriber<Ipc, [f64], WireHeader>,
    listener: Option<Listener<Ipc>>,
    waitset: Option<WaitSetWait>,
    topic: String,
    wait: Wait,
    timeout: Duration,
    /// Samples taken in a row without waiting (sleep-polling inlets).
    streak: std::cell::Cell<u32>,
}

/// A sleep-polling inlet working through a batch yields its core every this many samples: the
/// lockstep ring's processes spinning on that core then wait for one slice of the batch
/// (tens of µs), not for all of it (~1 ms for the 5 ms batches of a follower).
const BATCH_YIELD: u32 = 8;

impl Inlet {
    /// Waits by sleep-polling instead of the bus's strategy (for processes off the critical
    /// path). Their outlets still notify as the run's strategy requires.
    pub fn sleep_between_polls(&mut self, us: u32) {
        self.wait = Wait::Sleep(us);
    }

    /// How long a wait for a sample may last (10 s by default).
    pub fn set_timeout(&mut self, t: Duration) {
        self.timeout = t;
    }

    /// Takes a pending sample, if any, checking its step and copying its values into `out`.
    pub fn try_step(&self, step: u64, out: &mut [f64]) -> Result<Option<Header>, LockstepError> {
        let Some(sample) = self.subscriber.receive().map_err(LockstepError::ipc)? else {
            return Ok(None);
        };
        let received_ns = now_ns();
        let h = sample.user_header();
        let values = sample.payload();
        if h.protocol != PROTOCOL_VERSION {
            return Err(LockstepError::Protocol {
                topic: self.topic.clone(),
                got: h.protocol,
            });
        }
        if h.step != step {
            return Err(LockstepError::Step {
                topic: self.topic.clone(),
                expected: step,
                got: h.step,
            });
        }
        if values.len() != out.len() {
            return Err(LockstepError::Length {
                topic: self.topic.clone(),
                expected: out.len(),
                got: values.len(),
            });
        }
        out.copy_from_slice(values);
        Ok(Some(Header::of(h, received_ns)))
    }

    /// Waits for the sample of `step`, copying its values into `out`.
    pub fn wait_step(&self, step: u64, out: &mut [f64]) -> Result<Header, LockstepError> {
        let start = now_ns();
        let limit = self.timeout.as_nanos() as u64;
        let mut polls: u32 = 0;
        loop {
            if let Some(h) = self.try_step(step, out)? {
                if matches!(self.wait, Wait::Sleep(_)) && polls == 0 {
                    let n = self.streak.get().wrapping_add(1);
                    self.streak.set(n);
                    if n.is_multiple_of(BATCH_YIELD) {
                        std::thread::yield_now();
                    }
                }
                return Ok(h);
            }
            polls = polls.wrapping_add(1);
            match self.wait {
                Wait::Yield => {
                    std::thread::yield_now();
                    if polls.is_multiple_of(1024) && now_ns() - start > limit {
                        return Err(self.timed_out(step));
                    }
                }
                Wait::Block => self.block(start, limit, step)?,
                Wait::WaitSet => {
                    let elapsed = now_ns() - start;
                    if elapsed > limit {
                        return Err(self.timed_out(step));
                    }
                    let w = self.waitset.as_ref().expect("waitset waits have a waitset");
                    let slice = Duration::from_nanos((limit - elapsed).min(100_000_000));
                    w.ws.wait_and_process_once_with_timeout(
                        |_| {
                            let _ = w.listener.try_wait(|_| {});
                            CallbackProgression::Continue
                        },
                        slice,
                    )
                    .map_err(LockstepError::ipc)?;
                }
                Wait::SpinThenYield(ns) => {
                    if now_ns() - start < ns as u64 {
                        for _ in 0..32 {
                            std::hint::spin_loop();
                        }
                    } else {
                        std::thread::yield_now();
                        if polls.is_multiple_of(1024) && now_ns() - start > limit {
                            return Err(self.timed_out(step));
                        }
                    }
                }
                Wait::Sleep(us) => {
                    std::thread::sleep(Duration::from_micros(us as u64));
                    if now_ns() - start > limit {
                        return Err(self.timed_out(step));
                    }
                }
                Wait::SpinThenBlock(us) => {
                    let elapsed = now_ns() - start;
                    if elapsed < us as u64 * 1000 {
                        std::thread::yield_now();
                    } else {
                        self.block(start, limit, step)?;
                    }
                }
            }
        }
    }

    fn block(&self, start: u64, limit: u64, step: u64) -> Result<(), LockstepError> {
        let elapsed = now_ns() - start;
        if elapsed > limit {
            return Err(self.timed_out(step));
        }
        let listener = self
            .listener
            .as_ref()
            .expect("blocking waits have a listener");
        let slice = Duration::from_nanos((limit - elapsed).min(100_000_000));
        listener
            .timed_wait(|_| {}, slice)
            .map_err(LockstepError::ipc)?;
        Ok(())
    }

    fn timed_out(&self, step: u64) -> LockstepError {
        LockstepError::Timeout {
            topic: self.topic.clone(),
            step,
            secs: self.timeout.as_secs(),
        }
    }
}

/// Drains a service without blocking (the recorder).
pub struct Reader {
    subscriber: Subscriber<Ipc, [f64], WireHeader>,
}

impl Reader {
    /// Calls `f` with the header and values of every pending sample, in order; returns how
    /// many there were. The header is as sent: checking it is the caller's (the launcher names
    /// the component that broke the protocol).
    pub fn drain(&self, f: impl FnMut(&WireHeader, &[f64])) -> Result<usize, LockstepError> {
        self.drain_up_to(usize::MAX, f)
    }

    /// As [`Reader::drain`], but at most `max` samples.
    pub fn drain_up_to(
        &self,
        max: usize,
        mut f: impl FnMut(&WireHeader, &[f64]),
    ) -> Result<usize, LockstepError> {
        let mut count = 0;
        while count < max
            && let Some(sample) = self.subscriber.receive().map_err(LockstepError::ipc)?
        {
            f(sample.user_header(), sample.payload());
            count += 1;
        }
        Ok(count)
    }
}
