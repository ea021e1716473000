//! The observer form of observer/src/runtime.rs, split at the communication point:
//!
//! ```text
//! outputs at t_k:  x̂_k = P z_k + Q y_k,   r_k = y_k − C x̂_k      (from the inputs as set)
//! doStep(t_k, dt): z_{k+1} = F z_k + G u_k + K y_k               (inputs held over the step)
//! ```
//!
//! with z_0 = 0, or z_0 = P⁺(x̂₀ − Q y_0) from the y set at t_0 (formed again whenever outputs
//! are read before the first step, so x̂_0 follows y_0 until the master commits to it). At an
//! operating point c_z is added to z_{k+1} and c_x to x̂_k (subtracted in z_0), after the
//! products, as the runtime adds them; the inputs start at u_op and y_op.
//!
//! The arithmetic is the runtime's, operation for operation, with the same skips (P = I: a
//! copy; G = 0: no G u; Q = 0: no Q y) and `lti::kernel`'s products; the residual is the
//! recorder's (recording/src/write/metrics.rs). That is what makes x̂ and r bit-identical to a
//! recording.

use fmu_export::ObserverResource;
use lti::kernel::{mul_acc, mul_into};
use nalgebra::DMatrix;

/// Matrices, state and the current inputs of one instance.
#[derive(Debug, Clone)]
pub struct Observer {
    f: DMatrix<f64>,
    g: DMatrix<f64>,
    k: DMatrix<f64>,
    p: DMatrix<f64>,
    q: DMatrix<f64>,
    c: DMatrix<f64>,
    /// (x̂₀, P⁺) when the export carries an initial estimate.
    start: Option<(Vec<f64>, DMatrix<f64>)>,
    /// P = I (full-order observers): x̂ = z + Q y needs no product with P.
    p_identity: bool,
    /// G = 0: skip G u.
    g_zero: bool,
    /// Q = 0: skip Q y.
    q_zero: bool,
    z: Vec<f64>,
    z_next: Vec<f64>,
    /// z_0 is not fixed yet (no step taken).
    first: bool,
    /// Known inputs u, held over the next step.
    pub u: Vec<f64>,
    /// Measured outputs y at the current communication point.
    pub y: Vec<f64>,
    xhat: Vec<f64>,
    r: Vec<f64>,
    /// At an operating point: (u_op, y_op, c_z, c_x, c_r), c_r empty where it is 0.
    op: Option<[Vec<f64>; 5]>,
}

impl Observer {
    /// From a resource that passed [`ObserverResource::dims`].
    pub fn new(res: &ObserverResource) -> Self {
        let m = |d: &lti::MatData| DMatrix::from(d);
        let zero = |d: &lti::MatData| d.data.iter().all(|&x| x == 0.0);
        let p = m(&res.p);
        let (n, r, l, outputs) = (res.p.rows, res.f.rows, res.g.cols, res.k.cols);
        let mut o = Observer {
            p_identity: p.is_square() && p == DMatrix::identity(p.nrows(), p.ncols()),
            g_zero: zero(&res.g),
            q_zero: zero(&res.q),
            f: m(&res.f),
            g: m(&res.g),
            k: m(&res.k),
            p,
            q: m(&res.q),
            c: m(&res.c),
            start: res.xhat0.clone().zip(res.p_pinv.as_ref().map(m)),
            z: vec![0.0; r],
            z_next: vec![0.0; r],
            first: true,
            u: vec![0.0; l],
            y: vec![0.0; outputs],
            xhat: vec![0.0; n],
            r: vec![0.0; outputs],
            op: res.operating_point.as_ref().map(|o| {
                [
                    o.u.clone(),
                    o.y.clone(),
                    o.c_z.clone(),
                    o.c_x.clone(),
                    o.c_r.clone(),
                ]
            }),
        };
        o.start_inputs();
        o
    }

    /// The inputs at their start values: the operating point's u and y, else 0.
    fn start_inputs(&mut self) {
        match &self.op {
            Some([u, y, ..]) => {
                self.u.copy_from_slice(u);
                self.y.copy_from_slice(y);
            }
            None => {
                self.u.fill(0.0);
                self.y.fill(0.0);
            }
        }
    }

    /// Back to the instantiated state: z_0 not formed, inputs at their start values.
    pub fn reset(&mut self) {
        self.z.fill(0.0);
        self.first = true;
        self.start_inputs();
    }

