//! Contact elements (2-D, 3-D) in the harmonic balance: the AFT Jacobian, the gross-slip closed
//! form on a circular path, the equivalence with the Jenkins element under a constant normal
//! load, and the condensed balance against the full one with several contacts.
mod hbm_support;

use faer::Mat;
use hbm_support::*;
use stickslip_core::elements::{Contact, Element, Jenkins};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{AftPlan, CondensedHbm, ElementAft, HbmSettings};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, NonlinearModel};
use stickslip_core::post::{evaluate_point, OutputSelector};

const PI: f64 = std::f64::consts::PI;

/// AFT of `law` for coefficient-major harmonics `u` (`u[c·d + a]`), with the Jacobian.
fn aft(law: &dyn Element, plan: &AftPlan, u: &[f64]) -> (Vec<f64>, Mat<f64>, ElementAft) {
    let n = u.len();
    let mut a = ElementAft::new(law, plan);
    let (mut g, mut j, mut w) = (vec![0.0; n], Mat::zeros(n, n), vec![0.0; n]);
    a.evaluate(law, plan, 700.0, u, &mut g, Some((j.as_mut(), &mut w))).unwrap();
    (g, j, a)
}

/// Largest difference between the analytic AFT Jacobian and central differences, relative to
/// the Jacobian's largest entry.
fn jacobian_error(law: &dyn Element, u: &[f64]) -> f64 {
    let plan = AftPlan::new(4, 256).unwrap();
    let n = u.len();
    let (_, jac, mut a) = aft(law, &plan, u);
    let scale = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max(jac[(i, j)].abs()));
    let h = 1e-7 * u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    for col in 0..n {
        let (mut up, mut um) = (u.to_vec(), u.to_vec());
        up[col] += h;
        um[col] -= h;
        a.evaluate(law, &plan, 700.0, &up, &mut gp, None).unwrap();
        a.evaluate(law, &plan, 700.0, &um, &mut gm, None).unwrap();
        for row in 0..n {
            worst = worst.max(((gp[row] - gm[row]) / (2.0 * h) - jac[(row, col)]).abs() / scale);
        }
    }
    worst
}

/// Harmonics (N = 4) of a d-direction motion: tangential ellipse(s) with a mean and harmonic 2,
/// normal motion of amplitude `normal` with phase `phase` relative to the first tangential one.
fn contact_motion(d: usize, tangential: f64, normal: f64, phase: f64) -> Vec<f64> {
    let nc = 9;
    let mut u = vec![0.0; nc * d];
    let t = tangential;
    u[cos_index(1) * d] = t;
    u[sin_index(1) * d] = 0.3 * t;
    u[sin_index(2) * d] = -0.1 * t;
    u[0] = 0.05 * t;
    if d == 3 {
        u[cos_index(1) * d + 1] = -0.2 * t;
        u[sin_index(1) * d + 1] = 0.8 * t;
        u[cos_index(2) * d + 1] = 0.1 * t;
    }
    let n = d - 1;
    u[cos_index(1) * d + n] = normal * phase.cos();
    u[sin_index(1) * d + n] = normal * phase.sin();
    u[cos_index(2) * d + n] = 0.1 * normal;
    u
}

#[test]
fn contact_aft_jacobians_equal_finite_differences() {
    // k_t = 1e6 N/m, k_n = 2e6 N/m, μ = 0.5, N0 = 100 N: the tangential spring reaches the
    // threshold μN0 = 50 N at 5e-5 m, the contact opens at u_n = −5e-5 m. As for the Jenkins
    // element (element_aft tests), a perturbation h moves each stick/slip/open switch by O(h),
    // which central differences see as a kink in one sample of 256: error O(h·k/n_t) relative,
    // measured ≤ 1.6e-9 over these cases; bound 1e-7.
    let (kt, kn, mu, n0) = (1e6, 2e6, 0.5, 100.0);
    for d in [2, 3] {
        let law = if d == 2 { Contact::new_2d(kt, kn, mu, n0) } else { Contact::new_3d(kt, kn, mu, n0) }.unwrap();
        for (what, t, n, phase) in [
            ("stuck", 2e-5, 1e-5, 0.0),
            ("stick-slip, in-phase normal load", 8e-5, 3e-5, 0.0),
            ("stick-slip, out-of-phase normal load", 8e-5, 3e-5, PI / 2.0),
            ("gross slip with separation", 4e-4, 8e-5, 0.7),
        ] {
            let e = jacobian_error(&law, &contact_motion(d, t, n, phase));
            println!("{d}-D contact, {what}: {e:.2e}");
            assert!(e < 1e-7, "{d}-D contact, {what}: Jacobian vs finite differences {e:.2e}");
        }
    }
}

