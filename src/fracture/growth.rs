//! The crack-growth stage (SPEC §9, [RL10, §4]): criteria, nucleation,
//! propagation, arrest, particle splitting and the local rebuild of the
//! shape tables and lumped masses. See the module doc of
//! [`crate::fracture`] for the choices and deviations.

use super::geometry::{
    band_aim, closest_point_on_segment, left_bisector, left_normal, max_shear_direction, point_segment_distance,
    sector_angles, sector_contains, velocity_jump_direction, widest_empty_sector,
};
use super::nonlocal::NonlocalAverage;
use super::visibility::{CrackSegments, CrackVisibility};
use super::{tip_speed, Criterion, FractureError, FractureParameters, TipDirection, TipGate};
use crate::geometry::GeometryMode;
use crate::material::Constitutive;
use crate::math::{largest_principal, Block2, Real, Tensor3, Vec2};
use crate::model::{Gather, Model};
use crate::neighbors::CellGrid;
use crate::particles::{FaceSide, ParticleFlags};
use crate::shape::ShapeTable;
use crate::shape::{rebuild_rows, Basis, Row};
use nalgebra::Matrix2;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// Crack segments are extended by this many offsets `δ` beyond each end
/// that is not a growing tip.
pub const EXTENSION_PER_OFFSET: Real = 5.0;

/// A crack segment that starts or ends on the outer surface makes at most
/// this angle with the surface normal, degrees (module doc).
pub const MAX_SURFACE_OBLIQUITY: Real = 40.0;

/// No crack nucleates or grows into material whose stress triaxiality
/// `σ_m / σ_eq` is below this value: Bao and Wierzbicki's cut-off (2005), below which ductile
/// metals do not fracture (module doc of [`crate::fracture`]).
pub const NUCLEATION_MIN_TRIAXIALITY: Real = -1.0 / 3.0;

/// Smallest lumped mass of a re-lumped particle, as a fraction of its
/// nodal mass `ρ ΔV_I` (times `2πR` in axisymmetry: [`nodal_mass`]; see the
/// module doc of [`crate::fracture`]).
pub const MASS_FLOOR: Real = 0.5;

/// Nodal mass `ρ ΔV_I` of particle `i` from its nodal volume, in the units of
/// the lumped masses: per unit depth in plane strain, and revolved in
/// axisymmetry, where `ΔV_I` is an area: `ρ ΔV_I 2π max(R_I, h_I/4)`. On the
/// axis the cell `[0, h/2]` revolves about its own edge and its volume is
/// `ΔV_I 2π h/4`, hence the `h/4` (`mass_floor_is_revolved_in_axisymmetry`).
pub fn nodal_mass(model: &Model, i: usize) -> Real {
    let p = &model.particles;
    let rho = model.materials[p.body[i] as usize].density();
    let x = p.x0[i];
    let factor = match model.mode {
        GeometryMode::PlaneStrain => 1.0,
        GeometryMode::Axisymmetric => model.mode.volume_factor(&Vec2::new(x.x.max(0.25 * p.spacing[i]), x.y)),
    };
    rho * p.volume[i] * factor
}

/// The event of `kind` at `(time, step)` on `crack`, decided by particle
/// `decider` with criterion value `value`: its particle list holds the new
/// tip for nucleation and propagation (the split's children are put in
/// front by [`CrackGrowth::split_logged`]), and it records the decider's
/// lumped damage and adiabatic hardening, NaN for an inserted pre-crack
/// (whose `value` is NaN: no criterion decided it).
fn logged_event(
    model: &Model,
    at: (Real, u64),
    crack: usize,
    kind: EventKind,
    decider: usize,
    value: Real,
) -> CrackEvent {
    let (damage, hardening) = if value.is_nan() {
        (Real::NAN, Real::NAN)
    } else {
        (
            model.project_at(decider, |q| model.quad.damage[q]),
            model.project_at(decider, |q| model.adiabatic_hardening(q)),
        )
    };
    let particles = if kind.grows() { vec![decider] } else { Vec::new() };
    CrackEvent { time: at.0, step: at.1, crack, kind, particles, value, damage, hardening }
}

/// The in-plane block of a [`crate::math::Block2`] as a matrix.
fn in_plane_matrix(b: &crate::math::Block2) -> Matrix2<Real> {
    Matrix2::new(b.xx, b.xy, b.yx, b.yy)
}

/// How far ahead of a tip (along the crack, as a fraction of `ℓ`) the
/// sight lines of the band reading of `tip_direction = "velocity_jump"`
/// start: off the crack's line, so that both faces are seen.
const EYE_AHEAD: Real = 1e-3;

/// A segment may not pass within this fraction of a particle's spacing of
/// a particle it does not end at.
const PASS_OVER_FRACTION: Real = 0.1;

/// A particle counts as nearer a junction than the tip
/// ([`CrackGrowth::junction`]) only by more than this fraction of the
/// tip's spacing: lattice neighbours at the same distance are not between.
const LIGAMENT_TOLERANCE: Real = 1e-6;

/// Relative margin below the critical value within which
/// [`CrackGrowth::may_reach`]'s bound still asks for the average: far
/// wider than the round-off of a weighted mean (a few ulps), far narrower
/// than any change of the damage in a step.
const BOUND_MARGIN: Real = 1e-9;

/// Angle between two non-zero vectors, rad.
fn angle(a: &Vec2, b: &Vec2) -> Real {
    (a.dot(b) / (a.norm() * b.norm())).clamp(-1.0, 1.0).acos()
}

/// Whether `r` (from a tip) lies inside both fans of half-angle `half_fan`
/// (rad): around the last segment's direction `d` and the crack's mean
/// direction `mean` (crate::fracture, "The fan is applied twice").
fn in_fans(r: &Vec2, d: &Vec2, mean: &Vec2, half_fan: Real) -> bool {
    r.norm() > 0.0 && angle(r, d) <= half_fan && angle(r, mean) <= half_fan
}

/// What happened to a crack.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum EventKind {
    Nucleate,
    Propagate,
    Arrest,
    /// The tip reached another crack and ended on it (coalescence,
    /// `CrackGrowth::junction`).
    Join,
}

impl EventKind {
    pub fn name(self) -> &'static str {
        match self {
            EventKind::Nucleate => "nucleate",
            EventKind::Propagate => "propagate",
            EventKind::Arrest => "arrest",
            EventKind::Join => "join",
        }
    }

    /// Whether the crack grew into a new particle (its decider is a new
    /// tip): not at an arrest or a join, which end the crack at its tip.
    pub fn grows(self) -> bool {
        matches!(self, EventKind::Nucleate | EventKind::Propagate)
    }
}

/// One entry of the crack log.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CrackEvent {
    /// Simulated time, s.
    pub time: Real,
    pub step: u64,
    pub crack: usize,
    pub kind: EventKind,
    /// Particles involved: the split particle (left child), the new right
    /// child, and for nucleation and propagation the new tip.
    pub particles: Vec<usize>,
    /// Criterion value of the deciding particle (the new tip; the split
    /// tip at arrest).
    pub value: Real,
    /// The deciding particle's own Johnson–Cook damage `D` (lumped
    /// projection, module doc of [`crate::fracture`]), whatever the
    /// criterion: how much of the locus the material the crack enters has
    /// used. With `"damage"` it equals `value`; with `"nonlocal_damage"` it
    /// shows whether the crack runs through a band (`D` well above the
    /// average) or through diffuse material (`D ≈ D̄`, far below 1).
    pub damage: Real,
    /// The deciding particle's adiabatic hardening `(1/τ̄) dτ̄/dε̄`
    /// (lumped projection of [`crate::model::Model::adiabatic_hardening`]):
    /// ≤ 0 where the material has passed the onset of adiabatic shear
    /// localization, positive where the crack enters material that still
    /// hardens. NaN for an inserted pre-crack and in an elastic body.
    pub hardening: Real,
}

/// Summary of one quantity over the particles the cracks grew into
/// ([`CrackGrowth::tip_damage`]: the locus is `D = 1`;
/// [`CrackGrowth::tip_hardening`]: ≤ 0 past the onset of localization).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipValues {
    pub min: Real,
    /// The median (the mean of the middle two for an even count).
    pub median: Real,
    pub max: Real,
    /// Number of events.
    pub count: usize,
}

impl TipValues {
    /// Summary of `values` (finite), `None` if empty.
    pub fn of(mut values: Vec<Real>) -> Option<Self> {
        if values.is_empty() {
            return None;
        }
        values.sort_by(|a, b| a.partial_cmp(b).expect("finite values"));
        let n = values.len();
        let median = if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) };
        Some(TipValues { min: values[0], median, max: values[n - 1], count: n })
    }
}

/// What [`CrackGrowth::grow`] makes of a particle within reach of a
/// growing tip: the first of its checks that turns it down, in the order
/// it makes them, or [`Self::Eligible`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CandidateCheck {
    /// Already a crack face, or detached.
    Taken,
    /// Outside the fan of `θ_c` about the crack's direction.
    OutsideFan,
    /// Its criterion value is below the critical one.
    BelowCriterion,
    /// The tip's stress gate is closed there ([`super::TipGate`]).
    GateClosed,
    /// The step would pass over a third particle.
    PassesOver,
    /// A crack lies between the tip and it.
    Blocked,
    /// A surface particle the step would meet more obliquely than
    /// [`MAX_SURFACE_OBLIQUITY`].
    Oblique,
    /// The tip may step to it.
    Eligible,
}

