//! A parametric model of the test structure "Harmony" (paper Section 2.2, Table 1; Section 3.1):
//! base plate, external envelope, central body clamped at its bottom, four blades screwed on the
//! body top and pressed against the envelope, the shaker as an inertial mass on a soft spring.
//!
//! The paper gives the parts' materials, envelope dimensions and measured masses (Table 1), the
//! modelling of the joints (Section 3.1) and the frequencies of the updated model (Tables 4-5),
//! not the drawings. This geometry is therefore Harmony-like: bodies of revolution and Table 1's
//! blades (65 × 118 mm plates, 1.82 mm thick from their mass) whose free dimensions are set so
//! that (i) each part has its measured mass and (ii) the assembly's first two axial modes, its
//! all-slipping resonance and the substructures' modes are the paper's. Which dimension plays
//! which role:
//! - the body is a hub tube standing on a thin annular diaphragm, the body's flange inside
//!   `body_flange_radius` and the envelope's web outside, with a 12 mm top disk carrying the
//!   blades; the diaphragm thickness sets the body's axial mode with the blades slipping (paper:
//!   ~190 Hz), the flange radius the body substructure's synchronous mode, clamped on that
//!   circle (Table 4: 210.8 Hz);
//! - each blade is screwed flat on the top disk and bent up at the outer edge of its outer screw
//!   zone, rising `blade_rise` to its tip against the envelope's inner wall (the paper's blades
//!   are "compressed" against it, Section 2.1). The screws' radii set the free length, hence the
//!   blades' bending modes in the body substructure (Table 4: four at 254-260 Hz); the rise sets
//!   the stiffening when stuck (paper: 237.6 Hz): held by the contact, an inclined blade resists
//!   the body's axial motion by its membrane stiffness, slipping it follows as a rigid piece;
//! - the shaker's coupling to the base plate (radius of the coupled zone, 37 mm) sets the
//!   envelope substructure's first vertical mode on the shaker, the base plate and envelope
//!   bouncing on the base plate's bending (Table 4: 880.4 Hz, test 889 Hz); in the assembly that
//!   mode is the second axial mode (Table 5: 878.4 Hz).
//!
//! [`BodyVariant`] also builds the variants docs/harmony.md measured on the way (blades on edge,
//! a thin, stepped or rimmed top disk, flat blades).
//!
//! Modelling as Section 3.1: reference nodes rigidly drive the screw zones (radius 10 mm) on
//! each blade and on the body, the blade tip face ("Top_Blade") and the envelope's contact zone
//! ("Contact_Zone"); stiff connectors (1e10 N/m per component) join them; the shaker is a mass
//! moving vertically only, rigidly coupled to the bottom of the base plate and held by
//! K_soft = 22800 N/m. Friction acts on the vertical component of each contact connector.
//!
//! The paper calls its one friction element per blade (Section 3.4, Eqs. 7-11) a
//! simplification of a contact that is really an area: [`TipContact::Patch`] meshes that area
//! instead. Each blade's tip face is shaped to the wall's radius and the wall is cut at the
//! tip's own angular and vertical subdivisions, so the two faces have coincident, distinct
//! nodes (node sets `TIP_FACE_i` and `WALL_FACE_i`) that a contact patch pairs node to node;
//! no reference nodes, couplings or connectors are made there.
//!
//! Node numbering, independent of the refinement, so that studies can name DOFs
//! (`"node.direction"`): shaker 1; blade i = 1..4: Top_Blade 10+i, Contact_Zone 20+i (with
//! [`TipContact::Patch`], the mesh node at the centre of the tip face and the wall node facing
//! it), blade screw references 30+i and 40+i, body screw references 50+i and 60+i;
//! accelerometers 101..110 (mesh nodes, see [`ACCELEROMETERS`]); other mesh nodes from 1001.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use crate::element::SolidKind;
use crate::mesh::structured::{placed_box, revolve_at, Block, GenerateError, Part, ProfileRect, QuarterAngles};
use crate::mesh::{Material, Mesh, PointElement, RigidCoupling};

/// Node id of the shaker's mass.
pub const SHAKER: u64 = 1;
/// Node id of blade `i`'s tip reference ("Top_Blade", i = 1..4).
pub fn top_blade(i: usize) -> u64 {
    10 + i as u64
}
/// Node id of the envelope's contact zone reference facing blade `i` ("Contact_Zone").
pub fn contact_zone(i: usize) -> u64 {
    20 + i as u64
}
/// Node ids of blade `i`'s two screw references on the blade.
pub fn blade_screws(i: usize) -> [u64; 2] {
    [30 + i as u64, 40 + i as u64]
}
/// Node ids of the body's two screw references under blade `i`.
pub fn body_screws(i: usize) -> [u64; 2] {
    [50 + i as u64, 60 + i as u64]
}

/// The ten tri-axial accelerometers (paper Fig. 2): name and where, as (part, radius, angle in
/// degrees from blade 1, height z); node ids 101..110 in this order. The nearest mesh node of
/// the part is used.
pub const ACCELEROMETERS: [(&str, Part3, f64, f64, Height); 10] = [
    ("body_top", Part3::Body, 0.0, 0.0, Height::BodyTop),
    ("base_centre", Part3::Base, 0.0, 0.0, Height::BaseTop),
    ("envelope_top", Part3::Envelope, 1.0, 45.0, Height::EnvelopeTop),
    ("envelope_top_b", Part3::Envelope, 1.0, 135.0, Height::EnvelopeTop),
    ("envelope_top_c", Part3::Envelope, 1.0, 225.0, Height::EnvelopeTop),
    ("envelope_mid", Part3::Envelope, 1.0, 45.0, Height::EnvelopeMid),
    ("envelope_mid_b", Part3::Envelope, 1.0, 225.0, Height::EnvelopeMid),
    ("base_rim", Part3::Base, 1.0, 45.0, Height::BaseTop),
    ("body_rim", Part3::Body, 0.85, 45.0, Height::BodyTop),
    ("body_rim_b", Part3::Body, 0.85, 225.0, Height::BodyTop),
];

/// Which part an accelerometer is on (for the radius: a fraction of that part's outer radius).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part3 {
    Base,
    Envelope,
    Body,
}

/// Heights of the accelerometers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Height {
    BaseTop,
    EnvelopeTop,
    EnvelopeMid,
    BodyTop,
}

/// Node id of accelerometer `k` (0-based in [`ACCELEROMETERS`]).
pub fn accelerometer(k: usize) -> u64 {
    101 + k as u64
}

