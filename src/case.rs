//! Case files: one typed TOML format for everything a run needs (SPEC units:
//! SI throughout). Unknown keys, missing keys and non-physical values are
//! rejected before the run, each problem naming its key and the file.
//!
//! The same structs build cases in tests; [`Case::resolved_toml`] writes the
//! case with every default expanded, which each run stores beside its output.

use crate::contact::projectile::{cone_length, nose_segment_length};
use crate::contact::{
    mass_axisymmetric, mass_plane_strain, rectangle_outline, ContactError, NoseShape, Projectile, RigidBody,
};
use crate::discretize::RectangleGrid;
use crate::fracture::{Criterion, FractureParameters};
use crate::geometry::GeometryMode;
use crate::material::{Constitutive, Elastic, JohnsonCook, Material, ThermalProperties};
use crate::math::{Real, Vec2};
use crate::model::{BodySetup, Region, Support};
use crate::step::TimeStepRule;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// A whole case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Free-text title shown in the summary.
    #[serde(default)]
    pub title: String,
    /// Geometry mode.
    pub geometry: GeometrySection,
    /// Named materials defined in this file (bodies may also name built-ins).
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Deformable bodies.
    pub bodies: Vec<BodySpec>,
    /// Rigid bodies (projectiles, anvils).
    #[serde(default)]
    pub rigid_bodies: Vec<RigidBodySpec>,
    /// Contact with the rigid bodies (SPEC §8), between deformable bodies
    /// and of a cracked body with itself (`crate::contact::deformable`).
    #[serde(default)]
    pub contact: crate::contact::ContactParameters,
    /// Heat conduction (SPEC §7).
    #[serde(default)]
    pub heat: HeatSpec,
    /// Crack growth (SPEC §9). Default: the default model
    /// ([`FractureParameters::default`]); a material without a damage locus
    /// never cracks.
    #[serde(default)]
    pub fracture: FractureParameters,
    /// Time integration.
    pub time: TimeSpec,
    /// Output.
    #[serde(default)]
    pub output: OutputSpec,
    /// Checkpoints (see `checkpoint`).
    #[serde(default)]
    pub checkpoint: CheckpointSpec,
}

/// `[geometry]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometrySection {
    /// `"plane_strain"` or `"axisymmetric"` (x is then the radius).
    pub mode: GeometryMode,
}

/// `[materials.NAME]`: a material model and its constants.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// Hypoelastic (Jaumann).
    Elastic {
        /// Mass density ρ₀, kg/m³.
        density: Real,
        /// Young's modulus E, Pa.
        youngs_modulus: Real,
        /// Poisson's ratio ν, dimensionless, in (−1, 0.5).
        poisson_ratio: Real,
        /// Initial temperature, K. Default 293 K.
        #[serde(default = "room_temperature")]
        room_temperature: Real,
        /// Specific heat C_p, J/(kg K); optional (only for heat conduction).
        #[serde(default)]
        specific_heat: Option<Real>,
        /// Thermal conductivity κ, W/(m K); optional.
        #[serde(default)]
        thermal_conductivity: Option<Real>,
    },
    /// Johnson–Cook thermo-viscoplasticity with damage (SPEC §6). Keys are
    /// the fields of [`JohnsonCook`], units in its documentation: `density`,
    /// `youngs_modulus`, `poisson_ratio`, `yield_stress` (A), `hardening_modulus`
    /// (B), `hardening_exponent` (n), `rate_sensitivity` (C),
    /// `softening_exponent` (m), `melting_temperature`, `room_temperature`,
    /// `reference_strain_rate`, `rate_form` ("log" | "power"), `specific_heat`,
    /// `taylor_quinney`, `thermal_expansion`, `conductivity`,
    /// `damage = { d1, d2, d3, d4, d5 }`, `damage_coupling`, `theta`.
    JohnsonCook(JohnsonCook),
}

fn room_temperature() -> Real {
    293.0
}

/// `[[bodies]]`: a deformable body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name.
    pub name: String,
    /// Name of a material in `[materials]` or a built-in one.
    pub material: String,
    /// The body's shape and particle grid.
    pub rectangle: RectangleGrid,
    /// Initial velocities, m/s, applied in order (a later region overrides).
    #[serde(default)]
    pub initial_velocity: Vec<InitialVelocity>,
    /// Supports: `{ region = {...}, fix = "all" | "x" | "y" }`. A clamp
    /// (`fix = "all"`) should be at least one support width deep (SPEC §4).
    #[serde(default)]
    pub supports: Vec<Support>,
}

impl BodySpec {
    /// The velocity given over the whole body (the last `initial_velocity`
    /// entry without a region), m/s: a deformable projectile's flight.
    pub fn whole_body_velocity(&self) -> Option<[Real; 2]> {
        self.whole_body_entry().map(|j| self.initial_velocity[j].velocity)
    }

    /// [`Self::whole_body_velocity`], to change it.
    pub fn whole_body_velocity_mut(&mut self) -> Option<&mut [Real; 2]> {
        self.whole_body_entry().map(|j| &mut self.initial_velocity[j].velocity)
    }

    /// The index in `initial_velocity` of the entry that gives the whole
    /// body's velocity ([`Self::whole_body_velocity`]): what a `--set`
    /// override names to change it (`bodies.NAME.initial_velocity.J.velocity`).
    pub fn whole_body_entry(&self) -> Option<usize> {
        self.initial_velocity.iter().rposition(|iv| iv.region.is_none())
    }
}

/// `[[bodies.initial_velocity]]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocity {
    /// Velocity (vx, vy), m/s.
    pub velocity: [Real; 2],
    /// Region it applies to; the whole body if absent.
    #[serde(default)]
    pub region: Option<Region>,
}

/// `[[rigid_bodies]]`: a rigid body (the projectile).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBodySpec {
    /// Unique name.
    pub name: String,
    /// Closed outline, counter-clockwise, vertices (x, y) in m. Give this or
    /// `rectangle`.
    #[serde(default)]
    pub outline: Option<Vec<[Real; 2]>>,
    /// A rectangle: `{ center = [x, y], width, height }`, m.
    #[serde(default)]
    pub rectangle: Option<RigidRectangle>,
    /// A projectile by nose shape: `{ nose = "blunt" | "hemispherical" |
    /// "conical" | "ogival", tip = [x, y], diameter, length, ... }`, m (see
    /// [`ProjectileSpec`]). Give exactly one of `outline`, `rectangle` and
    /// `projectile`.
    #[serde(default)]
    pub projectile: Option<ProjectileSpec>,
    /// Mass, kg (per unit depth in plane strain: the section's `ρ A`; the
    /// whole body in axisymmetry). Give this or `density`.
    #[serde(default)]
    pub mass: Option<Real>,
    /// Density, kg/m³: mass from the area (plane strain) or the volume of
    /// revolution (axisymmetry) of the outline.
    #[serde(default)]
    pub density: Option<Real>,
    /// Initial velocity (vx, vy), m/s.
    pub velocity: [Real; 2],
    /// Move at `velocity` whatever the forces (a rigid punch or anvil).
    #[serde(default)]
    pub prescribed: bool,
}

