//! The RRD stream's framing, read with every length checked against the bytes the file still
//! holds before anything is allocated for it. Rerun's decoder (re_log_encoding 0.36.3) trusts
//! them: one damaged byte in a message header or in the stream footer makes it allocate what the
//! length claims (102 GB for the footer's entry count: an abort) or index past its buffer (a
//! panic). So this module does the framing and hands Rerun only whole, bounded payloads.
//!
//! The layout (re_log_encoding's `rrd/frames.rs`): a 12-byte stream header (`RRF2`, 4 version
//! bytes, compression 0|1, serializer 2, 0, 0); messages, each a 16-byte header (kind: u64 LE,
//! 0 = End, 1 = SetStoreInfo, 2 = ArrowMsg, 3 = BlueprintActivationCommand; payload length: u64
//! LE) and its payload; the End message, whose payload is the RRD footer (the chunk manifest);
//! then the 32-byte stream footer: that payload's offset (u64) and length (u64), its xxh32
//! (u32), `RRF2`, `FOOT` and the entry count (u32, always 1). Streams may follow each other.

use std::io::Read;

use re_log_encoding::{CrateVersion, Decodable as _, MessageKind, StreamFooter, StreamHeader};

/// One message of the stream, whole.
pub struct Message {
    /// What it holds.
    pub kind: MessageKind,
    /// Where its header starts in the file.
    pub at: u64,
    /// Its payload.
    pub payload: Vec<u8>,
}

/// Why the framing stops before the end of the file.
#[derive(Debug, PartialEq, Eq)]
pub enum Fault {
    /// The first bytes are not a Rerun stream header.
    NotRrd(String),
    /// The file ends inside a frame: what a writer that was killed leaves.
    Cut(String),
    /// A frame no writer writes: a length, kind, header or footer that is wrong.
    Bad(String),
}

/// Reads the frames of a file of `len` bytes.
pub struct Frames<R> {
    reader: R,
    len: u64,
    pos: u64,
    /// The version in the current stream's header (None before the first).
    version: Option<CrateVersion>,
    /// Whether the current stream's header has been read.
    in_stream: bool,
    /// Whether an End message and a valid stream footer closed the last stream.
    footer_ok: bool,
    /// Whether an End message carrying an RRD footer was read: only a finishing writer writes one.
    closing: bool,
}

impl<R: Read> Frames<R> {
    /// Frames of `reader`, which holds `len` bytes.
    pub fn new(reader: R, len: u64) -> Self {
        Frames {
            reader,
            len,
            pos: 0,
            version: None,
            in_stream: false,
            footer_ok: false,
            closing: false,
        }
    }

    /// The Rerun version that wrote the current stream.
    pub fn version(&self) -> Option<CrateVersion> {
        self.version
    }

    /// Whether the file ended right after a valid stream footer.
    pub fn footer_ok(&self) -> bool {
        self.footer_ok && self.pos == self.len
    }

    /// Whether an End message carrying an RRD footer was read: the writer was finishing the file
    /// (a zero-filled tail reads as an empty End message, so that one does not count).
    pub fn closing(&self) -> bool {
        self.closing
    }

    /// The next data message; None at the end of the file after whole frames.
    pub fn next_message(&mut self) -> Result<Option<Message>, Fault> {
        loop {
            if self.pos == self.len {
                return Ok(None);
            }
            if !self.in_stream {
                self.stream_header()?;
                continue;
            }
            let at = self.pos;
            let header = self.exactly(16, "a message header")?;
            let kind = u64::from_le_bytes(header[..8].try_into().expect("8 bytes"));
            let size = u64::from_le_bytes(header[8..].try_into().expect("8 bytes"));
            let kind = match kind {
                0 => MessageKind::End,
                1 => MessageKind::SetStoreInfo,
                2 => MessageKind::ArrowMsg,
                3 => MessageKind::BlueprintActivationCommand,
                k => {
                    return Err(Fault::Bad(format!(
                        "the message header at byte {at} has kind {k}, which is none of Rerun's"
                    )));
                }
            };
            let remaining = self.len - self.pos;
            if size > remaining {
                return Err(Fault::Cut(format!(
                    "the message at byte {at} claims {size} bytes, but the file holds {remaining} more"
                )));
            }
            let payload = self.exactly(size, "a message")?;
            if kind == MessageKind::End {
                self.closing |= !payload.is_empty();
                self.stream_footer(at + 16, &payload)?;
                continue;
            }
            return Ok(Some(Message { kind, at, payload }));
        }
    }

    /// Reads and checks a stream header.
    fn stream_header(&mut self) -> Result<(), Fault> {
        let at = self.pos;
        let bytes = self.exactly(StreamHeader::ENCODED_SIZE_BYTES as u64, "the stream header")?;
        let parsed = StreamHeader::from_rrd_bytes(&bytes).and_then(|h| h.to_version_and_options());
        match parsed {
            Ok((version, _)) => {
                self.version = Some(version);
                self.in_stream = true;
                self.footer_ok = false;
                Ok(())
            }
            Err(e) if at == 0 => Err(Fault::NotRrd(e.to_string())),
            Err(e) => Err(Fault::Bad(format!(
                "the bytes after the stream footer at byte {at} are no stream header ({e})"
            ))),
        }
    }

