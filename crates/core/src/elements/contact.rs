use super::{check_positive, Element, ElementError, Tangent};

/// Largest friction coefficient accepted: dry metal contacts lie below 1.5, and a value above
/// 10 is almost always a threshold (N) typed where a coefficient was expected.
pub const MAX_FRICTION_COEFFICIENT: f64 = 10.0;

/// Point contact with elastic dry friction, unilateral normal contact and a slip threshold that
/// follows the normal load: the 2-D (one tangential direction) and 3-D (two tangential
/// directions) elements of Yang, Chu & Menq (J. Sound Vib. 210, 1998) and Petrov & Ewins
/// (J. Turbomach. 125, 2003), in penalty form.
///
/// **Directions** (columns of `V`, in this order): the tangential relative displacements
/// `u_t = (u_1[, u_2])`, then the normal approach `u_n` (positive pushes the surfaces together).
/// `u` is measured from the preloaded static state, in which an external static load (a bolt, the
/// blade's compression) balances the preload `N0`.
///
/// **Normal law** (unilateral, Signorini with penalty `k_n`):
///
/// ```text
/// N = max(0, N0 + k_n u_n)
/// ```
///
/// **Tangential law** (vectorial return mapping, elastic-perfectly-plastic with threshold
/// `μ N`): the slider position `w` (`n_t` components) is the state; the trial force is
/// `T_tr = k_t (u_t − w)`;
///
/// ```text
/// N = 0:                separation, T = 0, w = u_t (the spring unloads)
/// |T_tr| < μ N:         stick,      T = T_tr
/// otherwise:            slip,       T = μ N T_tr/|T_tr|, w = u_t − T/k_t
/// ```
///
/// the radial return of plasticity (Simo & Hughes, Computational Inelasticity, Box 3.1, with a
/// circular yield surface of radius μN): on a circular or elliptic tangential path the force
/// turns with the slip direction instead of switching sign as a 1-D slider does.
///
/// **Restoring force** applied to the structure (module docs of [`crate::elements`]):
/// `g = (T, N − N0) − K_r u`: the variation of the contact forces about the preloaded state,
/// minus the stiffness `K_r` (d×d, zero unless set by [`Contact::replacing_stiffness`]) that the
/// linear model already holds for the stuck, closed contact (the paper-form Eq. 11 generalised).
/// With a constant normal load and a one-direction tangential motion the law is the Jenkins
/// element with `F_c = μ N0`, operation for operation.
///
/// **Stuck-mean convention** (as Jenkins): a march starts with the slider at the origin (`w = 0`),
/// or where the return mapping from the origin puts it when the first sample already slips or
/// separates.
#[derive(Clone, Debug)]
pub struct Contact {
    /// Number of tangential directions, 1 or 2.
    tangential: usize,
    tangential_stiffness: f64,
    normal_stiffness: f64,
    friction: f64,
    preload: f64,
    /// Replaced stiffness K_r, row-major d×d (zeros for a standalone element).
    replaced: [f64; 9],
}

/// What the return mapping found at one sample (computed without allocation).
#[derive(Clone, Copy, Debug)]
struct Mapped {
    normal: f64,
    closed: bool,
    stuck: bool,
    /// Trial force `k_t (u_t − w)` and its norm.
    trial: [f64; 2],
    norm: f64,
    /// Slip threshold μN.
    limit: f64,
}

impl Contact {
    /// 2-D contact (one tangential direction, then the normal): tangential stiffness `k_t`
    /// (N/m), normal stiffness `k_n` (N/m), friction coefficient `μ`, normal preload `N0` (N).
    pub fn new_2d(kt: f64, kn: f64, mu: f64, n0: f64) -> Result<Self, ElementError> {
        Self::new(1, kt, kn, mu, n0)
    }

    /// 3-D contact (two tangential directions, then the normal), parameters as [`Contact::new_2d`].
    pub fn new_3d(kt: f64, kn: f64, mu: f64, n0: f64) -> Result<Self, ElementError> {
        Self::new(2, kt, kn, mu, n0)
    }

    fn new(tangential: usize, kt: f64, kn: f64, mu: f64, n0: f64) -> Result<Self, ElementError> {
        let kind = if tangential == 1 { "contact2d" } else { "contact3d" };
        check_positive(kind, "tangential stiffness", kt)?;
        check_positive(kind, "normal stiffness", kn)?;
        if !(mu.is_finite() && (0.0..=MAX_FRICTION_COEFFICIENT).contains(&mu)) {
            return Err(ElementError {
                element: kind,
                message: format!("friction coefficient must lie in [0, {MAX_FRICTION_COEFFICIENT}], got {mu}"),
            });
        }
        if !(n0.is_finite() && n0 > 0.0) {
            return Err(ElementError {
                element: kind,
                message: format!(
                    "normal preload must be a finite number > 0 (the contact is open at rest otherwise), got {n0}"
                ),
            });
        }
        Ok(Contact {
            tangential,
            tangential_stiffness: kt,
            normal_stiffness: kn,
            friction: mu,
            preload: n0,
            replaced: [0.0; 9],
        })
    }

