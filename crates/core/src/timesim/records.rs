//! Time records written by the drivers.

use faer::Mat;

use super::{EnergyTally, State, TimesimError};
use crate::model::NonlinearModel;
use crate::signal::antialias::AntiAliasFilter;

/// Where recorded DOFs are read: the integrated coordinates themselves, or physical DOFs
/// `Φ η` of a model integrated in modal coordinates
/// ([`crate::model::NonlinearModel::into_modal`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct Probes {
    dofs: Vec<usize>,
    /// Modal coordinates: row `dofs[k]` of Φ for each recorded DOF.
    rows: Option<Vec<Vec<f64>>>,
}

impl Probes {
    pub(crate) fn new(n: usize, dofs: &[usize], shapes: Option<&Mat<f64>>) -> Result<Self, TimesimError> {
        let n_physical = shapes.map_or(n, |s| s.nrows());
        if let Some(&index) = dofs.iter().find(|&&i| i >= n_physical) {
            return Err(TimesimError::DofOutOfRange { index, n_dofs: n_physical });
        }
        if let Some(s) = shapes {
            if s.ncols() != n {
                return Err(TimesimError::Invalid(format!(
                    "the model has {n} modal coordinates, the mode shapes {} columns",
                    s.ncols()
                )));
            }
        }
        let rows = shapes.map(|s| dofs.iter().map(|&i| (0..n).map(|j| s[(i, j)]).collect()).collect());
        Ok(Probes { dofs: dofs.to_vec(), rows })
    }

    /// The coordinates the probes read, in the order [`Probes::combine`] expects them.
    pub(crate) fn sources(&self, n: usize) -> Vec<usize> {
        match self.rows {
            Some(_) => (0..n).collect(),
            None => self.dofs.clone(),
        }
    }

    /// Recorded DOF `k` from the values of the sources (anything linear in the coordinates:
    /// displacements, or their Fourier coefficients).
    pub(crate) fn combine(&self, k: usize, sources: &[f64]) -> f64 {
        match &self.rows {
            Some(rows) => rows[k].iter().zip(sources).map(|(a, b)| a * b).sum(),
            None => sources[k],
        }
    }

    /// Recorded DOF `k` of the state vector `x`.
    fn read(&self, k: usize, x: &[f64]) -> f64 {
        match &self.rows {
            Some(rows) => rows[k].iter().zip(x).map(|(a, b)| a * b).sum(),
            None => x[self.dofs[k]],
        }
    }
}

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
    /// The excitation's time function `e(t)` at each sample (`F(t) = e(t) · load`).
    pub excitation: Vec<f64>,
    probes: Probes,
    /// Anti-aliasing filters, one per recorded series (see [`Records::sample`]).
    filters: Vec<AntiAliasFilter>,
    /// Scratch: one sample of every series.
    row: Vec<f64>,
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
    /// Records of `dofs`: DOFs of the model, or of the physical model when the model is in
    /// modal coordinates and `shapes` are its mode shapes.
    pub(crate) fn new(model: &NonlinearModel, dofs: &[usize], shapes: Option<&Mat<f64>>) -> Result<Self, TimesimError> {
        let probes = Probes::new(model.linear.n_dofs(), dofs, shapes)?;
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
            excitation: Vec::new(),
            probes,
            filters: Vec::new(),
            row: Vec::new(),
        })
    }

    /// Low-pass filter every series at the integration rate `step_rate_hz` before sampling, as a
    /// test system does (see [`crate::signal::antialias`]): then [`Records::sample`] must see
    /// every step.
    pub(crate) fn anti_alias(&mut self, step_rate_hz: f64, cutoff_hz: f64) -> Result<(), TimesimError> {
        let series = 1 + 3 * self.dofs.len() + 3 * self.elements.names.len();
        let filter = AntiAliasFilter::new(step_rate_hz, cutoff_hz).map_err(|e| TimesimError::Invalid(e.to_string()))?;
        self.filters = vec![filter; series];
        Ok(())
    }

    /// Feed one step's state; it is kept when `keep` (through the anti-aliasing filters, if
    /// any, which then must see every step).
    pub(crate) fn sample(&mut self, model: &NonlinearModel, state: &State, slider: &mut [f64], keep: bool) {
        if self.filters.is_empty() {
            if keep {
                self.push(model, state, slider);
            }
            return;
        }
        let mut row = std::mem::take(&mut self.row);
        row.clear();
        row.push(state.excitation);
        for x in [&state.displacement, &state.velocity, &state.acceleration] {
            row.extend((0..self.dofs.len()).map(|k| self.probes.read(k, x)));
        }
        state.slider_velocity(model, slider);
        row.extend_from_slice(&state.element_displacement);
        row.extend_from_slice(&state.element_force);
        row.extend_from_slice(slider);
        for (x, f) in row.iter_mut().zip(&mut self.filters) {
            *x = f.run(*x);
        }
        if keep {
            let (n, q) = (self.dofs.len(), self.elements.names.len());
            self.time.push(state.time);
            self.excitation.push(row[0]);
            for k in 0..n {
                self.displacement[k].push(row[1 + k]);
                self.velocity[k].push(row[1 + n + k]);
                self.acceleration[k].push(row[1 + 2 * n + k]);
            }
            let e = &mut self.elements;
            for a in 0..q {
                e.displacement[a].push(row[1 + 3 * n + a]);
                e.force[a].push(row[1 + 3 * n + q + a]);
                e.slider_velocity[a].push(row[1 + 3 * n + 2 * q + a]);
            }
        }
        self.row = row;
    }

    pub(crate) fn clear(&mut self) {
        self.time.clear();
        self.excitation.clear();
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
        self.excitation.push(state.excitation);
        for k in 0..self.dofs.len() {
            self.displacement[k].push(self.probes.read(k, &state.displacement));
            self.velocity[k].push(self.probes.read(k, &state.velocity));
            self.acceleration[k].push(self.probes.read(k, &state.acceleration));
        }
        state.slider_velocity(model, slider);
        let e = &mut self.elements;
        for a in 0..e.names.len() {
            e.displacement[a].push(state.element_displacement[a]);
            e.force[a].push(state.element_force[a]);
            e.slider_velocity[a].push(slider[a]);
        }
    }

    pub(crate) fn probes(&self) -> &Probes {
        &self.probes
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
