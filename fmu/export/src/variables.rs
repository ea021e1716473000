//! The FMU's variables and their value references, shared by the modelDescription writer and
//! the library so that both number them the same way.
//!
//! ```text
//! 0                 time      independent
//! 1 … l             u_1 … u_l      input   (the known input held over [t_k, t_{k+1}))
//! l+1 … l+p         y_1 … y_p      input   (the measured output at t_k)
//! l+p+1 … l+p+n     xhat_1 … xhat_n output  x̂_k = P z_k + Q y_k
//! l+p+n+1 … +p      r_1 … r_p      output  r_k = y_k − C x̂_k
//! ```
//!
//! In FMI 2 a variable's index in ModelVariables is its value reference + 1.

use crate::resource::Dims;

/// What a variable is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Simulation time.
    Time,
    /// Known input u_i (0-based).
    U(usize),
    /// Measured output y_j.
    Y(usize),
    /// Estimate x̂_i.
    Xhat(usize),
    /// Residual r_j.
    R(usize),
}

/// Value references of one observer's variables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// The observer's dimensions.
    pub dims: Dims,
}

impl Layout {
    /// Number of variables, time included.
    pub fn len(&self) -> usize {
        let Dims { n, l, p, .. } = self.dims;
        1 + l + 2 * p + n
    }

    /// Never: `time` is always there.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The variable of value reference `vr`, if any.
    pub fn role(&self, vr: u32) -> Option<Role> {
        let Dims { n, l, p, .. } = self.dims;
        let v = vr as usize;
        Some(match v {
            0 => Role::Time,
            v if v <= l => Role::U(v - 1),
            v if v <= l + p => Role::Y(v - 1 - l),
            v if v <= l + p + n => Role::Xhat(v - 1 - l - p),
            v if v <= l + 2 * p + n => Role::R(v - 1 - l - p - n),
            _ => return None,
        })
    }

    /// The value reference of a variable.
    pub fn vr(&self, role: Role) -> u32 {
        let Dims { n, l, p, .. } = self.dims;
        (match role {
            Role::Time => 0,
            Role::U(i) => 1 + i,
            Role::Y(j) => 1 + l + j,
            Role::Xhat(i) => 1 + l + p + i,
            Role::R(j) => 1 + l + p + n + j,
        }) as u32
    }

    /// Every variable in value-reference order.
    pub fn roles(&self) -> impl Iterator<Item = Role> + '_ {
        (0..self.len() as u32).map(|vr| self.role(vr).expect("in range"))
    }

    /// The variable's name in the modelDescription.
    pub fn name(&self, role: Role) -> String {
        match role {
            Role::Time => "time".into(),
            Role::U(i) => format!("u_{}", i + 1),
            Role::Y(j) => format!("y_{}", j + 1),
            Role::Xhat(i) => format!("xhat_{}", i + 1),
            Role::R(j) => format!("r_{}", j + 1),
        }
    }
}

/// The inputs y_m each output depends on (0-based output indices into y), from the structure of
/// Q and C: x̂_i = (P z)_i + Σ_m Q_im y_m, r_j = y_j − Σ_i C_ji x̂_i. With an initial estimate,
/// x̂_0 = P P⁺(x̂₀ − Q y_0) + Q y_0 may involve every y: then every output depends on every y.
/// u never acts on an output directly (only on z⁺).
pub fn dependencies(
    role: Role,
    q: &lti::MatData,
    c: &lti::MatData,
    with_xhat0: bool,
) -> Vec<usize> {
    let p = q.cols;
    let q_at = |i: usize, m: usize| q.data[i * q.cols + m] != 0.0;
    match role {
        Role::Xhat(_) | Role::R(_) if with_xhat0 => (0..p).collect(),
        Role::Xhat(i) => (0..p).filter(|&m| q_at(i, m)).collect(),
        Role::R(j) => (0..p)
            .filter(|&m| m == j || (0..c.cols).any(|i| c.data[j * c.cols + i] != 0.0 && q_at(i, m)))
            .collect(),
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lti::MatData;

    #[test]
    fn value_references_number_every_variable_once() {
        let lay = Layout {
            dims: Dims {
                n: 3,
                r: 2,
                l: 2,
                p: 2,
            },
        };
        assert_eq!(lay.len(), 10);
        for (vr, role) in lay.roles().enumerate() {
            assert_eq!(lay.vr(role), vr as u32);
        }
        assert_eq!(lay.role(3), Some(Role::Y(0)));
        assert_eq!(lay.role(5), Some(Role::Xhat(0)));
        assert_eq!(lay.role(9), Some(Role::R(1)));
        assert_eq!(lay.role(10), None);
        assert_eq!(lay.name(Role::Xhat(2)), "xhat_3");
    }

    #[test]
    fn dependencies_follow_q_and_c() {
        // Q = [[0, 1], [0, 0]], C = [[1, 0], [0, 1]]: x̂_1 on y_2, x̂_2 on none; r_1 on y_1, y_2.
        let q = MatData {
            rows: 2,
            cols: 2,
            data: vec![0.0, 1.0, 0.0, 0.0],
        };
        let c = MatData {
            rows: 2,
            cols: 2,
            data: vec![1.0, 0.0, 0.0, 1.0],
        };
        assert_eq!(dependencies(Role::Xhat(0), &q, &c, false), [1]);
        assert!(dependencies(Role::Xhat(1), &q, &c, false).is_empty());
        assert_eq!(dependencies(Role::R(0), &q, &c, false), [0, 1]);
        assert_eq!(dependencies(Role::R(1), &q, &c, false), [1]);
        assert_eq!(dependencies(Role::Xhat(1), &q, &c, true), [0, 1]);
        assert!(dependencies(Role::U(0), &q, &c, false).is_empty());
    }
}