#[test]
fn circular_gross_slip_dissipates_mu_n_times_the_slider_path() {
    // u_t = R (cos θ, sin θ), constant N = N0: in the periodic regime the slider turns on a
    // circle of radius R' = √(R² − r²), r = μN/k_t (the spring stays tangent to the slider's
    // circle, the slip being along the force), and W = μN · 2πR'.
    let (kt, kn, mu, n0, r_path) = (1e6, 2e6, 0.3, 500.0, 5e-4);
    let law = Contact::new_3d(kt, kn, mu, n0).unwrap();
    let plan = AftPlan::new(3, 300).unwrap();
    let nc = plan.n_coeffs();
    let mut u = vec![0.0; nc * 3];
    u[cos_index(1) * 3] = r_path;
    u[sin_index(1) * 3 + 1] = r_path;
    let (g, _, a) = aft(&law, &plan, &u);
    let limit = mu * n0;
    let r = limit / kt;
    let w_exact = limit * 2.0 * PI * (r_path * r_path - r * r).sqrt();
    let w_aft: f64 = (0..2)
        .map(|a| {
            PI * (u[sin_index(1) * 3 + a] * g[cos_index(1) * 3 + a] - u[cos_index(1) * 3 + a] * g[sin_index(1) * 3 + a])
        })
        .sum();
    // The return mapping is implicit (backward Euler): the force at a sample is the one at the
    // end of the step, which lags the continuous solution by half a step and tilts the force
    // by π/n_t against the path, W changing by ≈ (r/R)·π/n_t relative: first order, measured
    // 3.34e-3, 8.26e-4, 2.06e-4 at 300, 1200, 4800 samples for r/R = 0.3. Bounds: 4e-3 at 300,
    // and the 1e-3 of the closed-form check reached from 1200 samples on.
    let err = (w_aft - w_exact).abs() / w_exact;
    assert!(err < 4e-3, "energy per cycle {w_aft:.6e} J vs μN·2πR' = {w_exact:.6e} J ({err:.2e})");
    {
        let fine = AftPlan::new(3, 1200).unwrap();
        let mut uf = vec![0.0; nc * 3];
        uf[cos_index(1) * 3] = r_path;
        uf[sin_index(1) * 3 + 1] = r_path;
        let (gf, _, _) = aft(&law, &fine, &uf);
        let wf: f64 = (0..2)
            .map(|a| {
                PI * (uf[sin_index(1) * 3 + a] * gf[cos_index(1) * 3 + a]
                    - uf[cos_index(1) * 3 + a] * gf[sin_index(1) * 3 + a])
            })
            .sum();
        let ef = (wf - w_exact).abs() / w_exact;
        assert!(ef < 1e-3 && ef < err / 3.5, "1200 samples: {ef:.2e} (300: {err:.2e}), not first order");
    }
    let nt = plan.n_samples();
    for j in 0..nt {
        // Force of magnitude μN (to round-off) at every sample, and the slider's step from the
        // previous sample along it: the friction force on the sliding body opposes its slip.
        let (t1, t2) = (a.g[j], a.g[nt + j]);
        assert!((t1.hypot(t2) - limit).abs() < 1e-12 * limit, "sample {j}: |T| = {}", t1.hypot(t2));
        let p = (j + nt - 1) % nt;
        let (w1, w2) = (a.u[j] - t1 / kt, a.u[nt + j] - t2 / kt);
        let (w1p, w2p) = (a.u[p] - a.g[p] / kt, a.u[nt + p] - a.g[nt + p] / kt);
        let (s1, s2) = (w1 - w1p, w2 - w2p);
        let cos = (s1 * t1 + s2 * t2) / (s1.hypot(s2) * limit);
        assert!((cos - 1.0).abs() < 1e-9, "sample {j}: slip not along the force (cos {cos})");
        assert!(a.slipping[j]);
    }
    assert!(a.u[2 * nt..].iter().all(|x| x.abs() < 1e-30));
}

/// The Table 6 oscillator with `extra` decoupled DOFs (mass 2 kg, stiffness 3e7 N/m) standing
/// for the contact's other directions; `law` acts on x and those DOFs. Standalone form
/// (`replaced` None): K holds K − k_J along x and the joint adds its own stiffness. Paper form:
/// K also holds the stuck contact stiffness `replaced[i]` along each direction, which the joint
/// replaces.
fn oscillator(extra: usize, law: Box<dyn Element>, replaced: Option<&[f64]>) -> NonlinearModel {
    let n = 1 + extra;
    let k = |i: usize| match (i, replaced) {
        (0, None) => K_TOTAL - K_JENKINS,
        (_, None) => 3e7,
        (_, Some(r)) => (if i == 0 { K_TOTAL - K_JENKINS } else { 3e7 }) + r[i],
    };
    let linear = LinearModel::new(
        dense(n, |i, j| {
            if i != j {
                0.0
            } else if i == 0 {
                MASS
            } else {
                2.0
            }
        }),
        dense(n, |i, j| if i != j { 0.0 } else { k(i) }),
        Damping::Matrix(dense(n, |i, j| {
            if i != j {
                0.0
            } else if i == 0 {
                DAMPING
            } else {
                50.0
            }
        })),
        (0..n).map(|i| DofLabel::named(format!("x{i}"))).collect(),
        vec![],
    )
    .unwrap();
    let directions = (0..n).map(|i| relative_direction(n, i, None)).collect();
    NonlinearModel::new(linear, vec![ElementSite { name: "joint".into(), law, directions }]).unwrap()
}

