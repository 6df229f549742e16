//! The assembled discretization: particles, quadrature points, shape-function
//! tables and materials of all deformable bodies (SPEC §3–§4).

use crate::discretize::RectangleGrid;
use crate::geometry::GeometryMode;
use crate::material::{Constitutive, Material, PointState};
use crate::math::{Real, Tensor3, Vec2};
use crate::particles::{ParticleFlags, Particles};
use crate::quadrature::QuadraturePoints;
use crate::shape::{build_table, AllVisible, ShapeError, ShapeTable};
use rayon::prelude::*;

/// An axis-aligned box in the reference configuration, used to select
/// particles (supports, initial-velocity regions).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// m
    pub x_min: Real,
    /// m
    pub x_max: Real,
    /// m
    pub y_min: Real,
    /// m
    pub y_max: Real,
}

impl Region {
    /// Whether `p` lies in the closed box (with a relative tolerance).
    pub fn contains(&self, p: &Vec2) -> bool {
        let tol = 1e-9 * ((self.x_max - self.x_min).abs() + (self.y_max - self.y_min).abs()).max(1e-12);
        p.x >= self.x_min - tol && p.x <= self.x_max + tol && p.y >= self.y_min - tol && p.y <= self.y_max + tol
    }
}

/// Which displacement components a support holds at zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fix {
    /// Both components: a clamp.
    All,
    /// Only x (r): a roller on a plane of constant x, or a symmetry plane.
    X,
    /// Only y (z): a roller on a plane of constant y.
    Y,
}

/// A support: the particles in `region` have the `fix` components of their
/// generalized displacement held at zero (SPEC §4).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Support {
    /// The particles held.
    pub region: Region,
    /// Components held. Default `"all"` (clamped).
    #[serde(default = "fix_all")]
    pub fix: Fix,
}

fn fix_all() -> Fix {
    Fix::All
}

/// What the model builder needs for one deformable body.
#[derive(Clone, Debug)]
pub struct BodySetup {
    pub name: String,
    pub grid: RectangleGrid,
    pub material: Material,
    /// Initial velocity and, optionally, the region it applies to (all if `None`).
    pub initial_velocity: Vec<(Vec2, Option<Region>)>,
    /// Supports: regions and the components they hold.
    pub supports: Vec<Support>,
}

/// Per-body bookkeeping.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BodyInfo {
    pub name: String,
    /// Particle index range in the store.
    pub particles: std::ops::Range<usize>,
    /// Quadrature point index range.
    pub quad_points: std::ops::Range<usize>,
    pub columns: usize,
    pub rows: usize,
}

/// Transpose of the quadrature shape table: for each particle, the table
/// entries (and their rows) that involve it, in ascending entry order. The
/// internal force is a gather over this list, so no two threads ever write
/// the same particle and sums are bit-identical for any thread count.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Gather {
    /// Per-particle starts into `entry`, length `particles + 1`.
    pub offsets: Vec<usize>,
    /// Entry index `k` into the quadrature table.
    pub entry: Vec<u32>,
    /// Quadrature point (row) of that entry.
    pub point: Vec<u32>,
    /// `N_I(X_q)` of that entry, copied in gather order so the force sweep
    /// streams through memory. Not in checkpoints (nor `grad`): copies of
    /// the table's entries, refilled on reading ([`Gather::copy_entries`]).
    #[serde(skip)]
    pub value: Vec<Real>,
    /// `∇N_I(X_q)` of that entry, in gather order.
    #[serde(skip)]
    pub grad: Vec<Vec2>,
}

impl Gather {
    /// Fill `value` and `grad` with the entries of `table` that `entry`
    /// names (every entry must be in range), in gather order.
    pub fn copy_entries(&mut self, table: &ShapeTable) {
        self.value = self.entry.iter().map(|&k| table.value[k as usize]).collect();
        self.grad = self.entry.iter().map(|&k| table.grad[k as usize]).collect();
    }