impl CandidateCheck {
    /// The check's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            CandidateCheck::Taken => "taken",
            CandidateCheck::OutsideFan => "outside fan",
            CandidateCheck::BelowCriterion => "below criterion",
            CandidateCheck::GateClosed => "gate closed",
            CandidateCheck::PassesOver => "passes over",
            CandidateCheck::Blocked => "blocked",
            CandidateCheck::Oblique => "oblique",
            CandidateCheck::Eligible => "eligible",
        }
    }
}

/// One particle within reach of a growing tip
/// ([`CrackGrowth::tip_candidates`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipCandidate {
    pub particle: usize,
    /// Its reference position less the tip's, m.
    pub offset: Vec2,
    /// Its criterion value (NaN if taken).
    pub value: Real,
    /// Its rank (larger first; NaN if taken or outside the fan).
    pub rank: Real,
    /// What the tip's gate reads there: the triaxiality, or with
    /// `tip_gate = "tension"` the mean largest principal stress, Pa (NaN
    /// if taken).
    pub gate: Real,
    pub check: CandidateCheck,
}

/// A growing tip as [`CrackGrowth::tip_candidates`] reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct TipReport {
    /// Where the tip heads in the reference configuration, if its
    /// `tip_direction` gives a heading (the candidates' rank is then
    /// minus their angle to it).
    pub heading: Option<Vec2>,
    /// Every particle within reach of the tip.
    pub candidates: Vec<TipCandidate>,
}

/// A growing tip's fan: what its candidates are measured against.
struct TipFan {
    tip: usize,
    /// The tip's reference position, m.
    xt: Vec2,
    /// The last segment's direction.
    d: Vec2,
    /// The direction from the crack's start to the tip.
    mean: Vec2,
    /// Half the fan angle, rad.
    half_fan: Real,
    /// Where the tip heads ([`CrackGrowth::heading`]).
    heading: Option<Vec2>,
}

/// A vertex of a crack path.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CrackVertex {
    /// Reference position, m.
    pub x0: Vec2,
    /// `(left, right)` children if a particle was split here; `None` at a
    /// growing tip and at the end point past the surface after arrest.
    pub faces: Option<(u32, u32)>,
}

/// A crack: a polyline in the reference configuration whose tip is a
/// particle while it grows.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Crack {
    pub id: usize,
    pub vertices: Vec<CrackVertex>,
    /// Tip particle while growing.
    pub tip: Option<usize>,
    /// Split offset δ of this crack, m.
    pub offset: Real,
    /// Nucleation time, s, and step.
    pub nucleated: (Real, u64),
    /// Arrest time, s, and step.
    pub arrested: Option<(Real, u64)>,
    /// Distance the tip may still advance under the speed limit, m
    /// ([`super::tip_speed`]; stays 0 without a limit).
    pub allowance: Real,
}

impl Crack {
    /// Unit direction of the last segment.
    pub fn direction(&self) -> Vec2 {
        let n = self.vertices.len();
        (self.vertices[n - 1].x0 - self.vertices[n - 2].x0).normalize()
    }

    /// Whether the crack still grows.
    pub fn growing(&self) -> bool {
        self.tip.is_some()
    }

    /// Opaque segments of this crack, extended by `EXTENSION_PER_OFFSET δ`
    /// at every end except a growing tip.
    pub fn segments(&self) -> Vec<(Vec2, Vec2)> {
        let ext = EXTENSION_PER_OFFSET * self.offset;
        let n = self.vertices.len();
        (0..n - 1)
            .map(|k| {
                let (a, b) = (self.vertices[k].x0, self.vertices[k + 1].x0);
                let d = (b - a).normalize();
                let b_ext = if k + 2 == n && self.growing() { 0.0 } else { ext };
                (a - d * ext, b + d * b_ext)
            })
            .collect()
    }

    /// The particles of the two faces, `[left, right]`, each in the
    /// direction of growth: the children of every split vertex, and a
    /// growing tip closing both (the contact's master segments,
    /// `crate::contact::deformable`).
    pub fn face_chains(&self) -> [Vec<u32>; 2] {
        let mut chains = [Vec::new(), Vec::new()];
        for v in &self.vertices {
            match (v.faces, self.tip) {
                (Some((l, r)), _) => {
                    chains[0].push(l);
                    chains[1].push(r);
                }
                (None, Some(t)) if v.x0 == self.vertices.last().map_or(v.x0, |last| last.x0) => {
                    chains[0].push(t as u32);
                    chains[1].push(t as u32);
                }
                _ => {}
            }
        }
        chains
    }

    /// The two faces in the current configuration (`x = X + u(X)`, with
    /// the children's physical displacements): `[left, right]` polylines.
    /// A growing tip closes both; the end point past the surface moves with
    /// the last split vertex.
    pub fn face_polylines(&self, model: &Model) -> [Vec<Vec2>; 2] {
        let u = |i: usize| model.particle_shape.interpolate(i, &model.particles.u);
        let mut faces = [Vec::new(), Vec::new()];
        let mut last = (Vec2::zeros(), Vec2::zeros());
        for v in &self.vertices {
            let (l, r) = match v.faces {
                Some((l, r)) => (u(l as usize), u(r as usize)),
                None => match self.tip {
                    Some(t) if model.particles.x0[t] == v.x0 => (u(t), u(t)),
                    _ => last,
                },
            };
            last = (l, r);
            faces[0].push(v.x0 + l);
            faces[1].push(v.x0 + r);
        }
        faces
    }
}

/// The crack-growth stage: the cracks, their log, and the opaque segments.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CrackGrowth {
    pub params: FractureParameters,
    pub cracks: Vec<Crack>,
    /// Every event, in order.
    pub events: Vec<CrackEvent>,
    /// Not in checkpoints: rebuilt from the cracks on reading
    /// ([`Self::refresh_segments`]).
    #[serde(skip)]
    segments: CrackSegments,
    /// Reference positions binned for the circle searches (rebuilt when
    /// particles move or are added). Not in checkpoints: rebuilt at its
    /// next use.
    #[serde(skip)]
    grid: Option<CellGrid>,
    /// Quadrature rows built with a reduced basis (too few visible
    /// particles next to a crack; [`crate::shape::rebuild_rows`]).
    pub reduced_quadrature_rows: BTreeMap<usize, Basis>,
    /// Particle rows built with a reduced basis.
    pub reduced_particle_rows: BTreeMap<usize, Basis>,
    /// Buffers that every local rebuild fills and swaps with the model's
    /// tables: the tables are rewritten after each split, and writing them
    /// into fresh allocations (page faults on tens of MB) took longer than
    /// the copying itself. Scratch, not in checkpoints.
    #[serde(skip)]
    spare: Spare,
    /// Time of the last stage, s: the speed limit's `Δt` ([`super::tip_speed`]).
    last_time: Option<Real>,
    /// The quadrature points binned for the non-local average (built at
    /// its first use; the points never move in the reference
    /// configuration). Not in checkpoints.
    #[serde(skip)]
    nonlocal: OnceLock<NonlocalAverage>,
    /// The quadrature points found eroded so far by
    /// [`CrackGrowth::detach_isolated`]: those eroded since are the new
    /// ones whose particles it looks at.
    eroded_seen: Vec<bool>,
    /// The particles whose gather a local rebuild (a split's, a
    /// detachment's) changed since [`CrackGrowth::detach_isolated`] last
    /// looked: a split can leave a crack-face particle's share of live
    /// material under `detach_below` with no point newly eroded (its rows
    /// lose the live points across the crack). Drained by every call,
    /// which runs in the same step as the changes, so empty between steps
    /// and not in checkpoints.
    #[serde(skip)]
    gather_changed: Vec<usize>,
    /// The particles detached so far and when, s, in order.
    pub detached: Vec<(usize, Real)>,
}

/// See [`CrackGrowth::spare`].
#[derive(Clone, Default)]
struct Spare {
    gather: Gather,
    qp_shape: ShapeTable,
    particle_shape: ShapeTable,
}

impl std::fmt::Debug for Spare {
    /// Sizes only: the contents are scratch.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Spare")
            .field("gather_entries", &self.gather.entry.len())
            .field("qp_entries", &self.qp_shape.nnz())
            .field("particle_entries", &self.particle_shape.nnz())
            .finish()
    }
}

/// Scratch of the failed-zone search of one nucleation stage.
struct FailedZones {
    /// Criterion values computed so far.
    value: Vec<Option<Real>>,
    /// Particles of zones found to hold a crack.
    cracked: Vec<bool>,
    /// Search stamp per particle.
    seen: Vec<u32>,
    stamp: u32,
}

impl FailedZones {
    fn new(n: usize) -> Self {
        FailedZones { value: vec![None; n], cracked: vec![false; n], seen: vec![0; n], stamp: 0 }
    }

    /// Room for particles appended by splits.
    fn grow(&mut self, n: usize) {
        self.value.resize(n, None);
        self.cracked.resize(n, false);
        self.seen.resize(n, 0);
    }
}

/// A split to perform at a crack vertex.
struct Split {
    parent: usize,
    vertex: Vec2,
    incoming: Vec2,
    outgoing: Vec2,
    reach: Real,
    offset: Real,
}