#[test]
fn contacts_under_constant_normal_load_and_1d_motion_equal_the_jenkins_element() {
    // F_c = μ N0 with μ = 0.5, N0 = 2000 N; the normal and second tangential DOFs are not
    // forced and not coupled to x, so they stay at rest and the threshold stays μN0. The
    // contact's return mapping then does the Jenkins element's operations (|T_tr| of a
    // one-component vector is its absolute value, T_tr/|T_tr| = ±1 exactly): the residuals
    // agree to round-off and so do the solutions. Bound 1e-12 relative.
    let (mu, n0, kn) = (0.5, 2000.0, 5e6);
    let settings = HbmSettings { harmonics: 7, samples: 300 };
    let nc = 2 * settings.harmonics + 1;
    for paper in [false, true] {
        let jenkins: Box<dyn Element> = if paper {
            Box::new(Jenkins::replacing_stiffness(K_JENKINS, mu * n0).unwrap())
        } else {
            Box::new(Jenkins::new(K_JENKINS, mu * n0).unwrap())
        };
        let reference = oscillator(0, jenkins, paper.then_some(&[K_JENKINS][..]));
        let mut h_ref = CondensedHbm::new(&reference, &[F_EXCIT], settings).unwrap();
        for d in [2, 3] {
            let law =
                if d == 2 { Contact::new_2d(K_JENKINS, kn, mu, n0) } else { Contact::new_3d(K_JENKINS, kn, mu, n0) }
                    .unwrap();
            // Stuck closed contact: k_t along the tangential directions, k_n along the normal.
            let diag: Vec<f64> = (0..d).map(|i| if i + 1 < d { K_JENKINS } else { kn }).collect();
            let law: Box<dyn Element> = if paper {
                let kr: Vec<f64> = (0..d * d).map(|i| if i % (d + 1) == 0 { diag[i / d] } else { 0.0 }).collect();
                Box::new(law.replacing_stiffness(&kr).unwrap())
            } else {
                Box::new(law)
            };
            let model = oscillator(d - 1, law, paper.then_some(&diag[..]));
            let mut force = vec![0.0; d];
            force[0] = F_EXCIT;
            let mut h = CondensedHbm::new(&model, &force, settings).unwrap();
            let mut worst = 0.0f64;
            let mut slipped = false;
            // Natural continuation on a 1 Hz grid across the resonance, from the stuck solution.
            let mut x0 = h_ref.stuck_solution(TWO_PI * 200.0, 1.0).unwrap();
            for f in (0..=60).map(|i| 200.0 + i as f64) {
                let omega = TWO_PI * f;
                let (xr, _) = h_ref.solve(omega, 1.0, &x0, 1e-14, 60).unwrap();
                x0.clone_from(&xr);
                // The same point embedded in the contact's unknowns (other directions at rest).
                let embed = |x: &[f64]| -> Vec<f64> {
                    let mut y = vec![0.0; nc * d];
                    for c in 0..nc {
                        y[c * d] = x[c];
                    }
                    y
                };
                let (mut r1, mut r2) = (vec![0.0; nc], vec![0.0; nc * d]);
                h_ref.evaluate(&xr, omega, 1.0, &mut r1, None).unwrap();
                h.evaluate(&embed(&xr), omega, 1.0, &mut r2, None).unwrap();
                let xn = norm(&xr);
                for c in 0..nc {
                    worst = worst.max((r1[c] - r2[c * d]).abs() / xn);
                    for a in 1..d {
                        assert!(r2[c * d + a].abs() < 1e-15 * xn, "{f} Hz: direction {a} is not at rest");
                    }
                }
                let (xc, _) = h.solve(omega, 1.0, &embed(&xr), 1e-14, 60).unwrap();
                for c in 0..nc {
                    worst = worst.max((xc[c * d] - xr[c]).abs() / xn);
                }
                // The joint slips at these frequencies (else the test checks linear algebra).
                let p = evaluate_point(&mut h, &xc, omega, 1.0, &[]).unwrap();
                slipped |= p.elements[0].stick_fraction < 0.9 && p.elements[0].energy_per_cycle > 0.0;
            }
            assert!(slipped, "the joint never slips");
            println!("paper form {paper}, {d}-direction contact vs Jenkins: {worst:.2e}");
            assert!(worst < 1e-12, "paper form {paper}, {d}-direction contact vs Jenkins: {worst:.2e}");
        }
    }
}

/// A chain of 14 DOFs with three contacts (two 2-D, one 3-D, between DOFs and to the ground).
fn contact_chain(damping: Damping) -> NonlinearModel {
    let n = 14;
    let base = chain(n, damping, vec![]);
    let c2 = |kt, kn, mu, n0| -> Box<dyn Element> { Box::new(Contact::new_2d(kt, kn, mu, n0).unwrap()) };
    let sites = vec![
        ElementSite {
            name: "a".into(),
            law: c2(3e5, 4e5, 0.4, 30.0),
            directions: vec![relative_direction(n, 3, Some(4)), relative_direction(n, 5, Some(4))],
        },
        ElementSite {
            name: "b".into(),
            law: Box::new(Contact::new_3d(2e5, 3e5, 0.3, 40.0).unwrap()),
            directions: vec![
                relative_direction(n, 8, None),
                relative_direction(n, 9, None),
                relative_direction(n, 7, None),
            ],
        },
        ElementSite {
            name: "c".into(),
            law: c2(2.5e5, 2e5, 0.6, 20.0),
            directions: vec![relative_direction(n, 12, Some(13)), relative_direction(n, 11, None)],
        },
    ];
    NonlinearModel::new(base.linear, sites).unwrap()
}

#[test]
fn condensed_solution_equals_the_full_solution_with_three_contacts() {
    let n = 14;
    for damping in [
        Damping::Rayleigh { alpha: 15.0, beta: 1e-6 },
        Damping::Matrix(dense(n, |i, j| if i == j { 25.0 } else { 0.0 })),
    ] {
        let model = contact_chain(damping);
        let mut force = vec![0.0; n];
        force[0] = 1.0;
        force[7] = -0.5;
        let settings = HbmSettings { harmonics: 5, samples: 128 };
        let modes = model.linear.dense_modes().unwrap();
        let omega = 0.97 * modes.omega[0];
        let level = 400.0;
        let mut cond = CondensedHbm::new(&model, &force, settings).unwrap();
        let x0 = cond.linear_solution(omega, level);
        let (xq, _) = cond.solve(omega, level, &x0, 1e-13, 80).unwrap();
        let outputs: Vec<OutputSelector> =
            (0..n).map(|i| OutputSelector { name: format!("x{i}"), vector: relative_direction(n, i, None) }).collect();
        let p = evaluate_point(&mut cond, &xq, omega, level, &outputs).unwrap();
        // Every contact slips, and at least one opens over part of the cycle.
        let states: Vec<(f64, f64)> = p.elements.iter().map(|e| (e.energy_per_cycle, e.stick_fraction)).collect();
        assert!(states.iter().all(|&(w, stick)| w > 0.0 && stick < 0.99), "no slip: {states:?}");
        let opened = p.elements.iter().any(|e| {
            let law = model.elements.iter().find(|s| s.name == e.name).unwrap();
            e.force.last().unwrap().iter().any(|&g| g + law_preload(law.law.as_ref()) <= 1e-9)
        });
        assert!(opened, "no contact opens");
        // Normal directions dissipate nothing (elastic unilateral law): |W_n| ≤ 1e-9 of the total.
        // Normal directions dissipate nothing: g_n is a function of u_n alone, so ∮ g_n du_n
        // vanishes but for the quadrature of its kink at opening on 128 samples. Measured
        // ≤ 1e-4 of the normal energy scale max|g_n| · (max u_n − min u_n); bound 2e-3.
        for e in &p.elements {
            let wn = *e.direction_energy.last().unwrap();
            let (un, gn) = (e.displacement.last().unwrap(), e.force.last().unwrap());
            let range = un.iter().fold(f64::MIN, |m, x| m.max(*x)) - un.iter().fold(f64::MAX, |m, x| m.min(*x));
            let scale = gn.iter().fold(0.0f64, |m, x| m.max(x.abs())) * range;
            println!("{}: normal work {:.2e} of the normal energy scale", e.name, wn / scale);
            assert!(wn.abs() < 2e-3 * scale, "{}: normal work {wn:e} J, scale {scale:e} J", e.name);
        }
        let nc = 2 * settings.harmonics + 1;
        let recovered: Vec<f64> = (0..nc * n).map(|idx| p.outputs[idx % n].coeffs[idx / n]).collect();
        // Both solve the same equations to round-off (condensed to 1e-13 of ‖x‖; measured
        // 3e-15 apart); 1e-8 leaves room for the full solve's conditioning on other machines.
        let err = full_balance_distance(&model, &force, settings, omega, level, &recovered, 60);
        println!("condensed vs full: {err:.2e}");
        assert!(err < 1e-8, "condensed vs full: {err:.2e}");
    }
}