/// How each blade tip meets the envelope wall.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TipContact {
    /// The paper's model (Section 3.1): the tip face and the wall's contact zone rigidly
    /// coupled to reference nodes (Top_Blade, Contact_Zone) joined by a connector, on whose
    /// vertical component one friction element acts.
    #[default]
    Connector,
    /// Conforming faces: the tip face shaped to the wall's radius, the wall cut at the tip's
    /// angular and vertical subdivisions, coincident nodes in `TIP_FACE_i` and `WALL_FACE_i`
    /// (the two bodies apart) for a node-to-node contact patch.
    Patch,
}

impl TipContact {
    /// The key that chooses it, and the values it takes.
    pub const KEY: &'static str = "tip_contact";
    pub const VALUES: [&'static str; 2] = ["connector", "patch"];
}

impl std::str::FromStr for TipContact {
    type Err = GenerateError;

    fn from_str(value: &str) -> Result<TipContact, GenerateError> {
        match value {
            "connector" => Ok(TipContact::Connector),
            "patch" => Ok(TipContact::Patch),
            other => Err(GenerateError::Geometry {
                part: "harmony".into(),
                msg: format!(
                    "{} must be {}, got {other:?}",
                    TipContact::KEY,
                    TipContact::VALUES.map(|v| format!("{v:?}")).join(" or ")
                ),
            }),
        }
    }
}

/// Dimensions (m), materials, masses (kg) and joint values of the Harmony-like assembly.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// Target element size (m) of the bodies of revolution; blades are cut in proportion.
    pub element_size: f64,
    /// hex20 (default) or hex8.
    pub kind: SolidKind,
    pub base_radius: f64,
    /// Base plate mass (Table 1: 9.47 kg); its thickness follows.
    pub base_mass: f64,
    pub envelope_radius: f64,
    pub envelope_height: f64,
    /// Envelope mass (Table 1: 44.88 kg); the wall thickness follows.
    pub envelope_mass: f64,
    /// Height of the envelope's bottom ring, which holds the body's diaphragm.
    pub envelope_ring_height: f64,
    /// Inner radius of the bottom ring (= outer radius of the diaphragm).
    pub envelope_ring_inner_radius: f64,
    /// Central body height (Table 1: 300 mm), mass (11.92 kg); the top disk thickness or the
    /// hub's inner radius follows.
    pub body_height: f64,
    pub body_mass: f64,
    pub body_top_radius: f64,
    pub hub_outer_radius: f64,
    pub hub_inner_radius: f64,
    pub diaphragm_thickness: f64,
    /// Geometry of the body and blades beyond Table 1 (flange, top disk, the blades' rise).
    /// Boxed: a study keeps a `Design` by value.
    pub variant: Box<BodyVariant>,
    /// Blade length (Table 1: 118 mm), mass (0.1086 kg), thickness; the width follows.
    pub blade_length: f64,
    pub blade_mass: f64,
    pub blade_thickness: f64,
    /// Radii of the two screws of each blade.
    pub screw_radii: [f64; 2],
    /// Radius of the zones the screw references drive (paper: 10 mm).
    pub screw_zone_radius: f64,
    /// Half-height of the envelope's contact zone around the blade tip.
    pub contact_zone_half_height: f64,
    pub connector_stiffness: f64,
    /// Vertical stiffness of the contact connectors; 0 releases them (all blades slipping).
    pub contact_vertical_stiffness: f64,
    /// Connectors at the blade tips (the paper's) or conforming faces for contact patches.
    pub tip_contact: TipContact,
    pub shaker_mass: f64,
    pub shaker_spring: f64,
    /// Radius of the base plate's bottom zone rigidly coupled to the shaker (the shaker's
    /// armature insert).
    pub shaker_zone_radius: f64,
    pub steel_304l: Material,
    pub aluminium_2017a: Material,
    pub blade_steel: Material,
}

impl Default for Design {
    fn default() -> Self {
        Design {
            element_size: 0.03,
            kind: SolidKind::Hex20,
            base_radius: 0.204,
            base_mass: 9.47,
            envelope_radius: 0.204,
            envelope_height: 0.420,
            envelope_mass: 44.88,
            envelope_ring_height: 0.030,
            envelope_ring_inner_radius: 0.150,
            body_height: 0.300,
            body_mass: 11.92,
            body_top_radius: 0.156,
            hub_outer_radius: 0.060,
            hub_inner_radius: 0.054,
            diaphragm_thickness: 0.00448,
            variant: Box::default(),
            blade_length: 0.118,
            blade_mass: 0.1086,
            blade_thickness: 0.00182,
            screw_radii: [0.093, 0.115],
            screw_zone_radius: 0.010,
            contact_zone_half_height: 0.010,
            connector_stiffness: 1e10,
            contact_vertical_stiffness: 1e10,
            tip_contact: TipContact::Connector,
            shaker_mass: 10.0,
            shaker_spring: 22800.0,
            shaker_zone_radius: 0.037,
            steel_304l: Material { young: 193e9, poisson: 0.29, density: 7900.0 },
            aluminium_2017a: Material { young: 72.5e9, poisson: 0.33, density: 2790.0 },
            blade_steel: Material { young: 196e9, poisson: 0.272, density: 7780.0 },
        }
    }
}

/// Geometry of the body and blades beyond Table 1, set by the calibration of the body
/// substructure (Table 4); its default is the calibrated design's.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyVariant {
    /// Outer radius of the body's flange: the diaphragm from the hub to this radius is the body's,
    /// from it to the bottom ring the envelope's inner web (counted in the envelope's mass). The
    /// body substructure is clamped on this circle. `None`: the whole diaphragm is the body's,
    /// clamped at the bottom ring.
    pub body_flange_radius: Option<f64>,
    /// Top disk thickness; `None`: from the body mass. Given, the rest of the body mass is in a
    /// rim ring under the disk's edge, `rim_width` wide, or, if `rim_width` is 0, in the hub tube
    /// (its inner radius follows).
    pub top_disk_thickness: Option<f64>,
    pub rim_width: f64,
    /// A thinner inner zone of the top disk (with `top_disk_thickness` given and no rim): its
    /// outer radius and thickness; the hub stops under it.
    pub top_disk_inner: Option<(f64, f64)>,
    /// Blades standing on edge: a plate `blade_height` high (vertical), its thickness
    /// (tangential) from the mass; `blade_thickness` is then not used. `None`: flat blades.
    pub blade_height: Option<f64>,
    /// Blades bent up at the outer edge of their outer screw zone, rising by this much (m) to
    /// their tip: leaf springs pressed against the wall (the paper's blades "are compressed",
    /// Section 2.1). Stuck, an inclined blade holds the body top by its membrane stiffness
    /// (E A / L sin² of the angle); slipping, it follows the body as a rigid piece; its
    /// bending modes are those of the flat cantilever. 0: flat blades.
    pub blade_rise: f64,
}