impl CrackGrowth {
    pub fn new(params: FractureParameters) -> Self {
        CrackGrowth {
            params,
            cracks: Vec::new(),
            events: Vec::new(),
            segments: CrackSegments::default(),
            grid: None,
            reduced_quadrature_rows: BTreeMap::new(),
            reduced_particle_rows: BTreeMap::new(),
            spare: Spare::default(),
            last_time: None,
            nonlocal: OnceLock::new(),
            eroded_seen: Vec::new(),
            gather_changed: Vec::new(),
            detached: Vec::new(),
        }
    }

    /// The opaque segments of all cracks.
    pub fn segments(&self) -> &CrackSegments {
        &self.segments
    }

    /// The visibility of the current crack set for `model`'s particles.
    pub fn visibility<'a>(&'a self, model: &'a Model) -> CrackVisibility<'a> {
        CrackVisibility { segments: &self.segments, x0: &model.particles.x0, face_side: &model.particles.face_side }
    }

    /// Per-particle criterion value: the lumped projection of the
    /// quadrature field (module doc of [`crate::fracture`]).
    pub fn criterion_value(&self, model: &Model, i: usize) -> Real {
        let col = match self.params.criterion {
            Criterion::EffectiveStrain => &model.quad.eps_p,
            Criterion::Damage => &model.quad.damage,
            Criterion::NonlocalDamage => return self.nonlocal_damage(model, i),
            Criterion::None => return 0.0,
        };
        model.project_at(i, |q| col[q])
    }

    /// Johnson–Cook damage of particle `i` averaged over the material
    /// length `nonlocal_radius` ([`super::nonlocal`]): the points of its
    /// body within `ℓ` whose sight line to `X_i` crosses no crack.
    pub fn nonlocal_damage(&self, model: &Model, i: usize) -> Real {
        super::nonlocal::mean(self.over_length(model, i, |k| model.quad.damage[k]))
    }

    /// `(Σ α A f, Σ α A)` of `f` over the ball of [`Self::nonlocal_damage`]
    /// around particle `i`: the points of its body within `ℓ` whose sight
    /// line to `X_i` crosses no crack, with the bell weight `α` and the
    /// reference area `A` of each.
    fn over_length<T>(&self, model: &Model, i: usize, f: impl Fn(usize) -> T) -> (T, Real)
    where
        T: Default + std::ops::AddAssign + std::ops::Mul<Real, Output = T>,
    {
        self.over_length_seen_from(model, i, &model.particles.x0[i], f)
    }

    /// [`Self::over_length`] with the sight lines drawn from `eye` (near
    /// `X_i`) instead of from `X_i`: a tip particle lies on its crack's
    /// line and sees one face only; from a point just ahead of it the
    /// ball takes both.
    fn over_length_seen_from<T>(&self, model: &Model, i: usize, eye: &Vec2, f: impl Fn(usize) -> T) -> (T, Real)
    where
        T: Default + std::ops::AddAssign + std::ops::Mul<Real, Output = T>,
    {
        let q = &model.quad;
        let av = self.nonlocal_average(model);
        let (xi, body) = (model.particles.x0[i], model.particles.body[i]);
        let area = |k: usize| q.weight[k] / model.mode.volume_factor(&q.x0[k]);
        av.sums(&xi, &q.x0, area, f, |k| q.body[k] == body && !self.segments.blocked(eye, &q.x0[k]))
    }

    /// The quadrature points binned for the averages over `ℓ` (built on
    /// first use: the points do not move in the reference configuration).
    fn nonlocal_average(&self, model: &Model) -> &NonlocalAverage {
        self.nonlocal.get_or_init(|| {
            NonlocalAverage::new(&model.quad.x0, self.params.nonlocal_radius, self.params.nonlocal_weight)
        })
    }

    /// Whether particle `i`'s criterion value may reach `critical`: false
    /// only where it cannot. With `"nonlocal_damage"`, `maxima` holds the
    /// largest damage of each cell of the average's points
    /// ([`NonlocalAverage::cell_maxima`]), and a particle whose ball
    /// reaches no point as damaged as `critical` cannot average to it
    /// ([`NonlocalAverage::upper_bound`]; the margin covers the average's
    /// round-off). This spares the ball sums of the nucleation scan, which
    /// visits every surface particle each stage, where nothing near has
    /// failed; the particles it keeps and the values they get are the
    /// same (`no_average_exceeds_its_cell_bound`).
    fn may_reach(&self, model: &Model, i: usize, critical: Real, maxima: Option<&[Real]>) -> bool {
        maxima.is_none_or(|m| {
            self.nonlocal_average(model).upper_bound(&model.particles.x0[i], m) >= critical * (1.0 - BOUND_MARGIN)
        })
    }

    /// The weighted sum of `f` over the quadrature points that a crack
    /// tip's gate reads at candidate `i`, and the sum of the weights: over
    /// `ℓ` with the weights of [`Self::nonlocal_damage`] with
    /// `nonlocal_tip_triaxiality`, else the particle's own
    /// ([`lumped_sum`]). The gates read only ratios and signs of the sum;
    /// the weight turns it into a mean for [`Self::tip_candidates`].
    fn tip_reading<T>(&self, model: &Model, i: usize, f: impl Fn(usize) -> T) -> (T, Real)
    where
        T: Default + std::ops::AddAssign + std::ops::Mul<Real, Output = T>,
    {
        if self.params.nonlocal_tip_triaxiality {
            self.over_length(model, i, f)
        } else {
            lumped_sum(model, i, f)
        }
    }

    /// The triaxiality that gates a crack tip's step into candidate `i`
    /// (`tip_min_triaxiality`): the ratio of the mean and von Mises
    /// stresses read by [`Self::tip_reading`], the particle's own
    /// ([`Self::triaxiality`]) or averaged over `ℓ` (module doc of
    /// [`crate::fracture`], "The compression gate on the tip").
    fn tip_triaxiality(&self, model: &Model, i: usize) -> Real {
        triaxiality_of(self.tip_reading(model, i, |k| mean_and_von_mises(&model.quad.tau[k])).0)
    }

    /// The tip's gate at candidate `i` ([`TipGate`]): what it reads and
    /// whether it opens. Its triaxiality ([`Self::tip_triaxiality`]) at
    /// least `tip_min_triaxiality`, or with `tip_gate = "tension"` a
    /// tensile largest principal value of the Kirchhoff stress read by
    /// [`Self::tip_reading`], reported as the weighted mean, Pa (a
    /// positive weighting does not change the sign of `σ₁` in a uniform
    /// state, `the_tension_gate_reads_the_largest_principal_stress`; the
    /// sign is taken of the sum, before the division).
    fn tip_gate(&self, model: &Model, i: usize) -> (Real, bool) {
        match self.params.tip_gate {
            TipGate::Triaxiality => {
                let t = self.tip_triaxiality(model, i);
                (t, t >= self.params.tip_min_triaxiality)
            }
            TipGate::Tension => {
                let (sum, weight) = self.tip_reading(model, i, |k| model.quad.tau[k].to_tensor());
                let s1 = largest_principal(&sum);
                (if weight > 0.0 { s1 / weight } else { 0.0 }, s1 > 0.0)
            }
        }
    }

    /// The value that ranks the candidates meeting the criterion, given
    /// particle `i`'s criterion value `value`: the value itself, except
    /// with `"nonlocal_damage"`, where it is the particle's own damage
    /// (lumped projection): the average decides *whether* the band has
    /// failed, the band's centre line — its most damaged particles —
    /// *where* the crack runs (module doc of [`crate::fracture`]).
    fn path_value(&self, model: &Model, i: usize, value: Real) -> Real {
        if self.params.criterion != Criterion::NonlocalDamage {
            return value;
        }
        model.project_at(i, |q| model.quad.damage[q])
    }

    /// The direction a tip at particle `i` heads for in the reference
    /// configuration, given the crack's (or, at nucleation, the inward)
    /// direction `reference`: with `tip_direction = "max_shear"` the slip
    /// line through the particle ([`max_shear_direction`] of the lumped
    /// Kirchhoff stress and deformation gradient), with `"velocity_jump"`
    /// the band across which the velocity jumps
    /// ([`velocity_jump_direction`] of `Ḟ = Σ_J v_J ⊗ ∇N_J` summed over
    /// the ball of [`Self::nonlocal_damage`]: over the material length,
    /// not the particle's own, which zigzags at 96 rows), aimed at the
    /// band's centre line one `ℓ` ahead ([`band_aim`]; the centre line
    /// through the centroid of the sliding rate over the ball);
    /// `None` with `"most_damaged"` or where the field prefers no direction
    /// (module doc of [`crate::fracture`], "The tip's direction").
    fn heading(&self, model: &Model, i: usize, reference: &Vec2) -> Option<Vec2> {
        let q = &model.quad;
        match self.params.tip_direction {
            TipDirection::MostDamaged => None,
            TipDirection::MaxShear => {
                let tau = model.project_at(i, |k| in_plane_matrix(&q.tau[k]));
                let f = model.project_at(i, |k| in_plane_matrix(&q.f[k]));
                max_shear_direction(&tau, &f, reference)
            }
            TipDirection::VelocityJump => {
                let v = &model.particles.v;
                let fdot = |k: usize| model.qp_shape.gradient_pair(k, v, v).0;
                let xi = model.particles.x0[i];
                let eye = xi + reference.normalize() * (EYE_AHEAD * self.params.nonlocal_radius);
                let (sum, _) = self.over_length_seen_from(model, i, &eye, fdot);
                let along = velocity_jump_direction(&sum, reference)?;
                // where across the ball the band lies: the centroid of
                // the sliding rate on the band's plane
                let normal = left_normal(&along);
                // (Σ α A s d, Σ α A s) of the sliding rate s at signed distance d
                let (moments, _) = self.over_length_seen_from(model, i, &eye, |k| {
                    let rate = (along.transpose() * fdot(k) * normal)[0].abs();
                    Vec2::new(rate * (q.x0[k] - xi).dot(&normal), rate)
                });
                let offset = if moments.y > 0.0 { moments.x / moments.y } else { 0.0 };
                Some(band_aim(&along, offset, self.params.nonlocal_radius))
            }
        }
    }

