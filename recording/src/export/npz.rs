//! `uio-launcher export --npz FILE`: a NumPy `.npz` (a zip of `.npy` files, stored uncompressed as
//! `numpy.savez` writes it) holding `step` (int64) and `t` (sim_time in s, float64; NaN when
//! the recording has no `dt`) over every step of the recording, and one float64 array per entity
//! group, steps × members, named by the group's path (`/observer/uio/xhat` →
//! `observer_uio_xhat`), its columns in the CSV export's order. A member with no value at a
//! step — latency can lag one step, `/latency/step` is timed every 16th step in-process, and
//! groups need not share steps — holds NaN there, where the CSV leaves a cell empty.
//!
//! The arrays are written column by column (Fortran order, which `numpy.load` reads as is), so
//! no group is held in memory twice. The `.npy` encoding is npyz's, the crate the scenario
//! loader reads `.npy` matrices with.

use std::io::{Seek, Write};
use std::path::Path;

use npyz::WriterBuilder as _;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use super::staged;
use super::table::{aligned, all_steps, array_name, labelled, sim_time, unique_names};
use crate::read::Recording;

/// Writes `path`; returns how many arrays it holds.
pub fn export(r: &Recording, path: &Path, dt: Option<f64>) -> Result<usize, String> {
    let groups = labelled(r);
    let names = unique_names(&groups, &["t", "step"], array_name)?;
    let steps = all_steps(&groups);
    let fail = |e: &dyn std::fmt::Display| staged::cannot_write(path, e);
    staged::write(path, |w| {
        let mut zip = ZipWriter::new(w);
        let rows = steps.len() as u64;
        array(&mut zip, "step", &[rows], steps.iter().copied()).map_err(|e| fail(&e))?;
        array(
            &mut zip,
            "t",
            &[rows],
            steps.iter().map(|&k| sim_time(k, dt).unwrap_or(f64::NAN)),
        )
        .map_err(|e| fail(&e))?;
        for (g, name) in groups.iter().zip(&names) {
            let values = g
                .members
                .iter()
                .flat_map(|m| aligned(&steps, m.series).map(|v| v.unwrap_or(f64::NAN)));
            array(&mut zip, name, &[rows, g.members.len() as u64], values).map_err(|e| fail(&e))?;
        }
        zip.finish().map_err(|e| fail(&e))?;
        Ok(())
    })?;
    Ok(names.len() + 2)
}

/// One `<name>.npy` entry of `shape` (Fortran order: `values` column by column).
fn array<W: Write + Seek, T: npyz::AutoSerialize + npyz::Serialize>(
    zip: &mut ZipWriter<W>,
    name: &str,
    shape: &[u64],
    values: impl Iterator<Item = T>,
) -> std::io::Result<()> {
    // The size of the entry bounds whether it needs zip64: data plus a header of at most 256 bytes.
    let bytes = shape.iter().product::<u64>() * 8 + 256;
    // A fixed entry date (zip's epoch, 1980-01-01), not the clock's: the same recording gives
    // the same file.
    let options = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Stored)
        .last_modified_time(zip::DateTime::default())
        .large_file(bytes >= u32::MAX as u64);
    zip.start_file(format!("{name}.npy"), options)?;
    let mut npy = npyz::WriteOptions::<T>::new()
        .default_dtype()
        .shape(shape)
        .order(npyz::Order::Fortran)
        .writer(&mut *zip)
        .begin_nd()?;
    for v in values {
        npy.push(&v)?;
    }
    npy.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Cursor, Read};

    #[test]
    fn an_entry_is_a_fortran_order_npy_of_its_shape() {
        let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
        // Columns (1, 2, 3) and (4, NaN, 6) of a 3×2 array.
        array(
            &mut zip,
            "g",
            &[3, 2],
            [1.0, 2.0, 3.0, 4.0, f64::NAN, 6.0].into_iter(),
        )
        .unwrap();
        let mut archive = zip::ZipArchive::new(zip.finish().unwrap()).unwrap();
        let mut entry = archive.by_name("g.npy").unwrap();
        assert_eq!(entry.compression(), CompressionMethod::Stored);
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).unwrap();
        assert_eq!(&bytes[..6], b"\x93NUMPY");
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 16, 0, "data aligned as numpy aligns it");
        let header: String = std::str::from_utf8(&bytes[10..10 + header_len])
            .unwrap()
            .split_whitespace()
            .collect();
        for part in ["'descr':'<f8'", "'fortran_order':True", "'shape':(3,2"] {
            assert!(header.contains(part), "{header}");
        }
        let data: Vec<u64> = bytes[10 + header_len..]
            .chunks(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let want: Vec<u64> = [1.0, 2.0, 3.0, 4.0, f64::NAN, 6.0]
            .iter()
            .map(|v: &f64| v.to_bits())
            .collect();
        assert_eq!(data, want);
    }
}