impl Default for BodyVariant {
    fn default() -> Self {
        BodyVariant {
            body_flange_radius: Some(0.1378),
            top_disk_thickness: Some(0.012),
            rim_width: 0.0,
            top_disk_inner: None,
            blade_height: None,
            blade_rise: 0.0145,
        }
    }
}

/// Which parts to build: the assembly or one of the paper's substructures (Table 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Configuration {
    /// Everything, on the shaker.
    Assembly,
    /// Base plate and envelope on the shaker (the body removed).
    Envelope,
    /// Central body and blades, the diaphragm's outer rim clamped, blade tips free.
    BodyWithBlades,
}

/// Derived dimensions (m) and the mass of each part (kg) as modelled.
#[derive(Clone, Debug, PartialEq)]
pub struct Dimensions {
    pub base_thickness: f64,
    pub envelope_inner_radius: f64,
    pub top_disk_thickness: f64,
    /// Height of the rim ring under the top disk's edge (0: none).
    pub rim_height: f64,
    /// Thickness of the top disk's inner zone (= `top_disk_thickness` if none) and its radius.
    pub top_disk_inner_thickness: f64,
    pub top_disk_step_radius: f64,
    pub hub_inner_radius: f64,
    pub blade_width: f64,
    pub masses: Vec<(&'static str, f64)>,
}

impl Design {
    /// A design with the default dimensions meshed `refinement` times finer (1: coarse).
    pub fn refined(refinement: f64) -> Design {
        let d = Design::default();
        Design { element_size: d.element_size / refinement, ..d }
    }

    fn fail(&self, msg: String) -> GenerateError {
        GenerateError::Geometry { part: "harmony".into(), msg }
    }

