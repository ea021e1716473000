//! Fixture readers shared by the integration tests.
#![allow(dead_code)]

use lti::{C64, Mat};
use serde_json::Value;

/// Parses a JSON file relative to the crate (`tests/fixtures/…`) or the workspace (`../fixtures/…`).
pub fn load(rel: &str) -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// Row-major nested list → matrix.
pub fn mat(v: &Value) -> Mat {
    let rows: Vec<Vec<f64>> = v
        .as_array()
        .expect("matrix")
        .iter()
        .map(|r| r.as_array().expect("row").iter().map(|x| x.as_f64().unwrap()).collect())
        .collect();
    let (m, n) = (rows.len(), rows.first().map_or(0, |r| r.len()));
    Mat::from_fn(m, n, |i, j| rows[i][j])
}

/// Column vector from a flat list.
pub fn col(v: &Value) -> Mat {
    let x: Vec<f64> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
    Mat::from_column_slice(x.len(), 1, &x)
}

/// [[re, im], …] or [x, …] → complex list.
pub fn complex_list(v: &Value) -> Vec<C64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| match p {
            Value::Array(a) => C64::new(a[0].as_f64().unwrap(), a[1].as_f64().unwrap()),
            x => C64::new(x.as_f64().unwrap(), 0.0),
        })
        .collect()
}

/// max |a − b| over entries.
pub fn max_diff(a: &Mat, b: &Mat) -> f64 {
    assert_eq!(a.shape(), b.shape());
    a.iter().zip(b.iter()).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}
