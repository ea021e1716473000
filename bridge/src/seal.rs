//! Every message of a run that crosses hosts is sealed with the run's own secret, so that a
//! peer holding the agent's or a launcher's credential but not this run's secret can neither
//! read a run's samples, nor forge or replay a sample, a status, a `go` or a clock probe.
//!
//! The proxy draws a fresh 256-bit secret for its component; it reaches the agent inside the
//! start request (over the mutually authenticated TLS link) and the worker on its stdin. Each
//! key expression has exactly one sender, so each gets its own key, K = HKDF-SHA256(secret,
//! info = key expression), and its messages are numbered 1, 2, …: the nonce is the number,
//! unique per key. A sealed message is `[n: u64 LE][ChaCha20-Poly1305(K, n, plaintext)]`; the
//! receiver accepts only numbers above the last it accepted (Zenoh delivers one publisher's
//! messages in order), so a replayed or reordered message is refused like a forged one.

use ring::aead::{Aad, CHACHA20_POLY1305, LessSafeKey, NONCE_LEN, Nonce, UnboundKey};
use ring::hkdf::{HKDF_SHA256, Salt};
use ring::rand::{SecureRandom, SystemRandom};

/// Bytes of a run secret.
pub const SECRET_BYTES: usize = 32;

/// Bytes a sealed message adds: the number and the tag.
pub const OVERHEAD: usize = 8 + 16;

/// A run's secret, drawn by the proxy.
#[derive(Clone)]
pub struct Secret([u8; SECRET_BYTES]);

impl Secret {
    /// A fresh secret from the system's random source.
    pub fn draw() -> Result<Self, String> {
        let mut s = [0u8; SECRET_BYTES];
        SystemRandom::new()
            .fill(&mut s)
            .map_err(|_| "the system's random source failed".to_string())?;
        Ok(Secret(s))
    }

    /// The secret as hex, for the start request.
    pub fn to_hex(&self) -> String {
        self.0.iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The secret from [`Secret::to_hex`].
    pub fn from_hex(hex: &str) -> Result<Self, String> {
        if hex.len() != 2 * SECRET_BYTES || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(format!("a run secret is {} hex digits", 2 * SECRET_BYTES));
        }
        let mut s = [0u8; SECRET_BYTES];
        for (i, b) in s.iter_mut().enumerate() {
            *b = u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).expect("hex digits");
        }
        Ok(Secret(s))
    }

    /// The key of one key expression.
    fn key(&self, key_expr: &str) -> LessSafeKey {
        struct Len;
        impl ring::hkdf::KeyType for Len {
            fn len(&self) -> usize {
                CHACHA20_POLY1305.key_len()
            }
        }
        let mut k = [0u8; 32];
        let info = [key_expr.as_bytes()];
        Salt::new(HKDF_SHA256, b"uio-observers run seal v1")
            .extract(&self.0)
            .expand(&info, Len)
            .and_then(|okm| okm.fill(&mut k))
            .expect("32 bytes is a valid HKDF-SHA256 output");
        LessSafeKey::new(UnboundKey::new(&CHACHA20_POLY1305, &k).expect("a 32-byte key"))
    }

    /// The sealer of the messages this side sends under `key_expr`.
    pub fn sealer(&self, key_expr: &str) -> Sealer {
        Sealer {
            key: self.key(key_expr),
            sent: 0,
        }
    }

    /// The opener of the messages the other side sends under `key_expr`.
    pub fn opener(&self, key_expr: &str) -> Opener {
        Opener {
            key: self.key(key_expr),
            last: 0,
            refused: 0,
        }
    }
}

fn nonce(n: u64) -> Nonce {
    let mut b = [0u8; NONCE_LEN];
    b[NONCE_LEN - 8..].copy_from_slice(&n.to_le_bytes());
    Nonce::assume_unique_for_key(b)
}

/// Seals one key expression's messages, numbering them.
pub struct Sealer {
    key: LessSafeKey,
    sent: u64,
}

impl Sealer {
    /// Seals `plain` into `out` (cleared first).
    pub fn seal_into(&mut self, plain: &[u8], out: &mut Vec<u8>) {
        self.sent += 1;
        out.clear();
        out.extend(self.sent.to_le_bytes());
        out.extend_from_slice(plain);
        let (head, body) = out.split_at_mut(8);
        let tag = self
            .key
            .seal_in_place_separate_tag(nonce(self.sent), Aad::from(&head[..]), body)
            .expect("a message under 256 GiB");
        out.extend_from_slice(tag.as_ref());
    }

    /// Seals `plain` into a new vector.
    #[cfg(test)]
    pub fn seal(&mut self, plain: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(plain.len() + OVERHEAD);
        self.seal_into(plain, &mut out);
        out
    }
}

/// Opens the other side's messages of one key expression; refuses anything else.
pub struct Opener {
    key: LessSafeKey,
    last: u64,
    /// How many messages were refused (forged, replayed, or from another run).
    pub refused: u64,
}

impl Opener {
    /// The plaintext of `sealed`, or `None` (counted in `refused`) when it is not the next
    /// authentic message.
    pub fn open<'a>(&mut self, sealed: &'a mut [u8]) -> Option<&'a [u8]> {
        let ok = sealed.len() >= OVERHEAD && {
            let n = u64::from_le_bytes(sealed[..8].try_into().expect("8 bytes"));
            let (head, body) = sealed.split_at_mut(8);
            n > self.last
                && self
                    .key
                    .open_in_place(nonce(n), Aad::from(&head[..]), body)
                    .is_ok()
                && {
                    self.last = n;
                    true
                }
        };
        if ok {
            let len = sealed.len() - 16;
            Some(&sealed[8..len])
        } else {
            self.refused += 1;
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_next_authentic_message_opens() {
        let s = Secret::draw().unwrap();
        let key = "uio/run/1x0x2/c/plant/out";
        let mut tx = s.sealer(key);
        let mut rx = s.opener(key);
        let mut first = tx.seal(b"sample one");
        let mut replay = first.clone();
        assert_eq!(rx.open(&mut first), Some(&b"sample one"[..]));
        // A replay of an accepted message, a message for another key, another run's secret,
        // a flipped byte and a short message are all refused.
        assert_eq!(rx.open(&mut replay), None);
        let mut other_key = s
            .sealer("uio/run/1x0x2/c/plant/status")
            .seal(b"exit 4 0 forged");
        assert_eq!(rx.open(&mut other_key), None);
        let mut other_run = Secret::draw().unwrap().sealer(key).seal(b"forged");
        assert_eq!(rx.open(&mut other_run), None);
        let mut flipped = tx.seal(b"sample two");
        flipped[12] ^= 1;
        assert_eq!(rx.open(&mut flipped), None);
        assert_eq!(rx.open(&mut [0u8; 10]), None);
        assert_eq!(rx.refused, 5);
        // The sender's next message still opens: refusals leave the stream intact.
        let mut third = tx.seal(b"sample three");
        assert_eq!(rx.open(&mut third), Some(&b"sample three"[..]));
        assert_eq!(Secret::from_hex(&s.to_hex()).unwrap().0, s.0);
        assert!(Secret::from_hex("**").is_err());
    }
}
