//! One implicit step of the Newmark family with local nonlinear elements.
//!
//! # The step
//!
//! HHT-α (Hilber, Hughes, Taylor 1977; α = 0 is Newmark's average acceleration) writes Eq. 12
//! at `t_{n+1+α} = t_{n+1} + α h`:
//!
//! ```text
//! M a_{n+1} + (1+α)(D v_{n+1} + K u_{n+1} + V g_{n+1}) − α (D v_n + K u_n + V g_n) = F(t_{n+1+α})
//! u_{n+1} = ũ + β h² a_{n+1},   ũ = u_n + h v_n + h² (½ − β) a_n
//! v_{n+1} = ṽ + γ h a_{n+1},    ṽ = v_n + h (1 − γ) a_n
//! ```
//!
//! With `c0 = 1/(βh²)`, `c1 = γ/(βh)` and `S = c0 M + (1+α)(c1 D + K)` this is
//! `S u_{n+1} + (1+α) V g(Vᵀu_{n+1}, Vᵀv_{n+1}) = b`. S is factorised once per step size.
//! Writing `u_lin = S⁻¹ b`, `W = S⁻¹ V`, `C = Vᵀ W` (q × q) the step reduces **exactly** to the
//! q element coordinates `z = Vᵀ u_{n+1}`:
//!
//! ```text
//! R(z) = z − Vᵀ u_lin + (1+α) C g(z, ż(z)) = 0,   ż(z) = Vᵀ ṽ + c1 (z − Vᵀ ũ)
//! ```
//!
//! solved by Newton with the consistent tangent `J = I + (1+α) C (∂g/∂u + c1 ∂g/∂v)`, every
//! evaluation starting from the committed history (the state at t_n). Then
//! `u_{n+1} = u_lin − (1+α) W g`. A step costs one solve with S plus O(n q) work, whatever the
//! number of Newton iterations; at the paper's size (n = 137, q = 4) a few matrix-vector products.
//!
//! # Stick/slip transitions
//!
//! The Jenkins and Iwan laws are return mappings (Eqs. 9-10): for a given displacement
//! increment over the step their state update is exact whatever the step, and Newton on the
//! piecewise-linear `R(z)` terminates once the stick/slip set of the step is settled (damped
//! steps guard against cycling between two sets). No event location (substepping to the
//! transition instant) is done, deliberately: across a Jenkins transition the friction force
//! is continuous and only its time derivative jumps (stick → slip) or its second derivative
//! (slip → stick, which happens at a velocity reversal), so the acceleration is continuous and
//! the trapezoidal rule's local error in a step containing a transition stays O(h³). With a
//! fixed number of transitions per period the global error stays O(h²), which the convergence
//! test confirms; locating the instants would cost extra solves for no gain in order. A
//! reversal inside a slipping step leaves the slider off by O(h²), and the next slip resets it
//! (`w = u ∓ F_c/k`), so errors do not accumulate: the slider does not drift.

use super::operator::{effective_solver, mass_solver, LinearOperators, Operator, SpdSolver};
use super::TimesimError;
use crate::elements::Tangent;
use crate::model::NonlinearModel;

/// Implicit time integration scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scheme {
    /// Newmark average acceleration (trapezoidal rule, β = 1/4, γ = 1/2): second order,
    /// unconditionally stable, no numerical damping; a harmonic of circular frequency ω is
    /// integrated as if it were at `(2/h) tan(ωh/2) ≈ ω (1 + (ωh)²/12)` (period error).
    AverageAcceleration,
    /// Hilber-Hughes-Taylor α-method, `α ∈ [−1/3, 0]` (β = (1−α)²/4, γ = ½ − α): second
    /// order, with numerical damping of the high frequencies growing as α decreases.
    Hht { alpha: f64 },
}

impl Scheme {
    /// `(α, β, γ)`.
    pub fn parameters(self) -> Result<(f64, f64, f64), TimesimError> {
        match self {
            Scheme::AverageAcceleration => Ok((0.0, 0.25, 0.5)),
            Scheme::Hht { alpha } if (-1.0 / 3.0..=0.0).contains(&alpha) => {
                Ok((alpha, (1.0 - alpha).powi(2) / 4.0, 0.5 - alpha))
            }
            Scheme::Hht { alpha } => Err(TimesimError::Invalid(format!(
                "HHT alpha must be in [-1/3, 0] (0 is average acceleration, -0.05 a usual choice), got {alpha}"
            ))),
        }
    }
}

