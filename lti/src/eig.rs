//! Eigenvalues of a real square matrix: balancing, then the real Schur form (faer's multishift
//! QR, [`crate::linalg::evd`]).
//!
//! Balancing (Parlett & Reinsch; LAPACK `xGEBAL` with job 'S') scales A by a diagonal D of powers
//! of two, D⁻¹AD, so that each row and column have comparable norms. The scaling is exact in
//! floating point and leaves the eigenvalues unchanged, but it makes the Schur iteration much
//! more accurate for models like the missile autopilot, whose entries span 10⁻³ … 10⁴.

use nalgebra::{Complex, DMatrix};

use crate::error::Result;
pub use crate::linalg::balance::balance;

/// A complex number in double precision.
pub type C64 = Complex<f64>;

/// Eigenvalues of a real square matrix, sorted by (real part, imaginary part).
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<C64>> {
    // Shape, emptiness and finiteness are checked there.
    let mut ev = crate::linalg::evd::eigenvalues(a)?;
    // A real matrix has exactly conjugate pairs; make them so bit for bit.
    for e in ev.iter_mut() {
        if e.im.abs() <= 8.0 * f64::EPSILON * e.re.abs() {
            e.im = 0.0;
        }
    }
    sort(&mut ev);
    Ok(ev)
}

/// Sorts by real part, then imaginary part (the reference data's convention).
pub fn sort(v: &mut [C64]) {
    v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
}

/// Largest real part (the spectral abscissa): the decay rate of a continuous system.
pub fn spectral_abscissa(ev: &[C64]) -> f64 {
    ev.iter().map(|e| e.re).fold(f64::NEG_INFINITY, f64::max)
}

/// ln(z)/dt of each sampled eigenvalue (the continuous one it is the image of, e^{s·dt} = z),
/// and how many were left out as deadbeat (z = 0 to rounding: no continuous image).
pub fn continuous_image(discrete: &[C64], dt: f64) -> (Vec<C64>, usize) {
    let kept: Vec<C64> = discrete
        .iter()
        .filter(|z| z.norm() >= 1e-12)
        .map(|z| z.ln() / dt)
        .collect();
    let dropped = discrete.len() - kept.len();
    (kept, dropped)
}

/// Largest modulus (the spectral radius): the decay factor of a discrete system.
pub fn spectral_radius(ev: &[C64]) -> f64 {
    ev.iter().map(|e| e.norm()).fold(0.0, f64::max)
}

/// Distance between two eigenvalue multisets: each requested value is matched to the nearest
/// unused achieved value; returns the largest |a − r| / max(1, |r|).
pub fn match_error(requested: &[C64], achieved: &[C64]) -> f64 {
    if requested.len() != achieved.len() {
        return f64::INFINITY;
    }
    let mut used = vec![false; achieved.len()];
    let mut worst: f64 = 0.0;
    for r in requested {
        let mut best = None;
        let mut best_d = f64::INFINITY;
        for (i, a) in achieved.iter().enumerate() {
            let d = (a - r).norm();
            if !used[i] && d < best_d {
                best_d = d;
                best = Some(i);
            }
        }
        match best {
            Some(i) => {
                used[i] = true;
                worst = worst.max(best_d / r.norm().max(1.0));
            }
            None => return f64::INFINITY,
        }
    }
    worst
}

/// Parts of an eigenvalue within this of zero, relative to the largest modulus shown (at least 1),
/// print as 0. The Schur form gives eigenvalues to ~ε‖A‖ absolute, and ‖A‖ can exceed the
/// largest |λ| by orders of magnitude (the missile: ‖A‖ ≈ 3·10⁴, |λ| ≤ 180), so a zero or a
/// marginal mode comes out as ±(a few 10⁻¹⁶ … 10⁻¹³): its sign is rounding noise, and printing it
/// ("unstable zero −2.2e-16") says more than the computation knows. 10⁻¹² ≈ 4500ε, far below the
/// six significant digits [`sig`] shows of the largest value.
pub const DISPLAY_ZERO: f64 = 1e-12;

/// `e` with each part within `DISPLAY_ZERO · scale` of zero set to 0.
fn snap(e: C64, scale: f64) -> C64 {
    let tol = DISPLAY_ZERO * scale;
    let part = |x: f64| if x.abs() <= tol { 0.0 } else { x };
    C64::new(part(e.re), part(e.im))
}

