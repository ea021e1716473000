//! `uio-launcher export --mat FILE`: a MATLAB level-5 MAT-file (`load` in MATLAB, `scipy.io.loadmat`)
//! with the arrays of the npz export ([`super::npz`]): `step` (int64) and `t` (sim_time in s,
//! NaN without `dt`) as column vectors over every step of the recording, and one double matrix
//! per entity group, steps × members, named by its path (`observer_uio_xhat`); NaN where a
//! member has no value at a step (where the CSV leaves a cell empty).
//!
//! Written here rather than with a crate: `matfile` only reads, `matio-rs` binds the C library
//! libmatio, and the pure-Rust writers are young single-author crates pulling in compression and
//! serde stacks — while the subset needed (uncompressed real numeric matrices) is a 128-byte
//! header and three tagged elements per variable, as MathWorks documents the format ("MAT-File
//! Format", Level 5). Names are made valid MATLAB identifiers (letters, digits, `_`, starting
//! with a letter); a variable larger than 4 GiB, which level 5 cannot hold, is refused.

use std::io::Write;
use std::path::Path;

use super::staged;
use super::table::{aligned, all_steps, array_name, labelled, sim_time, unique_names};
use crate::read::Recording;

/// Data types of the elements (MathWorks' table "MAT-File Data Types").
const MI_INT8: u32 = 1;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_MATRIX: u32 = 14;
/// Array classes (the "MATLAB Array Types and Classes" table).
const MX_DOUBLE_CLASS: u32 = 6;
const MX_INT64_CLASS: u32 = 14;

/// The 128-byte file header: text, no subsystem data, version 0x0100, "IM" (little-endian).
pub fn file_header() -> [u8; 128] {
    let mut h = [b' '; 128];
    let text = b"MATLAB 5.0 MAT-file, written by uio-observers (uio-launcher export)";
    h[..text.len()].copy_from_slice(text);
    h[116..124].fill(0);
    h[124..126].copy_from_slice(&0x0100u16.to_le_bytes());
    h[126..128].copy_from_slice(b"IM");
    h
}

/// The numeric classes written: doubles, and int64 for the step numbers.
#[derive(Clone, Copy)]
pub enum Class {
    Double,
    Int64,
}

/// The bytes of a matrix element up to its data: the miMATRIX tag, array flags, dimensions,
/// name, and the tag of the `rows`·`cols` values that follow (8 bytes each, column by column).
pub fn matrix_header(name: &str, rows: u64, cols: u64, class: Class) -> Result<Vec<u8>, String> {
    let too_big = || {
        format!(
            "{name}: {rows}×{cols} values do not fit a MAT-file (level 5 holds 4 GiB a variable)"
        )
    };
    let data = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(8))
        .filter(|&n| n <= u32::MAX as u64 - 1024)
        .ok_or_else(too_big)?;
    let (r, c) = (
        i32::try_from(rows).map_err(|_| too_big())?,
        i32::try_from(cols).map_err(|_| too_big())?,
    );
    let (class, data_type) = match class {
        Class::Double => (MX_DOUBLE_CLASS, MI_DOUBLE),
        Class::Int64 => (MX_INT64_CLASS, MI_INT64),
    };
    let mut sub = Vec::new();
    element(
        &mut sub,
        MI_UINT32,
        &[class.to_le_bytes(), 0u32.to_le_bytes()].concat(),
    );
    element(
        &mut sub,
        MI_INT32,
        &[r.to_le_bytes(), c.to_le_bytes()].concat(),
    );
    element(&mut sub, MI_INT8, name.as_bytes());
    tag(&mut sub, data_type, data as u32);
    let mut out = Vec::with_capacity(sub.len() + 8);
    tag(&mut out, MI_MATRIX, (sub.len() as u64 + data) as u32);
    out.extend(sub);
    Ok(out)
}

/// A data element tag: type and byte count.
fn tag(out: &mut Vec<u8>, data_type: u32, bytes: u32) {
    out.extend(data_type.to_le_bytes());
    out.extend(bytes.to_le_bytes());
}