    /// Build from a table whose column indices are particles `0..n`.
    ///
    /// In parallel over blocks of particles (`Gather::fill`): each block
    /// scans the table's indices and fills only its own particles' entries.
    /// Every particle's entries are still written in ascending entry order,
    /// so the result does not depend on the number of blocks (test
    /// `gather_is_the_same_for_any_number_of_threads`). A crack split
    /// patches it instead ([`Gather::patch_into`]).
    pub fn new(table: &ShapeTable, n: usize) -> Self {
        let mut offsets = vec![0usize; n + 1];
        for &i in &table.index {
            offsets[i as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let mut gather = Gather::default();
        gather.fill(offsets, |particles, out| {
            let mut fill: Vec<usize> = out.offsets[particles.clone()].iter().map(|o| o - out.base).collect();
            for q in 0..table.rows() {
                for k in table.range(q) {
                    let i = table.index[k] as usize;
                    if !particles.contains(&i) {
                        continue;
                    }
                    let slot = &mut fill[i - particles.start];
                    out.put(*slot, k, q, table.value[k], table.grad[k]);
                    *slot += 1;
                }
            }
        });
        gather
    }

    /// The particles (of `n`) in rows `changed` of the table `before` or
    /// `after` a rebuild: those whose entries [`Gather::patch_into`] must
    /// merge, and whose lumped masses change.
    pub fn touched(before: &ShapeTable, after: &ShapeTable, changed: &[usize], n: usize) -> Vec<bool> {
        let mut touched = vec![false; n];
        for &q in changed {
            for &i in before.index[before.range(q)].iter().chain(&after.index[after.range(q)]) {
                touched[i as usize] = true;
            }
        }
        touched
    }

    /// The transpose of `table` after its rows `changed` (ascending, no
    /// repeats) were rebuilt, written into `out` (its allocations reused),
    /// from `self`, the transpose of the table before, whose row starts were
    /// `old_offsets`; `n` particles (splits append
    /// particles, never remove them). `touched[i]` must hold for every
    /// particle in a changed row before or after the rebuild (it may hold
    /// for others). Equal to [`Gather::new`] of `table` (test
    /// `patched_gather_equals_a_fresh_one`) at the cost of one streaming
    /// copy: an untouched particle keeps its entries — point, value and
    /// gradient copied as one block, entry indices shifted with their rows —
    /// and a touched one keeps its entries of unchanged rows and merges in
    /// those of the rebuilt rows, in row order. A crack split changes a few
    /// hundred rows; rebuilding the whole transpose after each split was
    /// most of the crack-growth stage.
    pub fn patch_into(
        &self,
        old_offsets: &[usize],
        table: &ShapeTable,
        changed: &[usize],
        touched: &[bool],
        n: usize,
        out: &mut Gather,
    ) {
        let old_n = self.offsets.len() - 1;
        debug_assert!(n >= old_n && touched.len() >= n && old_offsets.len() == table.offsets.len());
        let mut is_changed = vec![false; table.rows()];
        for &q in changed {
            is_changed[q] = true;
        }
        // How far each row's entries moved.
        let shift: Vec<isize> =
            table.offsets.iter().zip(old_offsets).map(|(&new, &old)| new as isize - old as isize).collect();
        // The rebuilt rows' entries `(particle, row, entry)`, by particle and
        // then row (the sort is stable and the rows come ascending).
        let mut fresh: Vec<(u32, u32, u32)> =
            changed.iter().flat_map(|&q| table.range(q).map(move |k| (table.index[k], q as u32, k as u32))).collect();
        fresh.sort_by_key(|e| e.0);
        let mut fresh_start = vec![0usize; n + 1];
        for e in &fresh {
            debug_assert!(touched[e.0 as usize]);
            fresh_start[e.0 as usize + 1] += 1;
        }
        for i in 0..n {
            fresh_start[i + 1] += fresh_start[i];
        }
        let old_range = |i: usize| if i < old_n { self.range(i) } else { 0..0 };
        let kept = |i: usize| old_range(i).filter(|&j| !is_changed[self.point[j] as usize]);
        let counts: Vec<usize> = (0..n)
            .into_par_iter()
            .map(|i| {
                if touched[i] {
                    kept(i).count() + fresh_start[i + 1] - fresh_start[i]
                } else {
                    debug_assert!(kept(i).count() == old_range(i).len(), "particle {i} is in a changed row");
                    old_range(i).len()
                }
            })
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0);
        for c in counts {
            offsets.push(offsets.last().expect("starts at 0") + c);
        }
        let moved = |j: usize| (self.entry[j] as isize + shift[self.point[j] as usize]) as usize;
        out.fill(offsets, |particles, out| {
            for i in particles {
                let mut slot = out.offsets[i] - out.base;
                if !touched[i] {
                    let (r, len) = (old_range(i), out.offsets[i + 1] - out.offsets[i]);
                    out.point[slot..slot + len].copy_from_slice(&self.point[r.clone()]);
                    out.value[slot..slot + len].copy_from_slice(&self.value[r.clone()]);
                    out.grad[slot..slot + len].copy_from_slice(&self.grad[r.clone()]);
                    for (e, j) in out.entry[slot..slot + len].iter_mut().zip(r) {
                        *e = moved(j) as u32;
                    }
                    continue;
                }
                let mut old = kept(i).peekable();
                let mut new = fresh[fresh_start[i]..fresh_start[i + 1]].iter().peekable();
                loop {
                    let take_old = match (old.peek(), new.peek()) {
                        (Some(&j), Some(e)) => self.point[j] < e.1,
                        (Some(_), None) => true,
                        (None, Some(_)) => false,
                        (None, None) => break,
                    };
                    if take_old {
                        let j = old.next().expect("peeked");
                        out.put(slot, moved(j), self.point[j] as usize, self.value[j], self.grad[j]);
                    } else {
                        let &(_, q, k) = new.next().expect("peeked");
                        let (q, k) = (q as usize, k as usize);
                        out.put(slot, k, q, table.value[k], table.grad[k]);
                    }
                    slot += 1;
                }
            }
        });
    }

    /// Make `self` the transpose with row starts `offsets` (its allocations
    /// reused), the columns filled in parallel over blocks of particles, one
    /// per worker thread: `fill(particles, out)` writes exactly the entries
    /// of `particles`, which lie in one contiguous stretch of the columns
    /// (`out`, whose slot 0 is entry `out.base`). The result does not depend
    /// on the number of blocks.
    fn fill(&mut self, offsets: Vec<usize>, fill: impl Fn(std::ops::Range<usize>, &mut GatherBlock) + Sync) {
        let n = offsets.len() - 1;
        let nnz = offsets[n];
        // Every slot is written by `fill`: resizing only sizes the columns.
        self.entry.resize(nnz, 0);
        self.point.resize(nnz, 0);
        self.value.resize(nnz, 0.0);
        self.grad.resize(nnz, Vec2::zeros());
        self.offsets = offsets;
        let blocks = rayon::current_num_threads().clamp(1, n.max(1));
        let mut parts = Vec::with_capacity(blocks);
        let (mut e, mut p, mut v, mut g) =
            (&mut self.entry[..], &mut self.point[..], &mut self.value[..], &mut self.grad[..]);
        for b in 0..blocks {
            let particles = b * n / blocks..(b + 1) * n / blocks;
            let len = self.offsets[particles.end] - self.offsets[particles.start];
            let (e0, e1) = std::mem::take(&mut e).split_at_mut(len);
            let (p0, p1) = std::mem::take(&mut p).split_at_mut(len);
            let (v0, v1) = std::mem::take(&mut v).split_at_mut(len);
            let (g0, g1) = std::mem::take(&mut g).split_at_mut(len);
            (e, p, v, g) = (e1, p1, v1, g1);
            parts.push((particles, e0, p0, v0, g0));
        }
        let offsets = &self.offsets;
        parts.into_par_iter().for_each(|(particles, entry, point, value, grad)| {
            let base = offsets[particles.start];
            fill(particles, &mut GatherBlock { offsets, base, entry, point, value, grad });
        });
    }
    #[inline]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i]..self.offsets[i + 1]
    }
}

