//! Local nonlinear elements: friction joints and other laws (paper Section 3.4).
//!
//! # Sign convention
//!
//! An element sees `u = Vᵀ U` on its application vectors (the columns of `V`, Eq. 8) and
//! returns a **restoring force** `g` applied as `V g` on the left-hand side:
//!
//! ```text
//! M Ü + D U̇ + K U + V g(u, u̇, history) = F cos Ωt
//! ```
//!
//! so the paper's `F_nl = (k_J u − f) V` (Eq. 11) is `g = f − k_J u` here: the Jenkins element in
//! its *paper form* removes the stuck stiffness `k_J = Vᵀ K V` (Eq. 7) that K contains and puts
//! the elastic-Coulomb force `f` (Eqs. 9-10) in its place. A *standalone* element adds its own
//! stiffness (`g = f`).
//!
//! # One law, two users
//!
//! An element is its incremental law, sample by sample ([`Element::update`]): the harmonic
//! balance marches it over periods of a trial motion (AFT) and the time integrator over time
//! steps. Both get the partial derivatives in [`Tangent`], from which the harmonic balance builds
//! its analytic Jacobian by the chain rule through the recursion.

mod contact;
mod coulomb;
mod cubic;
mod iwan;
mod jenkins;

pub use contact::{Contact, MAX_FRICTION_COEFFICIENT};
pub use coulomb::RegularizedCoulomb;
pub use cubic::CubicSpring;
pub use iwan::Iwan;
pub use jenkins::Jenkins;

/// Partial derivatives of one update of an element with `d` directions and `s` state variables,
/// all row-major: `dg_du[a*d + b] = ∂g_a/∂u_b`, `dg_ds[a*s + m] = ∂g_a/∂state_m` (state before
/// the update), `ds_du[m*d + b] = ∂state'_m/∂u_b`, `ds_ds[m*s + l] = ∂state'_m/∂state_l`.
#[derive(Clone, Debug, Default)]
pub struct Tangent {
    pub dg_du: Vec<f64>,
    pub dg_dv: Vec<f64>,
    pub dg_ds: Vec<f64>,
    pub ds_du: Vec<f64>,
    pub ds_dv: Vec<f64>,
    pub ds_ds: Vec<f64>,
}

impl Tangent {
    /// Zeroed tangent for `d` directions and `s` state variables.
    pub fn new(d: usize, s: usize) -> Self {
        Tangent {
            dg_du: vec![0.0; d * d],
            dg_dv: vec![0.0; d * d],
            dg_ds: vec![0.0; d * s],
            ds_du: vec![0.0; s * d],
            ds_dv: vec![0.0; s * d],
            ds_ds: vec![0.0; s * s],
        }
    }

    /// Set every entry to zero.
    pub fn clear(&mut self) {
        for v in [&mut self.dg_du, &mut self.dg_dv, &mut self.dg_ds, &mut self.ds_du, &mut self.ds_dv, &mut self.ds_ds]
        {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    }
}

/// Invalid element parameters.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("{element}: {message}")]
pub struct ElementError {
    pub element: &'static str,
    pub message: String,
}

pub(crate) fn check_positive(element: &'static str, name: &str, value: f64) -> Result<(), ElementError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ElementError { element, message: format!("{name} must be a finite number > 0, got {value}") })
    }
}

/// A local nonlinear law acting on `d` application directions.
pub trait Element: Send + Sync + std::fmt::Debug {
    /// Short name of the law ("jenkins", "iwan", ...).
    fn kind(&self) -> &'static str;

    /// Number of application directions `d` (columns of `V`) the element sees.
    fn n_dirs(&self) -> usize {
        1
    }

    /// Number of internal (history) variables; 0 for memoryless laws.
    fn n_state(&self) -> usize {
        0
    }

    /// Does `g` depend on the velocity `u̇`? (Rate-independent laws such as friction with
    /// elastic Coulomb sliders do not.)
    fn depends_on_velocity(&self) -> bool {
        false
    }

