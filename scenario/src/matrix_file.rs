//! Matrices kept beside the scenario as NumPy `.npy` files (`A = "model/A.npy"`): a large
//! model's A (8 MB of doubles at n = 1000) does not belong in TOML text, and its authors have it
//! as an array already (`numpy.save`, or scipy.io from a MATLAB `.mat`). Paths are relative to
//! the scenario's folder; the array must be 2-D float64, in either byte or storage order.

use std::path::Path;

use super::raw::{RawScenario, Rows};
use super::untrusted::{open_regular, quoted};
use crate::check::{Bad, bad};

/// Largest matrix file read, bytes (1 GiB: n ≈ 11 000 states).
pub const MAX_MATRIX_FILE_BYTES: u64 = 1 << 30;

/// Replaces every matrix given as a file by its rows; an error names the field.
pub(crate) fn load_all(raw: &mut RawScenario, dir: &Path) -> Result<(), Bad> {
    let p = &mut raw.plant;
    let mut fields: Vec<(String, &mut Rows)> = vec![("plant.C".into(), &mut p.c)];
    for (name, m) in [
        ("plant.A", &mut p.a),
        ("plant.B", &mut p.b),
        ("plant.Phi", &mut p.phi),
        ("plant.Gamma_B", &mut p.gamma_b),
        ("plant.Gamma_E", &mut p.gamma_e),
        ("plant.E", &mut p.e),
        ("plant.D", &mut p.d),
        ("plant.Ff", &mut p.ff),
    ] {
        fields.extend(m.as_mut().map(|m| (name.to_string(), m)));
    }
    if let Some(noise) = raw.noise.as_mut() {
        for (name, m) in [
            ("noise.process", &mut noise.process),
            ("noise.G", &mut noise.g),
            ("noise.process_discrete", &mut noise.process_discrete),
            ("noise.measurement", &mut noise.measurement),
        ] {
            fields.extend(m.as_mut().map(|m| (name.to_string(), m)));
        }
    }
    for (i, o) in raw.observer.iter_mut().enumerate() {
        for (name, m) in [("H", &mut o.h), ("Q", &mut o.q), ("R", &mut o.r)] {
            fields.extend(
                m.as_mut()
                    .map(|m| (format!("observer[{}].{name}", i + 1), m)),
            );
        }
    }
    if let Some(c) = raw.controller.as_mut() {
        for (name, m) in [
            ("controller.gain", &mut c.gain),
            ("controller.track", &mut c.track),
            ("controller.Q", &mut c.q),
            ("controller.R", &mut c.r),
        ] {
            fields.extend(m.as_mut().map(|m| (name.to_string(), m)));
        }
    }
    for (field, m) in fields {
        if let Rows::File(name) = m {
            *m = Rows::Inline(read(dir, name).map_err(|reason| bad(field, reason))?);
        }
    }
    Ok(())
}

