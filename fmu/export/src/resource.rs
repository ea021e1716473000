//! `resources/observer.json`: what the FMU's library reads at instantiation.
//!
//! The sampled observer of observer/src/runtime.rs,
//!
//! ```text
//! z_{k+1} = F z_k + G u_k + K y_k,      x̂_k = P z_k + Q y_k,
//! ```
//!
//! with the plant's C (for the residual r = y − C x̂), the period dt, and for an initial estimate
//! x̂₀ the pseudo-inverse P⁺ formed here with `lti::pinv::pinv`, so that the library does no
//! decomposition and z_0 = P⁺(x̂₀ − Q y_0) has the bits of the run. serde_json with
//! `float_roundtrip` writes and reads every f64 exactly.
//!
//! At an operating point (the design in deviations, the FMU fed the plant's absolute u and y)
//! the runtime's two offsets come along ([`OperatingPoint`]):
//!
//! ```text
//! z_{k+1} = F z_k + G u_k + K y_k + c_z,   x̂_k = P z_k + Q y_k + c_x,   z_0 = P⁺(x̂₀ − Q y_0 − c_x)
//! ```
//!
//! with c_z = −(G u_op + K y_op) and c_x = x_op − Q y_op as `observer::LinearObserver` forms
//! them, so the FMU's x̂ is the run's, in absolute units; r = y − C x̂ − c_r with
//! c_r = y_op − C x_op where that is not 0, as the run's recorder forms it.

use lti::MatData;
use serde::{Deserialize, Serialize};

/// The schema's version; the library refuses any other.
pub const FORMAT: u32 = 1;

/// The file's name inside `resources/`.
pub const FILE: &str = "observer.json";

/// One exported observer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverResource {
    /// [`FORMAT`].
    pub format: u32,
    /// The modelDescription's `guid` / `instantiationToken`; the library checks it, so a
    /// modelDescription and resources of two different exports are not mixed.
    pub token: String,
    /// The observer's name in its scenario.
    pub observer: String,
    /// Sample period dt, s: the only communication step size accepted.
    pub dt: f64,
    /// F, r×r.
    pub f: MatData,
    /// G, r×l.
    pub g: MatData,
    /// K, r×p.
    pub k: MatData,
    /// P, n×r.
    pub p: MatData,
    /// Q, n×p.
    pub q: MatData,
    /// The plant's C, p×n.
    pub c: MatData,
    /// The initial estimate x̂₀ (n values); `None`: z_0 = 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xhat0: Option<Vec<f64>>,
    /// P⁺ (r×n), given exactly when `xhat0` is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_pinv: Option<MatData>,
    /// The operating point's offsets, when the design is in deviations from one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operating_point: Option<OperatingPoint>,
}

/// The operating point of an observer designed in deviations: the inputs' levels there (the
/// FMU's start values) and the offsets c_z (r values) and c_x (n values) of the module
/// documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperatingPoint {
    /// u_op, l values.
    pub u: Vec<f64>,
    /// y_op, p values.
    pub y: Vec<f64>,
    /// c_z = −(G u_op + K y_op).
    pub c_z: Vec<f64>,
    /// c_x = x_op − Q y_op.
    pub c_x: Vec<f64>,
    /// c_r = y_op − C x_op when not zero (an output map that is not linear at the point): the
    /// residual is then y − C x̂ − c_r, in deviations, as the run records it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub c_r: Vec<f64>,
}

/// The dimensions (n, r, l, p) of a resource that conforms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dims {
    /// Estimated states.
    pub n: usize,
    /// Observer order (size of z).
    pub r: usize,
    /// Known inputs.
    pub l: usize,
    /// Measured outputs.
    pub p: usize,
}

impl ObserverResource {
    /// The resource of an observer; P⁺ is formed here when x̂₀ is given, and the token from the
    /// rest of the content.
    #[allow(clippy::too_many_arguments)] // the observer form's five matrices, C, dt and x̂₀
    pub fn new(
        observer: &str,
        dt: f64,
        f: MatData,
        g: MatData,
        k: MatData,
        p: MatData,
        q: MatData,
        c: MatData,
        xhat0: Option<Vec<f64>>,
    ) -> Result<Self, String> {
        let p_pinv = xhat0
            .as_ref()
            .map(|_| MatData::from(&lti::pinv::pinv(&(&p).into())));
        let mut res = ObserverResource {
            format: FORMAT,
            token: String::new(),
            observer: observer.into(),
            dt,
            f,
            g,
            k,
            p,
            q,
            c,
            xhat0,
            p_pinv,
            operating_point: None,
        };
        res.dims()?;
        res.token = token(&res.to_json());
        Ok(res)
    }

    /// The same observer at an operating point (its offsets checked); the token follows.
    pub fn at_operating_point(mut self, op: OperatingPoint) -> Result<Self, String> {
        self.operating_point = Some(op);
        self.dims()?;
        self.token = String::new();
        self.token = token(&self.to_json());
        Ok(self)
    }