    /// State at the start of a march beginning at displacement `u0`, and `∂state/∂u0`
    /// (row-major `s × d`) if asked. This is the convention that fixes the indeterminate mean
    /// force of a hysteretic element that never slips; each law documents its choice.
    fn initial_state(&self, _u0: &[f64], _state: &mut [f64], _dstate_du0: Option<&mut [f64]>) {}

    /// One step of the law: from the state before (updated in place to the state after), the
    /// displacement `u` and velocity `v` now, write the restoring force `g` and, if asked, the
    /// partial derivatives. The tangent starts zeroed and is reused from call to call without
    /// clearing (this runs for every time sample): a law writes, at every call, every entry it
    /// ever makes non-zero.
    fn update(&self, u: &[f64], v: &[f64], state: &mut [f64], g: &mut [f64], tangent: Option<&mut Tangent>);

    /// A sample of the periodic motion `u` (`u[a·n_t + j]`, `n_t` samples per period) at which
    /// the law's periodic-regime state is known from the motion alone, with that state (the
    /// state *after* the update at that sample) and its derivative with respect to `u` there
    /// (row-major `s × d`). Marching one period from there gives the periodic regime at once;
    /// `None` (the default) means: march from [`Element::initial_state`] until periodic.
    fn periodic_start(&self, _u: &[f64], _n_t: usize, _state: &mut [f64], _dstate_du: &mut [f64]) -> Option<usize> {
        None
    }

    /// For an elastic–perfectly-plastic slider (one direction, one state: the slider position,
    /// rate independent, as Jenkins), its spring stiffness `k`. The harmonic balance then builds
    /// the AFT Jacobian in closed form (see `hbm::element_aft`) instead of differentiating
    /// sample by sample. `None` (the default): the generic chain rule.
    fn slider_stiffness(&self) -> Option<f64> {
        None
    }

    /// Is the law odd: the force history of the motion `−u` is `−g`, and a symmetric motion
    /// has one periodic regime? Then a half-wave symmetric motion, `u(t + T/2) = −u(t)`, has
    /// half-wave symmetric forces, and a balance of such elements can pin its even harmonics
    /// at zero. Default: no.
    fn odd_symmetric(&self) -> bool {
        false
    }

    /// Entry `(a, b)` of the d×d stiffness `K_r` of the linear model that the element replaces
    /// (paper form, Eq. 11: `k_J`, a 1×1 matrix for a Jenkins element; `Vᵀ K V` of a stuck
    /// contact), so that the joint's own force is `f = g + K_r u`; 0 for elements that add to
    /// the model.
    fn replaced_stiffness(&self, _a: usize, _b: usize) -> f64 {
        0.0
    }

    /// For a slider ([`Element::slider_stiffness`]: one direction, one state, no velocity):
    /// [`Element::update`] at the samples `range` of the motion `u`, `v` in order, from `state`
    /// (updated), each force into `g[j]` and [`Element::is_slipping`] of each step into
    /// `slipping[j]`. The same steps as calling both per sample; one call per stretch of a
    /// period lets them inline (the AFT runs this for every sample at every Newton iteration).
    fn update_slider_samples(
        &self,
        u: &[f64],
        v: &[f64],
        range: std::ops::Range<usize>,
        state: &mut f64,
        g: &mut [f64],
        slipping: &mut [bool],
    ) {
        let mut after = [*state];
        let mut force = [0.0];
        for j in range {
            let before = after;
            self.update(&u[j..j + 1], &v[j..j + 1], &mut after, &mut force, None);
            g[j] = force[0];
            slipping[j] = self.is_slipping(&before, &after);
        }
        *state = after[0];
    }

    /// Is the element slipping over this step (state before → after)? Used for the stick
    /// fraction and the slider velocity (Eq. 33). Memoryless laws never stick.
    fn is_slipping(&self, state_before: &[f64], state_after: &[f64]) -> bool {
        state_before.iter().zip(state_after).any(|(a, b)| a != b) || self.n_state() == 0
    }
}