    /// How a candidate `j` at `r` from the tip ranks (larger first): its
    /// [`Self::path_value`], or with a heading ([`Self::heading`]) its
    /// closeness in angle to it.
    fn rank(&self, model: &Model, j: usize, value: Real, r: &Vec2, heading: Option<&Vec2>) -> Real {
        match heading {
            Some(n) => -angle(r, n),
            None => self.path_value(model, j, value),
        }
    }

    /// Smallest radius at which a crack may nucleate, m: in axisymmetry
    /// with `"nonlocal_damage"`, the averaging length `ℓ` — a ring crack
    /// nearer the axis is a core thinner than the ball its criterion
    /// averages over (the axis truncates the ball there), held by the axis
    /// particles, whose masses shrink as `h³` (module doc of
    /// [`crate::fracture`]); otherwise no limit (`−∞`: the per-particle
    /// criteria keep \[RL10\]'s behaviour, and plane strain has no axis).
    fn smallest_ring_radius(&self, model: &Model) -> Real {
        if model.mode == GeometryMode::Axisymmetric && self.params.criterion == Criterion::NonlocalDamage {
            self.params.nonlocal_radius
        } else {
            Real::NEG_INFINITY
        }
    }

    /// Stress triaxiality `σ_m / σ_eq` at particle `i`: the ratio of the
    /// lumped projections of the quadrature points' mean and von Mises
    /// stresses (the same weights as [`Self::criterion_value`]).
    pub fn triaxiality(&self, model: &Model, i: usize) -> Real {
        triaxiality_of(lumped_sum(model, i, |q| mean_and_von_mises(&model.quad.tau[q])).0)
    }

    /// How far along its locus the material was where the cracks grew:
    /// the own damage ([`CrackEvent::damage`]) of the particles that
    /// nucleation and propagation made tips, `None` before any.
    pub fn tip_damage(&self) -> Option<TipValues> {
        self.tip_values(|e| e.damage)
    }

    /// Whether the material had localized where the cracks grew: the
    /// adiabatic hardening ([`CrackEvent::hardening`]) of the particles
    /// that nucleation and propagation made tips, `None` before any (or in
    /// an elastic body).
    pub fn tip_hardening(&self) -> Option<TipValues> {
        self.tip_values(|e| e.hardening)
    }

    fn tip_values(&self, value: impl Fn(&CrackEvent) -> Real) -> Option<TipValues> {
        let v: Vec<Real> = self.events.iter().filter(|e| e.kind.grows()).map(value).filter(|v| v.is_finite()).collect();
        TipValues::of(v)
    }

    /// Time of plug separation: when the through-cracks that cut a plug
    /// out have all arrested — two in plane strain (one on each side of
    /// the projectile), one in axisymmetry (a ring crack).
    pub fn separation_time(&self, mode: GeometryMode) -> Option<Real> {
        let needed = match mode {
            GeometryMode::PlaneStrain => 2,
            GeometryMode::Axisymmetric => 1,
        };
        let mut t: Vec<Real> = self.cracks.iter().filter_map(|c| c.arrested.map(|a| a.0)).collect();
        t.sort_by(|a, b| a.partial_cmp(b).expect("finite times"));
        t.get(needed - 1).copied()
    }

    /// One crack-growth stage at time `time` (after step `step`): each
    /// growing crack arrests or advances by at most one particle, then new
    /// cracks nucleate. Returns the new crack-face particles (for the
    /// contact slave set).
    pub fn grow(&mut self, model: &mut Model, time: Real, step: u64) -> Result<Vec<usize>, FractureError> {
        let Some(critical) = self.params.critical_value() else {
            return Ok(Vec::new());
        };
        let dt = self.last_time.map_or(0.0, |t| time - t);
        self.last_time = Some(time);
        let mut faces = Vec::new();
        for c in 0..self.cracks.len() {
            let Some(tip) = self.cracks[c].tip else {
                continue;
            };
            self.ensure_grid(model);
            let fan = self.fan(model, c);
            let circle = self.circle(model, tip);
            if self.at_surface(model, &fan, &circle) {
                faces.extend(self.arrest(model, c, time, step)?);
                continue;
            }
            // (rank, criterion value, particle)
            let mut best: Option<(Real, Real, usize)> = None;
            for &j in &circle {
                let Ok((rank, value)) = self.ranked(model, &fan, j) else {
                    continue;
                };
                if value < critical || best.is_some_and(|(bv, _, _)| bv >= rank) {
                    continue;
                }
                if self.admits(model, c, &fan, j).1 == CandidateCheck::Eligible {
                    best = Some((rank, value, j));
                }
            }
            if best.is_none() {
                if let Some(junction) = self.junction(model, c, critical, &circle, (fan.d, fan.mean)) {
                    faces.extend(self.join(model, c, junction, time, step)?);
                    continue;
                }
            }
            if !self.tip_may_advance(model, c, best.map(|(_, _, j)| j), dt) {
                continue;
            }
            if let Some((_, value, j)) = best {
                faces.extend(self.propagate(model, c, j, value, time, step)?);
            }
        }
        faces.extend(self.nucleate(model, critical, time, step)?);
        Ok(faces)
    }

    /// The fan of the growing tip of crack `c`: where it stands, where it
    /// came from and where it heads ([`Self::heading`]).
    fn fan(&self, model: &Model, c: usize) -> TipFan {
        let tip = self.cracks[c].tip.expect("growing");
        let d = self.cracks[c].direction();
        let xt = model.particles.x0[tip];
        TipFan {
            tip,
            xt,
            d,
            mean: (xt - self.cracks[c].vertices[0].x0).normalize(),
            half_fan: 0.5 * self.params.fan_angle.to_radians(),
            heading: self.heading(model, tip, &d),
        }
    }

    /// Whether the tip stands on the outer surface facing its own
    /// direction: its `circle` leaves an empty sector wider than `θ_c`
    /// that holds the crack's direction (the crack arrests).
    fn at_surface(&self, model: &Model, fan: &TipFan, circle: &[usize]) -> bool {
        let dirs: Vec<Vec2> = circle.iter().map(|&j| model.particles.x0[j] - fan.xt).collect();
        let sector = widest_empty_sector(&dirs);
        sector.0 > self.params.fan_angle.to_radians() && sector_contains(sector, &fan.d)
    }

    /// Candidate `j`'s `(rank, criterion value)` for the tip of `fan`
    /// ([`Self::rank`]), or why it is none: a crack face or detached
    /// particle, or outside the fan. The first checks of [`Self::grow`].
    fn ranked(&self, model: &Model, fan: &TipFan, j: usize) -> Result<(Real, Real), CandidateCheck> {
        if model.particles.flags[j].has(ParticleFlags::CRACK_FACE | ParticleFlags::DETACHED) {
            return Err(CandidateCheck::Taken);
        }
        let r = model.particles.x0[j] - fan.xt;
        if !in_fans(&r, &fan.d, &fan.mean, fan.half_fan) {
            return Err(CandidateCheck::OutsideFan);
        }
        let value = self.criterion_value(model, j);
        Ok((self.rank(model, j, value, &r, fan.heading.as_ref()), value))
    }

    /// The checks of [`Self::grow`] on candidate `j` of crack `c` after
    /// its criterion: the tip's gate ([`Self::tip_gate`]; its reading is
    /// returned), a path over another particle, a crack in the way, a
    /// surface met too obliquely.
    fn admits(&self, model: &Model, c: usize, fan: &TipFan, j: usize) -> (Real, CandidateCheck) {
        let (reading, open) = self.tip_gate(model, j);
        let check = if !open {
            CandidateCheck::GateClosed
        } else if self.passes_over(model, fan.tip, j) {
            CandidateCheck::PassesOver
        } else if self.blocked_from_tip(model, c, j) {
            CandidateCheck::Blocked
        } else if self
            .outward_normal(model, j)
            .is_some_and(|n| angle(&(model.particles.x0[j] - fan.xt), &n) > MAX_SURFACE_OBLIQUITY.to_radians())
        {
            CandidateCheck::Oblique
        } else {
            CandidateCheck::Eligible
        };
        (reading, check)
    }

