use super::{check_positive, Element, ElementError, Tangent};

/// Regularised Coulomb damper: `g = F_c tanh(u̇ / v_reg)`. A rigid-plastic friction law made
/// smooth; `v_reg` (m/s) is the velocity below which the force is proportional to velocity
/// (`F_c / v_reg` N·s/m). No stiffness, no history.
#[derive(Clone, Debug)]
pub struct RegularizedCoulomb {
    threshold: f64,
    velocity_scale: f64,
}

impl RegularizedCoulomb {
    pub fn new(threshold: f64, velocity_scale: f64) -> Result<Self, ElementError> {
        check_positive("coulomb", "threshold", threshold)?;
        check_positive("coulomb", "velocity_scale", velocity_scale)?;
        Ok(RegularizedCoulomb { threshold, velocity_scale })
    }
}

impl Element for RegularizedCoulomb {
    fn kind(&self) -> &'static str {
        "coulomb"
    }

    fn depends_on_velocity(&self) -> bool {
        true
    }

    fn update(&self, _u: &[f64], v: &[f64], _state: &mut [f64], g: &mut [f64], tangent: Option<&mut Tangent>) {
        let t = (v[0] / self.velocity_scale).tanh();
        g[0] = self.threshold * t;
        if let Some(tan) = tangent {
            tan.dg_dv[0] = self.threshold * (1.0 - t * t) / self.velocity_scale;
        }
    }
}