/// One block's stretch of the gather columns while they are filled
/// ([`Gather::fill`]).
struct GatherBlock<'a> {
    offsets: &'a [usize],
    /// Entry index of slot 0.
    base: usize,
    entry: &'a mut [u32],
    point: &'a mut [u32],
    value: &'a mut [Real],
    grad: &'a mut [Vec2],
}

impl GatherBlock<'_> {
    #[inline]
    fn put(&mut self, slot: usize, k: usize, q: usize, value: Real, grad: Vec2) {
        self.entry[slot] = k as u32;
        self.point[slot] = q as u32;
        self.value[slot] = value;
        self.grad[slot] = grad;
    }
}

/// Everything the time loop works on.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Model {
    pub mode: GeometryMode,
    pub particles: Particles,
    pub quad: QuadraturePoints,
    /// Material of each body (indexed by body number). Not in checkpoints:
    /// rebuilt from the case stored beside the state.
    #[serde(skip)]
    pub materials: Vec<Material>,
    pub bodies: Vec<BodyInfo>,
    /// `N_I(X_q)`, `∇N_I(X_q)` at the quadrature points.
    pub qp_shape: ShapeTable,
    /// `N_J(X_I)` at the particles themselves (physical displacement, output, contact).
    pub particle_shape: ShapeTable,
    /// Transpose of `qp_shape`.
    pub gather: Gather,
}