    /// Every particle within reach of the tip of crack `c` and what
    /// [`Self::grow`] would make of it now: the diagnosis of a stalled
    /// tip (`plugsim crack-tips`), and where it heads; no candidates if
    /// `c` no longer grows. The candidate the tip would step to is the
    /// [`CandidateCheck::Eligible`] one of largest rank (unless the tip
    /// stands on the surface, or the crack-speed limit holds it back).
    pub fn tip_candidates(&mut self, model: &Model, c: usize) -> TipReport {
        let Some(tip) = self.cracks.get(c).and_then(|k| k.tip) else {
            return TipReport { heading: None, candidates: Vec::new() };
        };
        let critical = self.params.critical_value().unwrap_or(Real::INFINITY);
        self.ensure_grid(model);
        let fan = self.fan(model, c);
        let circle = self.circle(model, tip);
        let candidates = circle
            .iter()
            .map(|&j| {
                let offset = model.particles.x0[j] - fan.xt;
                let (rank, value, gate, check) = match self.ranked(model, &fan, j) {
                    // what the tip would find there, were the fan wider
                    Err(CandidateCheck::OutsideFan) => (
                        Real::NAN,
                        self.criterion_value(model, j),
                        self.tip_gate(model, j).0,
                        CandidateCheck::OutsideFan,
                    ),
                    Err(check) => (Real::NAN, Real::NAN, Real::NAN, check),
                    Ok((rank, value)) => {
                        let (gate, check) = self.admits(model, c, &fan, j);
                        let check = if value < critical { CandidateCheck::BelowCriterion } else { check };
                        (rank, value, gate, check)
                    }
                };
                TipCandidate { particle: j, offset, value, rank, gate, check }
            })
            .collect();
        TipReport { heading: fan.heading, candidates }
    }

    /// The speed limit's hook ([`super::tip_speed`]): whether the tip of
    /// crack `c` may advance to `candidate` in a stage `dt` after the last,
    /// updating its allowance. Always true without a limit.
    fn tip_may_advance(&mut self, model: &Model, c: usize, candidate: Option<usize>, dt: Real) -> bool {
        let tip = self.cracks[c].tip.expect("growing");
        let m = &model.materials[model.particles.body[tip] as usize];
        let Some(speed) = self.params.max_tip_speed(m.shear_modulus(), m.bulk_modulus(), m.density()) else {
            return true;
        };
        let x = &model.particles.x0;
        let distance = candidate.map(|j| (x[j] - x[tip]).norm());
        let (go, allowance) = tip_speed::advance(self.cracks[c].allowance, speed, dt, distance);
        self.cracks[c].allowance = allowance;
        go
    }

    /// Insert a crack along the particles `path` (first: a surface
    /// particle; then each next tip) regardless of the criterion, arresting
    /// it at the end if `arrest` (the last particle on the far surface).
    /// For pre-cracked specimens and tests. Returns the crack id and the
    /// new crack-face particles.
    pub fn insert_crack(
        &mut self,
        model: &mut Model,
        path: &[usize],
        arrest: bool,
    ) -> Result<(usize, Vec<usize>), FractureError> {
        if path.len() < 2 {
            return Err(FractureError::InvalidPath("needs at least two particles".into()));
        }
        let n = model.particles.len();
        if let Some(&bad) = path.iter().find(|&&i| i >= n) {
            return Err(FractureError::InvalidPath(format!("particle {bad} does not exist ({n} particles)")));
        }
        if path.iter().any(|&i| model.particles.flags[i].has(ParticleFlags::CRACK_FACE)) {
            return Err(FractureError::InvalidPath("a particle of the path is already on a crack face".into()));
        }
        let c = self.cracks.len();
        let mut faces = self.start_crack(model, path[0], path[1], Real::NAN, 0.0, 0)?;
        for &j in &path[2..] {
            faces.extend(self.propagate(model, c, j, Real::NAN, 0.0, 0)?);
        }
        if arrest {
            faces.extend(self.arrest(model, c, 0.0, 0)?);
        }
        Ok((c, faces))
    }

    fn ensure_grid(&mut self, model: &Model) {
        if self.grid.is_none() {
            let p = &model.particles;
            let reach = p.spacing.iter().cloned().fold(0.0, Real::max) * self.params.radius_factor;
            self.grid = Some(CellGrid::new(&p.x0, reach.max(Real::MIN_POSITIVE)));
        }
    }

    /// Particles of `i`'s body within `R_i` of `X_i` (excluding `i`), ascending.
    fn circle(&self, model: &Model, i: usize) -> Vec<usize> {
        let p = &model.particles;
        let r = self.params.radius_factor * p.spacing[i];
        let mut out = Vec::new();
        self.grid.as_ref().expect("grid built").for_each_candidate(&p.x0[i], r, |j| {
            if j != i && p.body[j] == p.body[i] && (p.x0[j] - p.x0[i]).norm() <= r {
                out.push(j);
            }
        });
        out.sort_unstable();
        out
    }

    /// Outward normal of the outer surface at particle `i` (the bisector of
    /// the empty sector wider than `θ_c` in its circle), if it is on one.
    fn outward_normal(&self, model: &Model, i: usize) -> Option<Vec2> {
        let xi = model.particles.x0[i];
        let dirs: Vec<Vec2> = self.circle(model, i).iter().map(|&j| model.particles.x0[j] - xi).collect();
        let (width, start) = widest_empty_sector(&dirs);
        (width > self.params.fan_angle.to_radians()).then(|| {
            let a = start + 0.5 * width;
            Vec2::new(a.cos(), a.sin())
        })
    }

    /// Whether segment `X_i X_j` passes over a third particle.
    fn passes_over(&self, model: &Model, i: usize, j: usize) -> bool {
        let p = &model.particles;
        let (a, b) = (p.x0[i], p.x0[j]);
        let reach = (b - a).norm() + p.spacing[i];
        let mut hit = false;
        self.grid.as_ref().expect("grid built").for_each_candidate(&a, reach.min(self.grid_cell(model)), |k| {
            if k != i && k != j && point_segment_distance(&a, &b, &p.x0[k]) < PASS_OVER_FRACTION * p.spacing[k] {
                hit = true;
            }
        });
        hit
    }

    fn grid_cell(&self, model: &Model) -> Real {
        model.particles.spacing.iter().cloned().fold(0.0, Real::max) * self.params.radius_factor
    }

    /// Whether another crack's segment (or an earlier segment of this one)
    /// lies between the tip of crack `c` and particle `j`.
    fn blocked_from_tip(&self, model: &Model, c: usize, j: usize) -> bool {
        let tip = self.cracks[c].tip.expect("growing");
        let (xt, xj) = (model.particles.x0[tip], model.particles.x0[j]);
        // The crack's own last segment ends at the tip: start the sight
        // line a hair ahead of it.
        let start = xt + (xj - xt) * 1e-6;
        self.segments.blocked(&start, &xj)
    }

    fn nucleate(
        &mut self,
        model: &mut Model,
        critical: Real,
        time: Real,
        step: u64,
    ) -> Result<Vec<usize>, FractureError> {
        // In parallel (the scan visits every surface particle each step);
        // the collected order is the index order either way.
        let min_radius = self.smallest_ring_radius(model);
        let maxima = (self.params.criterion == Criterion::NonlocalDamage)
            .then(|| self.nonlocal_average(model).cell_maxima(|k| model.quad.damage[k]));
        let mut cores: Vec<(Real, usize)> = (0..model.particles.len())
            .into_par_iter()
            .filter(|&i| {
                let f = model.particles.flags[i];
                // The axis is a boundary of the r-z section but no surface
                // of the body: no crack starts there.
                f.has(ParticleFlags::SLAVE)
                    && !f.has(ParticleFlags::CRACK_FACE | ParticleFlags::DETACHED)
                    && !f.has(ParticleFlags::ON_AXIS)
                    && model.particles.x0[i].x >= min_radius
                    && self.may_reach(model, i, critical, maxima.as_deref())
            })
            .map(|i| (self.criterion_value(model, i), i))
            .filter(|&(v, i)| v >= critical && self.triaxiality(model, i) >= NUCLEATION_MIN_TRIAXIALITY)
            .collect();
        if cores.is_empty() {
            return Ok(Vec::new());
        }
        cores.sort_by(|a, b| b.0.partial_cmp(&a.0).expect("finite").then(a.1.cmp(&b.1)));
        let mut faces = Vec::new();
        let mut zones = FailedZones::new(model.particles.len());
        for (_, i) in cores {
            // the core may have been re-indexed by nothing (splits append), but
            // a split in this loop may have put it on a face
            if model.particles.flags[i].has(ParticleFlags::CRACK_FACE) {
                continue;
            }
            let xi = model.particles.x0[i];
            let exclusion = self.params.nucleation_distance_factor * model.particles.spacing[i];
            let near = self
                .cracks
                .iter()
                .any(|c| c.vertices.windows(2).any(|w| point_segment_distance(&w[0].x0, &w[1].x0, &xi) < exclusion));
            if near {
                continue;
            }
            self.ensure_grid(model);
            if self.failed_zone_holds_a_crack(model, i, critical, &mut zones) {
                continue;
            }
            let inward = self.outward_normal(model, i).map(|n| -n);
            let heading = inward.and_then(|n| self.heading(model, i, &n));
            // (rank, criterion value, particle)
            let mut best: Option<(Real, Real, usize)> = None;
            for j in self.circle(model, i) {
                let f = model.particles.flags[j];
                if f.has(ParticleFlags::CRACK_FACE) || f.has(ParticleFlags::SLAVE) || f.has(ParticleFlags::SURFACE) {
                    continue;
                }
                let value = self.criterion_value(model, j);
                let rank = self.rank(model, j, value, &(model.particles.x0[j] - xi), heading.as_ref());
                if value < critical || best.is_some_and(|(bv, _, _)| bv >= rank) {
                    continue;
                }
                if self.triaxiality(model, j) < NUCLEATION_MIN_TRIAXIALITY {
                    continue;
                }
                if self.passes_over(model, i, j) || self.segments.blocked(&xi, &model.particles.x0[j]) {
                    continue;
                }
                let oblique = MAX_SURFACE_OBLIQUITY.to_radians();
                if inward.is_some_and(|n| angle(&(model.particles.x0[j] - xi), &n) > oblique) {
                    continue;
                }
                best = Some((rank, value, j));
            }
            if let Some((_, value, j)) = best {
                faces.extend(self.start_crack(model, i, j, value, time, step)?);
            }
        }
        Ok(faces)
    }

