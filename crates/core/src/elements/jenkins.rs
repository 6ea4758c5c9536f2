use super::{check_positive, Element, ElementError, Tangent};

/// Jenkins (elastic Coulomb, Masing, Prandtl) element: a spring of stiffness `k` in series with
/// a Coulomb slider of threshold `F_c` (paper Section 3.4, Fig. 13).
///
/// State: the slider position `w`, so that the spring force is `f = k (u − w)`. The update is
/// the paper's return mapping (Eqs. 9-10): trial `f_tr = k (u − w)` (the stick prediction
/// `f_{i−1} + k (u_i − u_{i−1})` of Eq. 9); stick if `|f_tr| < F_c`, else slip with
/// `f = sgn(f_tr) F_c` and the slider moved to `w = u − f/k`.
///
/// **Stuck-mean convention**: a march starts with the slider at the origin (`w = 0`, the
/// unloaded assembled state), or at the nearest admissible position when `|k u0| ≥ F_c`. A
/// motion that never slips therefore gives `f = k u`, i.e. the stuck linear model, mean included.
#[derive(Clone, Debug)]
pub struct Jenkins {
    stiffness: f64,
    threshold: f64,
    /// Paper form (Eq. 11): the stuck stiffness is in K and the element replaces it (`g = f − k u`).
    replaces_stiffness: bool,
}

impl Jenkins {
    /// Standalone element with its own stiffness `k` (N/m) and slip threshold `F_c` (N).
    pub fn new(stiffness: f64, threshold: f64) -> Result<Self, ElementError> {
        check_positive("jenkins", "stiffness", stiffness)?;
        check_positive("jenkins", "threshold", threshold)?;
        Ok(Jenkins { stiffness, threshold, replaces_stiffness: false })
    }

    /// Paper form (Eqs. 7-11): `k = Vᵀ K V` is already in K and the element replaces it.
    pub fn replacing_stiffness(stiffness: f64, threshold: f64) -> Result<Self, ElementError> {
        Ok(Jenkins { replaces_stiffness: true, ..Self::new(stiffness, threshold)? })
    }

    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    pub fn replaces_stiffness(&self) -> bool {
        self.replaces_stiffness
    }
}

impl Element for Jenkins {
    fn kind(&self) -> &'static str {
        "jenkins"
    }

    fn n_state(&self) -> usize {
        1
    }

    fn initial_state(&self, u0: &[f64], state: &mut [f64], dstate_du0: Option<&mut [f64]>) {
        let (k, fc) = (self.stiffness, self.threshold);
        let f = k * u0[0];
        if f.abs() < fc {
            state[0] = 0.0;
            if let Some(d) = dstate_du0 {
                d[0] = 0.0;
            }
        } else {
            state[0] = u0[0] - f.signum() * fc / k;
            if let Some(d) = dstate_du0 {
                d[0] = 1.0;
            }
        }
    }

    fn replaced_stiffness(&self, _a: usize, _b: usize) -> f64 {
        if self.replaces_stiffness {
            self.stiffness
        } else {
            0.0
        }
    }

    /// When the motion's range exceeds `2 F_c / k`, the slider slips in both directions every
    /// period, and at the period's largest displacement it has just slipped forward: `f = F_c`,
    /// `w = u_max − F_c/k`, whatever happened before.
    fn periodic_start(&self, u: &[f64], n_t: usize, state: &mut [f64], dstate_du: &mut [f64]) -> Option<usize> {
        let u = &u[..n_t];
        // The largest value kept in a register rather than read back at j_max: the same first
        // maximum, without a load on the loop's dependency chain.
        let (mut j_max, mut u_max, mut u_min) = (0, u[0], u[0]);
        for (j, &x) in u.iter().enumerate() {
            if x > u_max {
                (j_max, u_max) = (j, x);
            }
            u_min = u_min.min(x);
        }
        if self.stiffness * (u_max - u_min) <= 2.0 * self.threshold {
            return None;
        }
        state[0] = u_max - self.threshold / self.stiffness;
        dstate_du[0] = 1.0;
        Some(j_max)
    }

    fn slider_stiffness(&self) -> Option<f64> {
        Some(self.stiffness)
    }

    fn update(&self, u: &[f64], _v: &[f64], state: &mut [f64], g: &mut [f64], tangent: Option<&mut Tangent>) {
        let (k, fc) = (self.stiffness, self.threshold);
        let trial = k * (u[0] - state[0]);
        let stuck = trial.abs() < fc;
        let f = if stuck {
            trial
        } else {
            let f = trial.signum() * fc;
            state[0] = u[0] - f / k;
            f
        };
        let linear = if self.replaces_stiffness { k } else { 0.0 };
        g[0] = f - linear * u[0];
        if let Some(t) = tangent {
            // Stick: f = k (u − w), w kept. Slip: f = ±F_c, w = u ∓ F_c/k.
            let (stick, slip) = if stuck { (1.0, 0.0) } else { (0.0, 1.0) };
            t.dg_du[0] = stick * k - linear;
            t.dg_ds[0] = -stick * k;
            t.ds_ds[0] = stick;
            t.ds_du[0] = slip;
        }
    }
}