    /// Reads the stream footer that must follow an End message whose payload (the RRD footer)
    /// starts at `payload_at`, and checks that it points at that payload and carries its xxh32.
    fn stream_footer(&mut self, payload_at: u64, payload: &[u8]) -> Result<(), Fault> {
        let at = self.pos;
        if at == self.len && payload.is_empty() {
            // A stream closed by an empty End message and no footer (older writers).
            self.in_stream = false;
            self.footer_ok = true;
            return Ok(());
        }
        let f = self.exactly(StreamFooter::ENCODED_SIZE_BYTES as u64, "the stream footer")?;
        let u64_at = |i: usize| u64::from_le_bytes(f[i..i + 8].try_into().expect("8 bytes"));
        let u32_at = |i: usize| u32::from_le_bytes(f[i..i + 4].try_into().expect("4 bytes"));
        let (start, size, crc, count) = (u64_at(0), u64_at(8), u32_at(16), u32_at(28));
        let bad = |what: String| Err(Fault::Bad(format!("its stream footer at byte {at} {what}")));
        if &f[20..28] != b"RRF2FOOT" {
            return bad("lacks its RRF2FOOT marker".into());
        }
        if count != 1 {
            return bad(format!(
                "claims {count} entries where a Rerun writer writes 1"
            ));
        }
        if start != payload_at || size != payload.len() as u64 {
            return bad(format!(
                "points at {size} bytes at byte {start}, not at the footer's {} bytes at byte {payload_at}",
                payload.len()
            ));
        }
        if StreamFooter::compute_crc(payload) != crc {
            return bad(format!(
                "does not match its checksum over the {} bytes of the footer (the chunk manifest)",
                payload.len()
            ));
        }
        self.in_stream = false;
        self.footer_ok = true;
        Ok(())
    }

    /// Reads `n` bytes, which must be within the file: the length is checked first.
    fn exactly(&mut self, n: u64, what: &str) -> Result<Vec<u8>, Fault> {
        let remaining = self.len - self.pos;
        if n > remaining {
            return Err(Fault::Cut(format!(
                "the file ends {remaining} bytes into {what} at byte {}",
                self.pos
            )));
        }
        let mut buf = vec![0; n as usize];
        self.reader
            .read_exact(&mut buf)
            .map_err(|e| Fault::Cut(format!("cannot read {what} at byte {}: {e}", self.pos)))?;
        self.pos += n;
        Ok(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stream of one ArrowMsg-kind message with `payload` and a footer over `footer`.
    fn stream(payload: &[u8], footer: &[u8]) -> Vec<u8> {
        let mut b = b"RRF2".to_vec();
        b.extend(CrateVersion::LOCAL.to_bytes());
        b.extend([0, 2, 0, 0]);
        for (kind, p) in [(2u64, payload), (0, footer)] {
            b.extend(kind.to_le_bytes());
            b.extend((p.len() as u64).to_le_bytes());
            b.extend(p);
        }
        let at = (b.len() - footer.len()) as u64;
        b.extend(at.to_le_bytes());
        b.extend((footer.len() as u64).to_le_bytes());
        b.extend(StreamFooter::compute_crc(footer).to_le_bytes());
        b.extend(b"RRF2FOOT");
        b.extend(1u32.to_le_bytes());
        b
    }

    fn all(bytes: &[u8]) -> (Vec<Vec<u8>>, Option<Fault>, bool) {
        let mut f = Frames::new(bytes, bytes.len() as u64);
        let mut got = Vec::new();
        loop {
            match f.next_message() {
                Ok(Some(m)) => got.push(m.payload),
                Ok(None) => return (got, None, f.footer_ok()),
                Err(e) => return (got, Some(e), f.footer_ok()),
            }
        }
    }

    #[test]
    fn a_whole_stream_reads_to_its_footer() {
        let (got, fault, ok) = all(&stream(b"hello", b"manifest"));
        assert_eq!((got, fault, ok), (vec![b"hello".to_vec()], None, true));
    }

    #[test]
    fn lengths_beyond_the_file_and_damaged_footers_are_refused_without_allocating() {
        let good = stream(b"hello", b"manifest");
        // The message's length claims 2^63 bytes.
        let mut b = good.clone();
        b[12 + 15] = 0x80;
        assert!(matches!(all(&b).1, Some(Fault::Cut(_))));
        // Every byte of the stream footer (the entry count, its marker, span and checksum) and
        // of the footer payload it covers.
        for i in good.len() - 32 - 8..good.len() {
            let mut b = good.clone();
            b[i] ^= 0xff;
            let (_, fault, ok) = all(&b);
            assert!(
                matches!(fault, Some(Fault::Bad(_))) && !ok,
                "byte {i}: {fault:?}"
            );
        }
        // A kind no writer writes.
        let mut b = good.clone();
        b[12] = 9;
        assert!(matches!(all(&b).1, Some(Fault::Bad(_))));
        // Not a stream at all.
        assert!(matches!(
            all(b"hello world, this is text").1,
            Some(Fault::NotRrd(_))
        ));
        // Cut anywhere: a killed writer's file.
        for cut in [5, 20, 30, good.len() - 3] {
            assert!(
                matches!(all(&good[..cut]).1, Some(Fault::Cut(_))),
                "cut at {cut}"
            );
        }
    }
}