/// Work done since the start of the integration (J), accumulated with the quadratures that
/// make Newmark's average acceleration conserve energy exactly: over any step,
/// `ΔT + ΔV_K + viscous + Σ elements = input` to round-off. HHT weights the forces at
/// `t_{n+1+α}`, so for it the balance holds only to second order in `ωh`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnergyTally {
    /// Work of the excitation `Σ Δuᵀ (F_n + F_{n+1})/2`.
    pub input: f64,
    /// Viscous dissipation `Σ (h/4)(v_n + v_{n+1})ᵀ D (v_n + v_{n+1})`.
    pub viscous: f64,
    /// Work absorbed by each element, `Σ Δz_eᵀ (g_n + g_{n+1})/2` (over a closed cycle the
    /// energy it dissipates; paper-form elements' stiffness part integrates to zero).
    pub elements: Vec<f64>,
}

/// The state of the integration at one instant.
#[derive(Clone, Debug)]
pub struct State {
    pub time: f64,
    pub displacement: Vec<f64>,
    pub velocity: Vec<f64>,
    pub acceleration: Vec<f64>,
    /// `z = Vᵀ U` for every application direction, element by element.
    pub element_displacement: Vec<f64>,
    /// `ż = Vᵀ U̇`.
    pub element_velocity: Vec<f64>,
    /// Element restoring forces `g` (the law's convention: paper-form elements return
    /// `f − k u`, see [`crate::elements`]).
    pub element_force: Vec<f64>,
    /// History variables of all elements, concatenated.
    pub element_history: Vec<f64>,
    /// Did each element slip over the last step?
    pub slipping: Vec<bool>,
    pub energy: EnergyTally,
    /// Value of the excitation's time function at `time`.
    pub(crate) excitation: f64,
    /// Cached `D v` at `time`, and `K u` (kept current only where it is used: HHT, sparse models).
    ku: Vec<f64>,
    dv: Vec<f64>,
}

impl State {
    /// Slider velocity of every direction (paper Eq. 33): `0` when the element sticks, `ż`
    /// when it slips.
    pub fn slider_velocity(&self, model: &NonlinearModel, out: &mut [f64]) {
        let mut a = 0;
        for (e, site) in model.elements.iter().enumerate() {
            for _ in 0..site.law.n_dirs() {
                out[a] = if self.slipping[e] { self.element_velocity[a] } else { 0.0 };
                a += 1;
            }
        }
    }
}

/// Newton stops when `|R|∞` is below this fraction of the element displacement scale. For the
/// piecewise-linear friction laws the residual drops to round-off (~1e-16 relative) as soon as
/// the stick/slip set of the step is right; smooth laws converge quadratically, so the margin
/// to round-off costs at most one more iteration.
const NEWTON_TOLERANCE: f64 = 1e-11;
const NEWTON_MAX_ITERATIONS: usize = 60;

/// Implicit integrator for one model, one scheme and one step size.
#[derive(Debug)]
pub struct Integrator<'m> {
    model: &'m NonlinearModel,
    step: f64,
    alpha: f64,
    beta: f64,
    gamma: f64,
    c0: f64,
    c1: f64,
    operators: LinearOperators,
    solver: SpdSolver,
    folded: Option<FoldedDense>,
    /// Application vectors, direction-major: direction `a` is `dirs[a*n..(a+1)*n]`.
    dirs: Vec<f64>,
    /// `W = S⁻¹ V`, same layout.
    w: Vec<f64>,
    /// `C = Vᵀ S⁻¹ V`, row-major q × q.
    c: Vec<f64>,
    /// Per element: (first direction, first history variable).
    offsets: Vec<(usize, usize)>,
    q: usize,
    work: Work,
}

/// Dense models: the solve with S folded into precomputed products,
/// `u_lin = P_M ũ + P_D ((1+α)(c1 ũ − ṽ) + α v_n) + α P_K u_n + α W g_n + e S⁻¹F`
/// with `P_M = c0 S⁻¹ M`, `P_D = S⁻¹ D`, `P_K = S⁻¹ K`: three n × n products per step
/// instead of four (average acceleration), four instead of five (HHT).
#[derive(Debug)]
struct FoldedDense {
    pm: Operator,
    pd: Operator,
    /// HHT only.
    pk: Option<Operator>,
    /// The load whose response `S⁻¹ F` is cached (NaN until the first step).
    load: Vec<f64>,
    load_response: Vec<f64>,
}