/// A rectangular rigid outline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidRectangle {
    /// Centre (x, y), m.
    pub center: [Real; 2],
    /// Extent along x, m.
    pub width: Real,
    /// Extent along y, m.
    pub height: Real,
}

/// `projectile = { ... }` of a `[[rigid_bodies]]` entry: a projectile by
/// nose shape ([`crate::contact::projectile`]), SI units. The nose points
/// along −y, onto a plate below it (the bodies translate only, so the
/// direction is that of the outline, not of the velocity). Its outline is
/// the full section through the axis in both geometry modes; curved noses
/// are faceted at a quarter of the smallest particle spacing of the
/// deformable bodies ([`crate::contact::projectile`] gives the rule). No
/// field has a default: a projectile has no typical size, and each
/// parameter applies to one nose only (given for another it is an error,
/// not ignored).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectileSpec {
    /// `"blunt"` (flat face), `"hemispherical"` (a half sphere of the
    /// shank's radius), `"conical"` (give `nose_length` or
    /// `nose_angle_deg`), `"ogival"` (tangent ogive; give
    /// `caliber_radius_head`).
    pub nose: NoseKind,
    /// Position (x, y) of the tip, m: the nose's foremost point on the axis
    /// (the centre of a blunt face). In axisymmetry x must be 0.
    pub tip: [Real; 2],
    /// Shank diameter, m.
    pub diameter: Real,
    /// Overall length from the tip to the back face, m; longer than the nose.
    pub length: Real,
    /// Conical only: length of the cone from the tip to the shank, m.
    #[serde(default)]
    pub nose_length: Option<Real>,
    /// Conical only: included apex angle of the cone, degrees, in (0, 180)
    /// (`nose_length = D / (2 tan(α/2))`). Give this or `nose_length`.
    #[serde(default)]
    pub nose_angle_deg: Option<Real>,
    /// Ogival only: calibre-radius-head ψ, the ogive's arc radius over the
    /// diameter, ≥ 0.5 (0.5 is the hemisphere); nose length `R √(4ψ − 1)`.
    #[serde(default)]
    pub caliber_radius_head: Option<Real>,
    /// Blunt only: radius of the quarter circle that rounds the flat face's
    /// edge onto the shank, m, in [0, D/2) (default 0: a sharp edge).
    #[serde(default)]
    pub edge_radius: Option<Real>,
}

/// The nose shapes of [`ProjectileSpec`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoseKind {
    Blunt,
    Hemispherical,
    Conical,
    Ogival,
}

impl ProjectileSpec {
    /// The geometry; `None` when a parameter the nose needs is missing or
    /// out of range (see [`ProjectileSpec::problems`]).
    pub fn projectile(&self) -> Option<Projectile> {
        let nose = match self.nose {
            NoseKind::Blunt => NoseShape::Blunt { edge_radius: self.edge_radius.unwrap_or(0.0) },
            NoseKind::Hemispherical => NoseShape::Hemispherical,
            NoseKind::Conical => NoseShape::Conical {
                nose_length: match (self.nose_length, self.nose_angle_deg) {
                    (Some(l), None) => l,
                    (None, Some(a)) => cone_length(0.5 * self.diameter, a),
                    _ => return None,
                },
            },
            NoseKind::Ogival => NoseShape::Ogival { caliber_radius_head: self.caliber_radius_head? },
        };
        Some(Projectile { diameter: self.diameter, length: self.length, nose })
    }

    /// Problems, each as (field, message), the field relative to the
    /// `projectile` table.
    pub fn problems(&self, mode: GeometryMode) -> Vec<(&'static str, String)> {
        let mut p = Vec::new();
        let name = match self.nose {
            NoseKind::Blunt => "blunt",
            NoseKind::Hemispherical => "hemispherical",
            NoseKind::Conical => "conical",
            NoseKind::Ogival => "ogival",
        };
        if !self.tip.iter().all(|c| c.is_finite()) {
            p.push(("tip", format!("must be finite (in m), got {:?}", self.tip)));
        } else if mode == GeometryMode::Axisymmetric && self.tip[0] != 0.0 {
            p.push(("tip", format!("must lie on the axis (x = 0) in axisymmetry, got x = {}", self.tip[0])));
        }
        for (field, v) in [("diameter", self.diameter), ("length", self.length)] {
            if !(v.is_finite() && v > 0.0) {
                p.push((field, format!("must be a positive number (in m), got {v}")));
            }
        }
        let conical = self.nose == NoseKind::Conical;
        let ogival = self.nose == NoseKind::Ogival;
        let blunt = self.nose == NoseKind::Blunt;
        for (field, given, applies, owner) in [
            ("edge_radius", self.edge_radius.is_some(), blunt, "blunt"),
            ("nose_length", self.nose_length.is_some(), conical, "conical"),
            ("nose_angle_deg", self.nose_angle_deg.is_some(), conical, "conical"),
            ("caliber_radius_head", self.caliber_radius_head.is_some(), ogival, "ogival"),
        ] {
            if given && !applies {
                p.push((field, format!("applies to {owner} noses only, not to a {name} one")));
            }
        }
        if conical {
            match (self.nose_length, self.nose_angle_deg) {
                (Some(_), Some(_)) => {
                    p.push(("nose_length", "give either `nose_length` or `nose_angle_deg`, not both".into()))
                }
                (None, None) => {
                    p.push(("nose_length", "a conical nose needs `nose_length` or `nose_angle_deg`".into()))
                }
                (Some(l), None) if !(l.is_finite() && l > 0.0) => {
                    p.push(("nose_length", format!("must be a positive number (in m), got {l}")))
                }
                (None, Some(a)) if !(a.is_finite() && a > 0.0 && a < 180.0) => {
                    p.push(("nose_angle_deg", format!("must lie in (0, 180) degrees, got {a}")))
                }
                _ => {}
            }
        }
        if let (true, Some(e)) = (blunt, self.edge_radius) {
            if !(e.is_finite() && e >= 0.0 && e < 0.5 * self.diameter) {
                p.push((
                    "edge_radius",
                    format!(
                        "must lie in [0, diameter/2) m (diameter/2 is the hemispherical nose), got {e} with diameter {}",
                        self.diameter
                    ),
                ));
            }
        }
        if ogival {
            match self.caliber_radius_head {
                None => p.push(("caliber_radius_head", "an ogival nose needs `caliber_radius_head`".into())),
                Some(c) if !(c.is_finite() && c >= 0.5) => p.push((
                    "caliber_radius_head",
                    format!("must be at least 0.5 (a hemisphere; smaller arcs cannot meet the axis), got {c}"),
                )),
                _ => {}
            }
        }
        if p.is_empty() {
            if let Some(g) = self.projectile() {
                let ln = g.nose_length();
                if ln.partial_cmp(&self.length) != Some(std::cmp::Ordering::Less) {
                    p.push((
                        "length",
                        format!("{} m must exceed the nose length {ln:.6} m (the shank would be empty)", self.length),
                    ));
                }
            }
        }
        p
    }
}