    /// Checks that the matrices conform and every number is finite; the dimensions.
    pub fn dims(&self) -> Result<Dims, String> {
        if self.format != FORMAT {
            return Err(format!(
                "format {} (this library reads format {FORMAT})",
                self.format
            ));
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(format!("dt = {} is not a positive finite number", self.dt));
        }
        let d = Dims {
            n: self.p.rows,
            r: self.f.rows,
            l: self.g.cols,
            p: self.k.cols,
        };
        let shapes = [
            ("F", &self.f, d.r, d.r),
            ("G", &self.g, d.r, d.l),
            ("K", &self.k, d.r, d.p),
            ("P", &self.p, d.n, d.r),
            ("Q", &self.q, d.n, d.p),
            ("C", &self.c, d.p, d.n),
        ];
        let pinv = self.p_pinv.as_ref().map(|m| ("P⁺", m, d.r, d.n));
        for (name, m, rows, cols) in shapes.into_iter().chain(pinv) {
            if m.rows != rows || m.cols != cols || m.data.len() != rows * cols {
                return Err(format!(
                    "{name} is {}×{} with {} entries; {rows}×{cols} expected",
                    m.rows,
                    m.cols,
                    m.data.len()
                ));
            }
            if m.data.iter().any(|v| !v.is_finite()) {
                return Err(format!("{name} has an entry that is not finite"));
            }
        }
        if let Some(op) = &self.operating_point {
            let c_r_len = if op.c_r.is_empty() { 0 } else { d.p };
            for (name, v, len) in [
                ("u", &op.u, d.l),
                ("y", &op.y, d.p),
                ("c_z", &op.c_z, d.r),
                ("c_x", &op.c_x, d.n),
                ("c_r", &op.c_r, c_r_len),
            ] {
                if v.len() != len || v.iter().any(|x| !x.is_finite()) {
                    return Err(format!(
                        "operating_point.{name} must hold {len} finite values"
                    ));
                }
            }
        }
        match (&self.xhat0, &self.p_pinv) {
            (Some(x), Some(_)) if x.len() != d.n || x.iter().any(|v| !v.is_finite()) => {
                Err(format!("xhat0 must hold {} finite values", d.n))
            }
            (Some(_), None) | (None, Some(_)) => Err("xhat0 and p_pinv come together".into()),
            _ => Ok(d),
        }
    }

    /// The JSON text (every f64 round-trips).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a resource serialises")
    }

    /// Reads and checks a resource's text.
    pub fn from_json(text: &str) -> Result<(Self, Dims), String> {
        let res: ObserverResource =
            serde_json::from_str(text).map_err(|e| format!("not an observer resource: {e}"))?;
        let dims = res.dims()?;
        Ok((res, dims))
    }
}

/// A GUID-shaped digest (two 64-bit FNV-1a hashes) of the resource's text: not secret, only
/// different for different content.
fn token(text: &str) -> String {
    let fnv = |seed: u64| {
        text.bytes()
            .fold(seed, |h, b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3))
    };
    let (a, b) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x6c62_272e_07bb_0142));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(rows: usize, cols: usize, data: &[f64]) -> MatData {
        MatData {
            rows,
            cols,
            data: data.to_vec(),
        }
    }

    #[test]
    fn round_trips_every_bit_and_checks_shapes() {
        let third = 1.0 / 3.0;
        let res = ObserverResource::new(
            "o",
            1e-3,
            m(1, 1, &[third]),
            m(1, 1, &[0.1]),
            m(1, 2, &[0.2, 0.7]),
            m(2, 1, &[1.0, 2.0]),
            m(2, 2, &[0.0, 0.3, 0.0, 0.0]),
            m(2, 2, &[1.0, 0.0, 0.0, 1.0]),
            Some(vec![1.0, -2.0]),
        )
        .unwrap();
        let (back, dims) = ObserverResource::from_json(&res.to_json()).unwrap();
        assert_eq!(back, res);
        assert_eq!(back.f.data[0].to_bits(), third.to_bits());
        assert_eq!(
            dims,
            Dims {
                n: 2,
                r: 1,
                l: 1,
                p: 2
            }
        );
        // P⁺ of [1; 2] is [1/5, 2/5].
        let pinv = back.p_pinv.unwrap();
        assert!((pinv.data[0] - 0.2).abs() < 1e-15 && (pinv.data[1] - 0.4).abs() < 1e-15);
        let mut bad = res.clone();
        bad.c = m(2, 1, &[1.0, 0.0]);
        assert!(bad.dims().unwrap_err().starts_with("C is 2×1"));
        let mut bad = res;
        bad.p_pinv = None;
        assert!(bad.dims().is_err());
        assert!(ObserverResource::from_json("{}").is_err());
    }

    #[test]
    fn the_token_follows_the_content() {
        let one = |v: f64| m(1, 1, &[v]);
        let a = ObserverResource::new(
            "o",
            0.1,
            one(0.5),
            one(1.0),
            one(1.0),
            one(1.0),
            one(0.0),
            one(1.0),
            None,
        )
        .unwrap();
        let b = ObserverResource::new(
            "o",
            0.1,
            one(0.5),
            one(1.0),
            one(1.0),
            one(1.0),
            one(0.0),
            one(1.0),
            None,
        )
        .unwrap();
        let c = ObserverResource::new(
            "o",
            0.1,
            one(0.25),
            one(1.0),
            one(1.0),
            one(1.0),
            one(0.0),
            one(1.0),
            None,
        )
        .unwrap();
        assert_eq!(a.token, b.token);
        assert_ne!(a.token, c.token);
        assert_eq!(a.token.len(), 38);
    }
}
