//! Checks of an ArrowMsg's lengths before Rerun decodes it. Rerun allocates what the message
//! says: its uncompressed size (for LZ4) and, inside the Arrow IPC stream, each message's
//! metadata length (i32) and body length (i64, `MutableBuffer::from_len_zeroed`). A damaged
//! length there is an abort, not an error; here each is checked against the bytes present.

use std::borrow::Cow;

use re_log_encoding::external::lz4_flex;
use re_protos::common::v1alpha1::Compression;
use re_protos::log_msg::v1alpha1::{ArrowMsg, Encoding};
use rerun::external::arrow::ipc::root_as_message;

/// LZ4's block format expands at most about 255-fold (a byte of match length for 255 bytes).
const LZ4_MAX_RATIO: u64 = 255;

/// The largest message decompressed, bytes: our writer never compresses, and Rerun's own
/// chunks are far smaller, so a larger claim is damage (255× a large file would be an abort).
const LZ4_MAX_BYTES: u64 = 256 << 20;

/// Why the message's lengths cannot be trusted, or Ok.
pub fn check(msg: &ArrowMsg) -> Result<(), String> {
    if msg.encoding() != Encoding::ArrowIpc {
        return Err("its data is not Arrow IPC".into());
    }
    let data: Cow<[u8]> = match msg.compression() {
        Compression::None | Compression::Unspecified => Cow::Borrowed(&msg.payload[..]),
        Compression::Lz4 => {
            let size = msg.uncompressed_size;
            if size > (msg.payload.len() as u64).saturating_mul(LZ4_MAX_RATIO) + 64
                || size > LZ4_MAX_BYTES
            {
                return Err(format!(
                    "it claims {size} bytes once uncompressed from {}, more than LZ4 can give",
                    msg.payload.len()
                ));
            }
            Cow::Owned(
                lz4_flex::block::decompress(&msg.payload, size as usize)
                    .map_err(|e| format!("its LZ4 data is damaged ({e})"))?,
            )
        }
    };
    ipc_lengths(&data)
}

/// Walks an Arrow IPC stream the way arrow's `MessageReader` does (an optional continuation
/// marker, an i32 metadata length, the flatbuffer `Message`, its body), checking each length.
fn ipc_lengths(data: &[u8]) -> Result<(), String> {
    let mut pos = 0usize;
    let word = |at: usize| {
        data.get(at..at + 4)
            .map(|w| <[u8; 4]>::try_from(w).expect("4 bytes"))
    };
    while let Some(mut w) = word(pos) {
        pos += 4;
        if w == [0xff; 4] {
            w = word(pos).ok_or("its Arrow data ends after a continuation marker")?;
            pos += 4;
        }
        let meta = i32::from_le_bytes(w);
        if meta == 0 {
            return Ok(());
        }
        let remaining = data.len() - pos;
        let meta = usize::try_from(meta)
            .ok()
            .filter(|&m| m <= remaining)
            .ok_or_else(|| {
                format!("an Arrow message claims {meta} bytes of metadata, with {remaining} left")
            })?;
        let message = root_as_message(&data[pos..pos + meta])
            .map_err(|e| format!("an Arrow message's metadata is damaged ({e})"))?;
        pos += meta;
        let remaining = data.len() - pos;
        let body = message.bodyLength();
        let body = usize::try_from(body)
            .ok()
            .filter(|&b| b <= remaining)
            .ok_or_else(|| {
                format!("an Arrow message claims a body of {body} bytes, with {remaining} left")
            })?;
        pos += body;
    }
    Ok(())
}