/// `[heat]`: heat conduction between particles after the adiabatic material
/// update (SPEC §7, [`crate::thermal`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeatSpec {
    /// Conduct heat (`true`) or keep every step adiabatic (`false`).
    /// Default: on when every deformable body's material has thermal
    /// properties (Johnson–Cook always has; an elastic material needs both
    /// `specific_heat` and `thermal_conductivity`), off otherwise. SPEC §7
    /// makes conduction part of every step, so a material that can conduct
    /// does; a case with a body that cannot is adiabatic unless it asks for
    /// conduction, and then it is an error rather than a silent partial
    /// switch. The resolved case records the value used.
    #[serde(default)]
    pub conduction: Option<bool>,
    /// Safety factor `s` of the conduction sub-step `Δt_th = s · 2/λ̂`, where
    /// `λ̂` is a guaranteed bound on the conduction operator's largest
    /// eigenvalue; in (0, 1]. Default 0.5
    /// ([`crate::thermal::DEFAULT_SAFETY_FACTOR`]: every mode decays without
    /// oscillating). The mechanical step is sub-cycled when it is longer.
    #[serde(default = "heat_safety")]
    pub safety_factor: Real,
    /// Conduct once every this many mechanical steps, over their summed
    /// time (SPEC §7 allows a larger conduction step when stable; the
    /// conduction itself still sub-cycles below its stable step). Default
    /// 10: in steel the diffusion length over 10 steps of ~40 ns is a few
    /// micrometres, far below the particle spacing, while the stage's cost
    /// drops tenfold. 1 conducts every step.
    #[serde(default = "heat_every")]
    pub every: u64,
}

fn heat_safety() -> Real {
    crate::thermal::DEFAULT_SAFETY_FACTOR
}

fn heat_every() -> u64 {
    10
}

impl Default for HeatSpec {
    fn default() -> Self {
        HeatSpec { conduction: None, safety_factor: heat_safety(), every: heat_every() }
    }
}

/// `[time]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// End time, s (> 0).
    pub end: Real,
    /// CFL safety factor s in `Δt₀ = s · min h / c_L`, in (0, 1]. Default 0.5
    /// (SPEC §5): half the 1D stability limit leaves room for the 2D
    /// stencil. The step then follows the model's stiffness from `Δt₀`
    /// down ([`crate::stability`]: split crack particles, compressed
    /// material).
    #[serde(default = "half")]
    pub safety_factor: Real,
    /// A fixed step, s, overriding the CFL rule (\[RL10\] used 4e-9 s).
    #[serde(default)]
    pub fixed_dt: Option<Real>,
    /// Stop early, s: the run ends once every moving rigid body's flight is
    /// over for this long ([`crate::residual`]): a plug has been cut out and
    /// the contact force along the body's flight direction has vanished
    /// (its speed no longer changes; a touch on the side wall of the hole
    /// does not count), or the body has stopped or bounced back (the plate
    /// held). Default: run to `end`.
    #[serde(default)]
    pub stop_after_release: Option<Real>,
    /// Artificial bulk viscosity, `{ linear = b₁, quadratic = b₂ }` (either
    /// may be left out for the common codes' 0.06 and 1.2): a deviation
    /// from SPEC §5, off when absent ([`crate::bulk_viscosity`]).
    #[serde(default)]
    pub bulk_viscosity: Option<crate::bulk_viscosity::BulkViscosity>,
    /// Mass scaling, a fraction of the spacing step `Δt₀` in (0, 1]: the
    /// step is kept at or above this fraction of `Δt₀` by adding mass, at
    /// rest, to the particles that would take it lower (light crack-face
    /// children, steep rows at a crack; [`crate::stability`]). A
    /// deviation from SPEC §5, off when absent; the run reports the mass
    /// added and the kinetic energy it took out. Needs the adaptive step
    /// (no `fixed_dt`).
    #[serde(default)]
    pub mass_scaling: Option<Real>,
    /// Erosion at the step's floor, a fraction of the spacing step `Δt₀`
    /// in (0, 1]: a fractured point (`D ≥ 1`, carrying pressure only)
    /// whose distortion would take the step below this fraction of `Δt₀`
    /// is eroded, as the explicit codes erode a failed element at a
    /// minimum step ([`crate::stability`]). A deviation from SPEC §5, off
    /// when absent; the run reports the points eroded. Needs the adaptive
    /// step (no `fixed_dt`) and a fracture criterion whose points fail.
    #[serde(default)]
    pub erode_failed_below: Option<Real>,
}

fn half() -> Real {
    0.5
}

/// `[output]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Simulated time between VTU snapshots, s. Default: end/50.
    #[serde(default)]
    pub interval: Option<Real>,
    /// Output directory. Default: `runs/<case file stem>`.
    #[serde(default)]
    pub directory: Option<String>,
    /// Point fields written to the VTU files. Default: all of
    /// [`OUTPUT_FIELDS`].
    #[serde(default = "all_fields")]
    pub fields: Vec<String>,
    /// Write one history (CSV) row every this many steps. Default 10.
    #[serde(default = "ten")]
    pub history_every: u64,
    /// Simulated times, s, at which to draw field plots of the deformed
    /// bodies (`effective_stress_<t>us.png` around the projectile,
    /// `temperature_<t>us.png` of the shear band at its corner), each from
    /// the first state at or after the time; times after `time.end` are
    /// not drawn (so a shortened run keeps its case's plot times). Default:
    /// none (the end-of-run plots are always drawn). The Borvik cases ask for \[RL10\]'s
    /// perforation times.
    #[serde(default)]
    pub plot_times: Vec<Real>,
    /// Particles whose forces are written at every step to `trace.csv`
    /// ([`crate::output::ParticleTrace`]): to find what accelerates a
    /// particle. Indices as generated (`0..n`), or, with a fracture
    /// criterion, of a crack-face child a split will make (a run summary
    /// names its fastest particle's index; the same case makes the same
    /// children), traced from the first step that integrates it. Default:
    /// none (no file).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trace_particles: Vec<usize>,
}

fn ten() -> u64 {
    10
}

/// `[checkpoint]`: when a run saves its complete state, so that
/// `plugsim resume` can continue it bit for bit (see `checkpoint`). A run
/// also saves one when interrupted (Ctrl-C, SIGTERM).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckpointSpec {
    /// Simulated time between checkpoints, s. Default: none (checkpoints by
    /// wall-clock time only).
    #[serde(default)]
    pub interval: Option<Real>,
    /// Wall-clock time between checkpoints, s; 0 turns them off. Default
    /// 1800 s: a crash costs at most half an hour of computing, and a
    /// checkpoint of even \[RL10\]'s fine model (about 0.25 GB) takes seconds,
    /// a negligible share of the run.
    #[serde(default = "half_hour")]
    pub wall_interval: Real,
    /// Checkpoints kept, newest first; older ones are deleted once a new one
    /// is safely written. Default 2: should the newest be damaged (a full
    /// disk at the wrong moment), the one before it still resumes the run.
    #[serde(default = "two_checkpoints")]
    pub keep: u32,
}

