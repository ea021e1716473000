//! Matrix norms used by the tolerances and scalings of every decomposition.

use nalgebra::DMatrix;

/// ‖M‖₁, the largest column sum of |mᵢⱼ|.
pub fn one_norm(m: &DMatrix<f64>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}
