//! The condensed balance (Eqs. 20-29) has the same solution as the full one (Eq. 16).
mod hbm_support;

use hbm_support::*;
use stickslip_core::elements::{Element, Iwan, Jenkins};
use stickslip_core::hbm::{CondensedHbm, HbmSettings};
use stickslip_core::model::{relative_direction, Damping};
use stickslip_core::post::{evaluate_point, OutputSelector};

#[test]
fn condensed_solution_equals_the_full_solution_on_20_dofs_with_3_elements() {
    let n = 20;
    let laws: Vec<(&str, Box<dyn Element>, Vec<f64>)> = vec![
        // Paper form between two DOFs, a standalone slider to the ground, a microslip joint.
        ("paper", Box::new(Jenkins::replacing_stiffness(4e5, 15.0).unwrap()), relative_direction(n, 3, Some(4))),
        ("ground", Box::new(Jenkins::new(2e5, 10.0).unwrap()), relative_direction(n, 12, None)),
        ("iwan", Box::new(Iwan::uniform(3e5, 20.0, 5).unwrap()), relative_direction(n, 17, Some(18))),
    ];
    for damping in [
        Damping::Rayleigh { alpha: 15.0, beta: 1e-6 },
        Damping::Matrix(dense(n, |i, j| if i == j { 25.0 } else { 0.0 })),
    ] {
        let model = chain(n, damping, laws.iter().map(|(a, _, v)| (*a, rebuild(a), v.clone())).collect());
        let mut force = vec![0.0; n];
        force[0] = 1.0;
        let settings = HbmSettings { harmonics: 5, samples: 128 };
        let modes = model.linear.dense_modes().unwrap();
        let omega = 0.97 * modes.omega[0];
        let level = 3000.0;
        let mut cond = CondensedHbm::new(&model, &force, settings).unwrap();
        let x0 = cond.linear_solution(omega, level);
        let (xq, _) = cond.solve(omega, level, &x0, 1e-13, 60).unwrap();
        // The elements do slip here (otherwise the test would only check linear algebra).
        let outputs: Vec<OutputSelector> =
            (0..n).map(|i| OutputSelector { name: format!("x{i}"), vector: relative_direction(n, i, None) }).collect();
        let p = evaluate_point(&mut cond, &xq, omega, level, &outputs).unwrap();
        let states: Vec<(f64, f64)> = p.elements.iter().map(|e| (e.energy_per_cycle, e.stick_fraction)).collect();
        assert!(states.iter().all(|&(w, stick)| w > 0.0 && stick < 0.99), "no slip: {states:?}");
        // Full unknowns recovered from the condensed solution (Eq. 27) ...
        let nc = 2 * settings.harmonics + 1;
        let recovered: Vec<f64> = (0..nc * n).map(|idx| p.outputs[idx % n].coeffs[idx / n]).collect();
        // ... perturbed by 1 % and corrected by Newton on the full (2N+1)n balance.
        let err = full_balance_distance(&model, &force, settings, omega, level, &recovered, 40);
        assert!(err < 1e-8, "condensed vs full: {err:.2e}");
    }
}

fn rebuild(name: &str) -> Box<dyn Element> {
    match name {
        "paper" => Box::new(Jenkins::replacing_stiffness(4e5, 15.0).unwrap()),
        "ground" => Box::new(Jenkins::new(2e5, 10.0).unwrap()),
        _ => Box::new(Iwan::uniform(3e5, 20.0, 5).unwrap()),
    }
}