    /// Paper form (Eq. 11 generalised to d directions): the linear model already holds the
    /// stiffness `K_r = Vᵀ K V` (row-major d×d, symmetric) of the stuck, closed contact, and
    /// the element replaces it.
    pub fn replacing_stiffness(mut self, kr: &[f64]) -> Result<Self, ElementError> {
        let d = self.tangential + 1;
        let kind = self.kind();
        if kr.len() != d * d {
            return Err(ElementError {
                element: kind,
                message: format!("replaced stiffness needs {} entries (d×d), got {}", d * d, kr.len()),
            });
        }
        for a in 0..d {
            for b in 0..d {
                let (x, y) = (kr[a * d + b], kr[b * d + a]);
                if !x.is_finite() || (x - y).abs() > 1e-12 * x.abs().max(y.abs()) {
                    return Err(ElementError {
                        element: kind,
                        message: format!("replaced stiffness must be finite and symmetric, entries ({a},{b}) = {x} and ({b},{a}) = {y}"),
                    });
                }
            }
        }
        self.replaced[..d * d].copy_from_slice(kr);
        Ok(self)
    }

    pub fn tangential_stiffness(&self) -> f64 {
        self.tangential_stiffness
    }

    pub fn normal_stiffness(&self) -> f64 {
        self.normal_stiffness
    }

    pub fn friction_coefficient(&self) -> f64 {
        self.friction
    }

    pub fn preload(&self) -> f64 {
        self.preload
    }

    /// Normal load and the tangential trial state at `u` from the slider position `w`.
    #[inline]
    fn map(&self, u: &[f64], w: &[f64]) -> Mapped {
        let nt = self.tangential;
        let n_trial = self.preload + self.normal_stiffness * u[nt];
        let closed = n_trial > 0.0;
        let normal = if closed { n_trial } else { 0.0 };
        let mut trial = [0.0; 2];
        let mut sq = 0.0;
        for a in 0..nt {
            trial[a] = self.tangential_stiffness * (u[a] - w[a]);
            sq += trial[a] * trial[a];
        }
        let norm = sq.sqrt();
        let limit = self.friction * normal;
        // Strict inequality as in the Jenkins element (Eq. 10): at the threshold, slip.
        Mapped { normal, closed, stuck: closed && norm < limit, trial, norm, limit }
    }

    /// Slip force `T = μN T_tr/|T_tr|` (zero for a zero threshold).
    #[inline]
    fn slip_force(m: &Mapped, a: usize) -> f64 {
        if m.limit > 0.0 {
            m.limit * (m.trial[a] / m.norm)
        } else {
            0.0
        }
    }

    /// `P = (μN/|T_tr|)(I − n nᵀ)`, the derivative of the slip direction times the threshold
    /// (zero for a zero threshold); `n = T_tr/|T_tr|`.
    #[inline]
    fn projector(m: &Mapped, a: usize, b: usize) -> f64 {
        if m.limit > 0.0 {
            let (na, nb) = (m.trial[a] / m.norm, m.trial[b] / m.norm);
            m.limit / m.norm * (f64::from(u8::from(a == b)) - na * nb)
        } else {
            0.0
        }
    }
}