fn law_preload(law: &dyn Element) -> f64 {
    // The restoring normal force is N − N0: open where it equals −N0. The three contacts'
    // preloads, by kind and threshold of the chain above.
    let mut g = [0.0; 3];
    let mut w = [0.0; 2];
    let d = law.n_dirs();
    let open = [0.0, 0.0, -1.0];
    law.update(&open[3 - d..], &[0.0; 3][..d], &mut w[..d - 1], &mut g[..d], None);
    -g[d - 1]
}

/// The 2-D contact law in continuous time for `u_t = a cos θ`, `u_n = b cos(θ − φ)`, solved
/// event by event: stick, slip and open phases in closed form (T = T_s + k_t (u_t − u_s),
/// T = ±μN(θ), T = 0), switches located by bisection to round-off. Independent of the AFT's
/// sampled return mapping; the reference for variable normal load at any phase. The closed
/// forms of [`closed_form`] (the cases of Yang, Chu & Menq 1998 derived below) check it in turn.
struct EventReference {
    a: f64,
    b: f64,
    phi: f64,
    kt: f64,
    kn: f64,
    mu: f64,
    n0: f64,
}

#[derive(Clone, Copy, Debug)]
enum Phase {
    Stick { t0: f64, u0: f64 },
    Slip(f64),
    Open,
}

impl EventReference {
    fn ut(&self, th: f64) -> f64 {
        self.a * th.cos()
    }
    fn dut(&self, th: f64) -> f64 {
        -self.a * th.sin()
    }
    fn n_trial(&self, th: f64) -> f64 {
        self.n0 + self.kn * self.b * (th - self.phi).cos()
    }
    fn dn(&self, th: f64) -> f64 {
        -self.kn * self.b * (th - self.phi).sin()
    }
    fn force(&self, p: Phase, th: f64) -> f64 {
        match p {
            Phase::Stick { t0, u0 } => t0 + self.kt * (self.ut(th) - u0),
            Phase::Slip(s) => s * self.mu * self.n_trial(th).max(0.0),
            Phase::Open => 0.0,
        }
    }
    /// Smallest of the functions that stay positive while phase `p` holds.
    fn margin(&self, p: Phase, th: f64) -> f64 {
        match p {
            Phase::Stick { .. } => self.mu * self.n_trial(th) - self.force(p, th).abs(),
            // Slip goes on while sticking would push the force beyond the moving threshold.
            Phase::Slip(s) => (s * self.kt * self.dut(th) - self.mu * self.dn(th)).min(self.n_trial(th)),
            Phase::Open => -self.n_trial(th),
        }
    }
    /// The phase entered at a switch at θ from phase `p`.
    fn next(&self, p: Phase, th: f64) -> Phase {
        let closing = |th: f64| {
            // Re-contact (or the end of a slip): slip if the spring would outrun μN, else stick.
            let (v, dn) = (self.kt * self.dut(th), self.mu * self.dn(th));
            if v.abs() > dn {
                Phase::Slip(v.signum())
            } else {
                Phase::Stick { t0: self.force(p, th), u0: self.ut(th) }
            }
        };
        match p {
            Phase::Stick { .. } => {
                if self.n_trial(th) <= 1e-12 * self.n0 {
                    Phase::Open
                } else {
                    Phase::Slip(self.force(p, th).signum())
                }
            }
            Phase::Slip(s) => {
                if self.n_trial(th) <= 1e-12 * self.n0 {
                    Phase::Open
                } else {
                    Phase::Stick { t0: s * self.mu * self.n_trial(th), u0: self.ut(th) }
                }
            }
            Phase::Open => closing(th),
        }
    }
    /// Energy per cycle ∮ T du_t and the first harmonic (cos, sin) of T over the third period.
    fn solve(&self) -> (f64, f64, f64) {
        let two_pi = 2.0 * PI;
        let mut p = if self.n_trial(0.0) > 0.0 { Phase::Stick { t0: 0.0, u0: self.ut(0.0) } } else { Phase::Open };
        let mut th = 0.0;
        let (end, keep_from) = (3.0 * two_pi, 2.0 * two_pi);
        let step = two_pi / 20000.0;
        let (mut w, mut c1, mut s1) = (0.0, 0.0, 0.0);
        while th < end {
            // March to the next switch (a sign change of the margin), then bisect it.
            let mut hi = th;
            let mut switch = false;
            while hi < end {
                let next = (hi + step).min(end);
                if self.margin(p, next) <= 0.0 && next > th + 1e-13 {
                    let mut lo = hi.max(th);
                    let mut up = next;
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + up);
                        if self.margin(p, mid) > 0.0 {
                            lo = mid;
                        } else {
                            up = mid;
                        }
                    }
                    hi = up;
                    switch = true;
                    break;
                }
                hi = next;
            }
            // Integrate the phase over [th, hi] ∩ [keep_from, end] by composite Simpson
            // (smooth integrands inside a phase: 200 intervals give round-off accuracy).
            let (lo, up) = (th.max(keep_from), hi);
            if up > lo {
                let m = 200;
                let h = (up - lo) / m as f64;
                for i in 0..=m {
                    let x = lo + i as f64 * h;
                    let wgt = if i == 0 || i == m {
                        1.0
                    } else if i % 2 == 1 {
                        4.0
                    } else {
                        2.0
                    } * h
                        / 3.0;
                    let t = self.force(p, x);
                    w += wgt * t * self.dut(x);
                    c1 += wgt * t * x.cos() / PI;
                    s1 += wgt * t * x.sin() / PI;
                }
            }
            if switch {
                p = self.next(p, hi);
            }
            th = hi;
        }
        (w, c1, s1)
    }
}