/// A tagged element, its data padded to a multiple of 8 bytes.
fn element(out: &mut Vec<u8>, data_type: u32, data: &[u8]) {
    tag(out, data_type, data.len() as u32);
    out.extend(data);
    out.resize(out.len().next_multiple_of(8), 0);
}

/// A valid MATLAB identifier for a group: other characters become `_`, a name not starting
/// with a letter gets an `x` in front.
pub fn variable_name(group: &str) -> String {
    let name: String = array_name(group)
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if name.starts_with(|c: char| c.is_ascii_alphabetic()) {
        name
    } else {
        format!("x{name}")
    }
}

/// Writes `path`; returns how many variables it holds.
pub fn export(r: &Recording, path: &Path, dt: Option<f64>) -> Result<usize, String> {
    let groups = labelled(r);
    let names = unique_names(&groups, &["t", "step"], variable_name)?;
    let steps = all_steps(&groups);
    let rows = steps.len() as u64;
    // Every header first, so that a variable too large is refused before anything is written.
    let mut headers = vec![
        matrix_header("step", rows, 1, Class::Int64)?,
        matrix_header("t", rows, 1, Class::Double)?,
    ];
    for (g, name) in groups.iter().zip(&names) {
        headers.push(matrix_header(
            name,
            rows,
            g.members.len() as u64,
            Class::Double,
        )?);
    }
    staged::write(path, |w| {
        let io = |e: std::io::Error| staged::cannot_write(path, &e);
        w.write_all(&file_header()).map_err(io)?;
        let mut headers = headers.iter();
        let mut next = |w: &mut dyn Write| {
            w.write_all(headers.next().expect("one header per variable"))
                .map_err(io)
        };
        next(w)?;
        for &k in &steps {
            w.write_all(&k.to_le_bytes()).map_err(io)?;
        }
        next(w)?;
        for &k in &steps {
            w.write_all(&sim_time(k, dt).unwrap_or(f64::NAN).to_le_bytes())
                .map_err(io)?;
        }
        for g in &groups {
            next(w)?;
            for m in &g.members {
                for v in aligned(&steps, m.series) {
                    w.write_all(&v.unwrap_or(f64::NAN).to_le_bytes())
                        .map_err(io)?;
                }
            }
        }
        Ok(())
    })?;
    Ok(names.len() + 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_header_is_level_5_little_endian() {
        let h = file_header();
        assert!(h.starts_with(b"MATLAB 5.0 MAT-file"));
        assert_eq!(&h[116..124], &[0; 8]);
        assert_eq!(&h[124..128], &[0x00, 0x01, b'I', b'M']);
    }

    #[test]
    fn a_matrix_header_tags_flags_dimensions_name_and_data() {
        let h = matrix_header("xhat", 3, 2, Class::Double).unwrap();
        let word = |i: usize| u32::from_le_bytes(h[i..i + 4].try_into().unwrap());
        // miMATRIX, counting everything after its tag: 16 flags + 16 dims + 16 name + 8 tag + 48 data.
        assert_eq!((word(0), word(4)), (MI_MATRIX, 16 + 16 + 16 + 8 + 48));
        assert_eq!(
            (word(8), word(12), word(16), word(20)),
            (MI_UINT32, 8, MX_DOUBLE_CLASS, 0)
        );
        assert_eq!(
            (word(24), word(28), word(32), word(36)),
            (MI_INT32, 8, 3, 2)
        );
        assert_eq!((word(40), word(44)), (MI_INT8, 4));
        assert_eq!(&h[48..56], b"xhat\0\0\0\0");
        assert_eq!((word(56), word(60)), (MI_DOUBLE, 48));
        assert_eq!(h.len(), 64);
    }

    #[test]
    fn a_variable_over_4_gib_is_refused() {
        assert!(matrix_header("big", 1 << 27, 5, Class::Double).is_err());
        assert!(matrix_header("ok", 1 << 20, 5, Class::Double).is_ok());
    }

    #[test]
    fn names_become_matlab_identifiers() {
        assert_eq!(variable_name("/observer/uio-2/xhat"), "observer_uio_2_xhat");
        assert_eq!(variable_name("/1st"), "x1st");
    }
}