/// Most points or particles one piece of a parallel sweep takes (rayon's
/// `with_max_len`). Rayon's adaptive splitting cuts a loop into a few
/// pieces per thread and cuts further only when a piece is stolen; where
/// the cost per item is uneven (points in plastic flow cost several times
/// an elastic one, and they lie together in the space-filling-curve order
/// under the projectile), a thread can be left holding one long costly
/// piece while the other waits. Pieces of this size keep both busy; one
/// is about 0.3 ms of the material sweep's work, against microseconds to
/// cut and steal it. Each item's result does not depend on the cut, so
/// neither do the bits.
pub const PARALLEL_PIECE: usize = 1024;

/// Errors while building a model.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    #[error("body '{body}': {source}")]
    Shape {
        body: String,
        #[source]
        source: ShapeError,
    },
    #[error("body '{body}': {message}")]
    Invalid { body: String, message: String },
}

impl Model {
    /// Generate particles and quadrature points for every body, build the
    /// shape-function tables, lump the masses and apply initial conditions.
    pub fn build(mode: GeometryMode, bodies: &[BodySetup]) -> Result<Model, ModelError> {
        let mut particles = Particles::default();
        let mut quad = QuadraturePoints::default();
        let mut infos = Vec::new();
        let mut qp_rows: Vec<ShapeTable> = Vec::new();
        let mut p_rows: Vec<ShapeTable> = Vec::new();
        let mut materials = Vec::new();
        for (b, setup) in bodies.iter().enumerate() {
            let mut grid = setup.grid.clone();
            grid.resolve(mode);
            let mut g = grid.generate(mode);
            g.sort_along_space_filling_curve();
            let t0 = setup.material.initial_temperature();
            let p_start = particles.len();
            for k in 0..g.particles.len() {
                let x = g.particles[k];
                let mut flags = ParticleFlags::default();
                if g.on_boundary[k] {
                    flags.set(ParticleFlags::SURFACE);
                }
                if mode == GeometryMode::Axisymmetric && x.x.abs() < 1e-12 {
                    flags.set(ParticleFlags::ON_AXIS | ParticleFlags::FIX_X);
                }
                for s in setup.supports.iter().filter(|s| s.region.contains(&x)) {
                    match s.fix {
                        Fix::All => flags.set(ParticleFlags::FIX_X | ParticleFlags::FIX_Y),
                        Fix::X => flags.set(ParticleFlags::FIX_X),
                        Fix::Y => flags.set(ParticleFlags::FIX_Y),
                    }
                }
                particles.push(x, g.volume[k], g.spacing[k], g.support[k], t0, b as u32, flags);
            }
            let p_end = particles.len();
            let q_start = quad.len();
            let s0 = PointState::at_rest(t0);
            for ((x, w), l) in g.quad_points.iter().zip(&g.quad_weights).zip(&g.quad_lengths) {
                quad.push(*x, *w, *l, b as u32, &s0);
            }
            let shape_err = |source| ModelError::Shape { body: setup.name.clone(), source };
            let x0 = &particles.x0[p_start..p_end];
            let sup = &particles.support[p_start..p_end];
            let vol = &particles.volume[p_start..p_end];
            let mut tq = build_table(&g.quad_points, x0, sup, vol, &AllVisible).map_err(shape_err)?;
            let mut tp = build_table(x0, x0, sup, vol, &AllVisible).map_err(shape_err)?;
            for i in tq.index.iter_mut().chain(tp.index.iter_mut()) {
                *i += p_start as u32;
            }
            qp_rows.push(tq);
            p_rows.push(tp);
            infos.push(BodyInfo {
                name: setup.name.clone(),
                particles: p_start..p_end,
                quad_points: q_start..quad.len(),
                columns: g.columns,
                rows: g.rows,
            });
            materials.push(setup.material.clone());
        }
        let qp_shape = concat_tables(qp_rows);
        let particle_shape = concat_tables(p_rows);
        let gather = Gather::new(&qp_shape, particles.len());
        let mut model = Model { mode, particles, quad, materials, bodies: infos, qp_shape, particle_shape, gather };
        model.lump_masses();
        for (b, setup) in bodies.iter().enumerate() {
            let range = model.bodies[b].particles.clone();
            for (v, region) in &setup.initial_velocity {
                for i in range.clone() {
                    if region.is_none_or(|r| r.contains(&model.particles.x0[i])) {
                        model.particles.v[i] = *v;
                    }
                }
            }
            if model.particles.mass[range.clone()].iter().any(|m| *m <= 0.0) {
                return Err(ModelError::Invalid {
                    body: setup.name.clone(),
                    message: "a particle received no mass (its support covers no quadrature point)".into(),
                });
            }
        }
        model.apply_constraints();
        Ok(model)
    }

