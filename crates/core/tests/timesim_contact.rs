//! Harmonic balance against time integration with a contact that slips and opens: the two
//! methods share only the element law, so agreement checks the AFT march, its periodic start
//! at the opening sample and the condensation.
use faer::Mat;
use stickslip_core::elements::Contact;
use stickslip_core::hbm::{CondensedHbm, HbmSettings};
use stickslip_core::model::{relative_direction, Damping, DofLabel, ElementSite, LinearModel, Matrix, NonlinearModel};
use stickslip_core::post::evaluate_point;
use stickslip_core::timesim::{steady_state, SteadyState, SteadyStateOptions};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;
const N_HARMONICS: usize = 7;

/// Two DOFs: a tangential one x (1 kg, 1e6 N/m to the ground) and a normal one y (1 kg,
/// 1e6 N/m), tied to the ground by a 2-D contact (k_t = 5e5 N/m, k_n = 2e6 N/m, μ = 0.4,
/// N0 = 50 N) on (x, y), 20 N·s/m dashpots; both forced in phase, 40 N on x and 60 N on y.
/// Stuck modes at 195 Hz (x) and 276 Hz (y); the y force opens the contact over part of the
/// period (its motion exceeds N0/k_n = 2.5e-5 m) and x slips against a threshold μN(t).
fn model() -> (NonlinearModel, Vec<f64>) {
    let n = 2;
    let diag = |v: [f64; 2]| Matrix::Dense(Mat::from_fn(n, n, |i, j| if i == j { v[i] } else { 0.0 }));
    let linear = LinearModel::new(
        diag([1.0, 1.0]),
        diag([1e6, 1e6]),
        Damping::Matrix(diag([20.0, 20.0])),
        vec![DofLabel::named("x"), DofLabel::named("y")],
        vec![],
    )
    .unwrap();
    let site = ElementSite {
        name: "contact".into(),
        law: Box::new(Contact::new_2d(5e5, 2e6, 0.4, 50.0).unwrap()),
        directions: vec![relative_direction(n, 0, None), relative_direction(n, 1, None)],
    };
    (NonlinearModel::new(linear, vec![site]).unwrap(), vec![40.0, 60.0])
}

fn pair(x: &[f64], q: usize, k: usize, a: usize) -> (f64, f64) {
    (x[(2 * k - 1) * q + a], x[2 * k * q + a])
}

#[test]
fn contact_with_slip_and_separation_time_solution_matches_hbm_n7() {
    let (model, load) = model();
    let q = 2;
    let nc = 2 * N_HARMONICS + 1;
    // 1024 AFT samples: with a varying normal load the slip switches happen at non-zero slip
    // velocity, and the AFT places them to within a sample, a first-order error. At 130 Hz,
    // where the contact slips briefly (stick 58 % of the period), the energy per cycle differs
    // from the time solution's by 1.5 % at 512 samples and 0.2 % at 1024 to 8192 samples
    // (measured); at 150 and 190 Hz by < 1e-4 from 512 samples on. (At 170 Hz the time response
    // does not settle on a period-1 regime within 5000 periods; the balance looks for periodic
    // solutions only, so that frequency is left out.)
    let mut hbm = CondensedHbm::new(&model, &load, HbmSettings { harmonics: N_HARMONICS, samples: 1024 }).unwrap();
    for f in [130.0, 150.0, 190.0] {
        let mut o = SteadyStateOptions::new(f, load.clone());
        // 1024 steps per period: Newmark's error on harmonic 1 is second order in the step
        // (6e-4 at 512 steps on Table 6), and the opening and slip switches fall inside steps.
        o.steps_per_period = 1024;
        o.tolerance = 1e-9;
        let s = steady_state(&model, &o).unwrap();
        let mut xt = vec![0.0; nc * q];
        for a in 0..q {
            let c = SteadyState::harmonics(&s.records.elements.displacement[a], N_HARMONICS).unwrap();
            for (k, v) in c.iter().enumerate() {
                xt[k * q + a] = *v;
            }
        }
        // The balance solved by Newton from the time solution's harmonics.
        let (xh, _) = hbm.solve(TWO_PI * f, 1.0, &xt, 1e-10, 50).unwrap();
        let p = evaluate_point(&mut hbm, &xh, TWO_PI * f, 1.0, &[]).unwrap();
        let e = &p.elements[0];
        // The regime the test is about: the contact slips and opens.
        let opened = e.force[1].iter().filter(|g| **g <= -50.0 + 1e-9).count();
        assert!(opened > 0 && e.stick_fraction < 0.9, "{f} Hz: open on {opened} samples, stick {}", e.stick_fraction);
        for a in 0..q {
            let (ct, st) = pair(&xt, q, 1, a);
            let (ch, sh) = pair(&xh, q, 1, a);
            let e1 = (ct - ch).hypot(st - sh) / ch.hypot(sh);
            println!("{f} Hz, direction {a}: harmonic 1 differs by {e1:.2e}");
            assert!(e1 < 5e-3, "{f} Hz, direction {a}: harmonic 1 differs by {e1:.3e}");
        }
        let (w_time, w_hbm) = (s.energy.elements[0], e.energy_per_cycle);
        let ew = (w_time - w_hbm).abs() / w_hbm;
        println!("{f} Hz: energy per cycle time {w_time:.5e} J, HBM {w_hbm:.5e} J ({ew:.2e}); open {opened}/1024 samples, stick {:.3}", e.stick_fraction);
        assert!(ew < 1e-2, "{f} Hz: dissipation time {w_time:e} J, HBM {w_hbm:e} J");
    }
}