/// Scratch of a step, allocated once.
#[derive(Debug)]
struct Work {
    u_pred: Vec<f64>,
    v_pred: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    tmp: Vec<f64>,
    rhs: Vec<f64>,
    u_lin: Vec<f64>,
    u_new: Vec<f64>,
    v_new: Vec<f64>,
    a_new: Vec<f64>,
    dv_new: Vec<f64>,
    z_lin: Vec<f64>,
    z_pred: Vec<f64>,
    zv_pred: Vec<f64>,
    z: Vec<f64>,
    z_try: Vec<f64>,
    zv: Vec<f64>,
    g: Vec<f64>,
    g_try: Vec<f64>,
    dz: Vec<f64>,
    residual: Vec<f64>,
    residual_try: Vec<f64>,
    jac: Vec<f64>,
    /// Element tangent (∂g/∂u + c1 ∂g/∂v), block diagonal, row-major q × q.
    b: Vec<f64>,
    b_try: Vec<f64>,
    history: Vec<f64>,
    history_try: Vec<f64>,
    tangents: Vec<Tangent>,
}

impl<'m> Integrator<'m> {
    /// Factorise the linear part for step `step` (s).
    pub fn new(model: &'m NonlinearModel, scheme: Scheme, step: f64) -> Result<Self, TimesimError> {
        if !(step.is_finite() && step > 0.0) {
            return Err(TimesimError::InvalidStep(step));
        }
        let (alpha, beta, gamma) = scheme.parameters()?;
        model.check_no_rigid_contacts("the time integrator")?;
        let lin = &model.linear;
        lin.check()?;
        let n = lin.n_dofs();
        let c0 = 1.0 / (beta * step * step);
        let c1 = gamma / (beta * step);
        let operators = LinearOperators::new(lin)?;
        let mut solver = effective_solver(lin, &operators, c0, (1.0 + alpha) * c1, 1.0 + alpha)?;
        let folded = match &solver {
            SpdSolver::DenseInverse(inv) => {
                let fold = |a: &faer::Mat<f64>, scale: f64| Operator::from_dense(&(faer::Scale(scale) * (inv * a)));
                Some(FoldedDense {
                    pm: fold(&lin.mass.to_dense(), c0),
                    pd: fold(&operators.damping.to_dense(lin), 1.0),
                    pk: (alpha != 0.0).then(|| fold(&lin.stiffness.to_dense(), 1.0)),
                    load: vec![f64::NAN; n],
                    load_response: vec![0.0; n],
                })
            }
            SpdSolver::Sparse { .. } | SpdSolver::Diagonal(_) => None,
        };
        let q = model.n_directions();
        let dirs: Vec<f64> = model.application_vectors().flat_map(|v| v.iter().copied()).collect();
        let mut w = vec![0.0; q * n];
        for a in 0..q {
            solver.solve(&dirs[a * n..(a + 1) * n], &mut w[a * n..(a + 1) * n]);
        }
        let mut c = vec![0.0; q * q];
        for a in 0..q {
            for b in 0..q {
                c[a * q + b] = dot(&dirs[a * n..(a + 1) * n], &w[b * n..(b + 1) * n]);
            }
        }
        let mut offsets = Vec::with_capacity(model.elements.len());
        let (mut da, mut ds) = (0, 0);
        for e in &model.elements {
            offsets.push((da, ds));
            da += e.law.n_dirs();
            ds += e.law.n_state();
        }
        let tangents = model.elements.iter().map(|e| Tangent::new(e.law.n_dirs(), e.law.n_state())).collect();
        let vq = || vec![0.0; q];
        let vn = || vec![0.0; n];
        let work = Work {
            u_pred: vn(),
            v_pred: vn(),
            x: vn(),
            y: vn(),
            tmp: vn(),
            rhs: vn(),
            u_lin: vn(),
            u_new: vn(),
            v_new: vn(),
            a_new: vn(),
            dv_new: vn(),
            z_lin: vq(),
            z_pred: vq(),
            zv_pred: vq(),
            z: vq(),
            z_try: vq(),
            zv: vq(),
            g: vq(),
            g_try: vq(),
            dz: vq(),
            residual: vq(),
            residual_try: vq(),
            jac: vec![0.0; q * q],
            b: vec![0.0; q * q],
            b_try: vec![0.0; q * q],
            history: vec![0.0; ds],
            history_try: vec![0.0; ds],
            tangents,
        };
        Ok(Integrator {
            model,
            step,
            alpha,
            beta,
            gamma,
            c0,
            c1,
            operators,
            solver,
            folded,
            dirs,
            w,
            c,
            offsets,
            q,
            work,
        })
    }