    /// Dimensions that follow from the masses, checked for a buildable geometry.
    pub fn dimensions(&self) -> Result<Dimensions, GenerateError> {
        let positive = [
            ("element_size", self.element_size),
            ("base_radius", self.base_radius),
            ("base_mass", self.base_mass),
            ("envelope_radius", self.envelope_radius),
            ("envelope_height", self.envelope_height),
            ("envelope_mass", self.envelope_mass),
            ("envelope_ring_height", self.envelope_ring_height),
            ("envelope_ring_inner_radius", self.envelope_ring_inner_radius),
            ("body_height", self.body_height),
            ("body_mass", self.body_mass),
            ("body_top_radius", self.body_top_radius),
            ("hub_outer_radius", self.hub_outer_radius),
            ("hub_inner_radius", self.hub_inner_radius),
            ("diaphragm_thickness", self.diaphragm_thickness),
            ("blade_length", self.blade_length),
            ("blade_mass", self.blade_mass),
            ("blade_thickness", self.blade_thickness),
            ("blade_height", self.variant.blade_height.unwrap_or(1.0)),
            ("screw_zone_radius", self.screw_zone_radius),
            ("contact_zone_half_height", self.contact_zone_half_height),
            ("connector_stiffness", self.connector_stiffness),
            ("shaker_mass", self.shaker_mass),
            ("shaker_spring", self.shaker_spring),
            ("shaker_zone_radius", self.shaker_zone_radius),
        ];
        for (key, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(self.fail(format!("{key} must be > 0 and finite, got {v}")));
            }
        }
        if !(self.contact_vertical_stiffness >= 0.0 && self.contact_vertical_stiffness.is_finite()) {
            return Err(self.fail(format!(
                "contact_vertical_stiffness must be >= 0 N/m, got {}",
                self.contact_vertical_stiffness
            )));
        }
        let order = |a: (&str, f64), b: (&str, f64)| -> Result<(), GenerateError> {
            if a.1 < b.1 {
                Ok(())
            } else {
                Err(self.fail(format!("{} ({} m) must be smaller than {} ({} m)", a.0, a.1, b.0, b.1)))
            }
        };
        order(("hub_inner_radius", self.hub_inner_radius), ("hub_outer_radius", self.hub_outer_radius))?;
        order(
            ("hub_outer_radius", self.hub_outer_radius),
            ("envelope_ring_inner_radius", self.envelope_ring_inner_radius),
        )?;
        order(("hub_outer_radius", self.hub_outer_radius), ("body_top_radius", self.body_top_radius))?;
        order(("diaphragm_thickness", self.diaphragm_thickness), ("envelope_ring_height", self.envelope_ring_height))?;
        order(
            ("envelope_ring_inner_radius", self.envelope_ring_inner_radius),
            ("envelope_radius", self.envelope_radius),
        )?;
        let steel = self.steel_304l.density;
        let base_thickness = self.base_mass / (self.aluminium_2017a.density * PI * self.base_radius.powi(2));
        // The diaphragm: the body's flange inside the flange radius, the envelope's web outside.
        let diaphragm = steel
            * PI
            * (self.envelope_ring_inner_radius.powi(2) - self.hub_outer_radius.powi(2))
            * self.diaphragm_thickness;
        let flange_radius = self.flange_radius();
        if !(flange_radius >= self.hub_outer_radius && flange_radius <= self.envelope_ring_inner_radius) {
            return Err(self.fail(format!(
                "body_flange_radius ({flange_radius} m) must lie between the hub's outer radius and the bottom ring's inner radius"
            )));
        }
        let flange = steel * PI * (flange_radius.powi(2) - self.hub_outer_radius.powi(2)) * self.diaphragm_thickness;
        let web = diaphragm - flange;
        // Envelope: the bottom ring (and the web), then a wall of the thickness that gives the mass.
        let ring_mass = steel
            * PI
            * (self.envelope_radius.powi(2) - self.envelope_ring_inner_radius.powi(2))
            * self.envelope_ring_height
            + web;
        let wall_height = self.envelope_height - self.envelope_ring_height;
        if ring_mass >= self.envelope_mass || wall_height <= 0.0 {
            return Err(self.fail(format!(
                "the envelope's bottom ring alone weighs {ring_mass:.2} kg, more than envelope_mass = {} kg, or is taller than the envelope",
                self.envelope_mass
            )));
        }
        let inner2 = self.envelope_radius.powi(2) - (self.envelope_mass - ring_mass) / (steel * PI * wall_height);
        if inner2 <= self.envelope_ring_inner_radius.powi(2) {
            return Err(self.fail(format!(
                "envelope_mass = {} kg needs a wall thicker than the bottom ring is wide",
                self.envelope_mass
            )));
        }
        let envelope_inner_radius = inner2.sqrt();
        // Body: (diaphragm and) hub tube, then a top disk of the thickness that gives the mass,
        // or of the given thickness with a rim ring carrying the rest.
        let hub_area = PI * (self.hub_outer_radius.powi(2) - self.hub_inner_radius.powi(2));
        let disk_area = PI * self.body_top_radius.powi(2);
        let hub_height_full = self.body_height - self.diaphragm_thickness;
        let rest = self.body_mass / steel - flange / steel - hub_area * hub_height_full;
        let mut hub_inner_radius = self.hub_inner_radius;
        let (mut inner_t, mut step_r) = (0.0, 0.0);
        let (top_disk_thickness, rim_height) = match self.variant.top_disk_thickness {
            None => (rest / (disk_area - hub_area), 0.0),
            Some(t) if self.variant.rim_width == 0.0 => {
                // The hub tube, under the disk's inner zone, takes the rest of the mass: its
                // cross-section, hence its inner radius, follows.
                (step_r, inner_t) = self.variant.top_disk_inner.unwrap_or((self.hub_outer_radius, t));
                if !(inner_t > 0.0 && inner_t <= t && step_r >= self.hub_outer_radius && step_r < self.body_top_radius)
                {
                    return Err(self.fail(format!(
                        "top_disk_inner ({step_r} m, {inner_t} m): the inner zone must be thinner than the disk and outside the hub"
                    )));
                }
                let full = PI * self.hub_outer_radius.powi(2);
                let disk = PI * step_r.powi(2) * inner_t + PI * (self.body_top_radius.powi(2) - step_r.powi(2)) * t;
                let hub = (self.body_mass / steel - flange / steel - disk) / (hub_height_full - inner_t);
                let inner2 = (full - hub) / PI;
                if !(inner2 > 0.0 && hub > 0.0) {
                    return Err(self.fail(format!(
                        "body_mass = {} kg cannot be met with a top disk {t} m thick and the hub's outer radius",
                        self.body_mass
                    )));
                }
                hub_inner_radius = inner2.sqrt();
                (t, 0.0)
            }
            Some(t) => {
                let inner = self.body_top_radius - self.variant.rim_width;
                if !(t > 0.0 && self.variant.rim_width > 0.0 && inner > self.hub_outer_radius) {
                    return Err(self.fail(format!(
                        "top_disk_thickness ({t} m) and rim_width ({} m) must be > 0, the rim outside the hub",
                        self.variant.rim_width
                    )));
                }
                let rim = rest - (disk_area - hub_area) * t;
                (t, rim / (PI * (self.body_top_radius.powi(2) - inner.powi(2))))
            }
        };
        if !(top_disk_thickness > 0.0 && rim_height >= 0.0 && top_disk_thickness + rim_height < 0.5 * hub_height_full) {
            return Err(self.fail(format!(
                "body_mass = {} kg cannot be met with these body dimensions (top disk thickness {top_disk_thickness:.4} m, rim height {rim_height:.4} m)",
                self.body_mass
            )));
        }
        let rise = self.variant.blade_rise;
        if !(rise >= 0.0 && rise.is_finite()) || (rise > 0.0 && self.variant.blade_height.is_some()) {
            return Err(self.fail(format!("blade_rise must be >= 0 m, and 0 for blades on edge, got {rise}")));
        }
        let blade_width = self.blade_mass
            / (self.blade_steel.density * self.blade_developed_length(envelope_inner_radius) * self.blade_vertical());
        // The blade runs from the envelope wall inwards, over the top disk, where it is screwed.
        let blade_root = envelope_inner_radius - self.blade_length;
        let free_span = envelope_inner_radius - self.body_top_radius;
        if blade_root <= 0.0 || free_span <= 0.0 {
            return Err(self.fail(format!(
                "blade_length = {} m does not fit between the axis and the envelope wall (inner radius {envelope_inner_radius:.4} m) over the top disk (radius {} m)",
                self.blade_length, self.body_top_radius
            )));
        }
        for (k, &r) in self.screw_radii.iter().enumerate() {
            if !(r - self.screw_zone_radius > blade_root && r + self.screw_zone_radius < self.body_top_radius) {
                return Err(self.fail(format!(
                    "screw_radii[{k}] = {r} m: a screw zone must lie on the blade ({blade_root:.4}..{envelope_inner_radius:.4} m) over the top disk (< {} m)",
                    self.body_top_radius
                )));
            }
        }
        if (self.screw_radii[1] - self.screw_radii[0]).abs() <= 2.0 * self.screw_zone_radius {
            return Err(self.fail(format!(
                "screw_radii = {:?} m: the two screw zones (radius {} m) overlap",
                self.screw_radii, self.screw_zone_radius
            )));
        }
        if blade_width >= 2.0 * self.body_top_radius * (PI / 4.0).sin() {
            return Err(self.fail(format!("blades {blade_width:.4} m wide overlap on the top disk")));
        }
        if rise + self.blade_vertical() + self.body_height + self.envelope_ring_height - self.diaphragm_thickness
            >= self.envelope_height
        {
            return Err(self.fail("the blades stand above the envelope's top".into()));
        }
        let masses = vec![
            ("base plate", self.base_mass),
            ("envelope", self.envelope_mass),
            ("central body", self.body_mass),
            ("blade", self.blade_mass),
        ];
        if inner_t == 0.0 {
            (inner_t, step_r) = (top_disk_thickness, self.hub_outer_radius);
        }
        Ok(Dimensions {
            base_thickness,
            envelope_inner_radius,
            top_disk_thickness,
            rim_height,
            top_disk_inner_thickness: inner_t,
            top_disk_step_radius: step_r,
            hub_inner_radius,
            blade_width,
            masses,
        })
    }

    /// Heights of the stack (m): base top, ring top, diaphragm bottom, hub top (top disk
    /// bottom), top disk top, blade top, envelope top.
    fn heights(&self, d: &Dimensions) -> [f64; 7] {
        let base_top = d.base_thickness;
        let ring_top = base_top + self.envelope_ring_height;
        let diaphragm_bottom = ring_top - self.diaphragm_thickness;
        let disk_top = diaphragm_bottom + self.body_height;
        let disk_bottom = disk_top - d.top_disk_inner_thickness;
        [
            base_top,
            ring_top,
            diaphragm_bottom,
            disk_bottom,
            disk_top,
            disk_top + self.variant.blade_rise + self.blade_vertical(),
            base_top + self.envelope_height,
        ]
    }