impl Element for Contact {
    fn kind(&self) -> &'static str {
        if self.tangential == 1 {
            "contact2d"
        } else {
            "contact3d"
        }
    }

    fn n_dirs(&self) -> usize {
        self.tangential + 1
    }

    fn n_state(&self) -> usize {
        self.tangential
    }

    fn initial_state(&self, u0: &[f64], state: &mut [f64], dstate_du0: Option<&mut [f64]>) {
        // The return mapping from the origin (stuck-mean convention, type docs).
        let (nt, d) = (self.tangential, self.tangential + 1);
        state.iter_mut().for_each(|w| *w = 0.0);
        let m = self.map(u0, state);
        if let Some(ds) = dstate_du0 {
            ds.iter_mut().for_each(|x| *x = 0.0);
            if !m.stuck {
                let kn = self.normal_stiffness;
                for a in 0..nt {
                    for b in 0..nt {
                        let p = if m.closed { Self::projector(&m, a, b) } else { 0.0 };
                        ds[a * d + b] = f64::from(u8::from(a == b)) - p;
                    }
                    if m.closed && m.limit > 0.0 {
                        ds[a * d + nt] = -self.friction * kn * (m.trial[a] / m.norm) / self.tangential_stiffness;
                    }
                }
            }
        }
        if !m.stuck {
            for a in 0..nt {
                let t = if m.closed { Self::slip_force(&m, a) } else { 0.0 };
                state[a] = u0[a] - t / self.tangential_stiffness;
            }
        }
    }

    fn replaced_stiffness(&self, a: usize, b: usize) -> f64 {
        self.replaced[a * (self.tangential + 1) + b]
    }

    /// A sample where the contact is open resets the slider (`w = u_t`, whatever came before):
    /// marching one period from the last such sample gives the periodic regime at once.
    fn periodic_start(&self, u: &[f64], n_t: usize, state: &mut [f64], dstate_du: &mut [f64]) -> Option<usize> {
        let (nt, d) = (self.tangential, self.tangential + 1);
        let normal = &u[nt * n_t..(nt + 1) * n_t];
        let j = (0..n_t).rev().find(|&j| self.preload + self.normal_stiffness * normal[j] <= 0.0)?;
        dstate_du.iter_mut().for_each(|x| *x = 0.0);
        for a in 0..nt {
            state[a] = u[a * n_t + j];
            dstate_du[a * d + a] = 1.0;
        }
        Some(j)
    }

    fn update(&self, u: &[f64], _v: &[f64], state: &mut [f64], g: &mut [f64], tangent: Option<&mut Tangent>) {
        let (nt, d) = (self.tangential, self.tangential + 1);
        let (kt, kn) = (self.tangential_stiffness, self.normal_stiffness);
        let m = self.map(u, state);
        // Forces and the new slider position (type docs).
        for a in 0..nt {
            g[a] = if m.stuck {
                m.trial[a]
            } else if m.closed {
                let t = Self::slip_force(&m, a);
                state[a] = u[a] - t / kt;
                t
            } else {
                state[a] = u[a];
                0.0
            };
        }
        g[nt] = m.normal - self.preload;
        for a in 0..d {
            for b in 0..d {
                g[a] -= self.replaced[a * d + b] * u[b];
            }
        }
        if let Some(t) = tangent {
            // Every entry is written at every call (the tangent is reused without clearing).
            let s = nt;
            for a in 0..d {
                for b in 0..d {
                    t.dg_du[a * d + b] = -self.replaced[a * d + b];
                }
            }
            t.dg_ds.iter_mut().for_each(|x| *x = 0.0);
            t.ds_du.iter_mut().for_each(|x| *x = 0.0);
            t.ds_ds.iter_mut().for_each(|x| *x = 0.0);
            if m.closed {
                t.dg_du[nt * d + nt] += kn;
            }
            for a in 0..nt {
                if m.stuck {
                    // T = k_t (u_t − w), w kept.
                    t.dg_du[a * d + a] += kt;
                    t.dg_ds[a * s + a] = -kt;
                    t.ds_ds[a * s + a] = 1.0;
                } else if m.closed {
                    // T = μN n, n = T_tr/|T_tr|: ∂T/∂T_tr = P, ∂T/∂N = μ n; w' = u_t − T/k_t.
                    let dn = if m.limit > 0.0 { self.friction * kn * (m.trial[a] / m.norm) } else { 0.0 };
                    t.dg_du[a * d + nt] += dn;
                    t.ds_du[a * d + nt] = -dn / kt;
                    for b in 0..nt {
                        let p = Self::projector(&m, a, b);
                        t.dg_du[a * d + b] += kt * p;
                        t.dg_ds[a * s + b] = -kt * p;
                        t.ds_du[a * d + b] = f64::from(u8::from(a == b)) - p;
                        t.ds_ds[a * s + b] = p;
                    }
                } else {
                    // Open: w' = u_t.
                    t.ds_du[a * d + a] = 1.0;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of one update against its tangent, for a state and a motion.
    fn check_tangent(law: &Contact, u: &[f64], w: &[f64]) -> f64 {
        let (d, s) = (law.n_dirs(), law.n_state());
        let mut t = Tangent::new(d, s);
        let (mut g, mut st) = (vec![0.0; d], w.to_vec());
        law.update(u, &[0.0; 3][..d], &mut st, &mut g, Some(&mut t));
        let h = 1e-9;
        let mut worst = 0.0f64;
        let eval = |u: &[f64], w: &[f64]| {
            let (mut g, mut st) = (vec![0.0; d], w.to_vec());
            law.update(u, &[0.0; 3][..d], &mut st, &mut g, None);
            (g, st)
        };
        let scale = law.tangential_stiffness.max(law.normal_stiffness);
        for b in 0..d {
            let (mut up, mut um) = (u.to_vec(), u.to_vec());
            up[b] += h;
            um[b] -= h;
            let ((gp, sp), (gm, sm)) = (eval(&up, w), eval(&um, w));
            for a in 0..d {
                worst = worst.max(((gp[a] - gm[a]) / (2.0 * h) - t.dg_du[a * d + b]).abs() / scale);
            }
            for a in 0..s {
                worst = worst.max(((sp[a] - sm[a]) / (2.0 * h) - t.ds_du[a * d + b]).abs());
            }
        }
        for b in 0..s {
            let (mut wp, mut wm) = (w.to_vec(), w.to_vec());
            wp[b] += h;
            wm[b] -= h;
            let ((gp, sp), (gm, sm)) = (eval(u, &wp), eval(u, &wm));
            for a in 0..d {
                worst = worst.max(((gp[a] - gm[a]) / (2.0 * h) - t.dg_ds[a * s + b]).abs() / scale);
            }
            for a in 0..s {
                worst = worst.max(((sp[a] - sm[a]) / (2.0 * h) - t.ds_ds[a * s + b]).abs());
            }
        }
        worst
    }

    #[test]
    fn tangents_equal_finite_differences_in_stick_slip_and_separation() {
        let (kt, kn, mu, n0) = (1e6, 2e6, 0.4, 500.0);
        // Displacements ~1e-4 m: with h = 1e-9 m the central differences are exact to round-off
        // (≈ 1e-16·1e-4/1e-9 = 1e-11 relative) away from a switch; the tangents are piecewise
        // smooth, so the check is of order 1e-7 at most (curvature of the slip direction, h/|u|).
        let law3 = Contact::new_3d(kt, kn, mu, n0)
            .unwrap()
            .replacing_stiffness(&[1e5, 0.0, 2e4, 0.0, 1e5, 0.0, 2e4, 0.0, 3e5])
            .unwrap();
        let law2 = Contact::new_2d(kt, kn, mu, n0).unwrap();
        let cases3: [(&[f64], &[f64]); 4] = [
            (&[1e-4, -5e-5, 1e-4], &[0.0, 0.0]),   // stick: |T_tr| = 112 N < μN = 280 N
            (&[3e-4, 2e-4, 1e-4], &[-1e-4, 1e-4]), // slip in an oblique direction
            (&[3e-4, 2e-4, -1e-4], &[0.0, 0.0]),   // slip with a reduced load (N = 300 N)
            (&[3e-4, 2e-4, -4e-4], &[1e-4, 0.0]),  // open
        ];
        for (u, w) in cases3 {
            let e = check_tangent(&law3, u, w);
            assert!(e < 1e-6, "3-D {u:?} {w:?}: {e:.2e}");
        }
        let cases2: [(&[f64], &[f64]); 3] =
            [(&[1e-4, 0.0], &[0.0]), (&[-4e-4, 5e-5], &[0.0]), (&[2e-4, -3e-4], &[0.0])];
        for (u, w) in cases2 {
            let e = check_tangent(&law2, u, w);
            assert!(e < 1e-6, "2-D {u:?} {w:?}: {e:.2e}");
        }
    }

    #[test]
    fn slip_force_has_magnitude_mu_n_along_the_trial_direction() {
        let law = Contact::new_3d(1e6, 2e6, 0.4, 500.0).unwrap();
        let (mut g, mut w) = ([0.0; 3], [0.0; 2]);
        law.update(&[3e-4, 4e-4, 5e-5], &[0.0; 3], &mut w, &mut g, None);
        let n = 500.0 + 2e6 * 5e-5;
        // |T| = μN to round-off, along (3, 4)/5; the slider sits μN/k_t behind the motion.
        assert!((g[0].hypot(g[1]) - 0.4 * n).abs() < 1e-12 * n);
        assert!((g[0] / g[1] - 0.75).abs() < 1e-14);
        assert!((g[2] - (n - 500.0)).abs() < 1e-12 * n);
        assert!(((3e-4 - w[0]) * 1e6 - g[0]).abs() < 1e-9);
    }

    #[test]
    fn bad_parameters_are_refused_with_the_name_and_the_range() {
        let e = Contact::new_2d(1e6, 0.0, 0.3, 100.0).unwrap_err();
        assert!(e.to_string().contains("normal stiffness must be a finite number > 0, got 0"), "{e}");
        let e = Contact::new_3d(1e6, 1e6, 12.0, 100.0).unwrap_err();
        assert!(e.to_string().contains("friction coefficient must lie in [0, 10], got 12"), "{e}");
        let e = Contact::new_2d(1e6, 1e6, 0.3, -1.0).unwrap_err();
        assert!(e.to_string().contains("open at rest"), "{e}");
    }
}
