//! A sealed heartbeat between a proxy and its worker. Liveliness tokens say when a peer's
//! session goes, but a token is not sealed: another credential holder may declare the same
//! one and keep it standing after the real peer is gone. Beats are sealed with the run's
//! secret ([`crate::seal`]), so only the run's other side can keep a run alive.
//!
//! Beats are sent by a thread of their own and taken by a Zenoh callback, so a side's busy or
//! starved polling loop neither delays its beats nor misses the other side's: the loop only
//! compares a time.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use zenoh::pubsub::Subscriber;
use zenoh::{Session, Wait};

use crate::keys;
use crate::seal::Secret;
use crate::sealed::SealedPublisher;

/// How often each side beats.
const PERIOD: Duration = Duration::from_millis(250);

/// Silence after which the other side is gone. A lost link is noticed first (the lease, the
/// liveliness tokens, the proxy's watchdog: about 1 s); beats are the backstop against a token
/// that another peer holds up, so their bound is generous: two runs at once on two cores
/// stopped as "lost its agent" with a 1 s and with a 1.5 s bound.
const LOST_NS: u64 = 5_000_000_000;

/// One side's beats out and the other side's in.
pub struct Beat {
    /// When the other side's last authentic beat arrived (CLOCK_MONOTONIC ns); 0 before arming.
    heard: Arc<AtomicU64>,
    armed: Arc<AtomicBool>,
    stop: Arc<AtomicBool>,
    _sub: Subscriber<()>,
}

impl Beat {
    /// Beats as `me` (`proxy` or `worker`) and listens to `other`, for component `name` of `run`.
    pub fn new(
        z: &Session,
        secret: &Secret,
        run: &str,
        name: &str,
        me: &str,
        other: &str,
    ) -> Result<Self, String> {
        let mut tx = SealedPublisher::new(z, secret, keys::beat(run, name, me))?;
        let (heard, armed, stop) = (
            Arc::new(AtomicU64::new(0)),
            Arc::new(AtomicBool::new(false)),
            Arc::new(AtomicBool::new(false)),
        );
        let key = keys::beat(run, name, other);
        let opener = Mutex::new(secret.opener(&key));
        let (h, a) = (heard.clone(), armed.clone());
        let sub = z
            .declare_subscriber(key.clone())
            .callback(move |s| {
                let mut bytes = s.payload().to_bytes().to_vec();
                let authentic = opener
                    .lock()
                    .is_ok_and(|mut o| o.open(&mut bytes).is_some());
                if authentic && a.load(Ordering::Relaxed) {
                    h.store(lockstep::now_ns(), Ordering::Relaxed);
                }
            })
            .wait()
            .map_err(|e| format!("zenoh subscriber {key}: {e}"))?;
        let s = stop.clone();
        // Detached: it ends at its next beat after `stop`, or with the process.
        std::thread::spawn(move || {
            while !s.load(Ordering::Relaxed) {
                if tx.put(b"beat").is_err() {
                    break;
                }
                std::thread::sleep(PERIOD);
            }
        });
        Ok(Beat {
            heard,
            armed,
            stop,
            _sub: sub,
        })
    }

    /// From now on, silence counts (once both sides are running).
    pub fn arm(&mut self) {
        self.heard.store(lockstep::now_ns(), Ordering::Relaxed);
        self.armed.store(true, Ordering::Relaxed);
    }

    /// False once an armed beat has heard nothing for [`LOST_NS`].
    pub fn alive(&self) -> bool {
        self.pulse().alive()
    }

    /// What another thread needs to tell whether the other side is alive.
    pub fn pulse(&self) -> Pulse {
        Pulse {
            heard: self.heard.clone(),
            armed: self.armed.clone(),
        }
    }
}

/// A [`Beat`]'s verdict, for another thread (a watchdog that must not wait for a blocked loop).
#[derive(Clone)]
pub struct Pulse {
    heard: Arc<AtomicU64>,
    armed: Arc<AtomicBool>,
}

impl Pulse {
    /// False once the armed beat has heard nothing for [`LOST_NS`].
    pub fn alive(&self) -> bool {
        let heard = self.heard.load(Ordering::Relaxed);
        !self.armed.load(Ordering::Relaxed) || lockstep::now_ns().saturating_sub(heard) < LOST_NS
    }
}

impl Drop for Beat {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}