    /// Number of DOFs of the mesh at this design's element size, estimated before meshing
    /// (3 per node, hex20 ≈ 4 nodes per element), to refuse a refinement out of memory.
    pub fn estimated_dofs(&self) -> Result<usize, GenerateError> {
        let d = self.dimensions()?;
        let h = self.element_size;
        let sectors = 4.0 * self.quarter_angles(&d).cells() as f64;
        let z = self.heights(&d)[6];
        let radial = (self.envelope_radius / h).ceil() + 6.0;
        let axial = (z / h).ceil() + 8.0;
        let nodes_per_cell = if self.kind == SolidKind::Hex8 { 1.0 } else { 4.0 };
        // The revolved solid fills about half of its (r, z) bounding box. In f64, saturating
        // on conversion: a tiny element size from a damaged study file overflowed usize here.
        let blade_cells: f64 = self.blade_cells(&d).iter().map(|&c| c as f64).product();
        Ok((3.0 * nodes_per_cell * 0.5 * radial * axial * sectors + 4.0 * 3.0 * blade_cells * 4.0) as usize)
    }

    /// Where a blade with a rise is bent up (m from the axis): the outer edge of its outer
    /// screw zone.
    fn blade_bend(&self) -> f64 {
        self.screw_radii[0].max(self.screw_radii[1]) + self.screw_zone_radius
    }

    /// Length of a blade along its plate: its radial length, or with a rise, the flat part and
    /// the inclined one.
    fn blade_developed_length(&self, envelope_inner_radius: f64) -> f64 {
        let rise = self.variant.blade_rise;
        if rise == 0.0 {
            return self.blade_length;
        }
        let inclined = envelope_inner_radius - self.blade_bend();
        self.blade_length - inclined + inclined.hypot(rise)
    }

    /// Vertical size of a blade: its thickness if flat, its height if standing on edge.
    fn blade_vertical(&self) -> f64 {
        self.variant.blade_height.unwrap_or(self.blade_thickness)
    }

    fn flange_radius(&self) -> f64 {
        self.variant.body_flange_radius.unwrap_or(self.envelope_ring_inner_radius)
    }

    fn sectors(&self) -> usize {
        // A multiple of 8 so that the blades' planes (0, 90, 180, 270 degrees) and the
        // accelerometers at 45 degrees fall on node lines.
        let s = (2.0 * PI * self.body_top_radius / self.element_size).ceil() as usize;
        s.div_ceil(8).max(2).saturating_mul(8)
    }

    /// Angles at which each quarter turn of the revolved part is cut. With
    /// [`TipContact::Patch`] the quarter's centre (a blade's plane) carries the tip's
    /// subdivisions across the blade, ±`tip_half_angle` each side, and equal sectors outside;
    /// an equal sector's edge within half a sector of the blade is left out (no sliver).
    fn quarter_angles(&self, d: &Dimensions) -> QuarterAngles {
        let quarter = self.sectors() / 4;
        if self.tip_contact == TipContact::Connector {
            return QuarterAngles::Uniform(quarter);
        }
        let half = self.tip_half_angle(d);
        let step = FRAC_PI_2 / quarter as f64;
        let across = self.blade_cells(d)[1];
        let mut stations = vec![-FRAC_PI_4, FRAC_PI_4];
        stations.extend((1..quarter).map(|j| -FRAC_PI_4 + j as f64 * step).filter(|t| t.abs() >= half + 0.5 * step));
        stations.extend((0..=across).map(|k| half * (2.0 * k as f64 / across as f64 - 1.0)));
        stations.sort_by(f64::total_cmp);
        QuarterAngles::Stations(stations)
    }

    /// Half the angle a blade's tip spans on the wall (rad): its edges lie on the wall's circle.
    fn tip_half_angle(&self, d: &Dimensions) -> f64 {
        (0.5 * d.blade_width / d.envelope_inner_radius).asin()
    }

    fn blade_cells(&self, d: &Dimensions) -> [usize; 3] {
        let along = ((self.blade_length / (0.5 * self.element_size)).ceil() as usize).max(8);
        if let Some(h) = self.variant.blade_height {
            // On edge: one quadratic element through the thin plate, the height cut as the length.
            return [along, 1, ((h / (0.5 * self.element_size)).ceil() as usize).max(2)];
        }
        // Across: at least 3 cm per cell, and two per element size on a wide blade (a screw
        // zone then has nodes around its centre, not only along the blade's middle line).
        let across = ((0.03 / self.element_size).ceil() as usize)
            .max(2)
            .max((d.blade_width / (0.5 * self.element_size)).ceil() as usize);
        [along, across, 1 + (self.element_size < 0.01) as usize]
    }

    /// The blocks of a blade along its length, root to tip: (start and end radius, rise over
    /// the block, cells along). Flat, one block; with a rise, a flat block over the screws to the
    /// bend and an inclined one from it to the wall, sharing the vertical face at the bend.
    fn blade_segments(&self, d: &Dimensions) -> Vec<(f64, f64, f64, usize)> {
        let (radius, rise) = (d.envelope_inner_radius, self.variant.blade_rise);
        let root = radius - self.blade_length;
        if rise == 0.0 {
            return vec![(root, radius, 0.0, self.blade_cells(d)[0])];
        }
        let cells = |l: f64| ((l / (0.5 * self.element_size)).ceil() as usize).max(4);
        let bend = self.blade_bend();
        vec![(root, bend, 0.0, cells(bend - root)), (bend, radius, rise, cells((radius - bend).hypot(rise)))]
    }

    /// A blade of [`TipContact::Patch`] along the unit vector `[c, s]`: the placed boxes of the
    /// connector model, but cut across at equal angles seen from the axis and ending on the
    /// wall's circle, so that each tip node lies on the wall at one of the angles that
    /// [`Design::quarter_angles`] gives the wall. The tip's edges stay at ±width/2; its corners
    /// move in by at most width²/(8 R), 0.12 mm for the default design, about 0.07 % of the
    /// blade's volume. With a rise, a flat block to the bend and an inclined one from it.
    fn blade_on_wall(&self, d: &Dimensions, [c, s]: [f64; 2], disk_top: f64) -> Vec<Block> {
        let (radius, half, vertical) = (d.envelope_inner_radius, self.tip_half_angle(d), self.blade_vertical());
        let [_, across, through] = self.blade_cells(d);
        let segments = self.blade_segments(d);
        let last = segments.len() - 1;
        segments
            .into_iter()
            .enumerate()
            .map(|(k, (start, end, up, n))| Block {
                cells: [n, across, through],
                map: Box::new(move |[u, v, w]| {
                    let angle = half * (2.0 * v - 1.0);
                    // The last block ends on the wall's circle.
                    let end = if k == last { radius * angle.cos() } else { end };
                    let along = start + u * (end - start);
                    let across = radius * angle.sin();
                    [along * c - across * s, along * s + across * c, disk_top + u * up + w * vertical]
                }),
                elset: "BLADES".into(),
            })
            .collect()
    }

