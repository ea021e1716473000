//! A `.npy` matrix file whose header claims more than the file holds is
//! refused from its header, before its values are read: a sparse 1 GiB file claiming
//! 11585×11585 was read whole first (2.1 GB of memory, 9.8 s). Alone in its test binary so
//! that the children's peak memory (RUSAGE_CHILDREN) is the launcher's of this test.

use std::time::{Duration, Instant};

use tests::*;

/// A version 1.0 `.npy` header for float64 values of `shape`, padded as numpy pads it.
fn npy_header(shape: &str) -> Vec<u8> {
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes
}

/// Peak resident memory of any waited-for child so far, bytes.
fn children_peak_rss() -> u64 {
    // SAFETY: getrusage fills the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) };
    usage.ru_maxrss as u64 * 1024
}

#[test]
fn a_sparse_matrix_file_claiming_a_huge_shape_is_refused_from_its_header() {
    let s = Scratch::new("npy-bounds");
    std::fs::create_dir_all(s.join("model")).unwrap();
    let scenario = s.join("big.toml");
    std::fs::write(&scenario, "name = \"big\"\ndt = 0.01\nduration = 0.1\n[plant]\nA = \"model/A.npy\"\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nx0 = [0.0, 0.0]\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n").unwrap();
    // 11585² doubles fit in 1 GiB but not in 1 GiB less the header; 300000² fit nowhere.
    for shape in ["(11585, 11585)", "(300000, 300000)"] {
        let path = s.join("model/A.npy");
        std::fs::write(&path, npy_header(shape)).unwrap();
        std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .unwrap()
            .set_len(1 << 30)
            .unwrap();
        let started = Instant::now();
        let out = launcher(&s).arg("design").arg(&scenario).output().unwrap();
        let took = started.elapsed();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{shape}: {err}");
        assert!(
            err.contains("plant.A")
                && err.contains("'model/A.npy'")
                && err.contains("its header says"),
            "{shape}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(
            took < Duration::from_secs(2),
            "{shape}: refused after {took:?}"
        );
        let peak = children_peak_rss();
        assert!(
            peak < 200 << 20,
            "{shape}: the launcher's memory peaked at {} MB",
            peak >> 20
        );
        eprintln!(
            "{shape}: refused in {took:?}, peak memory {} MB",
            peak >> 20
        );
    }
}