    /// Row-sum lumped masses `m_I = Σ_q ρ₀ N_I(X_q) w_q` (SPEC §4).
    pub fn lump_masses(&mut self) {
        for i in 0..self.particles.len() {
            self.particles.mass[i] = self.lumped_mass(i);
        }
    }

    /// Row-sum lumped mass of particle `i` from the current tables (SPEC §4).
    pub fn lumped_mass(&self, i: usize) -> Real {
        let mut m = 0.0;
        for j in self.gather.range(i) {
            let q = self.gather.point[j] as usize;
            let rho = self.materials[self.quad.body[q] as usize].density();
            m += rho * self.gather.value[j] * self.quad.weight[q];
        }
        m
    }

    /// Zero the constrained components of `U` and `V`: supports, and the
    /// radial component on the axis (SPEC §1, §4).
    pub fn apply_constraints(&mut self) {
        let p = &mut self.particles;
        for i in 0..p.len() {
            constrain(p.flags[i], &mut p.u[i]);
            constrain(p.flags[i], &mut p.v[i]);
        }
    }

    /// Physical displacement at each particle `u(X_I) = Σ_J N_J(X_I) U_J`.
    pub fn physical(&self, field: &[Vec2]) -> Vec<Vec2> {
        (0..self.particles.len()).into_par_iter().map(|i| self.particle_shape.interpolate(i, field)).collect()
    }

    /// The RK part of point `q`'s deformation gradient,
    /// `I + Σ_I u_I ⊗ ∇N_I(X_q)` (+ the hoop stretch in axisymmetry),
    /// from the current table: the same arithmetic, the same bits, as the
    /// solver's material update (without the carried jump).
    pub fn shape_deformation_gradient(&self, q: usize) -> Tensor3 {
        let u = &self.particles.u;
        let (gu, uq) = if self.mode.needs_point_values() {
            let (gu, _, uq, _) = self.qp_shape.gradient_pair_and_values(q, u, u);
            (gu, uq)
        } else {
            (self.qp_shape.gradient_pair(q, u, u).0, Vec2::zeros())
        };
        self.mode.deformation_gradient(&gu, &uq, &self.quad.x0[q], 1.0)
    }

