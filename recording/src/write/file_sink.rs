//! An `.rrd` file sink that writes Rerun's format uncompressed (or, asked, LZ4-compressed).
//!
//! Rerun's own `FileSink` always LZ4-compresses, which on this project's numeric series gains
//! little (about 1.7×) and costs a whole core at the rates a lockstep run produces samples. This
//! sink encodes with the same `Encoder` (stream header, messages, footer with the chunk
//! manifest), only without compression; Rerun reads both. It encodes on the thread that calls
//! `send` — Rerun's batcher thread — never on the launcher's recording loop.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use re_log_encoding::{Encoder, EncodingOptions};
use rerun::external::re_log_types::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};

type FileEncoder = Encoder<BufWriter<File>>;

/// Uncompressed `.rrd` writer; the footer is written when it is dropped.
pub struct UncompressedFileSink {
    encoder: Mutex<Option<FileEncoder>>,
    /// The first write error, shared with whoever must stop writing when the disk is full.
    error: Arc<Mutex<Option<String>>>,
}

impl UncompressedFileSink {
    /// Creates the file — a new regular file ([`outputs::create_new`]: nothing planted at its
    /// name is followed or truncated) — and writes the stream header.
    pub fn create(path: &Path) -> Result<Self, String> {
        Self::create_with(path, false)
    }

    /// The same, its chunks LZ4-compressed as Rerun's own sink writes them when `lz4`.
    pub fn create_with(path: &Path, lz4: bool) -> Result<Self, String> {
        let file = outputs::create_new(path)
            .map_err(|e| format!("{}: cannot create: {e}", path.display()))?;
        let options = if lz4 {
            EncodingOptions::PROTOBUF_COMPRESSED
        } else {
            EncodingOptions::PROTOBUF_UNCOMPRESSED
        };
        let encoder = Encoder::new_eager(
            re_build_info::CrateVersion::LOCAL,
            options,
            BufWriter::with_capacity(1 << 20, file),
        )
        .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(Self {
            encoder: Mutex::new(Some(encoder)),
            error: Arc::new(Mutex::new(None)),
        })
    }

    /// Where the first write error is kept: Rerun calls `send` on its own thread and cannot
    /// return the error, so the recorder polls this instead.
    pub fn error_slot(&self) -> Arc<Mutex<Option<String>>> {
        self.error.clone()
    }

    fn fail(&self, e: impl std::fmt::Display) {
        if let Ok(mut slot) = self.error.lock() {
            slot.get_or_insert_with(|| e.to_string());
        }
    }
}

impl LogSink for UncompressedFileSink {
    fn send(&self, msg: LogMsg) {
        let mut guard = self.encoder.lock().expect("encoder lock");
        if let Some(enc) = guard.as_mut()
            && let Err(e) = enc.append(&msg)
        {
            self.fail(e);
        }
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        let mut guard = self.encoder.lock().expect("encoder lock");
        if let Some(enc) = guard.as_mut() {
            enc.flush_blocking()
                .map_err(|e| SinkFlushError::failed(e.to_string()))?;
        }
        match self.error.lock().ok().and_then(|e| e.clone()) {
            Some(e) => Err(SinkFlushError::failed(e)),
            None => Ok(()),
        }
    }
}

impl Drop for UncompressedFileSink {
    fn drop(&mut self) {
        if let Ok(mut guard) = self.encoder.lock()
            && let Some(mut enc) = guard.take()
        {
            // The footer: a failure here (a full disk) is kept for the recorder to report.
            if let Err(e) = enc.finish() {
                self.fail(e);
            } else if let Err(e) = enc.flush_blocking() {
                self.fail(e);
            }
        }
    }
}