/// "−1, −2 ± 3j" style formatting of an eigenvalue list (one member per conjugate pair); parts
/// within [`DISPLAY_ZERO`] of zero, relative to the list's largest modulus, print as 0.
pub fn format_list(v: &[C64]) -> String {
    let scale = v.iter().map(|e| e.norm()).fold(1.0, f64::max);
    let v: Vec<C64> = v.iter().map(|&e| snap(e, scale)).collect();
    let mut out = Vec::new();
    for e in &v {
        if e.im < 0.0 && v.iter().any(|o| o.re == e.re && o.im == -e.im) {
            continue;
        }
        out.push(format_one(*e, true));
    }
    out.join(", ")
}

/// One eigenvalue; with `pair`, a complex value is shown as "re ± j·|im|". Parts within
/// [`DISPLAY_ZERO`] of zero, relative to max(1, |e|), print as 0.
pub fn format_one(e: C64, pair: bool) -> String {
    let e = snap(e, e.norm().max(1.0));
    if e.im == 0.0 {
        sig(e.re)
    } else if pair {
        format!("{} ± j{}", sig(e.re), sig(e.im.abs()))
    } else if e.im > 0.0 {
        format!("{} + j{}", sig(e.re), sig(e.im))
    } else {
        format!("{} - j{}", sig(e.re), sig(-e.im))
    }
}

/// Six significant digits, trailing zeros trimmed.
pub fn sig(x: f64) -> String {
    if x == 0.0 {
        return "0".into(); // −0 too: a sign on zero is noise
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let mag = x.abs().log10().floor() as i32;
    if (-3..7).contains(&mag) {
        let s = format!("{:.*}", (5 - mag).max(0) as usize, x);
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.5e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn companion_roots() {
        // s³ + 6s² + 11s + 6 = (s+1)(s+2)(s+3)
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -6.0, -11.0, -6.0]);
        let ev = eigenvalues(&a).unwrap();
        let want = [
            C64::new(-3.0, 0.0),
            C64::new(-2.0, 0.0),
            C64::new(-1.0, 0.0),
        ];
        assert!(match_error(&want, &ev) < 1e-12);
    }

    #[test]
    fn balancing_keeps_eigenvalues() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1e6, 1e-6, 2.0]);
        let b = balance(&a);
        let (ea, eb) = (eigenvalues(&a).unwrap(), eigenvalues(&b).unwrap());
        assert!(match_error(&ea, &eb) < 1e-13);
        assert!(b[(0, 1)].abs() < 1e3);
    }

    #[test]
    fn formatting() {
        let v = [
            C64::new(-84.2607, -127.9594),
            C64::new(-84.2607, 127.9594),
            C64::new(-1.0, 0.0),
        ];
        assert_eq!(format_list(&v), "-84.2607 ± j127.959, -1");
    }

    /// A zero computed as −2.2e-16 is a zero, not an unstable or stable one.
    #[test]
    fn rounding_noise_around_zero_prints_as_zero() {
        assert_eq!(format_list(&[C64::new(-2.220446049250313e-16, 0.0)]), "0");
        assert_eq!(format_one(C64::new(2.220446049250313e-16, 0.0), true), "0");
        assert_eq!(format_list(&[C64::new(-0.0, 0.0)]), "0");
        // The missile's undamped airframe pair ±j11.77 next to the actuator: the real part's noise
        // is relative to the largest modulus (180) and the conjugate pair still prints once.
        let v = [
            C64::new(3e-14, 11.77),
            C64::new(3e-14, -11.77),
            C64::new(-108.0, 144.0),
            C64::new(-108.0, -144.0),
        ];
        assert_eq!(format_list(&v), "0 ± j11.77, -108 ± j144");
        // Imaginary noise on a real value, and a conjugate pair whose noise differs in sign.
        assert_eq!(format_list(&[C64::new(-5.0, 1e-14)]), "-5");
        assert_eq!(
            format_list(&[C64::new(-1e-15, 2.0), C64::new(1e-15, -2.0)]),
            "0 ± j2"
        );
        // Small but real values are not hidden.
        assert_eq!(
            format_list(&[C64::new(-1e-3, 0.0), C64::new(-3e-9, 0.0)]),
            "-0.001, -3.00000e-9"
        );
    }
}