    /// For each blade of [`TipContact::Patch`], its tip nodes paired with the revolved part's
    /// wall nodes at the same positions, and the pair at the centre of the tip face (height
    /// `z_centre`). An error names the blade and the position of a tip node the wall lacks.
    fn tip_faces(
        &self,
        blades: &[Part],
        revolved: &Part,
        d: &Dimensions,
        z_centre: f64,
        tol: f64,
    ) -> Result<Vec<TipFace>, GenerateError> {
        let radius = d.envelope_inner_radius;
        let mut faces = Vec::with_capacity(blades.len());
        for (i, part) in blades.iter().enumerate() {
            let mut pairs = Vec::new();
            for n in part.nodes_where(|x| (x[0].hypot(x[1]) - radius).abs() < tol) {
                let x = part.nodes[n];
                let w = revolved.nearest(x);
                if dist2(revolved.nodes[w], x).sqrt() > tol {
                    return Err(self.fail(format!(
                        "the tip of blade {} does not conform to the envelope wall: no wall node at {x:?} m",
                        i + 1
                    )));
                }
                pairs.push((n, w));
            }
            let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][i];
            let middle = [radius * c, radius * s, z_centre];
            let centre = *pairs
                .iter()
                .min_by(|a, b| dist2(part.nodes[a.0], middle).total_cmp(&dist2(part.nodes[b.0], middle)))
                .ok_or_else(|| self.fail(format!("blade {} has no node on the envelope wall", i + 1)))?;
            faces.push(TipFace { pairs, centre });
        }
        Ok(faces)
    }

    /// The mesh of a configuration, with its sets, couplings, connectors, shaker and sensors.
    pub fn build(&self, configuration: Configuration) -> Result<Mesh, GenerateError> {
        let d = self.dimensions()?;
        let [base_top, ring_top, diaphragm_bottom, disk_bottom, disk_top, blade_top, envelope_top] = self.heights(&d);
        let tol = 1e-7 * self.envelope_radius;
        let size = self.element_size;
        let angles = self.quarter_angles(&d);
        let patch = self.tip_contact == TipContact::Patch;
        let rect = |r: [f64; 2], z: [f64; 2], set: &str| ProfileRect { r, z, elset: set.into() };
        let with_body = configuration != Configuration::Envelope;
        let with_envelope = configuration != Configuration::BodyWithBlades;

        // Revolved part: base plate, envelope, body, bonded where they touch (one mesh).
        let mut profile = Vec::new();
        if with_envelope {
            profile.push(rect([0.0, self.base_radius], [0.0, base_top], "BASE_PLATE"));
            profile.push(rect(
                [self.envelope_ring_inner_radius, self.envelope_radius],
                [base_top, diaphragm_bottom],
                "ENVELOPE",
            ));
            profile.push(rect(
                [self.envelope_ring_inner_radius, self.envelope_radius],
                [diaphragm_bottom, ring_top],
                "ENVELOPE",
            ));
            // The wall, cut at the blades' heights so that the contact zones have nodes there.
            let tip_bottom = blade_top - self.blade_vertical();
            let zc = 0.5 * (tip_bottom + blade_top);
            let mut cuts = vec![
                ring_top,
                zc - self.contact_zone_half_height,
                disk_top,
                tip_bottom,
                blade_top,
                zc + self.contact_zone_half_height,
                envelope_top,
            ];
            if patch {
                // The tip's vertical subdivisions, so that the wall's nodes meet the tip's.
                let cells = self.blade_cells(&d)[2];
                cuts.extend((1..cells).map(|k| tip_bottom + k as f64 / cells as f64 * self.blade_vertical()));
            }
            cuts.sort_by(f64::total_cmp);
            for w in cuts.windows(2) {
                if w[1] > w[0] + tol {
                    profile.push(rect([d.envelope_inner_radius, self.envelope_radius], [w[0], w[1]], "ENVELOPE"));
                }
            }
        }
        let flange_radius = self.flange_radius();
        let has_web = flange_radius < self.envelope_ring_inner_radius - tol;
        if has_web && with_envelope {
            let r = [flange_radius, self.envelope_ring_inner_radius];
            profile.push(rect(r, [diaphragm_bottom, ring_top], "ENVELOPE"));
        }
        if with_body {
            let (ri, ro) = (d.hub_inner_radius, self.hub_outer_radius);
            if flange_radius > ro + tol {
                profile.push(rect([ro, flange_radius], [diaphragm_bottom, ring_top], "BODY"));
            }
            profile.push(rect([ri, ro], [diaphragm_bottom, ring_top], "BODY"));
            profile.push(rect([ri, ro], [ring_top, disk_bottom], "BODY"));
            let rim_inner = self.body_top_radius - self.variant.rim_width;
            if d.rim_height > 0.0 {
                profile.push(rect(
                    [rim_inner, self.body_top_radius],
                    [disk_bottom - d.rim_height, disk_bottom],
                    "BODY",
                ));
            }
            // Top disk, cut at the screw zones so that each zone has a ring of nodes.
            let mut radii = vec![0.0, ri, ro];
            if d.rim_height > 0.0 {
                radii.push(rim_inner);
            }
            radii.push(d.top_disk_step_radius);
            for r in self.screw_radii {
                radii.extend([r - self.screw_zone_radius, r, r + self.screw_zone_radius]);
            }
            radii.push(self.body_top_radius);
            radii.sort_by(f64::total_cmp);
            radii.dedup_by(|a, b| (*a - *b).abs() <= tol);
            for w in radii.windows(2) {
                profile.push(rect([w[0], w[1]], [disk_bottom, disk_top], "BODY"));
                let outer_bottom = disk_top - d.top_disk_thickness;
                if w[0] >= d.top_disk_step_radius - tol && outer_bottom < disk_bottom - tol {
                    profile.push(rect([w[0], w[1]], [outer_bottom, disk_bottom], "BODY"));
                }
            }
        }
        let mut revolved = Part::new("STRUCTURE", self.kind, tol)?;
        revolve_at(&mut revolved, &profile, &angles, size)?;

        // Blades along x, y, -x, -y: lying on the top disk, tip against the envelope wall.
        let mut blades = Vec::new();
        if with_body {
            let [_, across, through] = self.blade_cells(&d);
            for i in 0..4 {
                let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][i];
                let w = d.blade_width;
                let mut part = Part::new(&format!("BLADE_{}", i + 1), self.kind, tol)?;
                if patch {
                    for block in self.blade_on_wall(&d, [c, s], disk_top) {
                        part.add_block(&block)?;
                    }
                } else {
                    let mut z = disk_top;
                    for (start, end, up, n) in self.blade_segments(&d) {
                        let origin = [start * c + 0.5 * w * s, start * s - 0.5 * w * c, z];
                        let edges = [
                            [(end - start) * c, (end - start) * s, up],
                            [-w * s, w * c, 0.0],
                            [0.0, 0.0, self.blade_vertical()],
                        ];
                        part.add_block(&placed_box(origin, edges, [n, across, through], "BLADES"))?;
                        z += up;
                    }
                }
                blades.push(part);
            }
        }

        // Sensors on the revolved part: nearest nodes to the accelerometer positions.
        let mut sensor_nodes = Vec::new();
        for (k, (name, part, r_frac, angle, height)) in ACCELEROMETERS.into_iter().enumerate() {
            let present = match part {
                Part3::Body => with_body,
                _ => with_envelope,
            };
            if !present {
                continue;
            }
            let radius = match part {
                Part3::Base => self.base_radius,
                Part3::Envelope => self.envelope_radius,
                Part3::Body => self.body_top_radius,
            } * r_frac;
            let z = match height {
                Height::BaseTop if r_frac == 0.0 => base_top,
                Height::BaseTop => 0.0,
                Height::EnvelopeTop => envelope_top,
                Height::EnvelopeMid => 0.5 * (ring_top + envelope_top),
                Height::BodyTop => disk_top,
            };
            let a = angle.to_radians();
            let n = revolved.nearest([radius * a.cos(), radius * a.sin(), z]);
            sensor_nodes.push((k, name, n));
        }

        // Mesh: reference nodes first, then the parts; sensors renumbered 101..
        let mut mesh = Mesh::default();
        let materials = [
            ("BASE_PLATE", "ALUMINIUM_2017A", self.aluminium_2017a.clone()),
            ("ENVELOPE", "STEEL_304L", self.steel_304l.clone()),
            ("BODY", "STEEL_304L", self.steel_304l.clone()),
            ("BLADES", "Z8CND17-04", self.blade_steel.clone()),
        ];
        // Conforming tips: each tip node's partner on the wall (part node indices), and the
        // nodes named Top_Blade and Contact_Zone, at the centre of the tip face.
        let faces = if patch && with_envelope {
            self.tip_faces(&blades, &revolved, &d, blade_top - 0.5 * self.blade_vertical(), tol)?
        } else {
            Vec::new()
        };
        let mut next_id = 1001u64;
        let structure_ids: Vec<u64> = (0..revolved.nodes.len())
            .map(|n| match sensor_nodes.iter().find(|&&(_, _, s)| s == n) {
                Some(&(k, _, _)) => accelerometer(k),
                None => match faces.iter().position(|f| f.centre.1 == n) {
                    Some(i) => contact_zone(i + 1),
                    None => {
                        next_id += 1;
                        next_id - 1
                    }
                },
            })
            .collect();
        let structure = revolved.add_to(&mut mesh, &structure_ids, 1, &materials)?;
        let mut blade_index = Vec::new();
        let mut next_element = revolved.elements.len() as u64 + 1;
        for (i, part) in blades.iter().enumerate() {
            let mut ids: Vec<u64> = (0..part.nodes.len()).map(|n| next_id + n as u64).collect();
            if let Some(face) = faces.get(i) {
                ids[face.centre.0] = top_blade(i + 1);
            }
            next_id += part.nodes.len() as u64;
            blade_index.push(part.add_to(&mut mesh, &ids, next_element, &materials)?);
            next_element += part.elements.len() as u64;
        }
        for (_, name, n) in &sensor_nodes {
            mesh.add_node_set(&format!("ACC_{}", name.to_uppercase()), [structure[*n]]);
            mesh.add_node_set("ACCELEROMETERS", [structure[*n]]);
        }

        let mut point_id = next_element + 1000;
        let add_ref = |mesh: &mut Mesh, id: u64, x: [f64; 3], name: &str| -> Result<usize, GenerateError> {
            let n = mesh.add_node(id, x).map_err(|id| self.fail(format!("node id {id} used twice")))?;
            mesh.add_node_set(name, [n]);
            Ok(n)
        };
        let k = self.connector_stiffness;
        let mut connector = |mesh: &mut Mesh, a: usize, b: usize, stiffness: [f64; 6]| {
            mesh.points.push(PointElement::Connector { id: point_id, a, b: Some(b), stiffness });
            point_id += 1;
        };

        // Zones: face nodes of a part within `radius` of a point, and if these are collinear
        // (a coarse mesh may have only a line of nodes within the paper's 10 mm), the nearest
        // node off their line: growing by the nearest nodes overall would reach along the
        // line into a neighbouring screw's zone.
        let zone = |nodes: &[usize], mesh: &Mesh, centre: [f64; 3], radius: f64| -> Vec<usize> {
            let dist = |n: usize| (0..3).map(|i| (mesh.nodes[n].xyz[i] - centre[i]).powi(2)).sum::<f64>().sqrt();
            let mut sorted: Vec<usize> = nodes.to_vec();
            sorted.sort_by(|&a, &b| dist(a).total_cmp(&dist(b)));
            let take =
                sorted.iter().take_while(|&&n| dist(n) <= radius).count().clamp(2.min(sorted.len()), sorted.len());
            let mut zone = sorted[..take].to_vec();
            if collinear(mesh, &zone) {
                if let Some(&off) = sorted[take..].iter().find(|&&n| {
                    zone.push(n);
                    let off = !collinear(mesh, &zone);
                    zone.pop();
                    off
                }) {
                    zone.push(off);
                }
            }
            zone
        };

        if with_body {
            let top_face: Vec<usize> =
                structure.iter().copied().filter(|&n| (mesh.nodes[n].xyz[2] - disk_top).abs() < tol).collect();
            for (i, part) in blades.iter().enumerate() {
                let (c, s) = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)][i];
                let idx = &blade_index[i];
                let bottom: Vec<usize> =
                    part.nodes_where(|x| (x[2] - disk_top).abs() < tol).iter().map(|&n| idx[n]).collect();
                for (j, &r) in self.screw_radii.iter().enumerate() {
                    let centre = [r * c, r * s, disk_top];
                    let b = add_ref(
                        &mut mesh,
                        blade_screws(i + 1)[j],
                        centre,
                        &format!("SCREW_{}_BLADE_{}", j + 1, i + 1),
                    )?;
                    let a =
                        add_ref(&mut mesh, body_screws(i + 1)[j], centre, &format!("SCREW_{}_BODY_{}", j + 1, i + 1))?;
                    let on_blade = zone(&bottom, &mesh, centre, self.screw_zone_radius);
                    let on_body = zone(&top_face, &mesh, centre, self.screw_zone_radius);
                    mesh.couplings.push(RigidCoupling {
                        reference: b,
                        nodes: on_blade,
                        dofs: (1..=6).collect(),
                        at: Default::default(),
                    });
                    mesh.couplings.push(RigidCoupling {
                        reference: a,
                        nodes: on_body,
                        dofs: (1..=6).collect(),
                        at: Default::default(),
                    });
                    connector(&mut mesh, a, b, [k; 6]);
                }
                for j in 0..2 {
                    let b = mesh.node(blade_screws(i + 1)[j]).expect("added above");
                    mesh.add_node_set("BLADE_SCREWS", [b]);
                }
                if patch {
                    let tip = part.nodes_where(|x| (x[0].hypot(x[1]) - d.envelope_inner_radius).abs() < tol);
                    mesh.add_node_set(&format!("TIP_FACE_{}", i + 1), tip.iter().map(|&n| idx[n]));
                    if let Some(face) = faces.get(i) {
                        let wall = face.pairs.iter().map(|&(_, w)| structure[w]);
                        mesh.add_node_set(&format!("WALL_FACE_{}", i + 1), wall);
                    }
                    continue;
                }
                let tip: Vec<usize> = part
                    .nodes_where(|x| (x[0] * c + x[1] * s - d.envelope_inner_radius).abs() < tol)
                    .iter()
                    .map(|&n| idx[n])
                    .collect();
                let zc = blade_top - 0.5 * self.blade_vertical();
                let tip_point = [d.envelope_inner_radius * c, d.envelope_inner_radius * s, zc];
                let t = add_ref(&mut mesh, top_blade(i + 1), tip_point, &format!("TOP_BLADE_{}", i + 1))?;
                mesh.couplings.push(RigidCoupling {
                    reference: t,
                    nodes: tip,
                    dofs: (1..=6).collect(),
                    at: Default::default(),
                });
                mesh.add_node_set("TOP_BLADES", [t]);
                if with_envelope {
                    let wall: Vec<usize> = structure
                        .iter()
                        .copied()
                        .filter(|&n| {
                            let x = mesh.nodes[n].xyz;
                            (x[0].hypot(x[1]) - d.envelope_inner_radius).abs() < 1e-6
                                && (x[2] - zc).abs() <= self.contact_zone_half_height + tol
                                && x[0] * c + x[1] * s > 0.0
                        })
                        .collect();
                    let cz = add_ref(&mut mesh, contact_zone(i + 1), tip_point, &format!("CONTACT_ZONE_{}", i + 1))?;
                    let nodes = zone(&wall, &mesh, tip_point, (0.5 * d.blade_width).max(self.contact_zone_half_height));
                    mesh.couplings.push(RigidCoupling {
                        reference: cz,
                        nodes,
                        dofs: (1..=6).collect(),
                        at: Default::default(),
                    });
                    // Contact: translations only (the tip may rotate on the wall); the vertical
                    // component is the one friction acts on (Section 3.1).
                    connector(&mut mesh, t, cz, [k, k, self.contact_vertical_stiffness, 0.0, 0.0, 0.0]);
                    mesh.add_node_set("CONTACT_ZONES", [cz]);
                }
            }
        }
        if with_envelope {
            // Shaker: a mass moving vertically only, coupled to the base plate's bottom, on K_soft.
            let shaker = add_ref(&mut mesh, SHAKER, [0.0, 0.0, 0.0], "SHAKER")?;
            let bottom: Vec<usize> = structure
                .iter()
                .copied()
                .filter(|&n| {
                    let x = mesh.nodes[n].xyz;
                    x[2].abs() < tol && x[0].hypot(x[1]) <= self.shaker_zone_radius + tol
                })
                .collect();
            mesh.couplings.push(RigidCoupling {
                reference: shaker,
                nodes: bottom,
                dofs: (1..=6).collect(),
                at: Default::default(),
            });
            mesh.points.push(PointElement::Mass { id: point_id, node: shaker, mass: self.shaker_mass });
            point_id += 1;
            mesh.points.push(PointElement::Spring {
                id: point_id,
                a: shaker,
                dir_a: 3,
                b: None,
                stiffness: self.shaker_spring,
            });
            for dir in [1, 2, 4, 5, 6] {
                mesh.fixed.push((shaker, dir));
            }
        } else {
            // Body alone: the body's flange clamped on its outer circle (its seat in the envelope).
            for &n in &structure {
                let x = mesh.nodes[n].xyz;
                let clamped = (x[0].hypot(x[1]) - flange_radius).abs() < 1e-6 && x[2] <= ring_top + tol;
                if clamped {
                    mesh.fixed.extend((1..=3).map(|dir| (n, dir)));
                }
            }
        }
        Ok(mesh)
    }
}

