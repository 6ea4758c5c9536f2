use super::Matrix;

/// Viscous damping of the linear model.
#[derive(Clone, Debug)]
pub enum Damping {
    /// No damping (only allowed where the response stays bounded, e.g. with friction elements
    /// in slip; most solvers need some damping at resonance).
    None,
    /// An explicit damping matrix `D`.
    Matrix(Matrix),
    /// Rayleigh damping `D = α M + β K` (the paper uses `D = α M`, Section 3.3).
    Rayleigh { alpha: f64, beta: f64 },
    /// Modal damping ratios ζ_r for the modes of `(K, M)` in increasing frequency order; modes
    /// beyond the list take the last ratio. `D = M Φ diag(2 ζ_r ω_r) Φᵀ M`.
    Modal { ratios: Vec<f64> },
}

impl Damping {
    /// Modal damping coefficient `c_r` (so that the modal equation is `q̈ + c_r q̇ + ω_r² q`) of
    /// the mode of circular frequency `omega_r` and index `r`, when the damping is diagonal in
    /// the undamped modes. `None` for a general damping matrix.
    pub fn modal_coefficient(&self, r: usize, omega_r: f64) -> Option<f64> {
        match self {
            Damping::None => Some(0.0),
            Damping::Matrix(_) => None,
            Damping::Rayleigh { alpha, beta } => Some(alpha + beta * omega_r * omega_r),
            Damping::Modal { ratios } => {
                let zeta = ratios.get(r).or(ratios.last()).copied().unwrap_or(0.0);
                Some(2.0 * zeta * omega_r)
            }
        }
    }

    /// Is the damping diagonal in the undamped modes (proportional or modal)?
    pub fn is_modal(&self) -> bool {
        !matches!(self, Damping::Matrix(_))
    }
}