/// The rows of a 2-D float64 `.npy` file.
pub fn read(dir: &Path, name: &str) -> Result<Vec<Vec<f64>>, String> {
    let shown = quoted(name);
    if name.is_empty() {
        return Err("an empty path is not a matrix file".into());
    }
    let path = dir.join(name);
    let (file, len) = open_regular(&path).map_err(|e| format!("{shown}: {e}"))?;
    if len > MAX_MATRIX_FILE_BYTES {
        return Err(format!(
            "{shown}: {len} bytes, larger than the 1 GiB a matrix file may hold"
        ));
    }
    let mut file = std::io::BufReader::new(file);
    let data_at =
        data_offset(&mut file, len).map_err(|e| format!("{shown}: not a .npy file ({e})"))?;
    let npy = npyz::NpyFile::new(file).map_err(|e| format!("{shown}: not a .npy file ({e})"))?;
    let descr = npy.dtype().descr();
    let dtype = descr.trim_matches('\'');
    if !matches!(dtype, "<f8" | ">f8") {
        return Err(format!(
            "{shown}: holds {dtype} values; save it as float64 (<f8)"
        ));
    }
    let (rows, cols) = match *npy.shape() {
        [r, c] => (r as usize, c as usize),
        ref s => {
            return Err(format!(
                "{shown}: has shape {s:?}; a matrix is 2-D (save a vector as (k, 1) or (1, k))"
            ));
        }
    };
    if rows == 0 || cols == 0 {
        return Err(format!(
            "{shown}: has shape ({rows}, {cols}); a matrix has at least one row and one column"
        ));
    }
    // The header's shape must be what the file holds (exactly, as numpy.save writes it) before
    // anything is allocated or read for it.
    let values = len - data_at;
    match rows.checked_mul(cols).and_then(|k| k.checked_mul(8)) {
        Some(b) if b as u64 == values => {}
        Some(b) if (b as u64) < values => {
            return Err(format!(
                "{shown}: its header says {rows}×{cols} ({b} bytes of values), but {values} bytes follow the header"
            ));
        }
        _ => {
            return Err(format!(
                "{shown}: its header says {rows}×{cols}, more values than its {len} bytes hold"
            ));
        }
    }
    let order = npy.order();
    let data: Vec<f64> = npy
        .into_vec()
        .map_err(|e| format!("{shown}: cannot read its values ({e})"))?;
    if data.len() != rows * cols {
        return Err(format!(
            "{shown}: holds {} values for a {rows}×{cols} shape",
            data.len()
        ));
    }
    let at = |i: usize, j: usize| {
        if order == npyz::Order::Fortran {
            data[j * rows + i]
        } else {
            data[i * cols + j]
        }
    };
    Ok((0..rows)
        .map(|i| (0..cols).map(|j| at(i, j)).collect())
        .collect())
}

/// Longest `.npy` header text read: numpy's own reader refuses more than 10 000 bytes.
const MAX_HEADER_BYTES: u64 = 10_000;

/// Where the values start, from the magic, version and header length (NEP 1), checked against
/// the file's `len` before npyz reads (and allocates) the header; the reader is left at 0. The
/// header's brackets are limited to a depth of 4 (numpy writes 2), so a parser of nested
/// literals cannot run out of stack.
fn data_offset<R: std::io::Read + std::io::Seek>(file: &mut R, len: u64) -> Result<u64, String> {
    use std::io::Read as _;
    let mut pre = Vec::with_capacity(12);
    file.by_ref()
        .take(12)
        .read_to_end(&mut pre)
        .map_err(|e| e.to_string())?;
    let got = pre.len();
    if got < 10 || &pre[..6] != b"\x93NUMPY" {
        return Err("no .npy magic".into());
    }
    let (size, at) = match pre[6] {
        1 => (u16::from_le_bytes([pre[8], pre[9]]) as u64, 10),
        2 | 3 if got == 12 => (
            u32::from_le_bytes([pre[8], pre[9], pre[10], pre[11]]) as u64,
            12,
        ),
        v => return Err(format!("format version {v} is not 1, 2 or 3")),
    };
    if size > MAX_HEADER_BYTES || at + size > len {
        return Err(format!(
            "its header claims {size} bytes, in a file of {len}"
        ));
    }
    let mut header = vec![0u8; size as usize];
    file.seek(std::io::SeekFrom::Start(at))
        .and_then(|_| file.read_exact(&mut header))
        .map_err(|e| e.to_string())?;
    let mut depth = 0i32;
    for b in &header {
        depth += match b {
            b'(' | b'[' | b'{' => 1,
            b')' | b']' | b'}' => -1,
            _ => 0,
        };
        if depth > 4 {
            return Err("its header nests brackets deeper than a shape does".into());
        }
    }
    file.seek(std::io::SeekFrom::Start(0))
        .map_err(|e| e.to_string())?;
    Ok(at + size)
}

/// A 2-D float64 `.npy` file's bytes (C order), as `numpy.save` writes it: what
/// `uio-launcher linearize` leaves beside the scenario it writes.
pub fn npy_bytes(rows: &[Vec<f64>]) -> Result<Vec<u8>, String> {
    let (r, c) = (rows.len(), rows.first().map_or(0, Vec::len));
    if rows.iter().any(|row| row.len() != c) {
        return Err("rows of different lengths".into());
    }
    let mut bytes = Vec::new();
    {
        use npyz::WriterBuilder as _;
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[r as u64, c as u64])
            .writer(&mut bytes)
            .begin_nd()
            .map_err(|e| e.to_string())?;
        w.extend(rows.iter().flatten().copied())
            .map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())?;
    }
    Ok(bytes)
}
