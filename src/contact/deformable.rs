//! Contact between deformable bodies, and between the faces of one body's
//! cracks (issue #20: SPEC §8's master/slave contact with deformable
//! masters).
//!
//! # Masters and slaves
//! - **Master surfaces** are polylines of particles: each body's outer
//!   boundary as generated ([`rectangle_boundary`]), and, once a body has
//!   cracks, both faces of each crack ([`DeformableMasters::set_crack_faces`]).
//!   A segment `[a, b]` has the body's material on its left (counter-clockwise
//!   around the material), so its outward normal is `(t_y, −t_x)` with
//!   `t = (x_b − x_a)/|x_b − x_a|`, the convention of the rigid outlines. In
//!   axisymmetry the edge on the axis is no surface and has no segments.
//! - **Slaves** are the same [`super::SlaveSet`] the rigid contact uses: every
//!   body's surface particles (detected per body, so that bodies that touch
//!   still see each other's surface) and the crack faces as cracks open.
//! - **Two passes**: every body is both master and slave, so neither body's
//!   particles can cross the other's surface (one pass lets the master's
//!   vertices through the slave's face). Where both passes constrain the same
//!   interface the joint Gauss–Seidel solve of
//!   [`super::ContactSystem::compute_forces`] shares the force between them.
//!
//! # Which points: physical
//! Positions are the physical points `x(X_I) = X_I + Σ_J N_J(X_I) U_J`
//! (SPEC §2: RK particles are not interpolating), of the slave and of the
//! segment's two end particles. The master point is
//! `x_m = (1 − λ) x(X_a) + λ x(X_b)`, the gap `g = (x(X_s) − x_m)·n`, and a
//! contact force `F` acts as the virtual work of a pair of point forces:
//! `+N_J(X_s) F` on the slave's row and `−((1 − λ) N_J(X_a) + λ N_J(X_b)) F`
//! on the masters'. The gap is a linear function of the generalized
//! displacements with the signed weights of that one row, so the force is
//! its gradient (variationally consistent), the one-step force and the
//! Coulomb cap are SPEC §8's with the effective mass of that row, and
//! `Σ_J f_J = F (Σ N(X_s) − (1 − λ) Σ N(X_a) − λ Σ N(X_b)) = 0` to the
//! round-off of the partition of unity: linear momentum is conserved
//! without a reaction to book. The same choice as the rigid contact's default
//! ([`super::Spreading::ShapeFunction`]); deformable masters use it whatever
//! `spreading` says, since the inverse-distance weights of [RL10, §3] have
//! no master-side counterpart. Test: `deformable_contact_measures_the_physical_points`
//! (tests/contact_deformable.rs).
//!
//! # Search (coarse to fine)
//! Per step: each segment's bounding box at the physical predicted
//! positions of its ends, grown by the largest slave spacing, is listed in
//! the cells of a uniform grid it covers; each slave takes the segments
//! listed in its own cell and keeps those onto which its predicted point
//! projects with `λ ∈ [0, 1]` and a gap in `(−h_s, 0)`.
//!
//! # Deviations and choices
//! - **Entry rule.** A pair counts only if the slave was outside the
//!   segment's line at the start of the step (`g⁰ ≥ −0.05 h_s`,
//!   [`ENTRY_TOLERANCE`]) or the pair carried a force in the last step
//!   (persistent contact). Contact is enforced every step, so a slave
//!   starts a step inside a master only by what the last step's solve
//!   left (below): a pair that starts deep inside is a face the slave is
//!   *behind*, not one it crossed: the left face's second particle of a
//!   fresh crack lies one spacing below the top surface segment on the
//!   crack's other side and projects onto it
//!   (`self_contact_ignores_faces_behind_the_slave`).
//!   Among the pairs left, the persistent one wins, then the face the slave
//!   was farthest outside of at the start (the entry face), then the
//!   shallower gap, then the lower segment index.
//! - **A penetration at the start of a step is held, not pushed out**
//!   (issue #19 item 5): the pair's force only keeps it from growing
//!   ([`super::force::gap_floor`], the `force` module doc's # Deviations),
//!   where SPEC §8's force threw the slave out at `|g⁰|/Δt`. Deformable
//!   slaves start inside more often than rigid ones: the candidates of a
//!   step come from the contact-free prediction, so a pair the other
//!   pairs' forces push together is only seen at the next step; the two
//!   passes cannot both hold exactly where two polylines cross
//!   (non-matching spacings, corners); and a slave behind a face by more
//!   than the entry tolerance that backs out enters it inside. Measured,
//!   `two-plates-axisymmetric` to 200 µs (rigid projectile through two
//!   plates): the front plate's plug slid along the back plate's crack
//!   face with its corner particles 0.04–0.07 h inside; each that backed
//!   into the tolerance was kicked out at ~800 m/s (10 J a kick) and the
//!   face particle it pushed flew back into the plug; from 106 µs the
//!   fastest particle climbed to 4514 m/s and the contact put 1.6 kJ into
//!   the run. Held, the contact dissipates 111 J, the residual velocity is
//!   273.75 m/s (264.37 before), and the fastest particle, 1000 m/s, is
//!   the front plate's axis particle pulled off the projectile's face by
//!   its internal force at 3 µs, before any slave starts a step inside.
//!   Test:
//!   `a_slave_starting_inside_a_deformable_master_is_not_thrown_out`.
//! - **Self-contact** (`contact.self_contact`, off by default:
//!   [`super::ContactParameters::self_contact`] says why). Within one
//!   body, only once it has cracks, and never
//!   between a slave and a segment with an end in the slave's own
//!   shape-function row: those particles are joined to it by material (the
//!   rows leave out particles across a crack, so the two faces of a crack
//!   do meet). Bodies without cracks have no self-contact (a folding outer
//!   surface is not handled).
//! - **Crack faces on the outer boundary.** When a crack splits a particle
//!   of the outer boundary, each boundary segment at it goes to the child
//!   whose shape-function row holds the segment's other end (the child on
//!   that side of the crack).
//! - **Corners.** The projection interval is closed and widened by a
//!   round-off allowance ([`LAMBDA_TOLERANCE`]), `λ` then clamped to
//!   [0, 1]: where two faces meet end to end (the mouth of a closing
//!   crack, whose last particles on both faces meet exactly), each end
//!   projects onto the other's segment at `λ = 1 + 10⁻¹⁶` or `−5·10⁻¹⁶`,
//!   and with `[0, 1]` alone both passed through each other
//!   (`crack_faces_pressed_together_do_not_cross`: 2·10⁻³ h of overlap at
//!   the mouth in one step). No vertex features: a slave outside every
//!   segment's interval is outside a convex corner; the other pass covers
//!   a master corner that reaches into a slave face.
//!   Limitation: two convex corners meeting exactly head on (the two
//!   particles at a crack's mouth, at the same height) can pass over each
//!   other by a hair, each just outside the other's surface, while the
//!   edges beside them cross: node-on-segment contact has no edge–edge
//!   test. In that test the faces overlapped by up to 1.05·10⁻³ h for one
//!   or two steps (a third of one step's closing motion) and were pushed
//!   apart in the next. Widening the interval further (accepting slaves up
//!   to 0.05 h, or up to their penetration, beyond a segment's end) closed
//!   it, but gave slaves beside a convex corner of a flat face pressed on
//!   another a sideways push: Coulomb's impulse ratio of
//!   `friction_between_deformable_bodies_obeys_coulomb` went from 0.2006
//!   to 0.233 and 1.17 at μ = 0.2.
//! - **Depth.** A penetration deeper than the slave's spacing is not a
//!   one-step penetration (the step moves particles by a fraction of a
//!   spacing): such pairs are ignored.
//!
//! # 3D and MPI
//! Nothing here is two-dimensional but the segment: in 3D the masters are
//! the generator's boundary triangles and the crack faces' triangles,
//! `λ` becomes the barycentric pair, and the rows, the entry rule, the
//! self-contact rule by shape-function rows and the two passes are
//! unchanged. Under MPI each rank searches its own slaves against the
//! master vertices it owns or holds as ghosts (the physical positions
//! need the ghosts' `U`, which the halo already carries); the pairs are
//! gathered in global slave order for the solve, as the rigid pairs
//! are (docs/design-3d.md §5, §7).