fn half_hour() -> Real {
    1800.0
}

fn two_checkpoints() -> u32 {
    2
}

impl Default for CheckpointSpec {
    fn default() -> Self {
        CheckpointSpec { interval: None, wall_interval: half_hour(), keep: two_checkpoints() }
    }
}

/// Most snapshots a run may ask for (`time.end / output.interval`): beyond
/// this, an interval is a typo (1e-12 for 1e-6) that would fill the disk.
pub const MAX_SNAPSHOTS: Real = 100_000.0;

/// Point fields the VTU writer knows.
pub const OUTPUT_FIELDS: &[&str] = &[
    "displacement",
    "velocity",
    "effective_stress",
    "pressure",
    "stress",
    "plastic_strain",
    "plastic_strain_rate",
    "temperature",
    "damage",
    "adiabatic_hardening",
    "average_triaxiality",
    "mass",
    "body",
    "flags",
];

fn all_fields() -> Vec<String> {
    OUTPUT_FIELDS.iter().map(|s| s.to_string()).collect()
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            interval: None,
            directory: None,
            fields: all_fields(),
            history_every: 10,
            plot_times: Vec::new(),
            trace_particles: Vec::new(),
        }
    }
}

/// One problem found in a case file.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    /// Dotted key, e.g. `bodies[0].rectangle.layers`.
    pub key: String,
    pub message: String,
}