    /// Quadrature point `k`'s adiabatic hardening
    /// ([`crate::material::johnson_cook::JohnsonCook::adiabatic_hardening`]
    /// at its plastic strain, temperature, damage and plastic rate; ≤ 0
    /// past the onset of adiabatic shear localization), NaN in an elastic
    /// body, held at no less than −100: a melted or fully damaged point's
    /// `−∞` would make every projection it enters `−∞`.
    pub fn adiabatic_hardening(&self, k: usize) -> Real {
        let q = &self.quad;
        self.materials[q.body[k] as usize]
            .adiabatic_hardening(q.eps_p[k], q.temperature[k], q.damage[k], q.eps_p_rate[k])
            .map_or(Real::NAN, |h| h.max(-100.0))
    }

    /// Lumped projection of the quadrature field `f` at particle `i`:
    /// `f_i = Σ_q N_i(X_q) w_q f_q / Σ_q N_i(X_q) w_q` (the same weights as
    /// the lumped mass), summed in the gather table's fixed order;
    /// `T::default()` (zero) where the particle has no points.
    pub fn project_at<T>(&self, i: usize, f: impl Fn(usize) -> T) -> T
    where
        T: Copy
            + std::ops::Add<Output = T>
            + std::ops::Mul<Real, Output = T>
            + std::ops::Div<Real, Output = T>
            + Default,
    {
        let (mut acc, mut wsum) = (T::default(), 0.0);
        for j in self.gather.range(i) {
            let q = self.gather.point[j] as usize;
            let w = self.gather.value[j] * self.quad.weight[q];
            acc = acc + f(q) * w;
            wsum += w;
        }
        if wsum != 0.0 {
            acc / wsum
        } else {
            T::default()
        }
    }

    /// [`Self::project_at`] at every particle, in parallel over them; the
    /// result does not depend on the thread count.
    pub fn project<T>(&self, f: impl Fn(usize) -> T + Sync) -> Vec<T>
    where
        T: Copy
            + Send
            + std::ops::Add<Output = T>
            + std::ops::Mul<Real, Output = T>
            + std::ops::Div<Real, Output = T>
            + Default,
    {
        (0..self.particles.len()).into_par_iter().map(|i| self.project_at(i, &f)).collect()
    }

    /// Whether the shape tables and the gather cover exactly the particles
    /// and points there are: false only between a crack split (which adds
    /// particles) and the rebuild of their rows, which a failed rebuild
    /// leaves undone (`fracture::FractureError`); then no field can be
    /// projected or interpolated.
    pub fn tables_match(&self) -> bool {
        let (n, nq) = (self.particles.len(), self.quad.len());
        self.particle_shape.rows() == n && self.qp_shape.rows() == nq && self.gather.offsets.len() == n + 1
    }

    /// Smallest particle spacing, m.
    pub fn min_spacing(&self) -> Real {
        self.particles.spacing.iter().cloned().fold(Real::INFINITY, Real::min)
    }

    /// Largest longitudinal wave speed of the materials, m/s.
    pub fn max_wave_speed(&self) -> Real {
        self.materials.iter().map(|m| m.longitudinal_wave_speed()).fold(0.0, Real::max)
    }
}

/// Zero the components of `v` that `flags` hold fixed.
#[inline]
pub fn constrain(flags: ParticleFlags, v: &mut Vec2) {
    flags.constrain(v);
}