    pub fn step_size(&self) -> f64 {
        self.step
    }

    pub fn model(&self) -> &'m NonlinearModel {
        self.model
    }

    /// Total number of element directions `q`.
    pub fn n_directions(&self) -> usize {
        self.q
    }

    /// The scheme's `(α, β, γ)`.
    pub fn parameters(&self) -> (f64, f64, f64) {
        (self.alpha, self.beta, self.gamma)
    }

    /// Continue from `previous` (displacement, velocity and element history kept) at time 0
    /// under the force `excitation · load`: the acceleration and the element forces are
    /// recomputed for this load, the energy tally restarts at zero. For stepped sines, where
    /// each frequency starts from the last state of the previous one.
    pub fn resume(&self, previous: &State, load: &[f64], excitation: f64) -> Result<State, TimesimError> {
        let n = self.model.linear.n_dofs();
        if previous.displacement.len() != n || previous.element_history.len() != self.work.history.len() {
            return Err(TimesimError::Invalid(format!(
                "the initial state has {} DOFs and {} history variables, the model {} and {}",
                previous.displacement.len(),
                previous.element_history.len(),
                n,
                self.work.history.len()
            )));
        }
        let mut state = self.start(0.0, &previous.displacement, &previous.velocity, load, excitation)?;
        state.element_history.copy_from_slice(&previous.element_history);
        self.initial_forces(&mut state, load, excitation)?;
        Ok(state)
    }

    /// State at time `time` with displacement `u0` and velocity `v0`, the elements' history
    /// from their [`crate::elements::Element::initial_state`] convention and the acceleration
    /// from the equation of motion under the force `excitation · load`.
    pub fn start(
        &self,
        time: f64,
        u0: &[f64],
        v0: &[f64],
        load: &[f64],
        excitation: f64,
    ) -> Result<State, TimesimError> {
        let lin = &self.model.linear;
        let n = lin.n_dofs();
        for (what, x) in [("initial displacement", u0), ("initial velocity", v0), ("load", load)] {
            if x.len() != n {
                return Err(TimesimError::WrongLength { what: what.into(), len: x.len(), expected: n });
            }
            if x.iter().any(|v| !v.is_finite()) {
                return Err(TimesimError::Invalid(format!("the {what} contains a non-finite value")));
            }
        }
        let q = self.q;
        let mut z = vec![0.0; q];
        let mut zv = vec![0.0; q];
        self.project(u0, &mut z);
        self.project(v0, &mut zv);
        let n_hist: usize = self.model.elements.iter().map(|e| e.law.n_state()).sum();
        let mut history = vec![0.0; n_hist];
        for (e, site) in self.model.elements.iter().enumerate() {
            let (da, ds) = self.offsets[e];
            let (d, s) = (site.law.n_dirs(), site.law.n_state());
            site.law.initial_state(&z[da..da + d], &mut history[ds..ds + s], None);
        }
        let mut state = State {
            time,
            displacement: u0.to_vec(),
            velocity: v0.to_vec(),
            acceleration: vec![0.0; n],
            element_displacement: z,
            element_velocity: zv,
            element_force: vec![0.0; q],
            element_history: history,
            slipping: vec![false; self.model.elements.len()],
            energy: EnergyTally { elements: vec![0.0; self.model.elements.len()], ..Default::default() },
            excitation,
            ku: vec![0.0; n],
            dv: vec![0.0; n],
        };
        self.initial_forces(&mut state, load, excitation)?;
        Ok(state)
    }

    /// Element forces from the state's history (an update at the same displacement leaves a
    /// return-mapped history unchanged), `K u`, `D v`, and the acceleration
    /// `M⁻¹ (e · load − D v − K u − V g)`.
    fn initial_forces(&self, state: &mut State, load: &[f64], excitation: f64) -> Result<(), TimesimError> {
        let lin = &self.model.linear;
        let n = lin.n_dofs();
        let mut mass = mass_solver(lin)?;
        for (e, site) in self.model.elements.iter().enumerate() {
            let (da, ds) = self.offsets[e];
            let (d, s) = (site.law.n_dirs(), site.law.n_state());
            site.law.update(
                &state.element_displacement[da..da + d],
                &state.element_velocity[da..da + d],
                &mut state.element_history[ds..ds + s],
                &mut state.element_force[da..da + d],
                None,
            );
        }
        let mut tmp = vec![0.0; n];
        self.operators.stiffness.apply(&state.displacement, &mut state.ku);
        self.operators.damp(&state.velocity, &mut state.dv, &mut tmp);
        let mut rhs: Vec<f64> = (0..n).map(|i| excitation * load[i] - state.ku[i] - state.dv[i]).collect();
        for a in 0..self.q {
            axpy(-state.element_force[a], &self.dirs[a * n..(a + 1) * n], &mut rhs);
        }
        mass.solve(&rhs, &mut state.acceleration);
        state.excitation = excitation;
        Ok(())
    }

    /// Advance `state` by one step under the force `F(t) = e(t) · load`, given
    /// `e(t_{n+1} + α h)` (`excitation_eval`, the HHT evaluation instant) and `e(t_{n+1})`
    /// (`excitation_end`, for the energy tally). Does not allocate.
    pub fn step(
        &mut self,
        state: &mut State,
        load: &[f64],
        excitation_eval: f64,
        excitation_end: f64,
    ) -> Result<(), TimesimError> {
        let lin = &self.model.linear;
        let n = lin.n_dofs();
        let q = self.q;
        let (h, alpha, beta, gamma, c0, c1) = (self.step, self.alpha, self.beta, self.gamma, self.c0, self.c1);
        let ap = 1.0 + alpha;
        let wk = &mut self.work;

        // Predictors, then u_lin = S⁻¹ b (the solution without the element forces at t_{n+1}).
        for i in 0..n {
            let (u, v, a) = (state.displacement[i], state.velocity[i], state.acceleration[i]);
            wk.u_pred[i] = u + h * v + h * h * (0.5 - beta) * a;
            wk.v_pred[i] = v + h * (1.0 - gamma) * a;
        }
        if let Some(fd) = &mut self.folded {
            if fd.load.as_slice() != load {
                fd.load.copy_from_slice(load);
                self.solver.solve(load, &mut fd.load_response);
            }
            for i in 0..n {
                wk.x[i] = ap * (c1 * wk.u_pred[i] - wk.v_pred[i]) + alpha * state.velocity[i];
            }
            fd.pm.apply(&wk.u_pred, &mut wk.u_lin);
            fd.pd.apply(&wk.x, &mut wk.y);
            for i in 0..n {
                wk.u_lin[i] += wk.y[i] + excitation_eval * fd.load_response[i];
            }
            if let Some(pk) = &fd.pk {
                pk.apply(&state.displacement, &mut wk.y);
                axpy(alpha, &wk.y, &mut wk.u_lin);
                for a in 0..q {
                    axpy(alpha * state.element_force[a], &self.w[a * n..(a + 1) * n], &mut wk.u_lin);
                }
            }
        } else {
            // b = M c0 ũ + D (1+α)(c1 ũ − ṽ) + α (D v_n + K u_n + V g_n) + e F.
            for i in 0..n {
                wk.x[i] = c0 * wk.u_pred[i];
            }
            self.operators.mass.apply(&wk.x, &mut wk.rhs);
            for i in 0..n {
                wk.x[i] = ap * (c1 * wk.u_pred[i] - wk.v_pred[i]);
            }
            self.operators.damp(&wk.x, &mut wk.y, &mut wk.tmp);
            for i in 0..n {
                wk.rhs[i] += wk.y[i] + alpha * (state.dv[i] + state.ku[i]) + excitation_eval * load[i];
            }
            if alpha != 0.0 {
                for a in 0..q {
                    axpy(alpha * state.element_force[a], &self.dirs[a * n..(a + 1) * n], &mut wk.rhs);
                }
            }
            self.solver.solve(&wk.rhs, &mut wk.u_lin);
        }

        if q > 0 {
            for a in 0..q {
                let va = &self.dirs[a * n..(a + 1) * n];
                wk.z_lin[a] = dot(va, &wk.u_lin);
                wk.z_pred[a] = dot(va, &wk.u_pred);
                wk.zv_pred[a] = dot(va, &wk.v_pred);
            }
            // Initial guess: the element forces frozen at t_n.
            for a in 0..q {
                wk.z[a] = wk.z_lin[a] - ap * (0..q).map(|b| self.c[a * q + b] * state.element_force[b]).sum::<f64>();
            }
            let scale = wk.z_lin.iter().chain(&wk.z_pred).fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
            let tol = NEWTON_TOLERANCE * scale;
            let mut norm = evaluate(self.model, &self.offsets, &self.c, ap, c1, &state.element_history, wk, false);
            let mut iterations = 0;
            while norm > tol {
                iterations += 1;
                if iterations > NEWTON_MAX_ITERATIONS {
                    return Err(TimesimError::NewtonFailed { time: state.time + h, iterations, residual: norm });
                }
                // J = I + (1+α) C B; J Δ = −R.
                for a in 0..q {
                    for b in 0..q {
                        let cb: f64 = (0..q).map(|m| self.c[a * q + m] * wk.b[m * q + b]).sum();
                        wk.jac[a * q + b] = if a == b { 1.0 } else { 0.0 } + ap * cb;
                    }
                    wk.dz[a] = -wk.residual[a];
                }
                if !solve_small(q, &mut wk.jac, &mut wk.dz) {
                    return Err(TimesimError::NewtonFailed { time: state.time + h, iterations, residual: norm });
                }
                // Damped Newton: halve the step until |R| decreases (the laws are piecewise
                // linear, so full steps are taken except when the iterate cycles between
                // two stick/slip sets).
                let mut lambda = 1.0;
                loop {
                    for a in 0..q {
                        wk.z_try[a] = wk.z[a] + lambda * wk.dz[a];
                    }
                    let trial = evaluate(self.model, &self.offsets, &self.c, ap, c1, &state.element_history, wk, true);
                    if trial < norm || lambda < 1e-6 {
                        std::mem::swap(&mut wk.z, &mut wk.z_try);
                        std::mem::swap(&mut wk.g, &mut wk.g_try);
                        std::mem::swap(&mut wk.residual, &mut wk.residual_try);
                        std::mem::swap(&mut wk.b, &mut wk.b_try);
                        std::mem::swap(&mut wk.history, &mut wk.history_try);
                        norm = trial;
                        break;
                    }
                    lambda *= 0.5;
                }
            }
        }

        // u_{n+1} = u_lin − (1+α) W g; Newmark's a and v.
        wk.u_new.copy_from_slice(&wk.u_lin);
        for a in 0..q {
            axpy(-ap * wk.g[a], &self.w[a * n..(a + 1) * n], &mut wk.u_new);
        }
        for i in 0..n {
            wk.a_new[i] = c0 * (wk.u_new[i] - wk.u_pred[i]);
            wk.v_new[i] = wk.v_pred[i] + gamma * h * wk.a_new[i];
        }
        if wk.u_new.iter().any(|x| !x.is_finite()) {
            return Err(TimesimError::Diverged { time: state.time + h });
        }
        self.operators.damp(&wk.v_new, &mut wk.dv_new, &mut wk.tmp);

        // Energy tally (before the state is overwritten).
        let e_mid = 0.5 * (state.excitation + excitation_end);
        let mut input = 0.0;
        let mut viscous = 0.0;
        for i in 0..n {
            input += (wk.u_new[i] - state.displacement[i]) * load[i] * e_mid;
            viscous += (state.velocity[i] + wk.v_new[i]) * (state.dv[i] + wk.dv_new[i]);
        }
        state.energy.input += input;
        state.energy.viscous += 0.25 * h * viscous;

        // Commit.
        for (e, site) in self.model.elements.iter().enumerate() {
            let (da, ds) = self.offsets[e];
            let (d, s) = (site.law.n_dirs(), site.law.n_state());
            let mut work = 0.0;
            for a in da..da + d {
                work += (wk.z[a] - state.element_displacement[a]) * 0.5 * (state.element_force[a] + wk.g[a]);
                state.element_velocity[a] = wk.zv_pred[a] + c1 * (wk.z[a] - wk.z_pred[a]);
            }
            state.energy.elements[e] += work;
            state.slipping[e] = site.law.is_slipping(&state.element_history[ds..ds + s], &wk.history[ds..ds + s]);
        }
        state.element_displacement.copy_from_slice(&wk.z);
        state.element_force.copy_from_slice(&wk.g);
        state.element_history.copy_from_slice(&wk.history);
        state.displacement.copy_from_slice(&wk.u_new);
        state.velocity.copy_from_slice(&wk.v_new);
        state.acceleration.copy_from_slice(&wk.a_new);
        std::mem::swap(&mut state.dv, &mut wk.dv_new);
        if alpha != 0.0 && self.folded.is_none() {
            self.operators.stiffness.apply(&state.displacement, &mut state.ku);
        }
        state.excitation = excitation_end;
        state.time += h;
        Ok(())
    }

    fn project(&self, x: &[f64], out: &mut [f64]) {
        let n = x.len();
        for (a, o) in out.iter_mut().enumerate() {
            *o = dot(&self.dirs[a * n..(a + 1) * n], x);
        }
    }
}