/// Why a case could not be used.
#[derive(Clone, Debug, PartialEq)]
pub enum CaseError {
    /// The file could not be read.
    Read { file: String, message: String },
    /// Not valid TOML, a wrong type, an unknown or a missing key.
    Parse { file: String, message: String },
    /// A `--set key=value` override could not be applied.
    Override { file: String, key: String, message: String },
    /// Values that parse but make no physical sense; all of them at once.
    Invalid { file: String, problems: Vec<Problem> },
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CaseError::Read { file, message } => write!(f, "{file}: cannot read case file: {message}"),
            CaseError::Parse { file, message } => write!(f, "{file}: {}", message.trim_end()),
            CaseError::Override { file, key, message } => write!(f, "{file}: --set {key}: {message}"),
            CaseError::Invalid { file, problems } if problems.len() == 1 => {
                write!(f, "{file}: {}: {}", problems[0].key, problems[0].message)
            }
            CaseError::Invalid { file, problems } => {
                write!(f, "{file}: {} problem(s) in the case:", problems.len())?;
                for p in problems {
                    write!(f, "\n  {}: {}", p.key, p.message)?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for CaseError {}

impl Case {
    /// Read, override, parse and validate a case file.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Case, CaseError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| CaseError::Read { file: file.clone(), message: e.to_string() })?;
        Case::from_str_with(&text, &file, overrides)
    }

    /// Parse and validate case text; `file` names it in messages.
    pub fn from_str_with(text: &str, file: &str, overrides: &[String]) -> Result<Case, CaseError> {
        let mut table: toml::Table = toml::from_str(text)
            .map_err(|e| CaseError::Parse { file: file.to_string(), message: toml_message(&e, Some(text)) })?;
        for o in overrides {
            apply_override(&mut table, o).map_err(|(key, message)| CaseError::Override {
                file: file.to_string(),
                key,
                message,
            })?;
        }
        fill_criterion_defaults(&mut table);
        let case: Case = table.try_into().map_err(|e: toml::de::Error| CaseError::Parse {
            file: file.to_string(),
            message: toml_message(&e, None),
        })?;
        let problems = case.validate();
        if problems.is_empty() {
            Ok(case)
        } else {
            Err(CaseError::Invalid { file: file.to_string(), problems })
        }
    }

    /// All semantic problems, each naming its key.
    pub fn validate(&self) -> Vec<Problem> {
        let mut p = Vec::new();
        let mut add = |key: String, message: String| p.push(Problem { key, message });
        for (name, m) in &self.materials {
            let k = format!("materials.{name}");
            match m {
                MaterialSpec::Elastic {
                    density,
                    youngs_modulus,
                    poisson_ratio,
                    room_temperature,
                    specific_heat,
                    thermal_conductivity,
                } => {
                    positive(&mut add, &format!("{k}.density"), *density, "kg/m^3");
                    positive(&mut add, &format!("{k}.youngs_modulus"), *youngs_modulus, "Pa");
                    if !(poisson_ratio.is_finite() && *poisson_ratio > -1.0 && *poisson_ratio < 0.5) {
                        add(format!("{k}.poisson_ratio"), format!("must lie in (-1, 0.5), got {poisson_ratio}"));
                    }
                    positive(&mut add, &format!("{k}.room_temperature"), *room_temperature, "K");
                    if let Some(c) = specific_heat {
                        positive(&mut add, &format!("{k}.specific_heat"), *c, "J/(kg K)");
                    }
                    if let Some(c) = thermal_conductivity {
                        non_negative(&mut add, &format!("{k}.thermal_conductivity"), *c, "W/(m K)");
                    }
                }
                MaterialSpec::JohnsonCook(jc) => {
                    if let Err(errors) = jc.validate() {
                        for e in errors {
                            add(format!("{k}.{}", e.parameter), format!("must be {}, got {}", e.requirement, e.value));
                        }
                    }
                }
            }
        }
        if self.bodies.is_empty() {
            add("bodies".into(), "at least one deformable body is needed".into());
        }
        let mut names = std::collections::BTreeSet::new();
        for (b, body) in self.bodies.iter().enumerate() {
            let k = format!("bodies[{b}]");
            if !names.insert(body.name.clone()) {
                add(format!("{k}.name"), format!("duplicate body name '{}'", body.name));
            }
            if !self.materials.contains_key(&body.material) && crate::material::builtin(&body.material).is_none() {
                add(
                    format!("{k}.material"),
                    format!(
                        "unknown material '{}' (defined: [{}]; built-in: [{}])",
                        body.material,
                        self.materials.keys().cloned().collect::<Vec<_>>().join(", "),
                        crate::material::builtin_names().join(", ")
                    ),
                );
            }
            validate_grid(&mut add, &format!("{k}.rectangle"), &body.rectangle, self.geometry.mode);
            for (j, iv) in body.initial_velocity.iter().enumerate() {
                finite2(&mut add, &format!("{k}.initial_velocity[{j}].velocity"), iv.velocity, "m/s");
                if let Some(message) = self.speed_problem(Vec2::from(iv.velocity).norm()) {
                    add(format!("{k}.initial_velocity[{j}].velocity"), message);
                }
                if let Some(r) = &iv.region {
                    validate_region(&mut add, &format!("{k}.initial_velocity[{j}].region"), r);
                }
            }
            for (j, s) in body.supports.iter().enumerate() {
                validate_region(&mut add, &format!("{k}.supports[{j}].region"), &s.region);
            }
        }
        for (r, rb) in self.rigid_bodies.iter().enumerate() {
            let k = format!("rigid_bodies[{r}]");
            if !names.insert(rb.name.clone()) {
                add(format!("{k}.name"), format!("duplicate body name '{}'", rb.name));
            }
            let shapes = [rb.outline.is_some(), rb.rectangle.is_some(), rb.projectile.is_some()];
            let shape_given = shapes.iter().filter(|&&s| s).count() == 1;
            match (&rb.outline, &rb.rectangle, &rb.projectile) {
                _ if shapes.iter().filter(|&&s| s).count() > 1 => {
                    add(k.clone(), "give one of `outline`, `rectangle` and `projectile`, not several".into())
                }
                (None, None, None) => {
                    add(k.clone(), "missing the shape: give `outline`, `rectangle` or `projectile`".into())
                }
                (None, None, Some(proj)) => {
                    for (field, message) in proj.problems(self.geometry.mode) {
                        add(format!("{k}.projectile.{field}"), message);
                    }
                }
                (Some(o), _, _) => {
                    if o.len() < 3 {
                        add(format!("{k}.outline"), format!("a polygon needs at least 3 vertices, got {}", o.len()));
                    } else if signed_area(o) <= 0.0 {
                        add(
                            format!("{k}.outline"),
                            "must be a simple polygon listed counter-clockwise (positive area)".into(),
                        );
                    }
                }
                (None, Some(rect), _) => {
                    positive(&mut add, &format!("{k}.rectangle.width"), rect.width, "m");
                    positive(&mut add, &format!("{k}.rectangle.height"), rect.height, "m");
                }
            }
            match (rb.mass, rb.density) {
                (Some(_), Some(_)) => add(k.clone(), "give either `mass` or `density`, not both".into()),
                (None, None) => add(k.clone(), "missing `mass` or `density`".into()),
                (Some(m), None) => positive(&mut add, &format!("{k}.mass"), m, "kg"),
                (None, Some(d)) => positive(&mut add, &format!("{k}.density"), d, "kg/m^3"),
            }
            let shape_valid = rb.projectile.as_ref().is_none_or(|p| p.problems(self.geometry.mode).is_empty());
            if shape_given && shape_valid && rb.mass.is_some() != rb.density.is_some() {
                if let Err(e) = self.rigid_body(rb) {
                    add(k.clone(), e.to_string());
                }
            }
            finite2(&mut add, &format!("{k}.velocity"), rb.velocity, "m/s");
            if let Some(message) = self.speed_problem(Vec2::from(rb.velocity).norm()) {
                add(format!("{k}.velocity"), message);
            }
        }
        let mu = self.contact.friction_coefficient;
        if !(mu.is_finite() && mu >= 0.0) {
            add("contact.friction_coefficient".into(), format!("must be >= 0, got {mu}"));
        }
        if !(self.contact.inverse_distance_floor.is_finite() && self.contact.inverse_distance_floor > 0.0) {
            add(
                "contact.inverse_distance_floor".into(),
                format!("must be > 0, got {}", self.contact.inverse_distance_floor),
            );
        }
        if self.contact.max_iterations == 0 {
            add("contact.max_iterations".into(), "must be at least 1".into());
        }
        if !(self.contact.tolerance.is_finite() && self.contact.tolerance > 0.0) {
            add("contact.tolerance".into(), format!("must be > 0, got {}", self.contact.tolerance));
        }
        if !(self.heat.safety_factor > 0.0 && self.heat.safety_factor <= 1.0) {
            add("heat.safety_factor".into(), format!("must lie in (0, 1], got {}", self.heat.safety_factor));
        }
        if self.heat.every == 0 {
            add("heat.every".into(), "must be at least 1 (conduct every step)".into());
        }
        if self.heat.conduction == Some(true) {
            for b in &self.bodies {
                if self.material(&b.material).is_some_and(|m| m.thermal().is_none()) {
                    add(
                        "heat.conduction".into(),
                        format!(
                            "is true, but body '{}' has material '{}' without thermal properties \
                             (give it specific_heat and thermal_conductivity, or set heat.conduction = false)",
                            b.name, b.material
                        ),
                    );
                }
            }
        }
        for (key, message) in self.fracture.problems() {
            add(format!("fracture.{key}"), message);
        }
        positive(&mut add, "time.end", self.time.end, "s");
        if !(self.time.safety_factor > 0.0 && self.time.safety_factor <= 1.0) {
            add("time.safety_factor".into(), format!("must lie in (0, 1], got {}", self.time.safety_factor));
        }
        if let Some(t) = self.time.stop_after_release {
            positive(&mut add, "time.stop_after_release", t, "s");
        }
        for (key, message) in self.time.bulk_viscosity.map_or(Vec::new(), |b| b.problems()) {
            add(format!("time.bulk_viscosity.{key}"), message);
        }
        // The step's floors: a fraction of the spacing step, with the adaptive step.
        for (key, floor) in
            [("mass_scaling", self.time.mass_scaling), ("erode_failed_below", self.time.erode_failed_below)]
        {
            let Some(f) = floor else { continue };
            if !(f > 0.0 && f <= 1.0) {
                add(format!("time.{key}"), format!("must lie in (0, 1] (a fraction of the spacing step), got {f}"));
            } else if self.time.fixed_dt.is_some() {
                add(format!("time.{key}"), format!("needs the adaptive step: leave out time.fixed_dt, or {key}"));
            }
        }
        if self.time.erode_failed_below.is_some() && !self.fracture.fractures_points() {
            add(
                "time.erode_failed_below".into(),
                "erodes fractured points, and this fracture criterion fractures none (fracture.criterion \
                 \"none\", or \"nonlocal_damage\" with nonlocal_point_fracture = false)"
                    .into(),
            );
        }
        if let Some(dt) = self.time.fixed_dt {
            positive(&mut add, "time.fixed_dt", dt, "s");
            if dt > self.time.end {
                add("time.fixed_dt".into(), format!("{dt} s is longer than time.end = {} s", self.time.end));
            }
        }
        if let Some(i) = self.output.interval {
            positive(&mut add, "output.interval", i, "s");
            if i > 0.0 && self.time.end / i > MAX_SNAPSHOTS {
                add(
                    "output.interval".into(),
                    format!(
                        "{i} s would write {:.3e} snapshots up to time.end (at most {MAX_SNAPSHOTS})",
                        self.time.end / i
                    ),
                );
            }
        }
        if let Some(i) = self.checkpoint.interval {
            positive(&mut add, "checkpoint.interval", i, "s");
        }
        non_negative(&mut add, "checkpoint.wall_interval", self.checkpoint.wall_interval, "s");
        if self.checkpoint.keep == 0 {
            add("checkpoint.keep".into(), "must be at least 1".into());
        }
        if self.output.history_every == 0 {
            add("output.history_every".into(), "must be at least 1".into());
        }
        for (j, &t) in self.output.plot_times.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                add(format!("output.plot_times[{j}]"), format!("must be a time >= 0 s, got {t}"));
            }
        }
        for (j, &i) in self.output.trace_particles.iter().enumerate() {
            if self.output.trace_particles[..j].contains(&i) {
                add(format!("output.trace_particles[{j}]"), format!("particle {i} is listed twice"));
            }
        }
        for (j, f) in self.output.fields.iter().enumerate() {
            if !OUTPUT_FIELDS.contains(&f.as_str()) {
                add(
                    format!("output.fields[{j}]"),
                    format!("unknown field '{f}' (known: {})", OUTPUT_FIELDS.join(", ")),
                );
            }
        }
        if p.is_empty() {
            p.extend(self.overlaps_at_start().into_iter().map(|(key, message)| Problem { key, message }));
        }
        p
    }

