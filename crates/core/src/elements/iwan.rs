use super::{check_positive, Element, ElementError, Tangent};

/// Iwan element: Jenkins elements in parallel with a distribution of slip thresholds, for
/// microslip (Iwan 1966, paper ref. \[32\]). Slider `i` has stiffness `k_i` and threshold
/// `F_i`; the element force is `Σ f_i`, so the response softens gradually from the stuck
/// stiffness `Σ k_i` to zero as sliders break loose one after the other.
///
/// The same stuck-mean convention as [`super::Jenkins`]: every slider starts at the origin.
#[derive(Clone, Debug)]
pub struct Iwan {
    stiffnesses: Vec<f64>,
    thresholds: Vec<f64>,
    replaces_stiffness: bool,
}

impl Iwan {
    /// Sliders with explicit stiffnesses (N/m) and thresholds (N).
    pub fn new(stiffnesses: Vec<f64>, thresholds: Vec<f64>) -> Result<Self, ElementError> {
        if stiffnesses.is_empty() || stiffnesses.len() != thresholds.len() {
            return Err(ElementError {
                element: "iwan",
                message: format!(
                    "needs as many slider stiffnesses as thresholds, at least one: got {} and {}",
                    stiffnesses.len(),
                    thresholds.len()
                ),
            });
        }
        for (&k, &f) in stiffnesses.iter().zip(&thresholds) {
            check_positive("iwan", "slider stiffness", k)?;
            check_positive("iwan", "slider threshold", f)?;
        }
        Ok(Iwan { stiffnesses, thresholds, replaces_stiffness: false })
    }

    /// Total stuck stiffness `k` (N/m) shared equally by `n` sliders whose break-loose
    /// displacements are uniformly spaced, `δ_i = δ_max i / n` (the discretised uniform Iwan
    /// density), scaled so that the force once every slider slips (macroslip) is `F_slip` (N):
    /// `F_i = F_slip · 2i / (n (n+1))`.
    pub fn uniform(stiffness: f64, slip_force: f64, n: usize) -> Result<Self, ElementError> {
        check_positive("iwan", "stiffness", stiffness)?;
        check_positive("iwan", "slip_force", slip_force)?;
        if n == 0 {
            return Err(ElementError { element: "iwan", message: "needs at least one slider (sliders >= 1)".into() });
        }
        let ks = vec![stiffness / n as f64; n];
        let fs = (1..=n).map(|i| slip_force * 2.0 * i as f64 / (n * (n + 1)) as f64).collect();
        Self::new(ks, fs)
    }

    /// Paper form: the total stuck stiffness is in K and the element replaces it.
    pub fn replacing_stiffness(mut self) -> Self {
        self.replaces_stiffness = true;
        self
    }

    /// Total stuck stiffness Σ k_i.
    pub fn stiffness(&self) -> f64 {
        self.stiffnesses.iter().sum()
    }

    /// Force when every slider slips, Σ F_i.
    pub fn gross_slip_force(&self) -> f64 {
        self.thresholds.iter().sum()
    }
}

impl Element for Iwan {
    fn kind(&self) -> &'static str {
        "iwan"
    }

    fn n_state(&self) -> usize {
        self.stiffnesses.len()
    }

    fn initial_state(&self, u0: &[f64], state: &mut [f64], mut dstate_du0: Option<&mut [f64]>) {
        for (i, (&k, &fc)) in self.stiffnesses.iter().zip(&self.thresholds).enumerate() {
            let f = k * u0[0];
            let (w, dw) = if f.abs() < fc { (0.0, 0.0) } else { (u0[0] - f.signum() * fc / k, 1.0) };
            state[i] = w;
            if let Some(d) = dstate_du0.as_deref_mut() {
                d[i] = dw;
            }
        }
    }

    fn replaced_stiffness(&self, _a: usize, _b: usize) -> f64 {
        if self.replaces_stiffness {
            self.stiffness()
        } else {
            0.0
        }
    }

    fn update(&self, u: &[f64], _v: &[f64], state: &mut [f64], g: &mut [f64], mut tangent: Option<&mut Tangent>) {
        let s = self.stiffnesses.len();
        let mut total = 0.0;
        if let Some(t) = tangent.as_deref_mut() {
            t.dg_du[0] = 0.0;
        }
        for i in 0..s {
            let (k, fc) = (self.stiffnesses[i], self.thresholds[i]);
            let trial = k * (u[0] - state[i]);
            let stuck = trial.abs() < fc;
            let f = if stuck {
                trial
            } else {
                let f = trial.signum() * fc;
                state[i] = u[0] - f / k;
                f
            };
            total += f;
            if let Some(t) = tangent.as_deref_mut() {
                let (stick, slip) = if stuck { (1.0, 0.0) } else { (0.0, 1.0) };
                t.dg_du[0] += stick * k;
                t.dg_ds[i] = -stick * k;
                t.ds_ds[i * s + i] = stick;
                t.ds_du[i] = slip;
            }
        }
        let linear = if self.replaces_stiffness { self.stiffness() } else { 0.0 };
        g[0] = total - linear * u[0];
        if let Some(t) = tangent {
            t.dg_du[0] -= linear;
        }
    }
}
