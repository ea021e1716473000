//! Matrices given as `.npy` files beside the scenario: read in either storage and byte order,
//! relative to the scenario's folder, and refused with a one-line error naming the field and
//! the file when they are not 2-D float64. The files are written here byte by byte from the
//! format's specification (NEP 1), not by the reader under test.

use std::path::{Path, PathBuf};

use scenario::Scenario;

/// A version 1.0 `.npy` file of `values` (given row by row) with shape `shape`.
fn npy(path: &Path, descr: &str, fortran: bool, shape: &[usize], values: &[f64]) {
    let shape_text = match shape {
        [k] => format!("({k},)"),
        s => format!(
            "({})",
            s.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!(
        "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape_text}, }}",
        if fortran { "True" } else { "False" }
    );
    // Magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    let (rows, cols) = (shape[0], shape.get(1).copied().unwrap_or(1));
    let order: Vec<f64> = if fortran {
        (0..cols)
            .flat_map(|j| (0..rows).map(move |i| values[i * cols + j]))
            .collect()
    } else {
        values.to_vec()
    };
    for v in order {
        bytes.extend(if descr.starts_with('>') {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        });
    }
    std::fs::write(path, bytes).unwrap();
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("uio-npy-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("model")).unwrap();
    d
}

fn scenario(d: &Path, a: &str) -> Result<Scenario, String> {
    let text = format!(
        "name = \"npy\"\ndt = 0.01\nduration = 0.1\n[plant]\nA = {a}\nB = \"model/B.npy\"\nC = [[1.0, 0.0, 0.0]]\nx0 = [0.0, 0.0, 0.0]\n[[input]]\nkind = \"constant\"\nvalue = 0.0\n"
    );
    let path = d.join("npy.toml");
    std::fs::write(&path, &text).unwrap();
    Scenario::load(&path).map_err(|e| e.to_string())
}

const A: [f64; 9] = [0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -6.0, -11.0, -6.0];

#[test]
fn every_storage_and_byte_order_gives_the_same_matrix() {
    let d = dir("orders");
    npy(
        &d.join("model/B.npy"),
        "<f8",
        false,
        &[3, 1],
        &[0.0, 0.0, 1.0],
    );
    let inline = scenario(
        &d,
        "[[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-6.0, -11.0, -6.0]]",
    )
    .unwrap();
    for (descr, fortran) in [("<f8", false), ("<f8", true), (">f8", false), (">f8", true)] {
        npy(&d.join("model/A.npy"), descr, fortran, &[3, 3], &A);
        let s = scenario(&d, "\"model/A.npy\"").unwrap();
        assert_eq!(s.model.a, inline.model.a, "{descr} fortran={fortran}");
        assert_eq!(s.model.b, inline.model.b);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_files_are_named_with_the_field() {
    let d = dir("bad");
    npy(
        &d.join("model/B.npy"),
        "<f8",
        false,
        &[3, 1],
        &[0.0, 0.0, 1.0],
    );
    let err = |a: &str| scenario(&d, a).unwrap_err();
    let missing = err("\"model/none.npy\"");
    assert!(
        missing.contains("plant.A")
            && missing.contains("'model/none.npy'")
            && missing.contains("cannot read"),
        "{missing}"
    );
    npy(&d.join("model/A4.npy"), "<f4", false, &[3, 3], &A);
    let single = err("\"model/A4.npy\"");
    assert!(
        single.contains("plant.A") && single.contains("<f4") && single.contains("float64"),
        "{single}"
    );
    npy(&d.join("model/v.npy"), "<f8", false, &[3], &[1.0, 2.0, 3.0]);
    let vector = err("\"model/v.npy\"");
    assert!(vector.contains("[3]") && vector.contains("2-D"), "{vector}");
    std::fs::write(d.join("model/text.npy"), "A = 1").unwrap();
    let text = err("\"model/text.npy\"");
    assert!(text.contains("not a .npy file"), "{text}");
    // A header claiming more values than the file holds is refused before anything is read.
    npy(&d.join("model/huge.npy"), "<f8", false, &[3, 3], &A);
    let bytes = std::fs::read(d.join("model/huge.npy")).unwrap();
    let header =
        String::from_utf8_lossy(&bytes[10..bytes.len() - 72]).replace("(3, 3)", "(300000, 300000)");
    let mut forged = bytes[..8].to_vec();
    forged.extend((header.len() as u16).to_le_bytes());
    forged.extend(header.as_bytes());
    forged.extend(&bytes[bytes.len() - 72..]);
    std::fs::write(d.join("model/huge.npy"), forged).unwrap();
    let huge = err("\"model/huge.npy\"");
    assert!(
        huge.contains("300000×300000") && huge.contains("more values"),
        "{huge}"
    );
    // The shape is checked as for inline rows: a 2×3 A is not square.
    npy(&d.join("model/A23.npy"), "<f8", false, &[2, 3], &A[..6]);
    let shape = err("\"model/A23.npy\"");
    assert!(
        shape.contains("plant.A") && shape.contains("square"),
        "{shape}"
    );
    // Every message is one line, located at the key.
    for e in [missing, single, vector, text, shape, huge] {
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(e.contains("npy.toml:5:"), "{e}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_header_is_checked_before_it_is_read() {
    let d = dir("header");
    npy(
        &d.join("model/B.npy"),
        "<f8",
        false,
        &[3, 1],
        &[0.0, 0.0, 1.0],
    );
    let err = |a: &str| scenario(&d, a).unwrap_err();
    // Version 2.0 with a header length of 4 GiB − 1 in a file of a few bytes.
    std::fs::write(
        d.join("model/long.npy"),
        b"\x93NUMPY\x02\x00\xff\xff\xff\xff{",
    )
    .unwrap();
    let long = err("\"model/long.npy\"");
    assert!(
        long.contains("plant.A") && long.contains("4294967295 bytes"),
        "{long}"
    );
    // Brackets nested 4000 deep, which a recursive parser would follow.
    let header = format!("{}{}\n", "(".repeat(4000), ")".repeat(4000));
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    std::fs::write(d.join("model/deep.npy"), bytes).unwrap();
    let deep = err("\"model/deep.npy\"");
    assert!(deep.contains("nests"), "{deep}");
    // Fewer values than the header's shape, and more: the size must be exact.
    npy(&d.join("model/A.npy"), "<f8", false, &[3, 3], &A);
    let whole = std::fs::read(d.join("model/A.npy")).unwrap();
    std::fs::write(d.join("model/short.npy"), &whole[..whole.len() - 8]).unwrap();
    assert!(err("\"model/short.npy\"").contains("more values"));
    let mut long_tail = whole.clone();
    long_tail.extend([0u8; 8]);
    std::fs::write(d.join("model/tail.npy"), long_tail).unwrap();
    let tail = err("\"model/tail.npy\"");
    assert!(
        tail.contains("3×3") && tail.contains("80 bytes follow"),
        "{tail}"
    );
    // A shape with no values at all matches an empty data part: (2⁶², 0) would otherwise build
    // 2⁶² empty rows.
    npy(&d.join("model/empty.npy"), "<f8", false, &[1 << 62, 0], &[]);
    let empty = err("\"model/empty.npy\"");
    assert!(empty.contains("at least one row and one column"), "{empty}");
    let _ = std::fs::remove_dir_all(&d);
}