use serde::{Deserialize, Serialize};

use super::system::{predict_gap_point, row_compliance, Candidate, GapPoint, Master, StepInput};
use super::{ContactError, Spreading};
use crate::math::{Real, Vec2};
use crate::neighbors::{CellGrid, CellLayout};
use crate::particles::{ParticleFlags, Particles};
use crate::shape::ShapeTable;

/// A master segment: particles `[a, b]`, the body's material on the left of
/// `a → b`.
pub type Segment = [u32; 2];

/// A pair counts if the slave was at most this fraction of its spacing
/// inside the segment's line at the start of the step (module doc, entry
/// rule). The one-step force leaves a slave on the surface up to the
/// second-order error of freezing the normal over a step, far below this;
/// faces behind the slave lie a spacing away. A pair that starts inside
/// is held at its depth, not pushed out (module doc).
pub const ENTRY_TOLERANCE: Real = 0.05;

/// A slave projecting beyond a segment's end by at most this fraction of
/// the segment is measured against that end (module doc, corners): two
/// corners that meet exactly project onto each other's segments at
/// `λ = 1 + 10⁻¹⁶` and `−5·10⁻¹⁶` and would both be let through. Far
/// below any geometric scale, so nothing else changes.
pub const LAMBDA_TOLERANCE: Real = 1e-9;