fn concat_tables(parts: Vec<ShapeTable>) -> ShapeTable {
    let mut t = ShapeTable { offsets: vec![0], ..Default::default() };
    for p in parts {
        let base = t.index.len();
        t.offsets.extend(p.offsets[1..].iter().map(|o| o + base));
        t.index.extend(p.index);
        t.value.extend(p.value);
        t.grad.extend(p.grad);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shape table of a 9 × 9 particle lattice at 64 points off the
    /// lattice; `(9, table)`.
    fn lattice_table() -> (usize, ShapeTable) {
        let h = 1e-3;
        let n = 9;
        let x0: Vec<Vec2> = (0..n * n).map(|k| Vec2::new((k % n) as Real * h, (k / n) as Real * h)).collect();
        let points: Vec<Vec2> = (0..(n - 1) * (n - 1))
            .map(|k| Vec2::new(((k % (n - 1)) as Real + 0.4) * h, ((k / (n - 1)) as Real + 0.7) * h))
            .collect();
        (n, build_table(&points, &x0, &vec![2.2 * h; n * n], &vec![h * h; n * n], &AllVisible).unwrap())
    }

    /// Patching the transpose after some rows changed length and content,
    /// and new particles appeared in them, gives exactly the transpose built
    /// afresh, for 1, 2 and 3 worker threads, including the entry indices
    /// of the unchanged rows, which shift with the rows before them.
    #[test]
    fn patched_gather_equals_a_fresh_one() {
        let (n, old) = lattice_table();
        // Rebuilt rows: every third entry dropped, one or two new particles
        // (indices n², n² + 1) added; the first and the last row among them.
        let changed: Vec<usize> = vec![0, 5, 6, 20, 33, old.rows() - 1];
        let mut new = ShapeTable { offsets: vec![0], ..Default::default() };
        for q in 0..old.rows() {
            let mut row: Vec<(u32, Real, Vec2)> =
                old.range(q).map(|k| (old.index[k], old.value[k], old.grad[k])).collect();
            if changed.contains(&q) {
                row = row.into_iter().enumerate().filter(|(m, _)| m % 3 != 1).map(|(_, e)| e).collect();
                for extra in 0..1 + q % 2 {
                    row.push(((n * n + extra) as u32, 0.01 * q as Real, Vec2::new(q as Real, -(extra as Real))));
                }
                for e in row.iter_mut() {
                    e.1 *= 1.5;
                }
            }
            for (i, v, g) in row {
                new.index.push(i);
                new.value.push(v);
                new.grad.push(g);
            }
            new.offsets.push(new.index.len());
        }
        let touched = Gather::touched(&old, &new, &changed, n * n + 2);
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (fresh, patched) = pool.install(|| {
                let before = Gather::new(&old, n * n);
                {
                    // `out` starts with stale contents of another size: every slot is rewritten.
                    let mut out = Gather::new(&old, n * n);
                    before.patch_into(&old.offsets, &new, &changed, &touched, n * n + 2, &mut out);
                    (Gather::new(&new, n * n + 2), out)
                }
            });
            assert_eq!(patched, fresh, "{threads} threads");
            assert!(patched.value.iter().zip(&fresh.value).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    /// The transpose built in parallel blocks is the serial transpose
    /// (particles' entries in ascending entry order) for 1, 2, 3 and 7
    /// worker threads.
    #[test]
    fn gather_is_the_same_for_any_number_of_threads() {
        let (n, table) = lattice_table();
        let mut serial: Vec<Vec<u32>> = vec![Vec::new(); n * n];
        for q in 0..table.rows() {
            for k in table.range(q) {
                serial[table.index[k] as usize].push(k as u32);
            }
        }
        for threads in [1, 2, 3, 7] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let g = pool.install(|| Gather::new(&table, n * n));
            for (i, entries) in serial.iter().enumerate() {
                let r = g.range(i);
                assert_eq!(&g.entry[r.clone()], &entries[..], "particle {i}, {threads} threads");
                for j in r {
                    let k = g.entry[j] as usize;
                    assert!(table.range(g.point[j] as usize).contains(&k));
                    assert_eq!(g.value[j].to_bits(), table.value[k].to_bits());
                    assert_eq!(g.grad[j], table.grad[k]);
                }
            }
            assert_eq!(g.offsets.last(), Some(&table.nnz()));
        }
    }
}