/// The 2-D contact's AFT at `n_t` samples for `u_t = a cos θ`, `u_n = b cos(θ − φ)`: the energy
/// per cycle `∮ T du_t = −π a s₁` (harmonic 1 alone moves) and harmonic 1 of T, `(W, c₁, s₁)`.
fn aft_harmonic_1(law: &Contact, nt: usize, a: f64, b: f64, phi: f64) -> (f64, f64, f64) {
    let plan = AftPlan::new(3, nt).unwrap();
    let mut u = vec![0.0; 2 * plan.n_coeffs()];
    u[cos_index(1) * 2] = a;
    u[cos_index(1) * 2 + 1] = b * phi.cos();
    u[sin_index(1) * 2 + 1] = b * phi.sin();
    let (g, _, _) = aft(law, &plan, &u);
    let (c1, s1) = (g[cos_index(1) * 2], g[sin_index(1) * 2]);
    (PI * a * (-s1), c1, s1)
}

#[test]
fn variable_normal_load_matches_the_event_resolved_solution() {
    // k_t = 1e6 N/m, k_n = 2e6 N/m, μ = 0.4, N0 = 400 N: μN0/k_t = 1.6e-4 m, the contact opens
    // at u_n = −2e-4 m. Tangential amplitude 4e-4 m (2.5 μN0/k_t).
    let (kt, kn, mu, n0, a) = (1e6, 2e6, 0.4, 400.0, 4e-4);
    let law = Contact::new_2d(kt, kn, mu, n0).unwrap();
    for (what, b, phi) in [
        ("in phase, closed", 1e-4, 0.0),
        ("in phase, partial separation", 3e-4, 0.0),
        ("out of phase (90°), partial separation", 3e-4, PI / 2.0),
        ("opposite phase, closed (the mirror of in phase: same W)", 1e-4, PI),
        ("45°, partial separation", 4e-4, PI / 4.0),
    ] {
        let reference = EventReference { a, b, phi, kt, kn, mu, n0 };
        let (w_ref, c_ref, s_ref) = reference.solve();
        let mut errors = Vec::new();
        for nt in [256, 1024, 4096] {
            let (w, c1, s1) = aft_harmonic_1(&law, nt, a, b, phi);
            let e_w = (w - w_ref).abs() / w_ref;
            // Equivalent stiffness c1/a and the dissipative part s1, relative to |T_1|.
            let e_1 = (c1 - c_ref).hypot(s1 - s_ref) / c_ref.hypot(s_ref);
            errors.push((nt, e_w, e_1));
        }
        println!("{what}: W = {w_ref:.6e} J, k_eq = {:.6e} N/m, errors (n_t, W, T_1) {errors:?}", c_ref / a);
        // The AFT places each switch to within a sample; the force is continuous across the
        // switches, so the error is second order in 1/n_t: measured ≤ 8e-5, 9e-6, 5.8e-7 at
        // 256, 1024, 4096 samples. Bounds 1e-3 (a tenth of the 1 % asked), 2e-5, 2e-6.
        for (nt, e_w, e_1) in errors {
            let bound = match nt {
                256 => 1e-3,
                1024 => 2e-5,
                _ => 2e-6,
            };
            assert!(e_w < bound && e_1 < bound, "{what}, {nt} samples: energy {e_w:.2e}, harmonic 1 {e_1:.2e}");
        }
    }
}