/// A blade tip of [`TipContact::Patch`] on the wall: (blade part node, revolved part node)
/// pairs at the same positions, and the pair at the centre of the face.
struct TipFace {
    pairs: Vec<(usize, usize)>,
    centre: (usize, usize),
}

/// Whether the nodes lie on one line (a coupling on them would leave a rotation free).
fn collinear(mesh: &Mesh, nodes: &[usize]) -> bool {
    if nodes.len() < 3 {
        return true;
    }
    let p0 = mesh.nodes[nodes[0]].xyz;
    let far = nodes.iter().map(|&n| mesh.nodes[n].xyz).max_by(|a, b| dist2(*a, p0).total_cmp(&dist2(*b, p0))).unwrap();
    let e = [0, 1, 2].map(|i| far[i] - p0[i]);
    let le = dist2(far, p0).sqrt();
    if le == 0.0 {
        return true;
    }
    nodes.iter().all(|&n| {
        let x = mesh.nodes[n].xyz;
        let v = [0, 1, 2].map(|i| x[i] - p0[i]);
        let c = [v[1] * e[2] - v[2] * e[1], v[2] * e[0] - v[0] * e[2], v[0] * e[1] - v[1] * e[0]];
        (c[0].powi(2) + c[1].powi(2) + c[2].powi(2)).sqrt() <= 1e-6 * le * le
    })
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum()
}
