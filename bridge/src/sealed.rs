//! A run's Zenoh publishers and subscribers, sealing what they send and opening what they
//! receive with the run's secret ([`crate::seal`]). A message that does not open is dropped
//! and counted — it comes from a peer that is not this run's other side — so it never changes
//! what the run does; the first and then every 1000th is reported on stderr.

use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::{CongestionControl, Priority};
use zenoh::sample::Sample;
use zenoh::{Session, Wait};

use crate::seal::{Opener, Sealer, Secret};

/// A publisher that never drops (the lockstep's no-loss rule, across the link): Zenoh's
/// default reliable delivery, and blocking congestion control instead of dropping.
pub struct SealedPublisher {
    publisher: Publisher<'static>,
    sealer: Sealer,
    buf: Vec<u8>,
}

impl SealedPublisher {
    /// Declares the publisher of `key` for the run of `secret`.
    pub fn new(z: &Session, secret: &Secret, key: String) -> Result<Self, String> {
        let publisher = z
            .declare_publisher(key.clone())
            .congestion_control(CongestionControl::Block)
            .priority(Priority::RealTime)
            .express(true)
            .wait()
            .map_err(|e| format!("zenoh publisher {key}: {e}"))?;
        Ok(SealedPublisher {
            sealer: secret.sealer(&key),
            publisher,
            buf: Vec::new(),
        })
    }

    /// Seals and sends `plain`.
    pub fn put(&mut self, plain: &[u8]) -> Result<(), String> {
        self.sealer.seal_into(plain, &mut self.buf);
        self.publisher
            .put(self.buf.as_slice())
            .wait()
            .map_err(|e| format!("sending to the other host: {e}"))
    }
}

/// A subscriber that yields only the run's other side's messages, in order.
pub struct SealedSubscriber {
    sub: Subscriber<FifoChannelHandler<Sample>>,
    opener: Opener,
    key: String,
    buf: Vec<u8>,
}

impl SealedSubscriber {
    /// Declares the subscriber of `key` for the run of `secret`.
    pub fn new(z: &Session, secret: &Secret, key: String) -> Result<Self, String> {
        let sub = z
            .declare_subscriber(key.clone())
            .wait()
            .map_err(|e| format!("zenoh subscriber {key}: {e}"))?;
        Ok(SealedSubscriber {
            sub,
            opener: secret.opener(&key),
            key,
            buf: Vec::new(),
        })
    }

    /// The next authentic message that has arrived, if any (without blocking).
    pub fn try_recv(&mut self) -> Option<&[u8]> {
        loop {
            let sample = self.sub.try_recv().ok()??;
            self.buf.clear();
            self.buf.extend(sample.payload().to_bytes().iter());
            let refused = self.opener.refused;
            // Two steps so the borrow of `buf` ends before it is returned.
            if self.opener.open(&mut self.buf).is_some() {
                let len = self.buf.len() - 16;
                return Some(&self.buf[8..len]);
            }
            if refused.is_multiple_of(1000) {
                say!(
                    "ignored a message on {} that is not from this run's other side ({} so far)",
                    self.key,
                    refused + 1
                );
            }
        }
    }

    /// [`SealedSubscriber::try_recv`] as text.
    pub fn try_recv_text(&mut self) -> Option<String> {
        self.try_recv()
            .map(|b| String::from_utf8_lossy(b).into_owned())
    }

    /// Waits up to `timeout` for the next authentic message.
    pub fn recv_timeout(&mut self, timeout: std::time::Duration) -> Option<&[u8]> {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            if self.try_recv().is_some() {
                let len = self.buf.len() - 16;
                return Some(&self.buf[8..len]);
            }
            if std::time::Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
    }
}
