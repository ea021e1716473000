//! The samples that cross a host boundary: [`Exports`] read local services and put them on
//! Zenoh, [`Imports`] take them from Zenoh and publish them on the local services. Zenoh's
//! reliable, blocking-congestion publishers and FIFO subscribers keep every sample, in order,
//! each sealed with the run's secret ([`crate::sealed`]);
//! the lockstep step checks of the receiving components and the launcher stay end to end.

use lockstep::{Bus, Outlet, Reader};
use zenoh::Session;

use crate::clock::shift;
use crate::seal::Secret;
use crate::sealed::{SealedPublisher, SealedSubscriber};
use crate::wire::{decode, encode};

/// Local services read and sent to the other host.
pub struct Exports {
    list: Vec<(Reader, SealedPublisher)>,
    buf: Vec<u8>,
    /// Samples sent so far.
    pub sent: u64,
}

/// Samples of the other host published on local services.
pub struct Imports {
    list: Vec<(SealedSubscriber, Outlet, String)>,
    values: Vec<f64>,
    /// Samples published so far.
    pub received: u64,
    /// Added to the header's times: the sending host's clock onto this one's ([`crate::clock`]).
    pub shift_ns: i64,
}

impl Exports {
    /// Reads each (service, key) on `bus` and sends it, sealed, under its key.
    pub fn new(
        bus: &Bus,
        z: &Session,
        secret: &Secret,
        services: &[(String, String)],
    ) -> Result<Self, String> {
        let mut list = Vec::new();
        for (s, key) in services {
            let reader = bus.reader(s).map_err(|e| format!("{s}: {e}"))?;
            list.push((reader, SealedPublisher::new(z, secret, key.clone())?));
        }
        Ok(Exports {
            list,
            buf: Vec::new(),
            sent: 0,
        })
    }

    /// Sends what has arrived; returns how many samples.
    pub fn pump(&mut self) -> Result<usize, String> {
        let mut n = 0;
        for (reader, publisher) in &mut self.list {
            let mut failed = None;
            n += reader
                .drain_up_to(64, |h, v| {
                    encode(h, v, &mut self.buf);
                    if let Err(e) = publisher.put(&self.buf) {
                        failed = Some(e);
                    }
                })
                .map_err(|e| e.to_string())?;
            if let Some(e) = failed {
                return Err(e);
            }
        }
        self.sent += n as u64;
        Ok(n)
    }
}

impl Imports {
    /// Publishes each (service, values per sample, key) on `bus` from its key's sealed samples.
    pub fn new(
        bus: &Bus,
        z: &Session,
        secret: &Secret,
        services: &[(String, usize, String)],
    ) -> Result<Self, String> {
        let mut list = Vec::new();
        for (s, len, key) in services {
            let outlet = bus.outlet(s, *len).map_err(|e| format!("{s}: {e}"))?;
            list.push((
                SealedSubscriber::new(z, secret, key.clone())?,
                outlet,
                s.clone(),
            ));
        }
        Ok(Imports {
            list,
            values: Vec::new(),
            received: 0,
            shift_ns: 0,
        })
    }

    /// Publishes what has arrived; returns how many samples. A sample of the wrong size from
    /// the run's other side is that side breaking the protocol.
    pub fn pump(&mut self) -> Result<usize, String> {
        let mut n = 0;
        for (sub, outlet, service) in &mut self.list {
            for _ in 0..64 {
                let Some(bytes) = sub.try_recv() else { break };
                let mut h =
                    decode(bytes, &mut self.values).map_err(|e| format!("{service}: {e}"))?;
                h.sent_ns = shift(h.sent_ns, self.shift_ns);
                h.taken_ns = shift(h.taken_ns, self.shift_ns);
                if self.values.len() != outlet.len() {
                    return Err(format!(
                        "{service}: a sample of {} values arrived; the service holds {}",
                        self.values.len(),
                        outlet.len()
                    ));
                }
                outlet
                    .forward(&h, &self.values)
                    .map_err(|e| format!("{service}: {e}"))?;
                n += 1;
            }
        }
        self.received += n as u64;
        Ok(n)
    }
}

/// Polls without holding a core: yields while work is recent, then sleeps briefly.
pub struct Idle(u32);

impl Idle {
    /// A fresh idle counter.
    pub fn new() -> Self {
        Idle(0)
    }

    /// Call after each round with whether it did any work.
    pub fn after(&mut self, worked: bool) {
        if worked {
            self.0 = 0;
            return;
        }
        self.0 = self.0.saturating_add(1);
        if self.0 < 256 {
            std::thread::yield_now();
        } else {
            std::thread::sleep(std::time::Duration::from_micros(50));
        }
    }
}

impl Default for Idle {
    fn default() -> Self {
        Self::new()
    }
}