/// Closed forms of the 2-D contact under `u_t = a cos θ`, `u_n = b cos(θ − φ)` with gross slip
/// both ways (the cases of Yang, Chu & Menq, J. Sound Vib. 210, 1998, derived here): with
/// `K = k_t a`, `P = μ N0`, `Q = μ k_n b`, the threshold is `F(θ) = P + Q cos(θ − φ)`.
///
/// A slip goes on while the spring would push the force beyond the moving threshold: backwards
/// while `K sin θ + Q sin(θ − φ) = R₁ sin(θ − δ₁) > 0`, forwards while
/// `−K sin θ + Q sin(θ − φ) = −R₂ sin(θ + δ₂) > 0`, with `R₁ e^{iδ₁} = K + Q cos φ + i Q sin φ`
/// and `R₂ e^{iδ₂} = K − Q cos φ + i Q sin φ`. So, closed (`P > Q`):
/// - the forward slip ends at `−δ₂` with `T_e = F(−δ₂)`; stick, `T = T_e + K (cos θ − cos δ₂)`,
///   until `T = −F`: `R₁ cos(θ₁ − δ₁) = −P − T_e + K cos δ₂`;
/// - backward slip, `T = −F(θ)`, until `π + δ₁`, where `T_c = −F(π + δ₁)`; stick,
///   `T = T_c + K (cos θ + cos δ₁)`, until `T = F`: `R₂ cos(θ₂ + δ₂) = P − T_c − K cos δ₁`;
/// - forward slip, `T = F(θ)`, until `2π − δ₂`.
///
/// In phase (`φ = 0`, `δ₁ = δ₂ = 0`) with partial separation (`Q > P`): the backward slip ends
/// where the contact opens, `F(θ_o) = 0`; open (`T = 0`) until `2π − θ_o`; then (`K > Q`) a
/// forward slip from the re-contact. In opposite phase (`φ = π`) with partial separation, see
/// [`opposite_phase_with_separation`]. Each phase has `T = α + β cos θ + γ sin θ`, so the
/// energy per cycle `W = ∮ T du_t` and the first harmonic of T are sums of elementary
/// integrals. Returns `(W, c₁, s₁)`, `T₁ = c₁ cos θ + s₁ sin θ`.
fn closed_form(a: f64, b: f64, phi: f64, kt: f64, kn: f64, mu: f64, n0: f64) -> (f64, f64, f64) {
    let (k, p, q) = (kt * a, mu * n0, mu * kn * b);
    let (qc, qs) = (q * phi.cos(), q * phi.sin());
    let threshold = |t: f64| p + qc * t.cos() + qs * t.sin();
    let (r1, d1) = ((k + qc).hypot(qs), qs.atan2(k + qc));
    let (r2, d2) = ((k - qc).hypot(qs), qs.atan2(k - qc));
    // Phases (from, to, α, β, γ).
    let phases: Vec<(f64, f64, f64, f64, f64)> = if p > q {
        let t_e = threshold(-d2);
        let c1 = (-p - t_e + k * d2.cos()) / r1;
        let t_c = -threshold(PI + d1);
        let c2 = (p - t_c - k * d1.cos()) / r2;
        assert!(c1.abs() < 1.0 && c2.abs() < 1.0, "gross slip both ways");
        let theta1 = d1 + c1.acos();
        let theta2 = 2.0 * PI - d2 - c2.acos();
        assert!(-d2 < theta1 && theta1 < PI + d1 && PI + d1 < theta2 && theta2 < 2.0 * PI - d2);
        vec![
            (-d2, theta1, t_e - k * d2.cos(), k, 0.0),
            (theta1, PI + d1, -p, -qc, -qs),
            (PI + d1, theta2, t_c + k * d1.cos(), k, 0.0),
            (theta2, 2.0 * PI - d2, p, qc, qs),
        ]
    } else if phi == PI {
        opposite_phase_with_separation(k, p, q)
    } else {
        assert!(phi == 0.0 && k > q && k > p, "partial separation: in phase, gross slip");
        let theta1 = ((k - 2.0 * p - q) / (k + q)).acos();
        let theta_open = (-p / q).acos();
        assert!(theta1 < theta_open, "backward slip before the contact opens");
        vec![
            (0.0, theta1, p + q - k, k, 0.0),
            (theta1, theta_open, -p, -q, 0.0),
            (2.0 * PI - theta_open, 2.0 * PI, p, q, 0.0),
        ]
    };
    let (mut w, mut c1, mut s1) = (0.0, 0.0, 0.0);
    for (t0, t1, alpha, beta, gamma) in phases {
        // ∫ (α + β cos θ + γ sin θ) sin θ dθ and ∫ (α + β cos θ + γ sin θ) cos θ dθ.
        let (half_sin2, half_cos2) = (|t: f64| 0.5 * t.sin().powi(2), |t: f64| 0.5 * t + 0.25 * (2.0 * t).sin());
        let sin_part = |t: f64| -alpha * t.cos() + beta * half_sin2(t) + gamma * (t - half_cos2(t));
        let cos_part = |t: f64| alpha * t.sin() + beta * half_cos2(t) + gamma * half_sin2(t);
        let (is, ic) = (sin_part(t1) - sin_part(t0), cos_part(t1) - cos_part(t0));
        w += -a * is;
        s1 += is / PI;
        c1 += ic / PI;
    }
    (w, c1, s1)
}

/// Opposite phase (`φ = π`: the normal load falls while the tangential displacement rises)
/// with partial separation (`Q > P`), derived here for the law the element implements (type
/// docs of `Contact`): the phases `(from, to, α, β, γ)` of one cycle, `T = α + β cos θ + γ sin θ`,
/// the open interval (`T = 0`) left out. `K = k_t a`, `P = μN0`, `Q = μ k_n b` as in
/// [`closed_form`].
///
/// The threshold is `F(θ) = P − Q cos θ`, least where `u_t = a` (θ = 0). The contact is open
/// while `N0 + k_n u_n < 0`, i.e. `F < 0`, on `|θ| < θ_o`, `cos θ_o = P/Q`. While open the
/// element sets `T = 0` and `w = u_t` (the spring unloads), so it re-closes at θ_o with the
/// slider where the contact closes, `T(θ_o) = 0 = F(θ_o)`, whatever came before: the cycle has
/// no memory across the open interval and the motion below is the periodic one at once.
///
/// On the closed interval `(θ_o, 2π − θ_o)`, centred on `u_t = −a`, `N = N0 + k_n b` at θ = π,
/// a stuck spring moves T at `dT/dθ = −K sin θ` while the bounds `±F` move at `±Q sin θ`:
/// - `K > Q`, the spring outruns the threshold from the re-contact on (the closing rule of
///   [`EventReference::next`]): backward slip, `T = −F(θ)`, which goes on while
///   `K sin θ − Q sin θ > 0` (the backward-slip margin of [`closed_form`] with φ = π), i.e. up
///   to the reversal at π, `T(π) = −(P + Q)`. Stick, `T = −(P + Q) + K (1 + cos θ)`: T rises at
///   `−K sin θ`, faster than the lower bound `−F` (at `−Q sin θ`), and meets the falling upper
///   bound `T = F` at θ₂ ∈ (π, 2π), `(K + Q) cos θ₂ = 2P + Q − K`. This happens before the
///   opening at `2π − θ_o`, where the stuck force would be `(K − Q)(P + Q)/Q > 0 = F`
///   (equivalently `cos θ₂ < P/Q ⇔ Q < K`). Forward slip, `T = F(θ)`, which goes on while
///   `−(K + Q) sin θ > 0`, i.e. until the contact opens at `2π − θ_o` with `T = F = 0`: no stick
///   between the forward slip and the opening. With `u = a cos θ` as variable the three phases
///   integrate to `W = a (P + Q)² (K − Q) / (Q (K + Q))`.
/// - `K ≤ Q`, the threshold outruns the spring: stick from the re-contact,
///   `T = K (cos θ − cos θ_o) = K (cos θ − P/Q)`, and then `F − T = (Q + K)(P/Q − cos θ)` and
///   `F + T = (Q − K)(P/Q − cos θ)` stay ≥ 0 over the whole closed interval: stuck until the
///   contact opens, where T = 0 again. T is a single-valued function of `u_t`: `W = 0`, and
///   harmonic 1 is a pure stiffness (`s₁ = 0`).
///
/// Every switch angle is an explicit arccosine here (the normal and tangential motions share
/// their zeros of `sin θ`), so no root finder is needed.
fn opposite_phase_with_separation(k: f64, p: f64, q: f64) -> Vec<(f64, f64, f64, f64, f64)> {
    assert!(q > p, "partial separation");
    let theta_open = (p / q).acos();
    if k > q {
        let theta2 = 2.0 * PI - ((2.0 * p + q - k) / (k + q)).acos();
        assert!(PI < theta2 && theta2 < 2.0 * PI - theta_open, "stick ends before the opening");
        vec![(theta_open, PI, -p, q, 0.0), (PI, theta2, k - p - q, k, 0.0), (theta2, 2.0 * PI - theta_open, p, -q, 0.0)]
    } else {
        vec![(theta_open, 2.0 * PI - theta_open, -k * p / q, k, 0.0)]
    }
}