    /// The fastest impact the model describes, m/s, and the body that sets
    /// it: the lowest elastic longitudinal wave speed `c_L` of the deformable
    /// bodies' materials (`None` where no body's material is known and
    /// sound). At or above `c_L` the impact outruns the elastic wave, a
    /// shock (hypervelocity) regime that SPEC §6's hypoelastic pressure with
    /// no shock equation of state does not describe; in practice such a
    /// speed is one given in another unit (mm/s, km/h). Steel's `c_L` is
    /// about 5.9 km/s, copper's 4.7: far above the few hundred m/s of
    /// ballistic plugging and Taylor tests.
    pub fn speed_ceiling(&self) -> Option<(Real, &str)> {
        self.bodies
            .iter()
            .filter_map(|b| {
                let c = self.material(&b.material)?.longitudinal_wave_speed();
                (c.is_finite() && c > 0.0).then_some((c, b.name.as_str()))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Why `speed` (m/s) is not an impact speed the model describes
    /// ([`Case::speed_ceiling`]); `None` where it is.
    pub fn speed_problem(&self, speed: Real) -> Option<String> {
        let (c, body) = self.speed_ceiling()?;
        (speed >= c).then(|| {
            format!(
                "{speed} m/s is at or above the elastic wave speed of body '{body}' ({c:.0} m/s): \
                 a hypervelocity impact, which the model (no shock equation of state) does not describe; \
                 is the speed in another unit?"
            )
        })
    }

    /// The material named `name`: from this file, else a built-in.
    pub fn material(&self, name: &str) -> Option<Material> {
        match self.materials.get(name) {
            Some(spec) => Some(spec.to_material()),
            None => crate::material::builtin(name),
        }
    }

    /// The case with every default written out (what the run actually used).
    pub fn resolved(&self) -> Case {
        let mut c = self.clone();
        for b in &mut c.bodies {
            b.rectangle.resolve(c.geometry.mode);
        }
        if c.output.interval.is_none() {
            c.output.interval = Some(c.time.end / 50.0);
        }
        c.heat.conduction = Some(self.heat_conduction());
        c
    }

    /// Whether the run conducts heat: `heat.conduction`, or by default
    /// whether every body's material has thermal properties (see [`HeatSpec`]).
    pub fn heat_conduction(&self) -> bool {
        self.heat.conduction.unwrap_or_else(|| {
            self.bodies.iter().all(|b| self.material(&b.material).is_some_and(|m| m.thermal().is_some()))
        })
    }

    /// The heat conduction of a run of this case on `model` (`None` where
    /// [`Case::heat_conduction`] is off), with `heat.safety_factor`. The one
    /// place a run attaches conduction: a fresh run at t = 0 and a run
    /// resumed from a checkpoint (conduction keeps no state between steps,
    /// so it is rebuilt from the model).
    pub fn heat_conduction_for(
        &self,
        model: &crate::model::Model,
    ) -> Result<Option<crate::thermal::HeatConduction>, crate::thermal::HeatError> {
        if !self.heat_conduction() {
            return Ok(None);
        }
        crate::thermal::HeatConduction::new(model, self.heat.safety_factor).map(Some)
    }

    /// Set on `sim` what a run takes from this case and checkpoints do not
    /// store: heat conduction ([`Case::heat_conduction_for`]), the bulk
    /// viscosity and the step's floors (mass scaling, erosion). The one
    /// place for both a fresh run at t = 0 and a run resumed from a
    /// checkpoint.
    pub fn apply_unstored_settings(&self, sim: &mut crate::step::Simulation) -> Result<(), crate::thermal::HeatError> {
        sim.heat = self.heat_conduction_for(&sim.model)?;
        sim.bulk_viscosity = self.bulk_viscosity();
        sim.floors =
            crate::stability::Floors { mass_scaling: self.time.mass_scaling, erosion: self.time.erode_failed_below };
        Ok(())
    }

    /// TOML text of [`Case::resolved`].
    pub fn resolved_toml(&self) -> String {
        toml::to_string_pretty(&self.resolved()).unwrap_or_else(|e| format!("# could not serialize the case: {e}\n"))
    }

    /// The rigid body of a (validated) spec: outline, mass (from density by
    /// area in plane strain, by volume of revolution in axisymmetry),
    /// velocity, prescribed motion.
    /// Bodies that overlap at t = 0, as `(key, message)` naming both: the
    /// deformable bodies' rectangles and the rigid bodies' outlines at their
    /// initial positions ([`crate::contact::polygons_overlap`]; touching is
    /// allowed). Contact assumes bodies start apart: a projectile placed
    /// inside the plate would be pushed out in one step with an impulse that
    /// inverts the points it crosses. Meaningful once every body is valid.
    pub fn overlaps_at_start(&self) -> Vec<(String, String)> {
        let corners = |g: &RectangleGrid| {
            vec![
                Vec2::new(g.x_min, g.y_min),
                Vec2::new(g.x_max, g.y_min),
                Vec2::new(g.x_max, g.y_max),
                Vec2::new(g.x_min, g.y_max),
            ]
        };
        let mut shapes: Vec<(String, String, Vec<Vec2>)> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (format!("bodies[{i}].rectangle"), b.name.clone(), corners(&b.rectangle)))
            .collect();
        for (r, rb) in self.rigid_bodies.iter().enumerate() {
            if let Ok(body) = self.rigid_body(rb) {
                shapes.push((format!("rigid_bodies[{r}]"), rb.name.clone(), body.outline_global().collect()));
            }
        }
        let mut found = Vec::new();
        for (j, (key, name, shape)) in shapes.iter().enumerate() {
            for (_, other, earlier) in &shapes[..j] {
                if crate::contact::polygons_overlap(shape, earlier) {
                    found.push((
                        key.clone(),
                        format!("body '{name}' overlaps body '{other}' at t = 0; place the two apart (they may touch)"),
                    ));
                }
            }
        }
        found
    }

    pub fn rigid_body(&self, rb: &RigidBodySpec) -> Result<RigidBody, ContactError> {
        let (outline, position) = match (&rb.outline, &rb.rectangle, &rb.projectile) {
            (Some(o), _, _) => (o.iter().map(|v| Vec2::new(v[0], v[1])).collect(), Vec2::zeros()),
            (None, Some(r), _) => (rectangle_outline(r.width, r.height), Vec2::new(r.center[0], r.center[1])),
            (None, None, Some(p)) => (
                p.projectile().map_or_else(Vec::new, |g| g.outline(nose_segment_length(self.smallest_spacing()))),
                Vec2::new(p.tip[0], p.tip[1]),
            ),
            (None, None, None) => (Vec::new(), Vec2::zeros()),
        };
        let mass = match (rb.mass, rb.density) {
            (Some(m), _) => m,
            (None, Some(rho)) => match self.geometry.mode {
                GeometryMode::PlaneStrain => mass_plane_strain(&outline, rho)?,
                GeometryMode::Axisymmetric => mass_axisymmetric(&outline, rho)?,
            },
            (None, None) => 0.0,
        };
        let velocity = Vec2::new(rb.velocity[0], rb.velocity[1]);
        let body = RigidBody::new(rb.name.clone(), outline, position, velocity, mass)?;
        let body = if rb.prescribed { body.with_prescribed_velocity(velocity) } else { body };
        // In axisymmetry a body is a body of revolution about the axis: it
        // cannot move radially.
        Ok(if self.geometry.mode == GeometryMode::Axisymmetric { body.held_on_axis() } else { body })
    }

    /// The smallest particle spacing of the deformable bodies' grids, m
    /// (the fine spacing along x or the thickness spacing, whichever is
    /// smaller): the scale curved projectile noses are faceted to
    /// ([`crate::contact::projectile`]). Without a valid body, the spacing
    /// of 24 rows through a 10 mm plate (0.42 mm), a typical value, so that
    /// a case being validated still gets an outline.
    pub fn smallest_spacing(&self) -> Real {
        let h = self
            .bodies
            .iter()
            .map(|b| {
                let layer = b.rectangle.layer_spacing();
                b.rectangle.fine_spacing.map_or(layer, |f| f.min(layer))
            })
            .filter(|h| h.is_finite() && *h > 0.0)
            .fold(Real::INFINITY, Real::min);
        if h.is_finite() {
            h
        } else {
            0.01 / 23.0
        }
    }

    /// All rigid bodies.
    pub fn rigid_bodies(&self) -> Result<Vec<RigidBody>, ContactError> {
        self.rigid_bodies.iter().map(|rb| self.rigid_body(rb)).collect()
    }

    /// Each rigid body's name and initial velocity (its flight direction,
    /// [`crate::residual`]), m/s.
    pub fn rigid_flights(&self) -> Vec<(String, Vec2)> {
        self.rigid_bodies.iter().map(|rb| (rb.name.clone(), Vec2::new(rb.velocity[0], rb.velocity[1]))).collect()
    }

    /// The deformable projectiles: each body given a non-zero initial
    /// velocity over its whole body (an `initial_velocity` entry without a
    /// region; the last such entry), with its index among the bodies and
    /// that velocity (its flight direction, [`crate::residual`]), m/s.
    pub fn deformable_flights(&self) -> Vec<(String, usize, Vec2)> {
        self.bodies
            .iter()
            .enumerate()
            .filter_map(|(b, body)| {
                let v = body.whole_body_velocity()?;
                let v = Vec2::new(v[0], v[1]);
                (v != Vec2::zeros()).then(|| (body.name.clone(), b, v))
            })
            .collect()
    }

    /// Every flight a run follows: the rigid bodies ([`Self::rigid_flights`]),
    /// then the deformable projectiles ([`Self::deformable_flights`]).
    pub fn flights(&self) -> Vec<(String, Vec2)> {
        let mut f = self.rigid_flights();
        f.extend(self.deformable_flights().into_iter().map(|(name, _, v)| (name, v)));
        f
    }

    /// Whether the run has a contact stage: rigid bodies, two deformable
    /// bodies or more with `contact.deformable`, or cracks with
    /// `contact.self_contact`.
    pub fn has_contact(&self) -> bool {
        !self.rigid_bodies.is_empty()
            || (self.contact.deformable && self.bodies.len() > 1)
            || (self.contact.self_contact && self.fracture.criterion != Criterion::None)
    }

    /// The artificial bulk viscosity ([`crate::bulk_viscosity`]; none
    /// unless `[time] bulk_viscosity` is given).
    pub fn bulk_viscosity(&self) -> crate::bulk_viscosity::BulkViscosity {
        self.time.bulk_viscosity.unwrap_or(crate::bulk_viscosity::BulkViscosity::NONE)
    }

    /// The time-step rule.
    pub fn time_step_rule(&self) -> TimeStepRule {
        match self.time.fixed_dt {
            Some(dt) => TimeStepRule::Fixed(dt),
            None => TimeStepRule::Cfl { safety: self.time.safety_factor },
        }
    }

    /// Inputs of [`crate::model::Model::build`].
    pub fn body_setups(&self) -> Vec<BodySetup> {
        self.bodies
            .iter()
            .map(|b| BodySetup {
                name: b.name.clone(),
                grid: b.rectangle.clone(),
                material: self.material(&b.material).expect("validated: material exists"),
                initial_velocity: b
                    .initial_velocity
                    .iter()
                    .map(|iv| (Vec2::new(iv.velocity[0], iv.velocity[1]), iv.region))
                    .collect(),
                supports: b.supports.clone(),
            })
            .collect()
    }
}

impl MaterialSpec {
    /// The solver's material.
    pub fn to_material(&self) -> Material {
        match self {
            MaterialSpec::Elastic {
                density,
                youngs_modulus,
                poisson_ratio,
                room_temperature,
                specific_heat,
                thermal_conductivity,
            } => Material::Elastic(Elastic {
                density: *density,
                youngs_modulus: *youngs_modulus,
                poisson_ratio: *poisson_ratio,
                room_temperature: *room_temperature,
                thermal: match (specific_heat, thermal_conductivity) {
                    (Some(c), Some(k)) => Some(ThermalProperties { specific_heat: *c, conductivity: *k }),
                    _ => None,
                },
            }),
            MaterialSpec::JohnsonCook(jc) => Material::JohnsonCook(jc.clone()),
        }
    }
}

fn positive(add: &mut impl FnMut(String, String), key: &str, v: Real, unit: &str) {
    if !(v.is_finite() && v > 0.0) {
        add(key.to_string(), format!("must be a positive number (in {unit}), got {v}"));
    }
}

fn non_negative(add: &mut impl FnMut(String, String), key: &str, v: Real, unit: &str) {
    if !(v.is_finite() && v >= 0.0) {
        add(key.to_string(), format!("must be zero or positive (in {unit}), got {v}"));
    }
}

fn finite2(add: &mut impl FnMut(String, String), key: &str, v: [Real; 2], unit: &str) {
    if !v.iter().all(|x| x.is_finite()) {
        add(key.to_string(), format!("must be finite (in {unit}), got {v:?}"));
    }
}

fn validate_region(add: &mut impl FnMut(String, String), key: &str, r: &Region) {
    if !(r.x_min.is_finite() && r.x_max.is_finite() && r.y_min.is_finite() && r.y_max.is_finite()) {
        add(key.to_string(), "bounds must be finite".into());
    } else if r.x_max < r.x_min || r.y_max < r.y_min {
        add(key.to_string(), format!("empty region: x {}..{}, y {}..{}", r.x_min, r.x_max, r.y_min, r.y_max));
    }
}

fn validate_grid(add: &mut impl FnMut(String, String), key: &str, g: &RectangleGrid, mode: GeometryMode) {
    for (name, v) in [("x_min", g.x_min), ("x_max", g.x_max), ("y_min", g.y_min), ("y_max", g.y_max)] {
        if !v.is_finite() {
            add(format!("{key}.{name}"), format!("must be finite, got {v}"));
        }
    }
    if g.x_max.partial_cmp(&g.x_min) != Some(std::cmp::Ordering::Greater) {
        add(format!("{key}.x_max"), format!("must exceed x_min (zero or negative length): {} <= {}", g.x_max, g.x_min));
    }
    if g.y_max.partial_cmp(&g.y_min) != Some(std::cmp::Ordering::Greater) {
        add(
            format!("{key}.y_max"),
            format!("must exceed y_min (zero or negative thickness): {} <= {}", g.y_max, g.y_min),
        );
    }
    if mode == GeometryMode::Axisymmetric && g.x_min < 0.0 {
        add(format!("{key}.x_min"), format!("is a radius in axisymmetry and must be >= 0, got {}", g.x_min));
    }
    if g.layers < 2 {
        add(format!("{key}.layers"), format!("need at least 2 particle rows through the thickness, got {}", g.layers));
    }
    if !(g.growth >= 1.0 && g.growth <= 2.0) {
        add(format!("{key}.growth"), format!("spacing growth ratio must lie in [1, 2], got {}", g.growth));
    }
    if !(g.support_factor >= 1.2 && g.support_factor <= 4.0) {
        add(
            format!("{key}.support_factor"),
            format!("must lie in [1.2, 4] (below ~1.2 the bilinear RK basis is singular), got {}", g.support_factor),
        );
    }
    if !(1..=4).contains(&g.gauss) {
        add(format!("{key}.gauss"), format!("Gauss points per direction must be 1..4, got {}", g.gauss));
    }
    if let Some(h) = g.fine_spacing {
        positive(add, &format!("{key}.fine_spacing"), h, "m");
    }
    if let Some(h) = g.coarse_spacing {
        positive(add, &format!("{key}.coarse_spacing"), h, "m");
    }
    if !(g.fine_half_width.is_finite() && g.fine_half_width >= 0.0) {
        add(format!("{key}.fine_half_width"), format!("must be >= 0 m, got {}", g.fine_half_width));
    }
    if let Some(x) = g.refine_at {
        if !(x >= g.x_min && x <= g.x_max) {
            add(format!("{key}.refine_at"), format!("must lie in [x_min, x_max], got {x}"));
        }
    }
    if let Some(x) = g.column_at {
        let x_f = g.refine_point(mode);
        let d = (x - x_f).abs();
        if !(x.is_finite() && d > 0.0 && d < g.fine_half_width && x > g.x_min && x < g.x_max) {
            add(
                format!("{key}.column_at"),
                format!(
                    "must lie inside the uniform fine zone (within fine_half_width = {} m of refine_at = {x_f} m, not at it) and inside the body, got {x}",
                    g.fine_half_width
                ),
            );
        }
    }
}

/// Gives `[fracture]` the defaults of its criterion where the case leaves
/// them out ([`FractureParameters::CRITERION_DEFAULTS`],
/// [`FractureParameters::for_criterion`]): the default model's tip rule
/// under `"nonlocal_damage"`, SPEC §9's under \[RL10\]'s criteria. Runs
/// after the `--set` overrides, so `--set fracture.criterion=damage` on a
/// default-model case gives the paper's tip as well. A criterion that does
/// not parse is left to the parse's own error.
fn fill_criterion_defaults(table: &mut toml::Table) {
    let Some(fracture) = table.get_mut("fracture").and_then(toml::Value::as_table_mut) else {
        return;
    };
    let Some(Ok(criterion)) = fracture.get("criterion").map(|c| c.clone().try_into::<Criterion>()) else {
        return;
    };
    let defaults = toml::Table::try_from(FractureParameters::for_criterion(criterion))
        .expect("fracture parameters serialize to a table");
    for key in FractureParameters::CRITERION_DEFAULTS {
        if !fracture.contains_key(key) {
            fracture.insert(key.to_string(), defaults[key].clone());
        }
    }
}

/// One line from a TOML error: `line L, column C: message (`source
/// line`)` where the error points into `text`, else the message with its
/// key path (`... in `time.end``).
fn toml_message(e: &toml::de::Error, text: Option<&str>) -> String {
    if let (Some(span), Some(text)) = (e.span(), text) {
        let start = span.start.min(text.len());
        let before = &text.as_bytes()[..start];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
        let column = start - line_start + 1;
        let source = text[line_start..].lines().next().unwrap_or("").trim();
        let message = e.message().trim().replace('\n', " ");
        return if source.is_empty() || source.len() > 80 {
            format!("line {line}, column {column}: {message}")
        } else {
            format!("line {line}, column {column}: {message} (`{source}`)")
        };
    }
    e.to_string().lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ")
}

fn signed_area(o: &[[Real; 2]]) -> Real {
    let n = o.len();
    (0..n).map(|i| o[i][0] * o[(i + 1) % n][1] - o[(i + 1) % n][0] * o[i][1]).sum::<Real>() * 0.5
}

/// Apply `key=value` to a TOML table. Keys are dotted paths; a path segment
/// into an array is an index (`bodies.0.material`) or the `name` of an
/// element (`bodies.plate.material`). The value is parsed as TOML, or taken
/// as a string if it does not parse.
pub fn apply_override(table: &mut toml::Table, assignment: &str) -> Result<(), (String, String)> {
    let Some((key, raw)) = assignment.split_once('=') else {
        return Err((assignment.to_string(), "expected key=value".into()));
    };
    let key = key.trim();
    let raw = raw.trim();
    let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        Ok(mut t) => t.remove("v").unwrap_or_else(|| toml::Value::String(raw.to_string())),
        Err(_) => toml::Value::String(raw.to_string()),
    };
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err((key.to_string(), "empty path segment".into()));
    }
    let mut root = toml::Value::Table(std::mem::take(table));
    let result = set_path(&mut root, &parts, value).map_err(|m| (key.to_string(), m));
    if let toml::Value::Table(t) = root {
        *table = t;
    }
    result
}

fn set_path(cur: &mut toml::Value, parts: &[&str], value: toml::Value) -> Result<(), String> {
    let (part, rest) = (parts[0], &parts[1..]);
    let next = match cur {
        toml::Value::Table(t) => {
            if rest.is_empty() {
                t.insert(part.to_string(), value);
                return Ok(());
            }
            t.entry(part.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()))
        }
        toml::Value::Array(a) => {
            let idx = match part.parse::<usize>() {
                Ok(i) if i < a.len() => i,
                Ok(i) => return Err(format!("index {i} out of range (array has {} elements)", a.len())),
                Err(_) => a
                    .iter()
                    .position(|e| e.get("name").and_then(|n| n.as_str()) == Some(part))
                    .ok_or_else(|| format!("no element named '{part}'"))?,
            };
            if rest.is_empty() {
                a[idx] = value;
                return Ok(());
            }
            &mut a[idx]
        }
        _ => return Err(format!("'{part}' is inside a value that is not a table or array")),
    };
    set_path(next, rest, value)
}
