//! A sealed heartbeat between a proxy and its worker. Liveliness tokens say when a peer's
//! session goes, but a token is not sealed: another credential holder may declare the same
//! one and keep it standing after the real peer is gone. Beats are sealed with the run's
//! secret ([`crate::seal`]), so only the run's other side can keep a run alive.

use std::time::{Duration, Instant};

use zenoh::Session;

use crate::keys;
use crate::seal::Secret;
use crate::sealed::{SealedPublisher, SealedSubscriber};

/// How often each side beats.
const PERIOD: Duration = Duration::from_millis(250);

/// Silence after which the other side is gone. The link's lease (1 s) and the liveliness
/// tokens notice a lost peer first; beats only stop a token held up by someone else from
/// keeping a run's side alive, so they may wait out a loop starved of CPU for a while (two
/// runs at once on two cores once went 1 s without a beat).
const LOST: Duration = Duration::from_secs(3);

/// One side's beats out and the other side's in.
pub struct Beat {
    tx: SealedPublisher,
    rx: SealedSubscriber,
    sent: Instant,
    heard: Option<Instant>,
}

impl Beat {
    /// Beats as `me` (`proxy` or `worker`) and listens to `other`, for component `name` of `run`.
    pub fn new(z: &Session, secret: &Secret, run: &str, name: &str, me: &str, other: &str) -> Result<Self, String> {
        let tx = SealedPublisher::new(z, secret, keys::beat(run, name, me))?;
        let rx = SealedSubscriber::new(z, secret, keys::beat(run, name, other))?;
        Ok(Beat { tx, rx, sent: Instant::now() - PERIOD, heard: None })
    }

    /// From now on, silence counts (once both sides are running).
    pub fn arm(&mut self) {
        self.heard = Some(Instant::now());
    }

    /// Beats when due and takes the other side's beats; false once an armed beat has heard
    /// nothing for [`LOST`].
    pub fn alive(&mut self) -> Result<bool, String> {
        if self.sent.elapsed() >= PERIOD {
            self.tx.put(b"beat")?;
            self.sent = Instant::now();
        }
        while self.rx.try_recv().is_some() {
            if self.heard.is_some() {
                self.heard = Some(Instant::now());
            }
        }
        Ok(self.heard.is_none_or(|h| h.elapsed() < LOST))
    }
}
