//! The contact law and its AFT (force, Jacobian) do not allocate once the buffers exist:
//! counted by a global allocator, in its own test binary.

use faer::Mat;
use stickslip_core::elements::{Contact, Element, Tangent};
use stickslip_core::hbm::fourier::{cos_index, sin_index};
use stickslip_core::hbm::{AftPlan, ElementAft};

mod allocation_counter;
use allocation_counter::allocations;

#[test]
fn contact_update_and_aft_do_not_allocate() {
    let law = Contact::new_3d(1e6, 2e6, 0.4, 100.0).unwrap();
    let plan = AftPlan::new(5, 256).unwrap();
    let n = 3 * plan.n_coeffs();
    let mut aft = ElementAft::new(&law, &plan);
    let (mut g, mut jac, mut dw) = (vec![0.0; n], Mat::zeros(n, n), vec![0.0; n]);
    let mut tangent = Tangent::new(3, 2);
    let (mut gs, mut w) = ([0.0; 3], [0.0; 2]);
    // Elliptic slip with a normal motion that opens the contact, and a stuck motion.
    let mut motions = Vec::new();
    for scale in [1.0, 0.05] {
        let mut u = vec![0.0; n];
        u[cos_index(1) * 3] = 3e-4 * scale;
        u[sin_index(1) * 3 + 1] = 2e-4 * scale;
        u[cos_index(1) * 3 + 2] = 8e-5 * scale;
        u[sin_index(2) * 3 + 2] = 1e-5 * scale;
        motions.push(u);
    }
    for u in &motions {
        aft.evaluate(&law, &plan, 500.0, u, &mut g, Some((jac.as_mut(), &mut dw))).unwrap();
    }
    let before = allocations();
    for _ in 0..5 {
        for u in &motions {
            aft.evaluate(&law, &plan, 500.0, u, &mut g, Some((jac.as_mut(), &mut dw))).unwrap();
            aft.evaluate(&law, &plan, 500.0, u, &mut g, None).unwrap();
        }
        law.update(&[1e-4, 2e-4, 1e-5], &[0.0; 3], &mut w, &mut gs, Some(&mut tangent));
    }
    assert_eq!(allocations() - before, 0, "allocations inside the AFT of a contact");
}
