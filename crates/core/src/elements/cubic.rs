use super::{Element, ElementError, Tangent};

/// Cubic spring `g = k3 u³` (Duffing stiffness; `k3 < 0` softens).
#[derive(Clone, Debug)]
pub struct CubicSpring {
    k3: f64,
}

impl CubicSpring {
    pub fn new(k3: f64) -> Result<Self, ElementError> {
        if !k3.is_finite() {
            return Err(ElementError { element: "cubic", message: format!("k3 must be finite, got {k3}") });
        }
        Ok(CubicSpring { k3 })
    }
}

impl Element for CubicSpring {
    fn kind(&self) -> &'static str {
        "cubic"
    }

    fn update(&self, u: &[f64], _v: &[f64], _state: &mut [f64], g: &mut [f64], tangent: Option<&mut Tangent>) {
        g[0] = self.k3 * u[0] * u[0] * u[0];
        if let Some(t) = tangent {
            t.dg_du[0] = 3.0 * self.k3 * u[0] * u[0];
        }
    }
}