#[test]
fn variable_normal_load_matches_the_closed_forms() {
    // The parameters of the event-resolved test: K = 400 N, P = μN0 = 160 N; closed with
    // Q = μ k_n b = 80 N at four phases (in phase: θ₁ = π/2, θ₂ = 4π/3), opening in phase with
    // Q = 240 N (θ₁ = acos(−1/4), θ_o = acos(−2/3)).
    let (kt, kn, mu, n0, a) = (1e6, 2e6, 0.4, 400.0, 4e-4);
    let law = Contact::new_2d(kt, kn, mu, n0).unwrap();
    for (what, b, phi) in [
        ("in phase, closed", 1e-4, 0.0),
        ("45°, closed", 1e-4, PI / 4.0),
        ("out of phase (90°), closed", 1e-4, PI / 2.0),
        ("opposite phase, closed", 1e-4, PI),
        ("in phase, partial separation", 3e-4, 0.0),
    ] {
        let (w, c1, s1) = closed_form(a, b, phi, kt, kn, mu, n0);
        // The event-resolved solution (switches by bisection, phases by Simpson) is the same
        // motion computed another way: equal to its quadrature's accuracy (~1e-10 measured).
        let (w_ref, c_ref, s_ref) = EventReference { a, b, phi, kt, kn, mu, n0 }.solve();
        assert!((w - w_ref).abs() < 1e-8 * w, "{what}: W {w} closed form, {w_ref} events");
        assert!((c1 - c_ref).hypot(s1 - s_ref) < 1e-8 * c1.hypot(s1), "{what}: T₁ ({c1}, {s1}), ({c_ref}, {s_ref})");
        // The AFT at 300 samples: each switch placed to within a sample, second-order errors
        // (8e-5 measured at 256 samples in the event-resolved test): asserted 1e-3, a tenth of
        // the 1 % asked.
        let (w_aft, g_c1, g_s1) = aft_harmonic_1(&law, 300, a, b, phi);
        assert!((w_aft - w).abs() < 1e-3 * w, "{what}: W {w_aft} AFT, {w} closed form");
        assert!((g_c1 - c1).hypot(g_s1 - s1) < 1e-3 * c1.hypot(s1), "{what}: T₁ ({g_c1}, {g_s1}) AFT");
        println!(
            "{what}: W = {w:.9e} J, k_eq = {:.9e} N/m (closed form); W relative to it: events {:.1e}, AFT {:.1e}",
            c1 / a,
            (w_ref - w) / w,
            (w_aft - w) / w
        );
    }
}