/// Evaluate the elements at `z` (or `z_try` when `trial`), from the committed history, and the
/// residual `R = z − z_lin + (1+α) C g`; returns `|R|∞`. Fills g, R, the tangent block B and
/// the updated history (the `_try` buffers when `trial`).
#[allow(clippy::too_many_arguments)]
fn evaluate(
    model: &NonlinearModel,
    offsets: &[(usize, usize)],
    c: &[f64],
    ap: f64,
    c1: f64,
    committed: &[f64],
    wk: &mut Work,
    trial: bool,
) -> f64 {
    let q = wk.z.len();
    let (z, g, r, b, hist) = if trial {
        (&wk.z_try, &mut wk.g_try, &mut wk.residual_try, &mut wk.b_try, &mut wk.history_try)
    } else {
        (&wk.z, &mut wk.g, &mut wk.residual, &mut wk.b, &mut wk.history)
    };
    hist.copy_from_slice(committed);
    b.iter_mut().for_each(|x| *x = 0.0);
    for (e, site) in model.elements.iter().enumerate() {
        let (da, ds) = offsets[e];
        let (d, s) = (site.law.n_dirs(), site.law.n_state());
        for a in da..da + d {
            wk.zv[a] = wk.zv_pred[a] + c1 * (z[a] - wk.z_pred[a]);
        }
        let t = &mut wk.tangents[e];
        t.clear();
        site.law.update(&z[da..da + d], &wk.zv[da..da + d], &mut hist[ds..ds + s], &mut g[da..da + d], Some(t));
        for i in 0..d {
            for j in 0..d {
                b[(da + i) * q + da + j] = t.dg_du[i * d + j] + c1 * t.dg_dv[i * d + j];
            }
        }
    }
    let mut norm = 0.0f64;
    for a in 0..q {
        let cg: f64 = (0..q).map(|m| c[a * q + m] * g[m]).sum();
        r[a] = z[a] - wk.z_lin[a] + ap * cg;
        norm = norm.max(r[a].abs());
    }
    if norm.is_nan() {
        f64::INFINITY
    } else {
        norm
    }
}