    /// Whether the failed zone of particle `i` — the particles meeting the
    /// criterion connected to `i` through circles of radius `R` with
    /// unblocked sight lines — already holds a crack (a crack-face particle
    /// or a growing tip). One crack per failed zone (module doc).
    /// `zones` remembers the particles seen in this stage: a zone found
    /// cracked stays cracked, and an uncracked one is searched again (a
    /// split in this stage may have put a crack into it).
    fn failed_zone_holds_a_crack(&self, model: &Model, i: usize, critical: Real, zones: &mut FailedZones) -> bool {
        zones.grow(model.particles.len());
        if zones.cracked[i] {
            return true;
        }
        let tips: Vec<usize> = self.cracks.iter().filter_map(|c| c.tip).collect();
        let is_crack = |j: usize| model.particles.flags[j].has(ParticleFlags::CRACK_FACE) || tips.contains(&j);
        zones.stamp += 1;
        let stamp = zones.stamp;
        zones.seen[i] = stamp;
        let mut stack = vec![i];
        let mut visited = vec![i];
        let mut found = false;
        while let Some(k) = stack.pop() {
            let xk = model.particles.x0[k];
            for j in self.circle(model, k) {
                if zones.seen[j] == stamp || self.segments.blocked(&xk, &model.particles.x0[j]) {
                    continue;
                }
                if is_crack(j) || zones.cracked[j] {
                    found = true;
                    break;
                }
                let value = *zones.value[j].get_or_insert_with(|| self.criterion_value(model, j));
                if value >= critical {
                    zones.seen[j] = stamp;
                    stack.push(j);
                    visited.push(j);
                }
            }
            if found {
                break;
            }
        }
        if found {
            for k in visited {
                zones.cracked[k] = true;
            }
        }
        found
    }

    /// Nucleation: split core `i` in halves normal to `X_i X_j`; `j` is the tip.
    fn start_crack(
        &mut self,
        model: &mut Model,
        i: usize,
        j: usize,
        value: Real,
        time: Real,
        step: u64,
    ) -> Result<Vec<usize>, FractureError> {
        let (xi, xj) = (model.particles.x0[i], model.particles.x0[j]);
        let d = (xj - xi).normalize();
        let offset = self.params.offset_ratio * model.particles.spacing[i];
        let id = self.cracks.len();
        self.cracks.push(Crack {
            id,
            vertices: vec![CrackVertex { x0: xi, faces: None }, CrackVertex { x0: xj, faces: None }],
            tip: Some(j),
            offset,
            nucleated: (time, step),
            arrested: None,
            allowance: 0.0,
        });
        let split = Split { parent: i, vertex: xi, incoming: d, outgoing: d, reach: (xj - xi).norm(), offset };
        let event = logged_event(model, (time, step), id, EventKind::Nucleate, j, value);
        self.split_logged(model, 0, split, event)
    }

    /// Split `split.parent` for crack `event.crack`, give the crack's vertex
    /// `vertex` the two children as its faces, and log `event` with the
    /// children first in its particle list (left, right, then the new tip
    /// if any). Returns the children.
    fn split_logged(
        &mut self,
        model: &mut Model,
        vertex: usize,
        split: Split,
        mut event: CrackEvent,
    ) -> Result<Vec<usize>, FractureError> {
        let c = event.crack;
        let (l, r) = self.split(model, c, split)?;
        self.cracks[c].vertices[vertex].faces = Some((l as u32, r as u32));
        event.particles.splice(0..0, [l, r]);
        self.events.push(event);
        Ok(vec![l, r])
    }

    /// Propagation: split the tip of crack `c` by the sector angles, `j` is the new tip.
    fn propagate(
        &mut self,
        model: &mut Model,
        c: usize,
        j: usize,
        value: Real,
        time: Real,
        step: u64,
    ) -> Result<Vec<usize>, FractureError> {
        let tip = self.cracks[c].tip.expect("growing");
        let (xt, xj) = (model.particles.x0[tip], model.particles.x0[j]);
        let incoming = self.cracks[c].direction();
        let outgoing = (xj - xt).normalize();
        let n = self.cracks[c].vertices.len();
        let last_len = (xt - self.cracks[c].vertices[n - 2].x0).norm();
        self.cracks[c].vertices.push(CrackVertex { x0: xj, faces: None });
        self.cracks[c].tip = Some(j);
        let split = Split {
            parent: tip,
            vertex: xt,
            incoming,
            outgoing,
            reach: last_len.min((xj - xt).norm()),
            offset: self.cracks[c].offset,
        };
        let event = logged_event(model, (time, step), c, EventKind::Propagate, j, value);
        self.split_logged(model, n - 1, split, event)
    }

    /// Arrest: split the tip in halves, extend the path by δ, stop.
    fn arrest(&mut self, model: &mut Model, c: usize, time: Real, step: u64) -> Result<Vec<usize>, FractureError> {
        let tip = self.cracks[c].tip.expect("growing");
        let xt = model.particles.x0[tip];
        let d = self.cracks[c].direction();
        let n = self.cracks[c].vertices.len();
        let last_len = (xt - self.cracks[c].vertices[n - 2].x0).norm();
        self.end_crack(model, c, EventKind::Arrest, (time, step), (xt + d * self.cracks[c].offset, d, last_len))
    }

    /// End crack `c` at its tip (an arrest or a join): the path's last
    /// vertex at `end.0`, the tip split between the incoming direction and
    /// `end.1` with reach `end.2`, the crack stopped, the event logged.
    fn end_crack(
        &mut self,
        model: &mut Model,
        c: usize,
        kind: EventKind,
        (time, step): (Real, u64),
        (end, outgoing, reach): (Vec2, Vec2, Real),
    ) -> Result<Vec<usize>, FractureError> {
        let tip = self.cracks[c].tip.expect("growing");
        let value = self.criterion_value(model, tip);
        let event = logged_event(model, (time, step), c, kind, tip, value);
        let xt = model.particles.x0[tip];
        let incoming = self.cracks[c].direction();
        let n = self.cracks[c].vertices.len();
        let offset = self.cracks[c].offset;
        self.cracks[c].vertices.push(CrackVertex { x0: end, faces: None });
        self.cracks[c].tip = None;
        self.cracks[c].arrested = Some((time, step));
        let split = Split { parent: tip, vertex: xt, incoming, outgoing, reach, offset };
        self.split_logged(model, n - 1, split, event)
    }

    /// Coalescence (a deviation from \[RL10\], issue #19): where the tip of
    /// crack `c`, with no candidate ahead, ends on another crack — the
    /// nearest point of another crack's path (its vertices, not the
    /// extensions) within the tip's circle `R` and inside both fans — if
    /// no intact material lies between them (no particle of the circle
    /// that is no crack face and is seen from the tip lies nearer that
    /// point than the tip: such a ligament only the criterion may cut)
    /// and the tip itself meets the criterion `critical`. The compression
    /// gate (`tip_min_triaxiality`) is not asked again: it decides where a
    /// tip may step, and a join steps into no material — the tip passed
    /// the gate when the crack stepped into it, as a propagation splits
    /// the tip it leaves without asking. \[RL10\]'s rules know the outer
    /// surface only: a tip that reaches another crack's face finds every
    /// particle ahead a face of that crack or behind it, so it neither
    /// advances nor arrests, and the ligament it leaves holds the plug,
    /// which is found between through-cracks only.
    /// Found on Case I's plate at 96 rows and 116.67 m/s: the ring crack
    /// from the corner stopped one spacing above a second crack from the
    /// bottom face while the plug moved away at 41 m/s (docs/validation.md,
    /// "The ladder"). The ligament, not the whole way ahead, is
    /// what must be cut: first built to join only where every particle
    /// ahead in the fans was a face or hidden, it left Case II's plate at
    /// 96 rows (an option's run, "The cut-off with the slip-line tip at 96
    /// rows") with two cracks passed side by side, one spacing apart: the
    /// crack from the back face stopped with its tip half a spacing below
    /// the other's path, its one way across that path cut by it, while
    /// intact material it could not enter lay beside (docs/validation.md,
    /// "Cracks that pass side by side"). The same rule carries to 3D as a
    /// crack front meeting another crack surface. `circle` is the tip's
    /// circle, `(d, mean)` its fans' directions, as `grow` found them.
    /// Tests: `a_tip_that_reaches_another_crack_joins_it`,
    /// `a_tip_beside_another_crack_joins_it_across_no_ligament`.
    fn junction(
        &self,
        model: &Model,
        c: usize,
        critical: Real,
        circle: &[usize],
        (d, mean): (Vec2, Vec2),
    ) -> Option<Vec2> {
        let tip = self.cracks[c].tip?;
        let p = &model.particles;
        let xt = p.x0[tip];
        if self.criterion_value(model, tip) < critical {
            return None;
        }
        let half_fan = 0.5 * self.params.fan_angle.to_radians();
        let in_fans = |r: &Vec2| in_fans(r, &d, &mean, half_fan);
        let reach = self.params.radius_factor * p.spacing[tip];
        let mut best: Option<(Real, Vec2)> = None;
        for (k, other) in self.cracks.iter().enumerate() {
            // the same body's cracks only (bodies overlap in the reference configuration)
            let body = other.vertices.iter().find_map(|v| v.faces).map(|(l, _)| p.body[l as usize]);
            if k == c || body != Some(p.body[tip]) {
                continue;
            }
            for w in other.vertices.windows(2) {
                let x = closest_point_on_segment(&w[0].x0, &w[1].x0, &xt);
                let r = x - xt;
                let dist = r.norm();
                if dist > reach || !in_fans(&r) {
                    continue;
                }
                if best.is_none_or(|(b, _)| dist < b) {
                    best = Some((dist, x));
                }
            }
        }
        let (dist, x) = best?;
        // A particle that is no crack face, is seen from the tip and lies
        // nearer the junction than the tip is intact material between
        // them, which the tip must cross by the criterion.
        let ligament = circle.iter().any(|&j| {
            (p.x0[j] - x).norm() < dist - LIGAMENT_TOLERANCE * p.spacing[tip]
                && !p.flags[j].has(ParticleFlags::CRACK_FACE)
                && !self.blocked_from_tip(model, c, j)
        });
        (!ligament).then_some(x)
    }

