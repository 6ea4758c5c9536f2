//! Time records written by the drivers.

use super::{EnergyTally, State, TimesimError};
use crate::model::NonlinearModel;

/// Time records of selected DOFs and of every element direction.
#[derive(Clone, Debug, Default)]
pub struct Records {
    /// Sample instants (s).
    pub time: Vec<f64>,
    /// Indices of the recorded DOFs.
    pub dofs: Vec<usize>,
    /// `displacement[k][j]`: DOF `dofs[k]` at `time[j]` (m); likewise velocity, acceleration.
    pub displacement: Vec<Vec<f64>>,
    pub velocity: Vec<Vec<f64>>,
    pub acceleration: Vec<Vec<f64>>,
    pub elements: ElementRecords,
}

/// Records of every element direction, element by element.
#[derive(Clone, Debug, Default)]
pub struct ElementRecords {
    /// `element` for a one-direction element, `element.k` (k from 1) otherwise.
    pub names: Vec<String>,
    /// Element displacement `z = Vᵀ U` (m).
    pub displacement: Vec<Vec<f64>>,
    /// Element restoring force `g` in the law's convention (N; paper-form Jenkins: `f − k u`).
    pub force: Vec<Vec<f64>>,
    /// Slider velocity (paper Eq. 33): 0 while the element sticks, `ż` while it slips (m/s).
    pub slider_velocity: Vec<Vec<f64>>,
}

impl Records {
    pub(crate) fn new(model: &NonlinearModel, dofs: &[usize]) -> Result<Self, TimesimError> {
        let n = model.linear.n_dofs();
        if let Some(&index) = dofs.iter().find(|&&i| i >= n) {
            return Err(TimesimError::DofOutOfRange { index, n_dofs: n });
        }
        let mut names = Vec::new();
        for e in &model.elements {
            let d = e.law.n_dirs();
            if d == 1 {
                names.push(e.name.clone());
            } else {
                names.extend((1..=d).map(|k| format!("{}.{k}", e.name)));
            }
        }
        let q = names.len();
        Ok(Records {
            time: Vec::new(),
            dofs: dofs.to_vec(),
            displacement: vec![Vec::new(); dofs.len()],
            velocity: vec![Vec::new(); dofs.len()],
            acceleration: vec![Vec::new(); dofs.len()],
            elements: ElementRecords {
                names,
                displacement: vec![Vec::new(); q],
                force: vec![Vec::new(); q],
                slider_velocity: vec![Vec::new(); q],
            },
        })
    }

    pub(crate) fn clear(&mut self) {
        self.time.clear();
        let e = &mut self.elements;
        for v in self.displacement.iter_mut().chain(&mut self.velocity).chain(&mut self.acceleration) {
            v.clear();
        }
        for v in e.displacement.iter_mut().chain(&mut e.force).chain(&mut e.slider_velocity) {
            v.clear();
        }
    }

    /// Append the state; `slider` is scratch of length q.
    pub(crate) fn push(&mut self, model: &NonlinearModel, state: &State, slider: &mut [f64]) {
        self.time.push(state.time);
        for (k, &i) in self.dofs.iter().enumerate() {
            self.displacement[k].push(state.displacement[i]);
            self.velocity[k].push(state.velocity[i]);
            self.acceleration[k].push(state.acceleration[i]);
        }
        state.slider_velocity(model, slider);
        let e = &mut self.elements;
        for a in 0..e.names.len() {
            e.displacement[a].push(state.element_displacement[a]);
            e.force[a].push(state.element_force[a]);
            e.slider_velocity[a].push(slider[a]);
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }
}

/// Energy over one excitation cycle (J).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CycleEnergy {
    /// Work of the excitation.
    pub input: f64,
    /// Dissipated by viscous damping.
    pub viscous: f64,
    /// Dissipated by each element (the element's work; over a closed cycle, its loop area).
    pub elements: Vec<f64>,
}

impl CycleEnergy {
    pub(crate) fn between(start: &EnergyTally, end: &EnergyTally) -> Self {
        CycleEnergy {
            input: end.input - start.input,
            viscous: end.viscous - start.viscous,
            elements: end.elements.iter().zip(&start.elements).map(|(b, a)| b - a).collect(),
        }
    }

    /// Viscous plus element dissipation.
    pub fn dissipated(&self) -> f64 {
        self.viscous + self.elements.iter().sum::<f64>()
    }
}