/// Solve the small dense system `A x = b` in place (row-major A, overwritten) by Gaussian
/// elimination with partial pivoting. Hand-written because q is a handful and the step must
/// not allocate; returns false if A is singular.
fn solve_small(q: usize, a: &mut [f64], b: &mut [f64]) -> bool {
    for k in 0..q {
        let p = (k..q).max_by(|&i, &j| a[i * q + k].abs().total_cmp(&a[j * q + k].abs())).unwrap_or(k);
        if a[p * q + k] == 0.0 || !a[p * q + k].is_finite() {
            return false;
        }
        if p != k {
            for j in 0..q {
                a.swap(k * q + j, p * q + j);
            }
            b.swap(k, p);
        }
        for i in k + 1..q {
            let f = a[i * q + k] / a[k * q + k];
            for j in k..q {
                a[i * q + j] -= f * a[k * q + j];
            }
            b[i] -= f * b[k];
        }
    }
    for k in (0..q).rev() {
        let s: f64 = (k + 1..q).map(|j| a[k * q + j] * b[j]).sum();
        b[k] = (b[k] - s) / a[k * q + k];
    }
    true
}

/// `aᵀ b` with four independent partial sums: a single running sum is bound by the latency
/// of the addition (4 cycles each), and the q projections of a step on a reduced model in
/// modal coordinates are most of its work.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    let mut s = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    y.iter_mut().zip(x).for_each(|(y, x)| *y += alpha * x);
}