    /// Join: end crack `c` at `junction` on another crack — split the tip
    /// toward it (the last segment runs from the tip to the junction and is
    /// extended beyond it, across the other crack, like an arrest's past
    /// the surface) and stop.
    fn join(
        &mut self,
        model: &mut Model,
        c: usize,
        junction: Vec2,
        time: Real,
        step: u64,
    ) -> Result<Vec<usize>, FractureError> {
        let tip = self.cracks[c].tip.expect("growing");
        let xt = model.particles.x0[tip];
        let n = self.cracks[c].vertices.len();
        let last_len = (xt - self.cracks[c].vertices[n - 2].x0).norm();
        let to_junction = junction - xt;
        let end = (junction, to_junction.normalize(), last_len.min(to_junction.norm()));
        self.end_crack(model, c, EventKind::Join, (time, step), end)
    }

    /// Split a particle at a crack vertex and rebuild what the change
    /// touches. The crack's path must already hold its new vertices.
    fn split(&mut self, model: &mut Model, crack: usize, s: Split) -> Result<(usize, usize), FractureError> {
        let momentum = model.particles.momentum();
        let (phi_l, phi_r) = sector_angles(&s.incoming, &s.outgoing);
        let two_pi = 2.0 * std::f64::consts::PI;
        let (fl, fr) = (phi_l / two_pi, phi_r / two_pi);
        let b = left_bisector(&s.incoming, &s.outgoing);
        let p = &mut model.particles;
        let old_x = p.x0[s.parent];
        let l = s.parent;
        let r = p.split(l);
        let side = |left: bool| FaceSide {
            vertex: s.vertex,
            incoming: s.incoming,
            outgoing: s.outgoing,
            left,
            reach: s.reach,
        };
        for (k, f, sign, left) in [(l, fl, 1.0, true), (r, fr, -1.0, false)] {
            p.x0[k] = s.vertex + b * (sign * s.offset);
            p.volume[k] *= f;
            p.mass[k] *= f;
            p.added_mass[k] *= f;
            p.f_ext[k] *= f;
            p.a[k] = Vec2::zeros();
            p.flags[k].set(ParticleFlags::CRACK_FACE | ParticleFlags::SLAVE);
            p.face_side[k] = Some(side(left));
        }
        debug_assert!(left_normal(&s.incoming).dot(&b) > 0.0 || s.incoming != s.outgoing);
        self.refresh_segments(model);
        self.grid = None;
        // Region whose rows can change: the segments at the vertex (the new
        // one whole, up to its far end within R; the old one's extension)
        // and the old and new particle positions, grown by the largest
        // support in `rebuild_local` (a sight line lies inside the window
        // of the particle it ends at).
        let radius =
            self.params.radius_factor * model.particles.spacing[l] * 1.01 + 2.0 * EXTENSION_PER_OFFSET * s.offset;
        let mut lo = old_x.inf(&s.vertex);
        let mut hi = old_x.sup(&s.vertex);
        for (a, bb) in self.cracks[crack].segments() {
            for x in [a, bb] {
                if (x - s.vertex).norm() <= radius {
                    lo = lo.inf(&x);
                    hi = hi.sup(&x);
                }
            }
        }
        let body = model.particles.body[l];
        self.rebuild_local(model, body, lo, hi, momentum).map_err(|source| FractureError::Shape {
            crack,
            particle: l,
            source,
        })?;
        Ok((l, r))
    }

    /// Detach the particles that erosion has left without material
    /// (`detach_below`; module doc, "Detached particles"): each particle
    /// whose share of its material at points not eroded,
    /// `Σ_live |N_I| ρ w / Σ |N_I| ρ w`, is below `detach_below` is
    /// flagged [`ParticleFlags::DETACHED`] and the rows around it are
    /// rebuilt without it (`Self::rebuild_local`: the deformation
    /// gradients carried over, the masses re-lumped with its own kept, the
    /// momentum restored). A point whose particles are then all detached
    /// is eroded, and the rebuild empties its row. The share can fall in
    /// three ways, and each is looked at: points of the particle's gather
    /// eroded since the last call, a split's rebuild that changed its
    /// gather, or a detachment's in this call (so the rounds repeat until
    /// one detaches nothing). The particles
    /// detached at `time` (s), in the order found (index order in each
    /// round).
    pub fn detach_isolated(&mut self, model: &mut Model, time: Real) -> Result<Vec<usize>, FractureError> {
        let threshold = self.params.detach_below;
        if threshold <= 0.0 {
            self.gather_changed.clear();
            return Ok(Vec::new());
        }
        let mut all = Vec::new();
        loop {
            let isolated = self.detach_round(model, time, threshold)?;
            if isolated.is_empty() {
                return Ok(all);
            }
            all.extend(isolated);
        }
    }

    /// One round of [`Self::detach_isolated`]: the particles whose share
    /// fell under `threshold` since the last round, detached.
    fn detach_round(&mut self, model: &mut Model, time: Real, threshold: Real) -> Result<Vec<usize>, FractureError> {
        let eroded = &model.quad.eroded;
        self.eroded_seen.resize(eroded.len(), false);
        // The particles in the rows of the points eroded since the last
        // call, and those whose gather a rebuild changed.
        let mut near: std::collections::BTreeSet<usize> = self.gather_changed.drain(..).collect();
        for (q, (&e, seen)) in eroded.iter().zip(self.eroded_seen.iter_mut()).enumerate() {
            if e && !*seen {
                *seen = true;
                near.extend(model.qp_shape.range(q).map(|k| model.qp_shape.index[k] as usize));
            }
        }
        let isolated: Vec<usize> = near
            .into_iter()
            .filter(|&i| !model.particles.flags[i].has(ParticleFlags::DETACHED) && live_share(model, i) < threshold)
            .collect();
        // All flagged first: a rebuild re-lumps the particles it touches,
        // and one detached later must keep the mass it has now.
        for &i in &isolated {
            model.particles.flags[i].set(ParticleFlags::DETACHED);
        }
        // A point whose particles are all detached is the fragment's own
        // material and no body's any more: eroded (its row is emptied by
        // the rebuild).
        for &i in &isolated {
            for j in model.gather.range(i) {
                let q = model.gather.point[j] as usize;
                if !model.quad.eroded[q] && only_detached(&model.qp_shape, &model.particles.flags, q) {
                    model.quad.erode(q);
                    self.eroded_seen[q] = true;
                }
            }
        }
        for &i in &isolated {
            let momentum = model.particles.momentum();
            let (x, body) = (model.particles.x0[i], model.particles.body[i]);
            self.rebuild_local(model, body, x, x, momentum)
                .map_err(|source| FractureError::Detach { particle: i, source })?;
        }
        self.detached.extend(isolated.iter().map(|&i| (i, time)));
        Ok(isolated)
    }

    /// Rebuild the binned opaque segments from the cracks, in cells of the
    /// largest support of `model`.
    pub fn refresh_segments(&mut self, model: &Model) {
        let all: Vec<(Vec2, Vec2)> = self.cracks.iter().flat_map(|c| c.segments()).collect();
        let cell = model.particles.support.iter().cloned().fold(0.0, Real::max);
        self.segments = CrackSegments::new(all, cell);
    }

