//! Eigenvalues and singular values of the real power-system models, faer's (what `lti` uses)
//! beside LAPACK's through the system OpenBLAS (`dgeev`, `dgesdd`), in one process, interleaved
//! ("measure both on the real models and choose").
//!
//!     cargo run --release -p tests --example eig_lapack_vs_faer [runs]
//!
//! For A and Φ = e^{A·1 ms} of each model in `fixtures/andes/`: the median wall time of each
//! library over `runs` (default 5) alternating runs, their ratio, and how far the two spectra
//! are apart (each eigenvalue of one matched to the nearest of the other, relative to ‖A‖₁).

use std::path::Path;
use std::time::Instant;

use nalgebra::DMatrix;

#[link(name = "openblas")]
unsafe extern "C" {
    fn dgeev_(
        jobvl: *const u8,
        jobvr: *const u8,
        n: *const i32,
        a: *mut f64,
        lda: *const i32,
        wr: *mut f64,
        wi: *mut f64,
        vl: *mut f64,
        ldvl: *const i32,
        vr: *mut f64,
        ldvr: *const i32,
        work: *mut f64,
        lwork: *const i32,
        info: *mut i32,
    );
    fn dgesdd_(
        jobz: *const u8,
        m: *const i32,
        n: *const i32,
        a: *mut f64,
        lda: *const i32,
        s: *mut f64,
        u: *mut f64,
        ldu: *const i32,
        vt: *mut f64,
        ldvt: *const i32,
        work: *mut f64,
        lwork: *const i32,
        iwork: *mut i32,
        info: *mut i32,
    );
}

/// LAPACK's eigenvalues of `a` (dgeev, no vectors; it balances as `lti` does).
fn lapack_eig(a: &DMatrix<f64>) -> Vec<(f64, f64)> {
    let n = a.nrows() as i32;
    let mut m = a.clone();
    let (mut wr, mut wi) = (vec![0.0; n as usize], vec![0.0; n as usize]);
    let (mut info, mut query) = (0, [0.0]);
    let mut dummy = [0.0];
    let one = 1;
    // SAFETY: column-major n×n data, buffers of the sizes LAPACK documents; a workspace query first.
    unsafe {
        dgeev_(
            b"N".as_ptr(),
            b"N".as_ptr(),
            &n,
            m.as_mut_ptr(),
            &n,
            wr.as_mut_ptr(),
            wi.as_mut_ptr(),
            dummy.as_mut_ptr(),
            &one,
            dummy.as_mut_ptr(),
            &one,
            query.as_mut_ptr(),
            &-1,
            &mut info,
        );
        let lwork = query[0] as i32;
        let mut work = vec![0.0; lwork as usize];
        dgeev_(
            b"N".as_ptr(),
            b"N".as_ptr(),
            &n,
            m.as_mut_ptr(),
            &n,
            wr.as_mut_ptr(),
            wi.as_mut_ptr(),
            dummy.as_mut_ptr(),
            &one,
            dummy.as_mut_ptr(),
            &one,
            work.as_mut_ptr(),
            &lwork,
            &mut info,
        );
    }
    assert_eq!(info, 0, "dgeev failed: info = {info}");
    wr.into_iter().zip(wi).collect()
}

/// LAPACK's singular values of `a` (dgesdd, no vectors).
fn lapack_sv(a: &DMatrix<f64>) -> Vec<f64> {
    let (m, n) = (a.nrows() as i32, a.ncols() as i32);
    let mut x = a.clone();
    let mut s = vec![0.0; m.min(n) as usize];
    let mut iwork = vec![0i32; 8 * m.min(n) as usize];
    let (mut info, mut query, mut dummy, one) = (0, [0.0], [0.0], 1);
    // SAFETY: as above.
    unsafe {
        dgesdd_(
            b"N".as_ptr(),
            &m,
            &n,
            x.as_mut_ptr(),
            &m,
            s.as_mut_ptr(),
            dummy.as_mut_ptr(),
            &one,
            dummy.as_mut_ptr(),
            &one,
            query.as_mut_ptr(),
            &-1,
            iwork.as_mut_ptr(),
            &mut info,
        );
        let lwork = query[0] as i32;
        let mut work = vec![0.0; lwork as usize];
        dgesdd_(
            b"N".as_ptr(),
            &m,
            &n,
            x.as_mut_ptr(),
            &m,
            s.as_mut_ptr(),
            dummy.as_mut_ptr(),
            &one,
            dummy.as_mut_ptr(),
            &one,
            work.as_mut_ptr(),
            &lwork,
            iwork.as_mut_ptr(),
            &mut info,
        );
    }
    assert_eq!(info, 0, "dgesdd failed: info = {info}");
    s
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn one_norm(a: &DMatrix<f64>) -> f64 {
    a.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/andes");
    println!(
        "| model | n | matrix | eigenvalues: faer | LAPACK dgeev | faer/LAPACK | spectra apart (rel. ‖·‖₁) | singular values: faer | LAPACK dgesdd | faer/LAPACK | max rel. difference |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for case in ["kundur", "ieee14", "ieee39", "npcc", "wecc"] {
        let rows = scenario::matrix_file::read(&root.join(case), "A.npy")
            .unwrap_or_else(|e| panic!("{case}: {e}"));
        let a = DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j]);
        let phi = lti::expm::expm(&a, 1e-3);
        for (name, m) in [("A", &a), ("Φ (1 ms)", &phi)] {
            let (mut tf, mut tl, mut sf, mut sl) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let (mut ef, mut el, mut vf, mut vl) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for _ in 0..runs {
                let t = Instant::now();
                ef = lti::linalg::evd::eigenvalues(m)
                    .map(|v| v.iter().map(|z| (z.re, z.im)).collect())
                    .unwrap_or_default();
                tf.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                el = lapack_eig(m);
                tl.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                vf = lti::linalg::svd::singular_values(m);
                sf.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                vl = lapack_sv(m);
                sl.push(t.elapsed().as_secs_f64());
            }
            let scale = one_norm(m);
            let apart = if ef.len() == el.len() {
                ef.iter()
                    .map(|&(r, i)| {
                        el.iter()
                            .map(|&(r2, i2)| (r - r2).hypot(i - i2))
                            .fold(f64::INFINITY, f64::min)
                    })
                    .fold(0.0, f64::max)
                    / scale
            } else {
                f64::NAN // faer did not converge
            };
            vf.sort_by(|x, y| y.total_cmp(x));
            vl.sort_by(|x, y| y.total_cmp(x));
            let sv = vf
                .iter()
                .zip(&vl)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
                / vl[0];
            let (mf, ml, mfs, mls) = (median(tf), median(tl), median(sf), median(sl));
            println!(
                "| {case} | {} | {name} | {:.2} ms | {:.2} ms | {:.2} | {apart:.1e} | {:.2} ms | {:.2} ms | {:.2} | {sv:.1e} |",
                m.nrows(),
                mf * 1e3,
                ml * 1e3,
                mf / ml,
                mfs * 1e3,
                mls * 1e3,
                mfs / mls
            );
        }
    }
}
