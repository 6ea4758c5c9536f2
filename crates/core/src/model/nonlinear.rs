use super::{LinearModel, ModelError};
use crate::elements::Element;

/// One element placed in a model: its law and its application vectors (Eq. 8: `u = Vᵀ U`).
#[derive(Debug)]
pub struct ElementSite {
    /// User's name for the joint (e.g. "blade1").
    pub name: String,
    pub law: Box<dyn Element>,
    /// The element's `d` application vectors, each of length `n_dofs`.
    pub directions: Vec<Vec<f64>>,
}

impl ElementSite {
    /// `u_a = V_aᵀ U` for each direction `a`.
    pub fn displacement(&self, dofs: &[f64], out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(&self.directions) {
            *o = v.iter().zip(dofs).map(|(a, b)| a * b).sum();
        }
    }
}

/// A rigid point contact (unilateral, Coulomb friction, no stiffness): its application vectors
/// (tangential first, then the normal approach, as for [`crate::elements::Contact`]), friction
/// coefficient and normal preload (N). Only the DLFT balance ([`crate::hbm::dlft`]) imposes
/// it; the penalty balances and the time integrator refuse a model that has one.
#[derive(Clone, Debug)]
pub struct RigidContact {
    pub name: String,
    pub directions: Vec<Vec<f64>>,
    pub friction: f64,
    pub preload: f64,
}

/// The linear model and its local nonlinear elements: Eq. 12 without the excitation,
/// `M Ü + D U̇ + K U + Σ_e V_e g_e = F`; or the linear model and rigid contacts, whose forces
/// are constraint reactions rather than functions of the motion.
#[derive(Debug)]
pub struct NonlinearModel {
    pub linear: LinearModel,
    pub elements: Vec<ElementSite>,
    /// Rigid contacts ([`NonlinearModel::with_rigid_contacts`]); empty for a model of elements.
    pub rigid_contacts: Vec<RigidContact>,
}

impl NonlinearModel {
    /// Check that every element has as many application vectors as its law has directions,
    /// each of the model's length and not zero.
    pub fn new(linear: LinearModel, elements: Vec<ElementSite>) -> Result<Self, ModelError> {
        let n = linear.n_dofs();
        for e in &elements {
            if e.directions.len() != e.law.n_dirs() {
                return Err(ModelError::Invalid(format!(
                    "element {:?} ({}) needs {} application vector(s), got {}",
                    e.name,
                    e.law.kind(),
                    e.law.n_dirs(),
                    e.directions.len()
                )));
            }
            for v in &e.directions {
                if v.len() != n {
                    return Err(ModelError::WrongLength {
                        what: format!("application vector of element {:?}", e.name),
                        len: v.len(),
                        expected: n,
                    });
                }
                if v.iter().all(|x| *x == 0.0) {
                    return Err(ModelError::Invalid(format!("application vector of element {:?} is zero", e.name)));
                }
            }
        }
        Ok(NonlinearModel { linear, elements, rigid_contacts: Vec::new() })
    }

    /// The linear model with rigid contacts and no element (what the DLFT balance solves).
    /// Each contact needs 2 or 3 application vectors of the model's length, none zero, a
    /// friction coefficient in `[0, MAX_FRICTION_COEFFICIENT]` and a preload > 0 N.
    pub fn with_rigid_contacts(linear: LinearModel, contacts: Vec<RigidContact>) -> Result<Self, ModelError> {
        let n = linear.n_dofs();
        let max = crate::elements::MAX_FRICTION_COEFFICIENT;
        for c in &contacts {
            let invalid = |m: String| Err(ModelError::Invalid(format!("rigid contact {:?}: {m}", c.name)));
            if !matches!(c.directions.len(), 2 | 3) {
                return invalid(format!(
                    "needs 2 or 3 application vectors (tangential, then normal), got {}",
                    c.directions.len()
                ));
            }
            if !(c.friction.is_finite() && (0.0..=max).contains(&c.friction)) {
                return invalid(format!("friction coefficient must lie in [0, {max}], got {}", c.friction));
            }
            if !(c.preload.is_finite() && c.preload > 0.0) {
                return invalid(format!(
                    "normal preload must be a finite number > 0 (the contact is open at rest otherwise), got {}",
                    c.preload
                ));
            }
            for v in &c.directions {
                if v.len() != n {
                    return Err(ModelError::WrongLength {
                        what: format!("application vector of rigid contact {:?}", c.name),
                        len: v.len(),
                        expected: n,
                    });
                }
                if v.iter().all(|x| *x == 0.0) {
                    return invalid("an application vector is zero".into());
                }
            }
        }
        Ok(NonlinearModel { linear, elements: Vec::new(), rigid_contacts: contacts })
    }

    /// An error unless the model is free of rigid contacts: `solver` (a penalty balance, the
    /// time integrator) computes element forces from the motion, which a rigid contact has
    /// not.
    pub fn check_no_rigid_contacts(&self, solver: &str) -> Result<(), ModelError> {
        match self.rigid_contacts.first() {
            None => Ok(()),
            Some(c) => Err(ModelError::Invalid(format!(
                "{solver} cannot solve rigid contacts (contact {:?}): they are solved by the DLFT balance only",
                c.name
            ))),
        }
    }

    /// Total number of application directions `q` (columns of `V`).
    pub fn n_directions(&self) -> usize {
        self.elements.iter().map(|e| e.law.n_dirs()).sum()
    }

    /// All application vectors, element by element: the columns of `V`.
    pub fn application_vectors(&self) -> impl Iterator<Item = &Vec<f64>> {
        self.elements.iter().flat_map(|e| e.directions.iter())
    }
}

/// Application vector `e_i − e_j` of an element between DOFs `i` and `j` (relative
/// displacement `u = U_i − U_j`), or `e_i` for an element between DOF `i` and the ground.
pub fn relative_direction(n_dofs: usize, i: usize, j: Option<usize>) -> Vec<f64> {
    let mut v = vec![0.0; n_dofs];
    v[i] = 1.0;
    if let Some(j) = j {
        v[j] -= 1.0;
    }
    v
}

/// Stuck stiffness seen by a normalised application vector (paper Eq. 7): `k = Vᵀ K V`.
pub fn stiffness_along(model: &LinearModel, v: &[f64]) -> f64 {
    model.stiffness.bilinear(v, v)
}