/// Which deformable pairs are in contact (`[contact]` keys).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeformableSwitches {
    /// Contact between different deformable bodies.
    pub bodies: bool,
    /// Contact of a cracked body with itself.
    pub self_contact: bool,
}

/// The deformable master surfaces, their contact state and the search
/// scratch (module doc).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DeformableMasters {
    /// Each body's outer boundary as generated.
    outer: Vec<Segment>,
    /// Body of each particle of the outer boundary segments' ends, per
    /// segment (the body of `outer[k]`).
    outer_body: Vec<u32>,
    /// Number of deformable bodies.
    bodies: u32,
    /// Contact between different bodies on.
    between_bodies: bool,
    /// Self-contact of cracked bodies on.
    self_contact: bool,
    /// Crack faces, per crack: the left and right chains of particles in
    /// the crack's direction of growth (a growing tip closes both).
    faces: Vec<[Vec<u32>; 2]>,
    /// Bodies with crack faces, ascending.
    cracked: Vec<u32>,
    /// The master segments of the current step and each one's body.
    segments: Vec<Segment>,
    segment_body: Vec<u32>,
    /// Pairs that carried a force in the last step: (slave, a, b), ascending.
    persistent: Vec<(u32, u32, u32)>,
    /// Search structures, rebuilt from `segments` (not in checkpoints).
    #[serde(skip)]
    scratch: Scratch,
}

/// Derived from the segments, and per-step scratch.
#[derive(Clone, Debug, Default, PartialEq)]
struct Scratch {
    /// Whether `vertices` and `vertex_segments` describe `segments`.
    ready: bool,
    /// Particles at the segments' ends, ascending.
    vertices: Vec<u32>,
    /// Segments at vertex `k`: `list[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    list: Vec<u32>,
    /// Each vertex's physical point over the step.
    points: Vec<GapPoint>,
    /// Each segment's bounding box at its predicted position.
    boxes: Vec<(Vec2, Vec2)>,
    /// The segments by the cells their boxes cover.
    grid: SegmentGrid,
}

/// A uniform grid of square cells, each listing the segments whose bounding
/// boxes, grown by a reach, cover it: every point within the reach of a
/// segment finds it in its own cell (the coarse search; no loop over all
/// segments per slave). A [`CellGrid`] filled with boxes, ascending segment
/// indices in each cell; rebuilt every step into the same allocations.
#[derive(Clone, Debug, Default, PartialEq)]
struct SegmentGrid {
    cells: CellGrid,
}

impl SegmentGrid {
    /// Rebuild over `boxes` grown by `reach` (m, > 0), with cells of about
    /// `reach` (enlarged so that there are at most `4 n + 64` of them:
    /// [`CellLayout::capped_cell`]). False if a box is not finite.
    fn fill(&mut self, boxes: &[(Vec2, Vec2)], reach: Real) -> bool {
        let finite = |v: &Vec2| v.x.is_finite() && v.y.is_finite();
        if boxes.is_empty() || !(reach.is_finite() && reach > 0.0) || !boxes.iter().all(|(a, b)| finite(a) && finite(b))
        {
            return false;
        }
        let grow = Vec2::new(reach, reach);
        let (mut lo, mut hi) = boxes[0];
        for (a, b) in boxes {
            lo = lo.inf(a);
            hi = hi.sup(b);
        }
        lo -= grow;
        hi += grow;
        let layout = CellLayout::new(lo, hi, CellLayout::capped_cell(hi - lo, reach, boxes.len()));
        self.cells.fill(layout, boxes.len(), |k| {
            let (a, b) = &boxes[k];
            layout.cells_of_box(&(a - grow), &(b + grow))
        });
        true
    }