    /// Recompute the quadrature and particle rows of body `body` with
    /// evaluation points in the box `[lo, hi]` grown by the largest support,
    /// patch the gather where those rows changed ([`Gather::patch_into`]),
    /// re-lump the masses of the particles in the old or new rows, and
    /// restore the linear momentum `momentum` (module doc). The tables and
    /// the gather are rewritten into [`CrackGrowth::spare`] and swapped in.
    ///
    /// Only the cracked body's rows, built from its own particles: the
    /// shape functions of each body are its own (`Model::build`), and a
    /// crack in a plate must not reach into a body lying on it. Before
    /// this, the rows near a crack mouth under a deformable projectile
    /// took in the projectile's particles 0.05 mm above, and the plate's
    /// stress pushed the free-flying projectile (its momentum grew by 10
    /// m/s in 30 µs without a contact force) and the momentum restoration
    /// shifted both bodies' velocities (`crack_rows_stay_in_their_body`,
    /// tests/contact_deformable.rs).
    fn rebuild_local(
        &mut self,
        model: &mut Model,
        body: u32,
        lo: Vec2,
        hi: Vec2,
        momentum: Vec2,
    ) -> Result<(), crate::shape::ShapeError> {
        let grow = model.particles.support.iter().cloned().fold(0.0, Real::max) * (1.0 + 1e-9);
        let (lo, hi) = (lo - Vec2::repeat(grow), hi + Vec2::repeat(grow));
        let inside = |x: &Vec2| x.x >= lo.x && x.x <= hi.x && x.y >= lo.y && x.y <= hi.y;
        let n = model.particles.len();
        let rows_q: Vec<usize> =
            (0..model.quad.len()).filter(|&q| model.quad.body[q] == body && inside(&model.quad.x0[q])).collect();
        let ps = &mut model.particle_shape;
        while ps.rows() < n {
            let end = *ps.offsets.last().expect("offsets start at 0");
            ps.offsets.push(end);
        }
        let rows_p: Vec<usize> =
            (0..n).filter(|&i| model.particles.body[i] == body && inside(&model.particles.x0[i])).collect();
        // The RK deformation gradients before the change (module doc:
        // "deformation gradient across a crack change").
        let f_before: Vec<Tensor3> = rows_q.iter().map(|&q| model.shape_deformation_gradient(q)).collect();
        let p = &model.particles;
        let cracks = CrackVisibility { segments: &self.segments, x0: &p.x0, face_side: &p.face_side };
        let vis = OwnBody { cracks, body_of: &p.body, flags: &p.flags, body };
        let mut qp_shape = std::mem::take(&mut model.qp_shape);
        let mut particle_shape = std::mem::take(&mut model.particle_shape);
        let spare = &mut self.spare;
        let (qx, px) = (&model.quad.x0, &p.x0);
        // An eroded point whose particles are all detached belongs to no
        // body any more (`detach_isolated`): its row is empty.
        let emptied: Vec<usize> =
            rows_q.iter().copied().filter(|&q| model.quad.eroded[q] && only_detached(&qp_shape, &p.flags, q)).collect();
        // A point that no particle sees any more (the crack has cut it off
        // from every particle of its body) has no displacement field to
        // follow: it takes an empty row and is eroded, and the rebuilt
        // particles keep its mass (below; `shape::rk::rebuild_rows_setting_aside_orphans`).
        let empty = |q: usize| emptied.binary_search(&q).is_ok().then(Row::new);
        let r1 = crate::shape::rk::rebuild_rows_setting_aside_orphans(&rows_q, &empty, |given| {
            rebuild_rows(&mut qp_shape, &mut spare.qp_shape, &rows_q, qx, px, &p.support, &p.volume, &vis, given)
        });
        // A detached particle moves by its own displacement alone: its
        // row is itself, `N = 1`, `∇N = 0` (the rows of the others no
        // longer see it).
        let own = |i: usize| p.flags[i].has(ParticleFlags::DETACHED).then(|| vec![(i as u32, 1.0, Vec2::zeros())]);
        let r2 = rebuild_rows(
            &mut particle_shape,
            &mut spare.particle_shape,
            &rows_p,
            px,
            px,
            &p.support,
            &p.volume,
            &vis,
            &own,
        );
        model.qp_shape = qp_shape;
        model.particle_shape = particle_shape;
        let (r1, orphans) = r1?;
        for &q in &orphans {
            model.quad.erode(q);
        }
        for (rows, reduced, map) in
            [(&rows_q, r1, &mut self.reduced_quadrature_rows), (&rows_p, r2?, &mut self.reduced_particle_rows)]
        {
            for r in rows {
                map.remove(r);
            }
            map.extend(reduced);
        }
        for (&q, before) in rows_q.iter().zip(&f_before) {
            let after = model.shape_deformation_gradient(q);
            if after != *before {
                model.quad.add_f_carry(q, &(before - after));
            }
        }
        // The table before the rebuild is now the spare one (its row starts
        // place the old gather's entries).
        let spare = &mut self.spare;
        let touched = Gather::touched(&spare.qp_shape, &model.qp_shape, &rows_q, n);
        model.gather.patch_into(&spare.qp_shape.offsets, &model.qp_shape, &rows_q, &touched, n, &mut spare.gather);
        std::mem::swap(&mut model.gather, &mut spare.gather);
        let touched: Vec<usize> = (0..n).filter(|&i| touched[i]).collect();
        self.gather_changed.extend_from_slice(&touched);
        // Re-lumped: the material's mass; the mass scaling added
        // ([`crate::stability`]) stays on its particle.
        let before: Real = touched.iter().map(|&i| model.particles.mass[i] - model.particles.added_mass[i]).sum();
        // Held at their mass: particles at the floor, and detached ones,
        // which keep the material they had (no row holds them any more).
        let mut floored = Vec::new();
        for &i in &touched {
            if model.particles.flags[i].has(ParticleFlags::DETACHED) {
                floored.push(i);
                model.particles.mass[i] -= model.particles.added_mass[i];
                continue;
            }
            let m = model.lumped_mass(i);
            let floor = MASS_FLOOR * nodal_mass(model, i);
            if m < floor {
                floored.push(i);
            }
            model.particles.mass[i] = m.max(floor);
        }
        if !floored.is_empty() || !orphans.is_empty() {
            // Take the floor's extra mass from the other re-lumped particles,
            // in proportion to their masses, and give them an orphaned
            // point's: the total stays exact.
            let p = &mut model.particles;
            let after: Real = touched.iter().map(|&i| p.mass[i]).sum();
            let rest: Real = touched.iter().filter(|i| !floored.contains(i)).map(|&i| p.mass[i]).sum();
            let scale = 1.0 - (after - before) / rest;
            for &i in touched.iter().filter(|i| !floored.contains(i)) {
                p.mass[i] *= scale;
            }
        }
        for &i in &touched {
            model.particles.mass[i] += model.particles.added_mass[i];
        }
        // Momentum: one uniform shift of the re-lumped particles' free components.
        let p = &mut model.particles;
        let dp = momentum - p.momentum();
        for c in 0..2 {
            let fix = if c == 0 { ParticleFlags::FIX_X } else { ParticleFlags::FIX_Y };
            let free: Vec<usize> = touched.iter().cloned().filter(|&i| !p.flags[i].has(fix)).collect();
            let m: Real = free.iter().map(|&i| p.mass[i]).sum();
            if m > 0.0 {
                let shift = dp[c] / m;
                for &i in &free {
                    p.v[i][c] += shift;
                }
            }
        }
        Ok(())
    }
}

/// The crack visibility within one body: the particles of other bodies,
/// and detached ones ([`CrackGrowth::detach_isolated`]), are hidden
/// ([`CrackGrowth::rebuild_local`]).
struct OwnBody<'a> {
    cracks: CrackVisibility<'a>,
    body_of: &'a [u32],
    flags: &'a [ParticleFlags],
    body: u32,
}

impl crate::shape::Visibility for OwnBody<'_> {
    #[inline]
    fn visible(&self, x: &Vec2, particle: usize) -> bool {
        self.body_of[particle] == self.body
            && !self.flags[particle].has(ParticleFlags::DETACHED)
            && self.cracks.visible(x, particle)
    }
}

/// Whether every particle in row `q` of `table` is detached
/// ([`CrackGrowth::detach_isolated`]): the point is then a fragment's own
/// material, no body's.
fn only_detached(table: &ShapeTable, flags: &[ParticleFlags], q: usize) -> bool {
    table.range(q).all(|k| flags[table.index[k] as usize].has(ParticleFlags::DETACHED))
}

/// The share of particle `i`'s material at quadrature points that are
/// not eroded: `Σ_live |N_I(X_q)| ρ w_q / Σ_q |N_I(X_q)| ρ w_q` over its
/// gather (1 for a particle no point holds).
pub fn live_share(model: &Model, i: usize) -> Real {
    let (mut live, mut all) = (0.0, 0.0);
    for j in model.gather.range(i) {
        let q = model.gather.point[j] as usize;
        let rho = model.materials[model.quad.body[q] as usize].density();
        let m = rho * model.gather.value[j].abs() * model.quad.weight[q];
        all += m;
        if !model.quad.eroded[q] {
            live += m;
        }
    }
    if all > 0.0 {
        live / all
    } else {
        1.0
    }
}

/// `(Σ_q N_i(X_q) w_q f(q), Σ_q N_i(X_q) w_q)` over particle `i`'s
/// gather: the lumped projection's numerator, unnormalised (the gates
/// read its ratios and signs), and its weight, as
/// [`CrackGrowth::over_length`] returns them.
fn lumped_sum<T>(model: &Model, i: usize, f: impl Fn(usize) -> T) -> (T, Real)
where
    T: Default + std::ops::AddAssign + std::ops::Mul<Real, Output = T>,
{
    let (mut sum, mut weight) = (T::default(), 0.0);
    for j in model.gather.range(i) {
        let q = model.gather.point[j] as usize;
        let w = model.gather.value[j] * model.quad.weight[q];
        sum += f(q) * w;
        weight += w;
    }
    (sum, weight)
}

/// A stress's mean and von Mises values `(τ_m, τ̄)`, the two sums a
/// triaxiality is the ratio of.
fn mean_and_von_mises(tau: &Block2) -> Vec2 {
    Vec2::new(tau.trace() / 3.0, tau.von_mises())
}

/// Triaxiality `Σ w τ_m / Σ w τ̄` from the two weighted sums (0 where no
/// point carries shear).
fn triaxiality_of(sums: Vec2) -> Real {
    if sums.y > 0.0 {
        sums.x / sums.y
    } else {
        0.0
    }
}