    /// z_0 = P⁺(x̂₀ − Q y_0), with x̂ as the scratch vector (as the runtime forms it); z_0 = 0
    /// without x̂₀.
    fn form_start(&mut self) {
        if let Some((x0, p_pinv)) = &self.start {
            mul_into(&mut self.xhat, &self.q, &self.y);
            for (v, x) in self.xhat.iter_mut().zip(x0) {
                *v = x - *v;
            }
            if let Some([_, _, _, c_x, _]) = &self.op {
                for (v, c) in self.xhat.iter_mut().zip(c_x) {
                    *v -= c;
                }
            }
            mul_into(&mut self.z, p_pinv, &self.xhat);
        }
    }

    /// Forms x̂ = P z + Q y and r = y − C x̂ at the current communication point.
    pub fn outputs(&mut self) {
        if self.first {
            self.form_start();
        }
        if self.p_identity {
            self.xhat.copy_from_slice(&self.z);
        } else {
            mul_into(&mut self.xhat, &self.p, &self.z);
        }
        if !self.q_zero {
            mul_acc(&mut self.xhat, &self.q, &self.y);
        }
        if let Some([_, _, _, c_x, _]) = &self.op {
            for (v, c) in self.xhat.iter_mut().zip(c_x) {
                *v += c;
            }
        }
        mul_into(&mut self.r, &self.c, &self.xhat);
        for (r, &y) in self.r.iter_mut().zip(&self.y) {
            *r = y - *r;
        }
        if let Some([.., c_r]) = &self.op {
            for (r, c) in self.r.iter_mut().zip(c_r) {
                *r -= c;
            }
        }
    }

    /// x̂ as last formed by [`Observer::outputs`].
    pub fn xhat(&self) -> &[f64] {
        &self.xhat
    }

    /// r as last formed by [`Observer::outputs`].
    pub fn residual(&self) -> &[f64] {
        &self.r
    }

    /// z ← F z + G u + K y: one sample period with the inputs held.
    pub fn advance(&mut self) {
        if self.first {
            self.form_start();
            self.first = false;
        }
        mul_into(&mut self.z_next, &self.f, &self.z);
        if !self.g_zero {
            mul_acc(&mut self.z_next, &self.g, &self.u);
        }
        mul_acc(&mut self.z_next, &self.k, &self.y);
        if let Some([_, _, c_z, _, _]) = &self.op {
            for (z, c) in self.z_next.iter_mut().zip(c_z) {
                *z += c;
            }
        }
        std::mem::swap(&mut self.z, &mut self.z_next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lti::MatData;

    fn one(v: f64) -> MatData {
        MatData {
            rows: 1,
            cols: 1,
            data: vec![v],
        }
    }

    #[test]
    fn steps_like_the_runtime() {
        // z⁺ = 0.5 z + u + y, x̂ = z + 2y, C = 1 (observer/src/runtime.rs's first test).
        let res = ObserverResource::new(
            "o",
            0.1,
            one(0.5),
            one(1.0),
            one(1.0),
            one(1.0),
            one(2.0),
            one(1.0),
            None,
        )
        .unwrap();
        let mut o = Observer::new(&res);
        o.y[0] = 3.0;
        o.outputs();
        assert_eq!((o.xhat(), o.residual()), (&[6.0][..], &[-3.0][..])); // z0 = 0; r = 3 − 6
        o.u[0] = 10.0;
        o.advance(); // z1 = 0 + 10 + 3
        o.y[0] = 1.0;
        o.outputs();
        assert_eq!(o.xhat(), &[15.0]);
    }

    #[test]
    fn the_initial_estimate_follows_y0_until_the_first_step() {
        // P = [1; 1], Q = [0; 1]: z0 = P⁺(x̂₀ − Q y0) (observer/src/runtime.rs's second test).
        let col = |a: f64, b: f64| MatData {
            rows: 2,
            cols: 1,
            data: vec![a, b],
        };
        let c = MatData {
            rows: 1,
            cols: 2,
            data: vec![1.0, 0.0],
        };
        let res = ObserverResource::new(
            "o",
            0.1,
            one(0.5),
            one(0.0),
            one(1.0),
            col(1.0, 1.0),
            col(0.0, 1.0),
            c,
            Some(vec![4.0, 2.0]),
        )
        .unwrap();
        let mut o = Observer::new(&res);
        o.y[0] = 3.0;
        o.outputs();
        o.y[0] = 1.0;
        o.outputs();
        assert_eq!(o.xhat(), &[2.5, 3.5]); // z0 = (4 + 1)/2 from the y set last
        o.advance(); // z1 = 0.5·2.5 + 1
        o.y[0] = 0.0;
        o.outputs();
        assert_eq!(o.xhat(), &[2.25, 2.25]);
        o.reset();
        o.y[0] = 1.0;
        o.outputs();
        assert_eq!(o.xhat(), &[2.5, 3.5]);
    }
}
