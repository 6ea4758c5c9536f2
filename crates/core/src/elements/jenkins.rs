use multiversion::multiversion;

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
        let (u_max, u_min) = extremes(u);
        let j_max = u.iter().position(|&x| x == u_max).unwrap_or(0);
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

    /// The return mapping is odd in (u, w, f), the stuck-mean convention starts `−u` at `−w`,
    /// and a motion that slips both ways forgets its start: its periodic regime is unique.
    fn odd_symmetric(&self) -> bool {
        true
    }

    /// The return mapping of [`Element::update`] marched over a stretch, bit for bit the same
    /// steps: a slip moves the slider to `u − sgn(f_tr) F_c/k`, and `(±F_c)/k = ±(F_c/k)`
    /// exactly, so the division is made once instead of on the loop's dependency chain (the
    /// AFT marches every sample of every slider at every Newton iteration).
    fn update_slider_samples(
        &self,
        u: &[f64],
        _v: &[f64],
        range: std::ops::Range<usize>,
        state: &mut f64,
        g: &mut [f64],
        slipping: &mut [bool],
    ) {
        let (k, fc) = (self.stiffness, self.threshold);
        let slip_offset = fc / k;
        let linear = if self.replaces_stiffness { k } else { 0.0 };
        let (u, g, slipping) = (&u[range.clone()], &mut g[range.clone()], &mut slipping[range]);
        let n = u.len();
        let mut w = *state;
        // One loop per state, each exit a branch: the slider's position then never waits on
        // its previous value's comparison (a single loop compiles to a select whose chain
        // through w costs ~12 cycles a sample). Sliding forward, w = u − F_c/k and
        // f = F_c are the return mapping's `u − sgn(f_tr) F_c/k` and `sgn(f_tr) F_c` exactly.
        let mut j = 0;
        while j < n {
            let start = j;
            // Stuck: w kept.
            while j < n {
                let trial = k * (u[j] - w);
                if trial.abs() < fc {
                    g[j] = trial - linear * u[j];
                    slipping[j] = false;
                    j += 1;
                } else {
                    break;
                }
            }
            // Sliding forward, then back.
            while j < n && k * (u[j] - w) >= fc {
                let before = w;
                w = u[j] - slip_offset;
                g[j] = fc - linear * u[j];
                slipping[j] = before != w;
                j += 1;
            }
            while j < n && k * (u[j] - w) <= -fc {
                let before = w;
                w = u[j] + slip_offset;
                g[j] = -fc - linear * u[j];
                slipping[j] = before != w;
                j += 1;
            }
            if j == start {
                // A trial force that is not a number: the return mapping's step as it is.
                let (before, trial) = (w, k * (u[j] - w));
                w = u[j] - trial.signum() * slip_offset;
                g[j] = trial.signum() * fc - linear * u[j];
                slipping[j] = before != w;
                j += 1;
            }
        }
        *state = w;
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

/// The largest and smallest of `u` (not empty): over four interleaved lanes (independent
/// chains the compiler vectorises, with AVX2 where the processor has it), the same maximum as
/// one strict `>` scan (a NaN never replaces a number, and a NaN first sample stays).
#[multiversion(targets("x86_64+avx2+fma", "x86_64+avx"))]
fn extremes(u: &[f64]) -> (f64, f64) {
    let (mut max4, mut min4) = ([u[0]; 4], [u[0]; 4]);
    let chunks = u.chunks_exact(4);
    for x in chunks.remainder() {
        max4[0] = if *x > max4[0] { *x } else { max4[0] };
        min4[0] = min4[0].min(*x);
    }
    for x in chunks {
        for l in 0..4 {
            max4[l] = if x[l] > max4[l] { x[l] } else { max4[l] };
            min4[l] = min4[l].min(x[l]);
        }
    }
    let u_max = max4.into_iter().fold(u[0], |m, x| if x > m { x } else { m });
    let u_min = min4.into_iter().fold(u[0], f64::min);
    (u_max, u_min)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Motions that stick and slip, with repeated extremes and samples exactly at the
    /// threshold: a few harmonics of random-like amplitudes plus a plateau at the maximum.
    fn motions() -> Vec<Vec<f64>> {
        let mut seed = 12345u64;
        let mut next = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let nt = 300;
        let mut all = Vec::new();
        for case in 0..200 {
            let amps: Vec<f64> = (0..5).map(|_| next() * 1e-4).collect();
            let phases: Vec<f64> = (0..5).map(|_| next() * 6.0).collect();
            let mut u: Vec<f64> = (0..nt)
                .map(|j| {
                    let th = 2.0 * std::f64::consts::PI * j as f64 / nt as f64;
                    (0..5).map(|h| amps[h] * ((h + 1) as f64 * th + phases[h]).cos()).sum()
                })
                .collect();
            if case % 4 == 0 {
                let top = u.iter().cloned().fold(f64::MIN, f64::max);
                let at = u.iter().position(|&x| x == top).unwrap();
                for x in u.iter_mut().skip(at).take(3) {
                    *x = top;
                }
            }
            all.push(u);
        }
        all
    }

    /// The marched stretch must be the sample-by-sample return mapping bit for bit (the AFT's
    /// results must not depend on which path a law takes).
    #[test]
    fn the_marched_stretch_is_the_return_mapping_bit_for_bit() {
        for law in [Jenkins::new(8.11e6, 300.0).unwrap(), Jenkins::replacing_stiffness(2.0e7, 150.0).unwrap()] {
            for u in motions() {
                let nt = u.len();
                let v = vec![0.0; nt];
                let (mut g_fast, mut slip_fast) = (vec![0.0; nt], vec![false; nt]);
                let mut w_fast = 1e-6;
                law.update_slider_samples(&u, &v, 0..nt, &mut w_fast, &mut g_fast, &mut slip_fast);
                let mut w = [1e-6];
                for j in 0..nt {
                    let before = w;
                    let mut g = [0.0];
                    law.update(&u[j..j + 1], &v[j..j + 1], &mut w, &mut g, None);
                    assert_eq!(g[0].to_bits(), g_fast[j].to_bits(), "force at sample {j}");
                    assert_eq!(law.is_slipping(&before, &w), slip_fast[j], "slip flag at sample {j}");
                }
                assert_eq!(w[0].to_bits(), w_fast.to_bits());
            }
        }
    }

    /// The same over the AFT's three stretches (the start sample, the rest of the period, the
    /// samples before the start) and on motions with a sample that is not finite (a NaN or an
    /// infinite trial force takes the return mapping's step, and the march goes on).
    #[test]
    fn stretches_and_non_finite_samples_march_as_the_return_mapping() {
        let law = Jenkins::new(8.11e6, 300.0).unwrap();
        let mut cases = motions();
        cases.truncate(40);
        for (case, u) in cases.iter_mut().enumerate() {
            if case % 3 == 1 {
                u[17 + case] = f64::NAN;
            } else if case % 3 == 2 {
                u[5 * case] = f64::INFINITY;
            }
        }
        for (case, u) in cases.iter().enumerate() {
            let nt = u.len();
            let v = vec![0.0; nt];
            let j0 = (7 * case) % nt;
            let (mut g_fast, mut slip_fast) = (vec![0.0; nt], vec![false; nt]);
            let mut w_fast = 0.0;
            for range in [j0..j0 + 1, j0 + 1..nt, 0..j0] {
                law.update_slider_samples(u, &v, range, &mut w_fast, &mut g_fast, &mut slip_fast);
            }
            let mut w = [0.0];
            for j in (j0..nt).chain(0..j0) {
                let before = w;
                let mut g = [0.0];
                law.update(&u[j..j + 1], &v[j..j + 1], &mut w, &mut g, None);
                assert_eq!(g[0].to_bits(), g_fast[j].to_bits(), "case {case}: force at sample {j}");
                assert_eq!(law.is_slipping(&before, &w), slip_fast[j], "case {case}: slip flag at sample {j}");
            }
            assert_eq!(w[0].to_bits(), w_fast.to_bits(), "case {case}");
        }
    }

    /// The periodic start is at the first sample of the largest displacement, as a strict `>`
    /// scan finds it, with the slider just slipped forward.
    #[test]
    fn the_periodic_start_is_at_the_first_maximum() {
        let law = Jenkins::new(8.11e6, 30.0).unwrap();
        for u in motions() {
            let (mut j_max, mut u_max, mut u_min) = (0, u[0], u[0]);
            for (j, &x) in u.iter().enumerate() {
                if x > u_max {
                    (j_max, u_max) = (j, x);
                }
                u_min = u_min.min(x);
            }
            let (mut state, mut ds) = ([0.0], [0.0]);
            let start = law.periodic_start(&u, u.len(), &mut state, &mut ds);
            if 8.11e6 * (u_max - u_min) <= 60.0 {
                assert_eq!(start, None);
            } else {
                assert_eq!(start, Some(j_max));
                assert_eq!(state[0].to_bits(), (u_max - 30.0 / 8.11e6).to_bits());
            }
        }
    }
}
