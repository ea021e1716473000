//! A sample between hosts: the 40-byte header laid out as in shared memory (PROTOCOL.md §4,
//! little-endian), then the values as little-endian f64 — the same bytes, so the far side
//! publishes exactly what was sent, bit for bit.

use lockstep::WireHeader;

/// Bytes of the header.
pub const HEADER_BYTES: usize = 40;

/// Appends the sample's bytes to `out` (cleared first).
pub fn encode(h: &WireHeader, values: &[f64], out: &mut Vec<u8>) {
    out.clear();
    out.extend(h.step.to_le_bytes());
    out.extend(h.sim_time.to_le_bytes());
    out.extend(h.sent_ns.to_le_bytes());
    out.extend(h.taken_ns.to_le_bytes());
    out.extend(h.protocol.to_le_bytes());
    out.extend(h.reserved.to_le_bytes());
    for v in values {
        out.extend(v.to_le_bytes());
    }
}

/// The header, and the values into `values` (resized).
pub fn decode(bytes: &[u8], values: &mut Vec<f64>) -> Result<WireHeader, String> {
    if bytes.len() < HEADER_BYTES || !(bytes.len() - HEADER_BYTES).is_multiple_of(8) {
        return Err(format!(
            "a sample of {} bytes is not a 40-byte header and whole f64 values",
            bytes.len()
        ));
    }
    let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let h = WireHeader {
        step: u64_at(0),
        sim_time: f64::from_bits(u64_at(8)),
        sent_ns: u64_at(16),
        taken_ns: u64_at(24),
        protocol: u32_at(32),
        reserved: u32_at(36),
    };
    values.clear();
    values.extend(
        bytes[HEADER_BYTES..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))),
    );
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_comes_back_bit_for_bit() {
        let h = WireHeader {
            step: 7,
            sim_time: 0.007,
            sent_ns: 123,
            taken_ns: 99,
            protocol: 1,
            reserved: 0,
        };
        let values = [1.0, -0.0, f64::MIN_POSITIVE, 1e300, std::f64::consts::PI];
        let mut bytes = Vec::new();
        encode(&h, &values, &mut bytes);
        assert_eq!(bytes.len(), HEADER_BYTES + 8 * values.len());
        let mut back = Vec::new();
        assert_eq!(decode(&bytes, &mut back).unwrap(), h);
        assert_eq!(
            back.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            values.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert!(decode(&bytes[..41], &mut back).is_err());
    }
}