#[test]
fn opposite_phase_with_partial_separation_matches_the_closed_form() {
    // k_t = 1e6 N/m, k_n = 2e6 N/m, μ = 0.4, N0 = 400 N (P = 160 N) as above, φ = π; the
    // contact is open over 2θ_o/2π = acos(P/Q)/π of the cycle.
    let (kt, kn, mu, n0) = (1e6, 2e6, 0.4, 400.0);
    let law = Contact::new_2d(kt, kn, mu, n0).unwrap();
    for (what, a, b) in [
        ("K = 400 N, Q = 240 N, open 27 % of the cycle", 4e-4, 3e-4),
        ("K = 800 N, Q = 600 N, open 41 %", 8e-4, 7.5e-4),
        ("K = 200 N, Q = 360 N, open 35 %, stuck while closed", 2e-4, 4.5e-4),
    ] {
        let (k, p, q) = (kt * a, mu * n0, mu * kn * b);
        let theta_open = (p / q).acos();
        let (w, c1, s1) = closed_form(a, b, PI, kt, kn, mu, n0);
        let t1 = c1.hypot(s1);
        // The phase integrals against the energy summed by hand: with u = a cos θ, the backward
        // slip gives a(P + Q)²/(2Q), the stick and the forward slip the rest, and with
        // (K + Q) cos θ₂ = 2P + Q − K the sum is W = a (P + Q)² (K − Q) / (Q (K + Q)) for K > Q
        // (zero at K = Q, continuous with the stuck case), below the rigid-spring limit
        // a (P + Q)²/Q (slip all the time the contact is closed), the energy scale used when W
        // vanishes. Same numbers summed differently: round-off, 1e-12.
        let w_max = a * (p + q).powi(2) / q;
        let w_hand = if k > q { w_max * (k - q) / (k + q) } else { 0.0 };
        assert!((w - w_hand).abs() < 1e-12 * w_max, "{what}: W {w} phases, {w_hand} by hand");
        let w_scale = if k > q { w } else { w_max };
        assert!(k > q || s1 == 0.0, "{what}: stuck while closed, yet s₁ = {s1}");
        // The event-resolved solution: switches by bisection to round-off, each phase by
        // Simpson on 200 intervals, error ≈ (L/200)⁴/180 of the integrand's fourth derivative
        // over a phase of length L ≤ 2π: ≤ 3e-9 relative for the longest (the stuck case's 4 rad);
        // measured ≤ 2.2e-9. Bound 1e-8, as for the closed cases.
        let (w_ref, c_ref, s_ref) = EventReference { a, b, phi: PI, kt, kn, mu, n0 }.solve();
        let (e_w, e_1) = ((w_ref - w).abs() / w_scale, (c_ref - c1).hypot(s_ref - s1) / t1);
        println!("{what}: W = {w:.9e} J, k_eq = {:.9e} N/m; events: W {e_w:.1e}, T₁ {e_1:.1e}", c1 / a);
        assert!(e_w < 1e-8 && e_1 < 1e-8, "{what}: events, W {e_w:.2e}, T₁ {e_1:.2e}");
        for nt in 300..308 {
            let (w_aft, g_c1, g_s1) = aft_harmonic_1(&law, nt, a, b, PI);
            let (e_w, e_1) = ((w_aft - w).abs() / w_scale, (g_c1 - c1).hypot(g_s1 - s1) / t1);
            if k > q {
                // Re-contact into a slip: the first closed sample slips at T = −F(θ_j) as the
                // continuous law does, stick and slip then follow the law at every sample, and
                // at an odd n_t the stick begins one sample after π with T off by
                // (K − Q)(π − θ_j)²/2 (second order; π is a sample at even n_t). The AFT's
                // harmonic 1 is then the trapezoidal rule of a continuous T with slope jumps J_i
                // at θ_o, θ₂ and 2π − θ_o (Q sin θ_o, (K + Q)|sin θ₂|, Q sin θ_o), second order:
                // at most |J_i|·Δθ²/12 each (Euler–Maclaurin, |B₂(t)|/2 ≤ 1/12 for a kink at
                // a fraction t of a step). Worst cases at 300 samples, K = 800 N: W within
                // a Σ|J_i sin θ_i|Δθ²/12 = 6.7e-4 of W, plus 0.9e-4 from the odd-n_t offset at π;
                // T₁ within Σ|J_i|Δθ²/(12π) = 7.6e-5 of |T₁|. Measured over 300–307 samples:
                // ≤ 1.9e-4 (W), 3.7e-5 (T₁). Bound 1e-3, a tenth of the 1 % asked.
                println!("  {nt} samples: AFT W {e_w:.1e}, T₁ {e_1:.1e}");
                assert!(e_w < 1e-3 && e_1 < 1e-3, "{what}, {nt} samples: AFT W {e_w:.2e}, T₁ {e_1:.2e}");
            } else {
                // Re-contact into a stick: the element resets the slider at the last open
                // sample θ_{j−1} (w = u_t there), not at θ_o, so the first closed sample θ_j has
                // T_j = K (cos θ_j − cos θ_{j−1}) if that stays within μN(θ_j), else −μN(θ_j),
                // where the continuous law has K (cos θ_j − P/Q). The offset
                // c = T_j − K (cos θ_j − P/Q), |c| ≤ K (1 − K/Q) sin θ_o Δθ (both branches), is
                // carried by the stick over the whole closed interval and shifts the
                // harmonic 1 by (1/π)∫c cos θ = −2c sin θ_o/π: a first-order error of the
                // sampled law, up to 4K (1 − K/Q) sin²θ_o/n_t = 6.2e-3 of |T₁| at 300 samples
                // (within the 1 % asked, not within 1e-3), which depends on where θ_o falls
                // between samples: 1.5e-4 at 300, 5.0e-3 at 303. Asserted: that bound, and the
                // predicted shift to a second-order residual (measured ≤ 1.2e-5 of |T₁|,
                // bound 5e-5, also the allowance on the first bound).
                let h = 2.0 * PI / nt as f64;
                let j = (theta_open / h).floor() + 1.0;
                let (tj, tp) = (j * h, (j - 1.0) * h);
                let (trial, limit) = (k * (tj.cos() - tp.cos()), p - q * tj.cos());
                let c = if trial.abs() < limit { trial } else { -limit } - k * (tj.cos() - p / q);
                let c_max = k * (1.0 - k / q) * theta_open.sin() * h;
                assert!(c.abs() <= c_max, "{what}, {nt} samples: offset {c} N beyond {c_max} N");
                let shift = -2.0 * c * theta_open.sin() / PI;
                let residual = (g_c1 - c1 - shift).hypot(g_s1 - s1) / t1;
                let bound = 2.0 * c_max * theta_open.sin() / PI / t1;
                // Dissipation: only a slip just before the opening, where the offset pushes T
                // onto −F: the slider moves at most |c|/k_t under a force at most |c|.
                let w_bound = c_max * c_max / kt / w_scale;
                println!("  {nt} samples: AFT W {e_w:.1e} (bound {w_bound:.1e}), T₁ {e_1:.1e} (bound {bound:.1e}, beyond the predicted shift {residual:.1e})");
                assert!(e_w <= w_bound, "{what}, {nt} samples: AFT W {e_w:.2e}");
                assert!(
                    e_1 <= bound + 5e-5 && residual < 5e-5,
                    "{what}, {nt} samples: AFT T₁ {e_1:.2e}, {residual:.2e}"
                );
            }
        }
    }
}