    /// The segments listed in the cell of `p` (none outside the grid).
    fn at(&self, p: &Vec2) -> &[u32] {
        self.cells.items_at(p)
    }
}

/// A deformable contact of the last step, for diagnostics and tests.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentContact {
    /// Slave particle.
    pub particle: u32,
    /// Master segment `[a, b]`.
    pub segment: Segment,
    /// Projection parameter on the segment, in [0, 1].
    pub lambda: Real,
    /// Predicted gap `g̃` (negative), m.
    pub gap: Real,
    /// Outward normal of the segment.
    pub normal: Vec2,
    /// Normal force magnitude, N.
    pub normal_force: Real,
    /// Tangential force along `(−n_y, n_x)`, N.
    pub tangential_force: Real,
    /// Whether friction is at the Coulomb cap.
    pub slipping: bool,
    /// Force on the slave point (the master point takes its negative), N.
    pub force: Vec2,
}

/// The outer boundary of a rectangular particle lattice (the particles
/// `range` of `x0`, whose extreme rows and columns are its edges), counter-
/// clockwise: the bottom edge by increasing x, the right edge by increasing
/// y, the top by decreasing x, the left by decreasing y. Segments between
/// two particles flagged [`ParticleFlags::ON_AXIS`] are left out (the axis
/// of axisymmetry is no surface).
pub fn rectangle_boundary(x0: &[Vec2], flags: &[ParticleFlags], range: std::ops::Range<usize>) -> Vec<Segment> {
    if range.is_empty() {
        return Vec::new();
    }
    let pts = &x0[range.clone()];
    let (mut lo, mut hi) = (pts[0], pts[0]);
    for p in pts {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let tol = 1e-9 * ((hi - lo).norm()).max(Real::MIN_POSITIVE);
    let on = |v: Real, edge: Real| (v - edge).abs() <= tol;
    let edge = |pick: &dyn Fn(&Vec2) -> bool, key: &dyn Fn(&Vec2) -> Real| {
        let mut e: Vec<usize> = range.clone().filter(|&i| pick(&x0[i])).collect();
        e.sort_by(|&i, &j| key(&x0[i]).total_cmp(&key(&x0[j])).then(i.cmp(&j)));
        e
    };
    let edges = [
        edge(&|p| on(p.y, lo.y), &|p| p.x),
        edge(&|p| on(p.x, hi.x), &|p| p.y),
        edge(&|p| on(p.y, hi.y), &|p| -p.x),
        edge(&|p| on(p.x, lo.x), &|p| -p.y),
    ];
    let axis = |i: usize| flags[i].has(ParticleFlags::ON_AXIS);
    let mut out = Vec::new();
    for e in &edges {
        for w in e.windows(2) {
            if w[0] != w[1] && !(axis(w[0]) && axis(w[1])) {
                out.push([w[0] as u32, w[1] as u32]);
            }
        }
    }
    out
}

/// Whether particle `j` is in row `s` of `table`.
#[inline]
fn in_row(table: &ShapeTable, s: usize, j: u32) -> bool {
    table.index[table.range(s)].contains(&j)
}

impl DeformableMasters {
    /// The masters of `bodies` deformable bodies with outer boundaries
    /// `outer` (segments with the body of each), with the switches of the
    /// case.
    pub fn new(outer: Vec<(Segment, u32)>, bodies: usize, switches: DeformableSwitches) -> Self {
        let (outer, outer_body) = outer.into_iter().unzip();
        let mut m = DeformableMasters {
            outer,
            outer_body,
            bodies: bodies as u32,
            between_bodies: switches.bodies,
            self_contact: switches.self_contact,
            ..Default::default()
        };
        m.rebuild(None);
        m
    }

    /// The masters of rectangular bodies as generated, body `b` being the
    /// particles `ranges[b]` of `particles` ([`rectangle_boundary`] of each).
    pub fn of_bodies(particles: &Particles, ranges: &[std::ops::Range<usize>], switches: DeformableSwitches) -> Self {
        let outer = ranges
            .iter()
            .enumerate()
            .flat_map(|(b, r)| {
                rectangle_boundary(&particles.x0, &particles.flags, r.clone()).into_iter().map(move |s| (s, b as u32))
            })
            .collect();
        Self::new(outer, ranges.len(), switches)
    }

    /// The master segments of the current step.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Bodies that hold crack faces, ascending.
    pub fn cracked_bodies(&self) -> &[u32] {
        &self.cracked
    }

    /// Contact between different bodies applies (on, and two bodies or more).
    fn multi_body(&self) -> bool {
        self.between_bodies && self.bodies > 1
    }

    /// Replace the crack faces with `faces` (per crack, the left and right
    /// chains of particles in the direction of growth), after a crack
    /// change: the segments are rebuilt, boundary segments at split
    /// particles given to the child on their side (module doc). `shape` is
    /// the particle shape table after the change, `body` each particle's
    /// body.
    pub fn set_crack_faces(&mut self, faces: Vec<[Vec<u32>; 2]>, shape: &ShapeTable, body: &[u32]) {
        self.faces = faces;
        let mut cracked: Vec<u32> =
            self.faces.iter().flat_map(|f| f[0].iter().chain(&f[1])).map(|&i| body[i as usize]).collect();
        cracked.sort_unstable();
        cracked.dedup();
        self.cracked = cracked;
        self.rebuild(Some((shape, body)));
    }

    /// Rebuild `segments`: the outer segments of the bodies that can be
    /// masters (with split ends given to their side's child), then both
    /// faces of every crack.
    fn rebuild(&mut self, after_split: Option<(&ShapeTable, &[u32])>) {
        let multi = self.multi_body();
        let self_contact = self.self_contact;
        let wanted = |b: u32, cracked: &[u32]| multi || (self_contact && cracked.binary_search(&b).is_ok());
        // Split particles: (left, right) children.
        let mut split: Vec<(u32, u32)> = self
            .faces
            .iter()
            .flat_map(|[l, r]| l.iter().zip(r).filter(|(a, b)| a != b).map(|(&a, &b)| (a, b)))
            .collect();
        split.sort_unstable();
        let child = |end: u32, other: u32| -> u32 {
            match (after_split, split.binary_search_by_key(&end, |s| s.0)) {
                (Some((shape, _)), Ok(k)) => {
                    let right = split[k].1;
                    let seen_left = in_row(shape, end as usize, other);
                    if !seen_left && in_row(shape, right as usize, other) {
                        right
                    } else {
                        end
                    }
                }
                _ => end,
            }
        };
        self.segments.clear();
        self.segment_body.clear();
        for (k, &[a, b]) in self.outer.iter().enumerate() {
            let body = self.outer_body[k];
            if wanted(body, &self.cracked) {
                self.segments.push([child(a, b), child(b, a)]);
                self.segment_body.push(body);
            }
        }
        if multi || self_contact {
            if let Some((_, body)) = after_split {
                for [left, right] in &self.faces {
                    for w in left.windows(2) {
                        self.segments.push([w[0], w[1]]);
                        self.segment_body.push(body[w[0] as usize]);
                    }
                    for w in right.windows(2) {
                        self.segments.push([w[1], w[0]]);
                        self.segment_body.push(body[w[0] as usize]);
                    }
                }
            }
        }
        self.segments.retain(|s| s[0] != s[1]);
        self.scratch.ready = false;
    }

    /// Vertices and the vertex → segment lists of `segments`.
    fn ensure_topology(&mut self) {
        if self.scratch.ready {
            return;
        }
        let s = &mut self.scratch;
        s.vertices = self.segments.iter().flatten().copied().collect();
        s.vertices.sort_unstable();
        s.vertices.dedup();
        let nv = s.vertices.len();
        s.start = vec![0; nv + 1];
        let vertex = |v: &Vec<u32>, i: u32| v.binary_search(&i).expect("a segment end is a vertex");
        for seg in &self.segments {
            for &i in seg {
                s.start[vertex(&s.vertices, i) + 1] += 1;
            }
        }
        for k in 0..nv {
            s.start[k + 1] += s.start[k];
        }
        s.list = vec![0; self.segments.len() * 2];
        let mut fill = s.start.clone();
        for (k, seg) in self.segments.iter().enumerate() {
            for &i in seg {
                let v = vertex(&s.vertices, i);
                s.list[fill[v] as usize] = k as u32;
                fill[v] += 1;
            }
        }
        s.ready = true;
    }

    /// Error unless every segment, face and persistent pair names a
    /// particle below `n`, with one body per segment (a state read from a
    /// checkpoint).
    pub fn check(&self, n: usize) -> Result<(), ContactError> {
        let bad = self
            .outer
            .iter()
            .chain(&self.segments)
            .flatten()
            .chain(self.faces.iter().flat_map(|f| f[0].iter().chain(&f[1])))
            .chain(self.persistent.iter().flat_map(|p| [&p.0, &p.1, &p.2]))
            .find(|&&i| i as usize >= n);
        if let Some(&i) = bad {
            return Err(ContactError::SlaveOutOfRange { particle: i as usize, particles: n });
        }
        if self.outer_body.len() != self.outer.len() {
            return Err(ContactError::LengthMismatch {
                field: "outer_body",
                expected: self.outer.len(),
                found: self.outer_body.len(),
            });
        }
        if self.segment_body.len() != self.segments.len() {
            return Err(ContactError::LengthMismatch {
                field: "segment_body",
                expected: self.segments.len(),
                found: self.segment_body.len(),
            });
        }
        Ok(())
    }

    /// Append the penetrating slave–segment pairs of this step to `out`,
    /// their signed rows to `gap_w` (module doc). `slaves` ascending;
    /// `physical`, if given, their physical gap points of this step (one
    /// per slave), else they are computed here.
    pub(super) fn candidates(
        &mut self,
        input: &StepInput,
        slaves: &[u32],
        physical: Option<&[GapPoint]>,
        gap_w: &mut Vec<(u32, Real)>,
        out: &mut Vec<Candidate>,
    ) -> Result<(), ContactError> {
        if self.segments.is_empty() || slaves.is_empty() {
            return Ok(());
        }
        let table = input.shape.ok_or(ContactError::MissingShapeTable { spreading: Spreading::ShapeFunction })?;
        let n = input.x0.len();
        if table.rows() != n {
            return Err(ContactError::LengthMismatch { field: "shape rows", expected: n, found: table.rows() });
        }
        if input.body.len() != n {
            return Err(ContactError::LengthMismatch { field: "body", expected: n, found: input.body.len() });
        }
        self.ensure_topology();
        let multi = self.multi_body();
        let s = &mut self.scratch;
        s.points.clear();
        for &v in &s.vertices {
            s.points.push(predict_gap_point(input, v as usize, Spreading::ShapeFunction)?);
        }
        let vertex = |i: u32| s.vertices.binary_search(&i).expect("a segment end is a vertex");
        let reach = slaves.iter().map(|&i| input.spacing[i as usize]).fold(0.0, Real::max);
        s.boxes.clear();
        for &[a, b] in &self.segments {
            let (pa, pb) = (s.points[vertex(a)].predicted, s.points[vertex(b)].predicted);
            s.boxes.push((pa.inf(&pb), pa.sup(&pb)));
        }
        if !s.grid.fill(&s.boxes, reach) {
            return Err(ContactError::NonFinite { particle: s.vertices[0] as usize, quantity: "master position" });
        }
        for (n_s, &slave) in slaves.iter().enumerate() {
            let sl = slave as usize;
            let body_s = input.body[sl];
            let own = self.self_contact && self.cracked.binary_search(&body_s).is_ok();
            if !multi && !own {
                continue;
            }
            let gs = match physical {
                Some(points) => points[n_s],
                None => predict_gap_point(input, sl, Spreading::ShapeFunction)?,
            };
            let h = input.spacing[sl];
            // (segment, λ, gap, normal, persistent, start-of-step gap)
            let mut best: Option<(usize, Real, Real, Vec2, bool, Real)> = None;
            for &k in s.grid.at(&gs.predicted) {
                let k = k as usize;
                let [a, b] = self.segments[k];
                if a == slave || b == slave {
                    continue;
                }
                let same = self.segment_body[k] == body_s;
                if (same && (!own || in_row(table, sl, a) || in_row(table, sl, b))) || (!same && !multi) {
                    continue;
                }
                let (ga, gb) = (&s.points[vertex(a)], &s.points[vertex(b)]);
                let d = gb.predicted - ga.predicted;
                let l2 = d.norm_squared();
                if l2.is_nan() || l2 <= 0.0 {
                    continue;
                }
                let along = (gs.predicted - ga.predicted).dot(&d) / l2;
                if !(-LAMBDA_TOLERANCE..=1.0 + LAMBDA_TOLERANCE).contains(&along) {
                    continue;
                }
                let lambda = along.clamp(0.0, 1.0);
                let normal = Vec2::new(d.y, -d.x) / l2.sqrt();
                let gap = (gs.predicted - (ga.predicted + d * lambda)).dot(&normal);
                if !(gap < 0.0 && -gap < h) {
                    continue;
                }
                let kept = self.persistent.binary_search(&(slave, a, b)).is_ok();
                let d0 = gb.now - ga.now;
                let l20 = d0.norm_squared();
                let gap0 = if l20 > 0.0 {
                    let lambda0 = ((gs.now - ga.now).dot(&d0) / l20).clamp(0.0, 1.0);
                    (gs.now - (ga.now + d0 * lambda0)).dot(&(Vec2::new(d0.y, -d0.x) / l20.sqrt()))
                } else {
                    0.0
                };
                if !(kept || gap0 >= -ENTRY_TOLERANCE * h) {
                    continue;
                }
                let better = match best {
                    None => true,
                    Some((_, _, g, _, p, g0)) => {
                        (kept, gap0, gap).partial_cmp(&(p, g0, g)) == Some(std::cmp::Ordering::Greater)
                    }
                };
                if better {
                    best = Some((k, lambda, gap, normal, kept, gap0));
                }
            }
            let Some((k, lambda, gap, normal, _, _)) = best else {
                continue;
            };
            let [a, b] = self.segments[k];
            let start = gap_w.len();
            for (i, w) in [(sl, 1.0), (a as usize, -(1.0 - lambda)), (b as usize, -lambda)] {
                gap_w.extend(table.range(i).map(|e| (table.index[e], w * table.value[e])));
            }
            let rows = (start as u32, gap_w.len() as u32);
            let tangent = Vec2::new(-normal.y, normal.x);
            let row = &gap_w[start..];
            let (c_n, c_t) = row_compliance(input, row, row, &normal, &tangent);
            let (ga, gb) = (&s.points[vertex(a)], &s.points[vertex(b)]);
            let relative = gs.velocity - (ga.velocity * (1.0 - lambda) + gb.velocity * lambda);
            let start_gap = (gs.now - (ga.now * (1.0 - lambda) + gb.now * lambda)).dot(&normal);
            out.push(
                Candidate::new(slave, Master::Segment { segment: [a, b], lambda }, rows, rows, gap, normal)
                    .with_motion(relative.dot(&tangent), c_n, c_t)
                    .with_start_gap(start_gap, h),
            );
        }
        Ok(())
    }

    /// Remember the pairs that carried a force this step (the entry rule's
    /// persistent contacts).
    pub(super) fn remember(&mut self, carried: impl Iterator<Item = (u32, Segment)>) {
        self.persistent.clear();
        self.persistent.extend(carried.map(|(s, [a, b])| (s, a, b)));
        self.persistent.sort_unstable();
        self.persistent.dedup();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(nx: usize, ny: usize) -> Vec<Vec2> {
        let mut x = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                x.push(Vec2::new(i as Real, j as Real));
            }
        }
        x
    }

    #[test]
    fn rectangle_boundary_is_a_counter_clockwise_loop() {
        let x = lattice(4, 3);
        let flags = vec![ParticleFlags::default(); x.len()];
        let segs = rectangle_boundary(&x, &flags, 0..x.len());
        // 2 (nx - 1) + 2 (ny - 1) segments, each end the start of the next.
        assert_eq!(segs.len(), 10);
        for w in segs.windows(2) {
            assert_eq!(w[0][1], w[1][0]);
        }
        assert_eq!(segs.last().unwrap()[1], segs[0][0]);
        // Material on the left: the signed area is positive.
        let area: Real = segs
            .iter()
            .map(|[a, b]| {
                let (p, q) = (x[*a as usize], x[*b as usize]);
                0.5 * (p.x * q.y - q.x * p.y)
            })
            .sum();
        assert!((area - 6.0).abs() < 1e-12, "{area}");
    }

    #[test]
    fn the_axis_edge_has_no_segments() {
        let x = lattice(3, 3);
        let mut flags = vec![ParticleFlags::default(); x.len()];
        for (i, p) in x.iter().enumerate() {
            if p.x == 0.0 {
                flags[i].set(ParticleFlags::ON_AXIS);
            }
        }
        let segs = rectangle_boundary(&x, &flags, 0..x.len());
        assert_eq!(segs.len(), 6);
        assert!(segs.iter().all(|[a, b]| x[*a as usize].x != 0.0 || x[*b as usize].x != 0.0));
    }
}
