//! Checkpoints: the complete state of a running simulation in one versioned
//! binary file, so that a run stopped at any point (Ctrl-C, SIGTERM, a
//! crash, a full queue slot) continues from its last checkpoint and
//! produces, bit for bit, what the uninterrupted run would have.
//!
//! # What is stored
//! Everything the time loop reads that is not fixed by the case text:
//! every column of the particle and quadrature-point stores, both
//! shape-function tables, the force gather, the body index ranges, time,
//! step, `Δt`, the speed bound, the energy account, the contact force of the
//! last step, the rigid bodies' positions and velocities, the slave set with
//! each slave's last pairing and the contact's running sums, the time
//! accumulated toward the next heat conduction (`heat_pending`, with
//! `heat_every`), whether constraints are driven, the crack growth (every
//! crack's reference polyline with its split children, tip, offset and
//! times, the event log, the rows built with a reduced basis), and where the
//! run's outputs stand (snapshot times, the length of `history.csv`, the next
//! snapshot and checkpoint times, the largest drift so far). The case itself
//! is stored as resolved TOML text with the built-in materials written out,
//! so a checkpoint resumes without the case file and without depending on
//! the built-in material library of the reading binary.
//!
//! The derived data (shape tables, gather, lumped masses) are stored rather
//! than rebuilt: a rebuild is deterministic today, but after a crack the
//! tables are patched locally and a global rebuild need not sum in the same
//! order, so only stored tables guarantee a bit-identical continuation. The
//! cost is size: about 36 bytes per quadrature-table entry, roughly 0.25 GB
//! for \[RL10\]'s fine model ([`crate::memory::Footprint::checkpoint_bytes`]).
//!
//! # File format (little-endian throughout)
//! ```text
//! header   magic "PLUGCKPT" (8 bytes) | format version u32 | writer length u32
//!          | writer (UTF-8: "plugsim VERSION (COMMIT)") | payload length u64
//!          | CRC-32 of the payload u32
//! payload  sections, each: tag (4 ASCII bytes) | length u64 | body
//! ```
//! The magic, the version and the writer come first in every format version,
//! so a reader can always say which version and which plugsim wrote a file
//! it cannot read. Version 2 has the sections `META`, `PART`, `QUAD`, `QTAB`,
//! `PTAB`, `GATH`, `BODY`, `FCON`, `CONT` (only with rigid bodies), `CRAK`
//! (only with a fracture criterion) and the terminator `END!`. Inside a section, a column is its element count (u64)
//! followed by the elements; a `Vec2` is x, y and a `Tensor3` its nine
//! components column by column, each as the IEEE-754 bits of the `f64`, so
//! values round-trip exactly. Adding state (the crack polylines, new
//! particle fields) means a new section or a new column, a bump of
//! [`FORMAT_VERSION`] and a test; a reader refuses every version but its own
//! ([`CheckpointError::Version`]). The `CRAK` section, for example, holds
//! the crack polylines, tips and event log (`crack_bytes`,
//! `restore_cracks`); the split particles, their face sides and the patched
//! tables are carried by `PART`, `QTAB`, `PTAB` and `GATH`. Heat conduction
//! keeps no state between steps and is rebuilt from the case and the model
//! ([`Case::heat_conduction_for`], as a fresh run builds it). Fields added to the particle or quadrature
//! stores fail to compile in `write_payload` (exhaustive destructuring)
//! until they are stored, and `tests/checkpoint.rs` compares the whole
//! `Simulation` of a resumed run with an uninterrupted one, so state kept
//! elsewhere and forgotten here fails a test.
//!
//! Hand-written rather than serde with a binary crate: the state is a few
//! dozen flat numeric columns, the layout above is short enough to document
//! and to keep stable, writing streams straight to the file without a
//! serialized copy of a model that may take gigabytes, and the physics
//! modules need no serialization derives (nalgebra's would pull in a feature
//! and pin the layout of its types).
//!
//! # Writing
//! The file is written to a hidden temporary sibling, `fsync`ed, renamed
//! over its final name and the directory `fsync`ed ([`write()`]): a crash
//! leaves either no new checkpoint or a complete one, and the older
//! checkpoints are untouched until the new one is safe ([`rotate`]).

use crate::case::{Case, MaterialSpec};
use crate::contact::{ContactAccumulators, ContactSystem, MasterFeature, Pairing, SlaveSet};
use crate::fracture::{Crack, CrackEvent, CrackGrowth, CrackVertex, Criterion, EventKind, FractureParameters};
use crate::material::Material;
use crate::math::{Block2, Real, Tensor3, Vec2};
use crate::model::{BodyInfo, Gather, Model};
use crate::particles::{FaceSide, ParticleFlags, Particles};
use crate::quadrature::{QuadraturePoints, NO_CARRY};
use crate::shape::Basis;
use crate::shape::ShapeTable;
use crate::step::{Energies, Simulation, TimeStepRule};
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// First bytes of every checkpoint file.
pub const MAGIC: [u8; 8] = *b"PLUGCKPT";
/// The format this build writes and the only one it reads.
///
/// Version 1 (before heat conduction and crack growth were carried) lacks
/// the conduction clock and the `CRAK` section; version 2 adds them;
/// version 3 adds the deformation-gradient jumps carried over crack changes
/// (a column of `QUAD` and the `FCAR` section).
pub const FORMAT_VERSION: u32 = 3;
/// Subdirectory of a run's output directory that holds its checkpoints.
pub const DIRECTORY: &str = "checkpoints";
/// File name extension of a checkpoint.
pub const EXTENSION: &str = "ckpt";

/// Where a run's outputs stood when the checkpoint was taken (the run
/// loop's own state besides the simulation).
#[derive(Clone, Debug, PartialEq)]
pub struct RunProgress {
    /// Simulated time of each snapshot written so far, s; snapshot `k` is
    /// `particles_{k:05}.vtu`.
    pub snapshot_times: Vec<Real>,
    /// Length of `history.csv` in bytes after the last row written.
    pub history_bytes: u64,
    /// Time of the next snapshot, s.
    pub next_snapshot: Real,
    /// Time of the next checkpoint by simulated time, s (infinite: none).
    pub next_checkpoint: Real,
    /// Largest |energy drift| seen at a history row so far.
    pub max_drift: Real,
}

/// A checkpoint read back: the case, the simulation and the run's progress.
#[derive(Debug)]
pub struct Restored {
    /// The file it came from.
    pub path: PathBuf,
    /// The plugsim that wrote it, `plugsim VERSION (COMMIT)`.
    pub writer: String,
    /// The case, as stored (resolved, built-in materials written out).
    pub case: Case,
    /// The simulation, ready for its next step.
    pub sim: Simulation,
    /// Where the outputs stood.
    pub progress: RunProgress,
}

/// Why a checkpoint could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    #[error("checkpoint {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{} is not a plugsim checkpoint (no PLUGCKPT header)", path.display())]
    NotACheckpoint { path: PathBuf },
    #[error(
        "checkpoint {} has format version {found} (written by {writer}), but this build, {}, \
         reads format version {supported} only; resume it with the plugsim that wrote it, or rerun the case",
        path.display(), this_writer()
    )]
    Version { path: PathBuf, found: u32, supported: u32, writer: String },
    #[error("checkpoint {} is damaged: {reason}", path.display())]
    Damaged { path: PathBuf, reason: String },
    #[error("checkpoint {}: its case no longer reads: {message}", path.display())]
    Case { path: PathBuf, message: String },
    #[error(
        "no checkpoint in {}: the run wrote none (checkpoints are written every [checkpoint] \
         interval or wall_interval, and when a run is interrupted)",
        dir.display()
    )]
    None { dir: PathBuf },
}

/// `plugsim VERSION (COMMIT)` of this build, written into every header.
pub fn this_writer() -> String {
    format!("plugsim {} ({})", env!("CARGO_PKG_VERSION"), option_env!("PLUGSIM_COMMIT").unwrap_or("unknown"))
}

/// The checkpoint directory of a run's output directory.
pub fn directory(out_dir: &Path) -> PathBuf {
    out_dir.join(DIRECTORY)
}

/// File name of the checkpoint taken after `step` steps.
pub fn file_name(step: u64) -> String {
    format!("checkpoint-{step:012}.{EXTENSION}")
}

/// The checkpoints in `dir` (a checkpoint directory), `(step, path)` in
/// ascending step order. Temporary files of interrupted writes are skipped.
pub fn list(dir: &Path) -> Vec<(u64, PathBuf)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found: Vec<(u64, PathBuf)> = entries
        .filter_map(|e| {
            let path = e.ok()?.path();
            let name = path.file_name()?.to_str()?;
            let step = name.strip_prefix("checkpoint-")?.strip_suffix(&format!(".{EXTENSION}"))?.parse().ok()?;
            Some((step, path))
        })
        .collect();
    found.sort();
    found
}

/// Remove all but the newest `keep` checkpoints (at least one is always
/// kept) and any temporary file left by an interrupted write.
pub fn rotate(dir: &Path, keep: usize) -> Result<(), CheckpointError> {
    let all = list(dir);
    let excess = all.len().saturating_sub(keep.max(1));
    for (_, path) in &all[..excess] {
        std::fs::remove_file(path).map_err(|source| CheckpointError::Io { path: path.clone(), source })?;
    }
    remove_temporaries(dir);
    Ok(())
}

/// Remove every checkpoint of `dir` (a checkpoint directory): a fresh run
/// into a reused output directory must not leave the old run's checkpoints
/// for `plugsim resume` to find.
pub fn remove_all(dir: &Path) -> Result<(), CheckpointError> {
    for (_, path) in list(dir) {
        std::fs::remove_file(&path).map_err(|source| CheckpointError::Io { path: path.clone(), source })?;
    }
    remove_temporaries(dir);
    Ok(())
}

fn remove_temporaries(dir: &Path) {
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with(".checkpoint-") && name.contains(".tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Read the newest readable checkpoint of a run's output directory. A
/// damaged or unreadable newer file is skipped for the one before it, and
/// each skip is reported in the returned warnings; a file of another format
/// version is an error (the older files of the same run will be the same).
pub fn read_latest(out_dir: &Path) -> Result<(Restored, Vec<String>), CheckpointError> {
    let dir = directory(out_dir);
    let all = list(&dir);
    let mut warnings = Vec::new();
    let mut first_error = None;
    for (_, path) in all.iter().rev() {
        match read(path) {
            Ok(r) => return Ok((r, warnings)),
            Err(e @ (CheckpointError::Version { .. } | CheckpointError::Case { .. })) => return Err(e),
            Err(e) => {
                warnings.push(format!("skipped {e}"));
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.unwrap_or(CheckpointError::None { dir }))
}

// ---------------------------------------------------------------- writing

/// One column of a section: a typed slice, written as its element count
/// followed by the elements.
enum Col<'a> {
    F64(&'a [Real]),
    V2(&'a [Vec2]),
    T3(&'a [Tensor3]),
    U32(&'a [u32]),
    U64(&'a [u64]),
    U8(&'a [u8]),
}

impl Col<'_> {
    fn byte_len(&self) -> u64 {
        let (n, size) = match self {
            Col::F64(v) => (v.len(), 8),
            Col::V2(v) => (v.len(), 16),
            Col::T3(v) => (v.len(), 72),
            Col::U32(v) => (v.len(), 4),
            Col::U64(v) => (v.len(), 8),
            Col::U8(v) => (v.len(), 1),
        };
        8 + (n * size) as u64
    }
}

/// Little-endian encoder over any writer.
struct Enc<W: Write> {
    w: W,
}

impl<W: Write> Enc<W> {
    fn raw(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.w.write_all(b)
    }
    fn u32(&mut self, v: u32) -> std::io::Result<()> {
        self.raw(&v.to_le_bytes())
    }
    fn u64(&mut self, v: u64) -> std::io::Result<()> {
        self.raw(&v.to_le_bytes())
    }
    fn f64(&mut self, v: Real) -> std::io::Result<()> {
        self.raw(&v.to_le_bytes())
    }
    fn str(&mut self, s: &str) -> std::io::Result<()> {
        self.u64(s.len() as u64)?;
        self.raw(s.as_bytes())
    }
    /// Many `f64` through a stack buffer (one `write_all` per 512 values).
    fn f64s(&mut self, values: impl Iterator<Item = Real>) -> std::io::Result<()> {
        let mut buf = [0u8; 4096];
        let mut k = 0;
        for v in values {
            buf[k..k + 8].copy_from_slice(&v.to_le_bytes());
            k += 8;
            if k == buf.len() {
                self.raw(&buf)?;
                k = 0;
            }
        }
        self.raw(&buf[..k])
    }
    fn col(&mut self, c: &Col) -> std::io::Result<()> {
        match c {
            Col::F64(v) => {
                self.u64(v.len() as u64)?;
                self.f64s(v.iter().copied())
            }
            Col::V2(v) => {
                self.u64(v.len() as u64)?;
                self.f64s(v.iter().flat_map(|p| [p.x, p.y]))
            }
            Col::T3(v) => {
                self.u64(v.len() as u64)?;
                self.f64s(v.iter().flat_map(|t| (0..9).map(move |k| t[k])))
            }
            Col::U32(v) => {
                self.u64(v.len() as u64)?;
                for chunk in v.chunks(1024) {
                    let bytes: Vec<u8> = chunk.iter().flat_map(|x| x.to_le_bytes()).collect();
                    self.raw(&bytes)?;
                }
                Ok(())
            }
            Col::U64(v) => {
                self.u64(v.len() as u64)?;
                for chunk in v.chunks(512) {
                    let bytes: Vec<u8> = chunk.iter().flat_map(|x| x.to_le_bytes()).collect();
                    self.raw(&bytes)?;
                }
                Ok(())
            }
            Col::U8(v) => {
                self.u64(v.len() as u64)?;
                self.raw(v)
            }
        }
    }
    /// A section of columns; its length is known from the columns, so it
    /// streams without a copy.
    fn section(&mut self, tag: &[u8; 4], cols: &[Col]) -> std::io::Result<()> {
        self.raw(tag)?;
        self.u64(cols.iter().map(Col::byte_len).sum())?;
        for c in cols {
            self.col(c)?;
        }
        Ok(())
    }
    /// A small section encoded in memory first.
    fn section_bytes(&mut self, tag: &[u8; 4], body: &[u8]) -> std::io::Result<()> {
        self.raw(tag)?;
        self.u64(body.len() as u64)?;
        self.raw(body)
    }
}

/// A writer that counts and checksums what passes through it.
struct Checksummed<W: Write> {
    inner: W,
    hasher: crc32fast::Hasher,
    len: u64,
}

impl<W: Write> Write for Checksummed<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hasher.update(&buf[..n]);
        self.len += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

fn offsets_u64(o: &[usize]) -> Vec<u64> {
    o.iter().map(|&x| x as u64).collect()
}

fn table_cols<'a>(t: &'a ShapeTable, offsets: &'a [u64]) -> [Col<'a>; 4] {
    let ShapeTable { offsets: _, index, value, grad } = t;
    [Col::U64(offsets), Col::U32(index), Col::F64(value), Col::V2(grad)]
}

/// The case with its built-in materials written out, so that the stored
/// text alone rebuilds the same materials.
fn self_contained(case: &Case) -> Case {
    let mut c = case.resolved();
    for b in &case.bodies {
        if c.materials.contains_key(&b.material) {
            continue;
        }
        if let Some(m) = crate::material::builtin(&b.material) {
            c.materials.insert(b.material.clone(), material_spec(&m));
        }
    }
    c
}

fn material_spec(m: &Material) -> MaterialSpec {
    match m {
        Material::Elastic(e) => MaterialSpec::Elastic {
            density: e.density,
            youngs_modulus: e.youngs_modulus,
            poisson_ratio: e.poisson_ratio,
            room_temperature: e.room_temperature,
            specific_heat: e.thermal.map(|t| t.specific_heat),
            thermal_conductivity: e.thermal.map(|t| t.conductivity),
        },
        Material::JohnsonCook(jc) => MaterialSpec::JohnsonCook(jc.clone()),
    }
}

/// The `META` section: case text, clocks, energies, run progress.
fn meta_bytes(sim: &Simulation, case_text: &str, progress: &RunProgress) -> std::io::Result<Vec<u8>> {
    let mut e = Enc { w: Vec::new() };
    e.str(case_text)?;
    e.f64(sim.time)?;
    e.u64(sim.step)?;
    e.f64(sim.dt)?;
    e.f64(sim.speed_bound)?;
    let Energies { kinetic, internal, rigid_kinetic, contact_work, rigid_work, initial_kinetic } = sim.energies;
    for v in [kinetic, internal, rigid_kinetic, contact_work, rigid_work, initial_kinetic] {
        e.f64(v)?;
    }
    let RunProgress { snapshot_times, history_bytes, next_snapshot, next_checkpoint, max_drift } = progress;
    e.col(&Col::F64(snapshot_times))?;
    e.u64(*history_bytes)?;
    e.f64(*next_snapshot)?;
    e.f64(*next_checkpoint)?;
    e.f64(*max_drift)?;
    e.u64(sim.model.particles.len() as u64)?;
    e.u64(sim.model.quad.len() as u64)?;
    e.u64(sim.heat_every)?;
    e.f64(sim.heat_pending)?;
    e.u32(u32::from(sim.driven_constraints))?;
    Ok(e.w)
}

fn body_bytes(bodies: &[BodyInfo]) -> std::io::Result<Vec<u8>> {
    let mut e = Enc { w: Vec::new() };
    e.u64(bodies.len() as u64)?;
    for b in bodies {
        let BodyInfo { name, particles, quad_points, columns, rows } = b;
        e.str(name)?;
        for v in [particles.start, particles.end, quad_points.start, quad_points.end, *columns, *rows] {
            e.u64(v as u64)?;
        }
    }
    Ok(e.w)
}

fn contact_bytes(c: &ContactSystem) -> std::io::Result<Vec<u8>> {
    let mut e = Enc { w: Vec::new() };
    e.u64(c.bodies.len() as u64)?;
    for b in &c.bodies {
        e.str(&b.name)?;
        e.col(&Col::V2(&[b.position, b.velocity]))?;
    }
    let slaves = c.slaves.particles();
    let (mut kind, mut body, mut feature) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..slaves.len() {
        let (t, b, f) = match c.slaves.pairing(k) {
            None => (0u8, 0u32, 0u32),
            Some(Pairing { body, feature: MasterFeature::Segment(s) }) => (1, body, s),
            Some(Pairing { body, feature: MasterFeature::Vertex(v) }) => (2, body, v),
        };
        kind.push(t);
        body.push(b);
        feature.push(f);
    }
    e.col(&Col::U32(slaves))?;
    e.col(&Col::U8(&kind))?;
    e.col(&Col::U32(&body))?;
    e.col(&Col::U32(&feature))?;
    let ContactAccumulators { work_on_particles, work_on_body, reaction, active_per_body } = c.accumulators();
    e.col(&Col::F64(&work_on_particles))?;
    e.col(&Col::F64(&work_on_body))?;
    e.col(&Col::V2(&reaction))?;
    e.col(&Col::U64(&active_per_body.iter().map(|&a| a as u64).collect::<Vec<_>>()))?;
    Ok(e.w)
}

fn basis_tag(b: Basis) -> u8 {
    match b {
        Basis::Bilinear => 0,
        Basis::Linear => 1,
        Basis::Constant => 2,
    }
}

/// The `CRAK` section: the crack-growth parameters, each crack (header,
/// then its vertices as columns: reference position, face tag 0 none /
/// 1 split, left child, right child), the event log as columns (the
/// particles of all events in one column with row offsets) and the rows
/// built with a reduced basis (row, basis tag). The binned segments and the
/// search grid are derived and rebuilt on reading
/// ([`CrackGrowth::from_state`]).
fn crack_bytes(c: &CrackGrowth) -> std::io::Result<Vec<u8>> {
    let mut e = Enc { w: Vec::new() };
    let FractureParameters {
        criterion,
        critical_effective_strain,
        critical_damage,
        radius_factor,
        fan_angle,
        offset_ratio,
        nucleation_distance_factor,
        erode_inverted,
    } = c.params;
    e.u32(match criterion {
        Criterion::EffectiveStrain => 0,
        Criterion::Damage => 1,
        Criterion::None => 2,
    })?;
    for v in
        [critical_effective_strain, critical_damage, radius_factor, fan_angle, offset_ratio, nucleation_distance_factor]
    {
        e.f64(v)?;
    }
    e.u32(erode_inverted as u32)?;
    e.u64(c.cracks.len() as u64)?;
    for k in &c.cracks {
        let Crack { id, vertices, tip, offset, nucleated, arrested } = k;
        e.u64(*id as u64)?;
        e.u64(tip.map_or(u64::MAX, |t| t as u64))?;
        e.f64(*offset)?;
        e.f64(nucleated.0)?;
        e.u64(nucleated.1)?;
        e.u32(u32::from(arrested.is_some()))?;
        let (at, at_step) = arrested.unwrap_or((0.0, 0));
        e.f64(at)?;
        e.u64(at_step)?;
        let x0: Vec<Vec2> = vertices.iter().map(|v| v.x0).collect();
        let tag: Vec<u8> = vertices.iter().map(|v| u8::from(v.faces.is_some())).collect();
        let left: Vec<u32> = vertices.iter().map(|v| v.faces.map_or(0, |f| f.0)).collect();
        let right: Vec<u32> = vertices.iter().map(|v| v.faces.map_or(0, |f| f.1)).collect();
        e.col(&Col::V2(&x0))?;
        e.col(&Col::U8(&tag))?;
        e.col(&Col::U32(&left))?;
        e.col(&Col::U32(&right))?;
    }
    let ev = &c.events;
    let mut offsets = vec![0u64];
    let mut particles = Vec::new();
    for CrackEvent { particles: p, .. } in ev {
        particles.extend(p.iter().map(|&i| i as u64));
        offsets.push(particles.len() as u64);
    }
    let time: Vec<Real> = ev.iter().map(|x| x.time).collect();
    let step: Vec<u64> = ev.iter().map(|x| x.step).collect();
    let crack: Vec<u64> = ev.iter().map(|x| x.crack as u64).collect();
    let kind: Vec<u8> = ev
        .iter()
        .map(|x| match x.kind {
            EventKind::Nucleate => 0,
            EventKind::Propagate => 1,
            EventKind::Arrest => 2,
        })
        .collect();
    let value: Vec<Real> = ev.iter().map(|x| x.value).collect();
    e.col(&Col::F64(&time))?;
    e.col(&Col::U64(&step))?;
    e.col(&Col::U64(&crack))?;
    e.col(&Col::U8(&kind))?;
    e.col(&Col::U64(&offsets))?;
    e.col(&Col::U64(&particles))?;
    e.col(&Col::F64(&value))?;
    for rows in [&c.reduced_quadrature_rows, &c.reduced_particle_rows] {
        let keys: Vec<u64> = rows.keys().map(|&k| k as u64).collect();
        let bases: Vec<u8> = rows.values().map(|&b| basis_tag(b)).collect();
        e.col(&Col::U64(&keys))?;
        e.col(&Col::U8(&bases))?;
    }
    Ok(e.w)
}

/// The payload: every section. Written in this order; read by tag.
fn write_payload<W: Write>(
    e: &mut Enc<W>,
    sim: &Simulation,
    case_text: &str,
    progress: &RunProgress,
) -> std::io::Result<()> {
    let m = &sim.model;
    e.section_bytes(b"META", &meta_bytes(sim, case_text, progress)?)?;
    // Exhaustive destructuring: a field added to a store fails to compile
    // here until the checkpoint carries it (and FORMAT_VERSION is bumped).
    let Particles { x0, u, v, a, f_int, f_ext, mass, volume, spacing, support, temperature, body, flags, face_side } =
        &m.particles;
    let flag_bytes: Vec<u8> = flags.iter().map(|f| f.0).collect();
    // Crack-face sides: a tag (0 none, 1 left, 2 right) and the geometry.
    let side_tag: Vec<u8> = face_side.iter().map(|s| s.map_or(0, |f| if f.left { 1 } else { 2 })).collect();
    let side_of = |pick: fn(&FaceSide) -> Vec2| -> Vec<Vec2> {
        face_side.iter().map(|s| s.as_ref().map_or(Vec2::zeros(), pick)).collect()
    };
    let (side_vertex, side_in, side_out) = (side_of(|f| f.vertex), side_of(|f| f.incoming), side_of(|f| f.outgoing));
    let side_reach: Vec<Real> = face_side.iter().map(|s| s.map_or(0.0, |f| f.reach)).collect();
    e.section(
        b"PART",
        &[
            Col::V2(x0),
            Col::V2(u),
            Col::V2(v),
            Col::V2(a),
            Col::V2(f_int),
            Col::V2(f_ext),
            Col::F64(mass),
            Col::F64(volume),
            Col::F64(spacing),
            Col::F64(support),
            Col::F64(temperature),
            Col::U32(body),
            Col::U8(&flag_bytes),
            Col::U8(&side_tag),
            Col::V2(&side_vertex),
            Col::V2(&side_in),
            Col::V2(&side_out),
            Col::F64(&side_reach),
        ],
    )?;
    let QuadraturePoints {
        x0,
        weight,
        body,
        f,
        tau,
        eps_p,
        eps_p_rate,
        temperature,
        damage,
        pw,
        pw_zz,
        f_carry_slot,
        f_carry,
        eroded,
    } = &m.quad;
    let eroded_bytes: Vec<u8> = eroded.iter().map(|&e| e as u8).collect();
    // `F`, `τ` and `P w` are kept as their block entries (`P w` in two
    // columns); the format stores the full tensors.
    let full = |c: &[Block2]| -> Vec<Tensor3> { c.iter().map(Block2::to_tensor).collect() };
    let pw: Vec<Tensor3> = pw.iter().zip(pw_zz).map(|(p, zz)| Block2::from_parts(p, *zz).to_tensor()).collect();
    let (f, tau) = (full(f), full(tau));
    e.section(
        b"QUAD",
        &[
            Col::V2(x0),
            Col::F64(weight),
            Col::U32(body),
            Col::T3(&f),
            Col::T3(&tau),
            Col::F64(eps_p),
            Col::F64(eps_p_rate),
            Col::F64(temperature),
            Col::F64(damage),
            Col::T3(&pw),
            Col::U32(f_carry_slot),
            Col::U8(&eroded_bytes),
        ],
    )?;
    e.section(b"FCAR", &[Col::T3(f_carry)])?;
    let qo = offsets_u64(&m.qp_shape.offsets);
    e.section(b"QTAB", &table_cols(&m.qp_shape, &qo))?;
    let po = offsets_u64(&m.particle_shape.offsets);
    e.section(b"PTAB", &table_cols(&m.particle_shape, &po))?;
    // `value` and `grad` are copies of the quadrature table's entries in
    // gather order: restored from the table on reading.
    let Gather { offsets, entry, point, value: _, grad: _ } = &m.gather;
    let go = offsets_u64(offsets);
    e.section(b"GATH", &[Col::U64(&go), Col::U32(entry), Col::U32(point)])?;
    e.section_bytes(b"BODY", &body_bytes(&m.bodies)?)?;
    e.section(b"FCON", &[Col::V2(&sim.f_contact)])?;
    if let Some(c) = &sim.contact {
        e.section_bytes(b"CONT", &contact_bytes(c)?)?;
    }
    if let Some(c) = &sim.cracks {
        e.section_bytes(b"CRAK", &crack_bytes(c)?)?;
    }
    e.section_bytes(b"END!", &[])
}

/// The simulation state as checkpoint payload bytes, without the header:
/// two simulations in the same state give the same bytes (tests compare a
/// resumed run with an uninterrupted one this way).
pub fn state_bytes(sim: &Simulation, case: &Case, progress: &RunProgress) -> Vec<u8> {
    let text = toml::to_string_pretty(&self_contained(case)).unwrap_or_default();
    let mut e = Enc { w: Vec::new() };
    write_payload(&mut e, sim, &text, progress).expect("writing to memory cannot fail");
    e.w
}

/// Write a checkpoint of `sim` (a run of `case` with outputs at `progress`)
/// to `path`, atomically: temporary sibling, `fsync`, rename, directory
/// `fsync`. Returns the file size in bytes.
pub fn write(path: &Path, sim: &Simulation, case: &Case, progress: &RunProgress) -> Result<u64, CheckpointError> {
    let io_err = |source| CheckpointError::Io { path: path.to_path_buf(), source };
    let case_text = toml::to_string_pretty(&self_contained(case))
        .map_err(|e| io_err(std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string())))?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io_err)?;
    }
    let tmp = crate::io::temporary_sibling(path, "").map_err(io_err)?;
    let result = (|| -> std::io::Result<u64> {
        let writer = this_writer();
        let mut file = File::create(&tmp)?;
        let mut head = Enc { w: &mut file };
        head.raw(&MAGIC)?;
        head.u32(FORMAT_VERSION)?;
        head.u32(writer.len() as u32)?;
        head.raw(writer.as_bytes())?;
        let len_at = 16 + writer.len() as u64;
        head.u64(0)?;
        head.u32(0)?;
        let mut body = Enc {
            w: BufWriter::with_capacity(1 << 20, Checksummed { inner: file, hasher: crc32fast::Hasher::new(), len: 0 }),
        };
        write_payload(&mut body, sim, &case_text, progress)?;
        let Checksummed { inner: mut file, hasher, len } = body.w.into_inner().map_err(|e| e.into_error())?;
        file.seek(SeekFrom::Start(len_at))?;
        file.write_all(&len.to_le_bytes())?;
        file.write_all(&hasher.finalize().to_le_bytes())?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)?;
        sync_directory(path);
        Ok(len_at + 12 + len)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io_err)
}

/// Make a rename durable: `fsync` the directory (Unix; elsewhere a no-op).
fn sync_directory(path: &Path) {
    #[cfg(unix)]
    if let Some(dir) = path.parent() {
        let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
}

// ---------------------------------------------------------------- reading

/// Little-endian decoder over a byte slice; every read is bounds-checked,
/// so a hostile file gives an error, never a panic or a huge allocation.
struct Dec<'a> {
    b: &'a [u8],
    pos: usize,
    what: &'static str,
}

impl<'a> Dec<'a> {
    fn new(b: &'a [u8], what: &'static str) -> Self {
        Dec { b, pos: 0, what }
    }
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        match self.pos.checked_add(n) {
            Some(end) if end <= self.b.len() => {
                let s = &self.b[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            _ => Err(format!("section {} ends early (wanted {n} more bytes at offset {})", self.what, self.pos)),
        }
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    fn usize(&mut self) -> Result<usize, String> {
        let v = self.u64()?;
        usize::try_from(v).map_err(|_| format!("section {}: value {v} out of range", self.what))
    }
    fn f64(&mut self) -> Result<Real, String> {
        Ok(Real::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    fn str(&mut self) -> Result<String, String> {
        let n = self.usize()?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| format!("section {}: text is not UTF-8", self.what))
    }
    /// A column's bytes: count, then `count × size` bytes (checked before
    /// anything is allocated).
    fn column(&mut self, size: usize) -> Result<(usize, &'a [u8]), String> {
        let n = self.usize()?;
        let bytes = n.checked_mul(size).ok_or_else(|| format!("section {}: column length {n} overflows", self.what))?;
        Ok((n, self.take(bytes)?))
    }
    fn f64s(&mut self) -> Result<Vec<Real>, String> {
        let (_, b) = self.column(8)?;
        Ok(b.chunks_exact(8).map(|c| Real::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
    }
    fn v2s(&mut self) -> Result<Vec<Vec2>, String> {
        let (_, b) = self.column(16)?;
        Ok(b.chunks_exact(16)
            .map(|c| {
                let x = Real::from_le_bytes(c[..8].try_into().expect("8 bytes"));
                let y = Real::from_le_bytes(c[8..].try_into().expect("8 bytes"));
                Vec2::new(x, y)
            })
            .collect())
    }
    fn t3s(&mut self) -> Result<Vec<Tensor3>, String> {
        let (_, b) = self.column(72)?;
        Ok(b.chunks_exact(72)
            .map(|c| {
                let v: Vec<Real> =
                    c.chunks_exact(8).map(|x| Real::from_le_bytes(x.try_into().expect("8 bytes"))).collect();
                Tensor3::from_column_slice(&v)
            })
            .collect())
    }
    fn u32s(&mut self) -> Result<Vec<u32>, String> {
        let (_, b) = self.column(4)?;
        Ok(b.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes"))).collect())
    }
    fn u64s(&mut self) -> Result<Vec<u64>, String> {
        let (_, b) = self.column(8)?;
        Ok(b.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
    }
    fn usizes(&mut self) -> Result<Vec<usize>, String> {
        self.u64s()?
            .into_iter()
            .map(|v| usize::try_from(v).map_err(|_| format!("section {}: value {v} out of range", self.what)))
            .collect()
    }
    fn u8s(&mut self) -> Result<Vec<u8>, String> {
        Ok(self.column(1)?.1.to_vec())
    }
    fn finish(&self) -> Result<(), String> {
        if self.pos == self.b.len() {
            Ok(())
        } else {
            Err(format!("section {} has {} unread bytes", self.what, self.b.len() - self.pos))
        }
    }
}

/// The sections of a payload by tag.
/// Sections of a payload: `(tag, body)` in file order.
type Sections<'a> = Vec<([u8; 4], &'a [u8])>;

fn sections(payload: &[u8]) -> Result<Sections<'_>, String> {
    let mut d = Dec::new(payload, "payload");
    let mut out: Sections = Vec::new();
    loop {
        let tag: [u8; 4] = d.take(4)?.try_into().expect("4 bytes");
        let len = d.usize()?;
        let body = d.take(len)?;
        if &tag == b"END!" {
            break;
        }
        const KNOWN: [&[u8; 4]; 11] =
            [b"META", b"PART", b"QUAD", b"FCAR", b"QTAB", b"PTAB", b"GATH", b"BODY", b"FCON", b"CONT", b"CRAK"];
        if !KNOWN.contains(&&tag) {
            return Err(format!("unknown section '{}'", String::from_utf8_lossy(&tag)));
        }
        if out.iter().any(|(t, _)| *t == tag) {
            return Err(format!("section '{}' appears twice", String::from_utf8_lossy(&tag)));
        }
        out.push((tag, body));
    }
    d.finish()?;
    Ok(out)
}

fn section<'a>(all: &Sections<'a>, tag: &[u8; 4], what: &'static str) -> Result<Dec<'a>, String> {
    all.iter()
        .find(|(t, _)| t == tag)
        .map(|(_, b)| Dec::new(b, what))
        .ok_or_else(|| format!("section {what} is missing"))
}

fn read_table(d: &mut Dec, rows: usize, columns: usize, what: &str) -> Result<ShapeTable, String> {
    let offsets = d.usizes()?;
    let index = d.u32s()?;
    let value = d.f64s()?;
    let grad = d.v2s()?;
    d.finish()?;
    let nnz = index.len();
    let ok = offsets.len() == rows + 1
        && offsets.first() == Some(&0)
        && offsets.last() == Some(&nnz)
        && offsets.windows(2).all(|w| w[0] <= w[1])
        && value.len() == nnz
        && grad.len() == nnz
        && index.iter().all(|&i| (i as usize) < columns);
    if !ok {
        return Err(format!("{what} shape table is inconsistent with {rows} rows and {columns} particles"));
    }
    Ok(ShapeTable { offsets, index, value, grad })
}

fn same_len(what: &str, n: usize, lens: &[usize]) -> Result<(), String> {
    if lens.iter().all(|&l| l == n) {
        Ok(())
    } else {
        Err(format!("{what} columns have different lengths ({lens:?}, expected {n})"))
    }
}

/// Read a checkpoint file: header, version, checksum, then the state.
pub fn read(path: &Path) -> Result<Restored, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointError::Io { path: path.to_path_buf(), source })?;
    let damaged = |reason: String| CheckpointError::Damaged { path: path.to_path_buf(), reason };
    if bytes.len() < 8 || bytes[..8] != MAGIC {
        return Err(CheckpointError::NotACheckpoint { path: path.to_path_buf() });
    }
    let mut h = Dec::new(&bytes[8..], "header");
    let version = h.u32().map_err(damaged)?;
    let writer_len = h.u32().map_err(damaged)? as usize;
    let writer = String::from_utf8_lossy(h.take(writer_len.min(4096)).map_err(damaged)?).to_string();
    if version != FORMAT_VERSION {
        return Err(CheckpointError::Version {
            path: path.to_path_buf(),
            found: version,
            supported: FORMAT_VERSION,
            writer,
        });
    }
    let payload_len = h.u64().map_err(damaged)?;
    let crc = h.u32().map_err(damaged)?;
    let payload = &bytes[8 + h.pos..];
    if payload.len() as u64 != payload_len {
        return Err(damaged(format!("{} payload bytes, the header says {payload_len} (truncated?)", payload.len())));
    }
    if crc32fast::hash(payload) != crc {
        return Err(damaged("checksum mismatch".into()));
    }
    let all = sections(payload).map_err(damaged)?;
    let mut meta = section(&all, b"META", "META").map_err(damaged)?;
    let case_text = meta.str().map_err(damaged)?;
    let case = Case::from_str_with(&case_text, &format!("<case in {}>", path.display()), &[])
        .map_err(|e| CheckpointError::Case { path: path.to_path_buf(), message: e.to_string() })?;
    let (sim, progress) = restore(&all, &mut meta, &case).map_err(damaged)?;
    Ok(Restored { path: path.to_path_buf(), writer, case, sim, progress })
}

fn restore(all: &Sections, meta: &mut Dec, case: &Case) -> Result<(Simulation, RunProgress), String> {
    let time = meta.f64()?;
    let step = meta.u64()?;
    let dt = meta.f64()?;
    let speed_bound = meta.f64()?;
    let mut e = [0.0; 6];
    for v in &mut e {
        *v = meta.f64()?;
    }
    let [kinetic, internal, rigid_kinetic, contact_work, rigid_work, initial_kinetic] = e;
    let energies = Energies { kinetic, internal, rigid_kinetic, contact_work, rigid_work, initial_kinetic };
    let progress = RunProgress {
        snapshot_times: meta.f64s()?,
        history_bytes: meta.u64()?,
        next_snapshot: meta.f64()?,
        next_checkpoint: meta.f64()?,
        max_drift: meta.f64()?,
    };
    let n = meta.usize()?;
    let nq = meta.usize()?;
    let heat_every = meta.u64()?;
    let heat_pending = meta.f64()?;
    let driven_constraints = match meta.u32()? {
        0 => false,
        1 => true,
        v => return Err(format!("driven-constraint flag {v} is neither 0 nor 1")),
    };
    meta.finish()?;
    if heat_every == 0 || !(heat_pending.is_finite() && heat_pending >= 0.0) {
        return Err(format!("conduction every {heat_every} steps with {heat_pending} s pending is not usable"));
    }
    if !(dt.is_finite() && dt > 0.0 && time.is_finite()) {
        return Err(format!("time {time} s or step {dt} s is not usable"));
    }

    let mut d = section(all, b"PART", "PART")?;
    let particles = Particles {
        x0: d.v2s()?,
        u: d.v2s()?,
        v: d.v2s()?,
        a: d.v2s()?,
        f_int: d.v2s()?,
        f_ext: d.v2s()?,
        mass: d.f64s()?,
        volume: d.f64s()?,
        spacing: d.f64s()?,
        support: d.f64s()?,
        temperature: d.f64s()?,
        body: d.u32s()?,
        flags: d.u8s()?.into_iter().map(ParticleFlags).collect(),
        face_side: Vec::new(),
    };
    let mut particles = particles;
    let (tags, vertex, incoming, outgoing, reach) = (d.u8s()?, d.v2s()?, d.v2s()?, d.v2s()?, d.f64s()?);
    if [vertex.len(), incoming.len(), outgoing.len(), reach.len()].iter().any(|&l| l != tags.len()) {
        return Err("crack-face side columns differ in length".to_string());
    }
    particles.face_side = (0..tags.len())
        .map(|i| match tags[i] {
            0 => Ok(None),
            t @ (1 | 2) => Ok(Some(FaceSide {
                vertex: vertex[i],
                incoming: incoming[i],
                outgoing: outgoing[i],
                left: t == 1,
                reach: reach[i],
            })),
            t => Err(format!("particle {i}: unknown crack-face tag {t}")),
        })
        .collect::<Result<_, String>>()?;
    d.finish()?;
    let p = &particles;
    same_len(
        "particle",
        n,
        &[
            p.x0.len(),
            p.u.len(),
            p.v.len(),
            p.a.len(),
            p.f_int.len(),
            p.f_ext.len(),
            p.mass.len(),
            p.volume.len(),
            p.spacing.len(),
            p.support.len(),
            p.temperature.len(),
            p.body.len(),
            p.flags.len(),
        ],
    )?;
    if p.mass.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
        return Err("a particle mass is not positive".into());
    }

    let mut d = section(all, b"QUAD", "QUAD")?;
    // The columns in the file's order (`P w` in the middle, split on load).
    let (x0, weight, body) = (d.v2s()?, d.f64s()?, d.u32s()?);
    let f = d.t3s()?.iter().map(Block2::block_part).collect();
    let tau = d.t3s()?.iter().map(Block2::block_part).collect();
    let (eps_p, eps_p_rate, temperature, damage) = (d.f64s()?, d.f64s()?, d.f64s()?, d.f64s()?);
    let pw = d.t3s()?;
    let (f_carry_slot, eroded) = (d.u32s()?, d.u8s()?.into_iter().map(|b| b != 0).collect());
    d.finish()?;
    let mut c = section(all, b"FCAR", "FCAR")?;
    let f_carry = c.t3s()?;
    c.finish()?;
    let quad = QuadraturePoints {
        x0,
        weight,
        body,
        f,
        tau,
        eps_p,
        eps_p_rate,
        temperature,
        damage,
        pw: pw.iter().map(|t| Block2::block_part(t).in_plane()).collect(),
        pw_zz: pw.iter().map(|t| t[(2, 2)]).collect(),
        f_carry_slot,
        f_carry,
        eroded,
    };
    let q = &quad;
    same_len(
        "quadrature-point",
        nq,
        &[
            q.x0.len(),
            q.weight.len(),
            q.body.len(),
            q.f.len(),
            q.tau.len(),
            q.eps_p.len(),
            q.eps_p_rate.len(),
            q.temperature.len(),
            q.damage.len(),
            q.pw.len(),
            q.pw_zz.len(),
            q.f_carry_slot.len(),
            q.eroded.len(),
        ],
    )?;
    if q.f_carry_slot.iter().any(|&s| s != NO_CARRY && s as usize >= q.f_carry.len()) {
        return Err("a quadrature point names a carried deformation-gradient jump that does not exist".into());
    }

    let qp_shape = read_table(&mut section(all, b"QTAB", "QTAB")?, nq, n, "quadrature")?;
    let particle_shape = read_table(&mut section(all, b"PTAB", "PTAB")?, n, n, "particle")?;
    let mut d = section(all, b"GATH", "GATH")?;
    let mut gather =
        Gather { offsets: d.usizes()?, entry: d.u32s()?, point: d.u32s()?, value: Vec::new(), grad: Vec::new() };
    d.finish()?;
    let nnz = qp_shape.nnz();
    let gather_ok = gather.offsets.len() == n + 1
        && gather.offsets.first() == Some(&0)
        && gather.offsets.last() == Some(&gather.entry.len())
        && gather.offsets.windows(2).all(|w| w[0] <= w[1])
        && gather.point.len() == gather.entry.len()
        && gather.entry.iter().all(|&k| (k as usize) < nnz)
        && gather.point.iter().all(|&q| (q as usize) < nq);
    if !gather_ok {
        return Err("the force gather is inconsistent with the tables".into());
    }
    gather.value = gather.entry.iter().map(|&k| qp_shape.value[k as usize]).collect();
    gather.grad = gather.entry.iter().map(|&k| qp_shape.grad[k as usize]).collect();

    let mut d = section(all, b"BODY", "BODY")?;
    let nb = d.usize()?;
    let setups = case.body_setups();
    if nb != setups.len() {
        return Err(format!("{nb} bodies, but the case has {}", setups.len()));
    }
    let mut bodies = Vec::with_capacity(nb);
    for s in &setups {
        let name = d.str()?;
        let v: Vec<usize> = (0..6).map(|_| d.usize()).collect::<Result<_, _>>()?;
        if name != s.name || v[0] > v[1] || v[1] > n || v[2] > v[3] || v[3] > nq {
            return Err(format!("body '{name}' does not match the case or the stores"));
        }
        bodies.push(BodyInfo { name, particles: v[0]..v[1], quad_points: v[2]..v[3], columns: v[4], rows: v[5] });
    }
    d.finish()?;
    if p.body.iter().chain(&q.body).any(|&b| b as usize >= nb) {
        return Err("a particle or quadrature point names a body that does not exist".into());
    }

    let mut d = section(all, b"FCON", "FCON")?;
    let f_contact = d.v2s()?;
    d.finish()?;
    if f_contact.len() != n {
        return Err(format!("{} contact forces for {n} particles", f_contact.len()));
    }

    let materials = setups.into_iter().map(|s| s.material).collect();
    let model =
        Model { mode: case.geometry.mode, particles, quad, materials, bodies, qp_shape, particle_shape, gather };
    let mut sim = Simulation::new(model, TimeStepRule::Fixed(dt));
    sim.time = time;
    sim.step = step;
    sim.energies = energies;
    sim.speed_bound = speed_bound;
    sim.f_contact = f_contact;
    sim.driven_constraints = driven_constraints;
    sim.heat_every = heat_every;
    sim.heat_pending = heat_pending;
    sim.heat = case.heat_conduction_for(&sim.model).map_err(|e| format!("heat conduction: {e}"))?;
    sim.contact = restore_contact(all, case, n)?;
    sim.cracks = restore_cracks(all, case, &sim.model)?;
    Ok((sim, progress))
}

fn restore_contact(all: &Sections, case: &Case, n: usize) -> Result<Option<ContactSystem>, String> {
    let stored = all.iter().any(|(t, _)| t == b"CONT");
    if case.rigid_bodies.is_empty() {
        return if stored { Err("contact state without rigid bodies in the case".into()) } else { Ok(None) };
    }
    let mut d = section(all, b"CONT", "CONT")?;
    let mut bodies = case.rigid_bodies().map_err(|e| e.to_string())?;
    if d.usize()? != bodies.len() {
        return Err("the number of rigid bodies does not match the case".into());
    }
    for b in &mut bodies {
        let name = d.str()?;
        let pv = d.v2s()?;
        if name != b.name || pv.len() != 2 {
            return Err(format!("rigid body '{name}' does not match the case"));
        }
        b.position = pv[0];
        b.velocity = pv[1];
    }
    let particles = d.u32s()?;
    let (kind, body, feature) = (d.u8s()?, d.u32s()?, d.u32s()?);
    let ns = particles.len();
    if kind.len() != ns || body.len() != ns || feature.len() != ns {
        return Err("slave pairing columns have different lengths".into());
    }
    if particles.windows(2).any(|w| w[0] >= w[1]) || particles.last().is_some_and(|&i| i as usize >= n) {
        return Err("slave particles are not ascending particle indices".into());
    }
    let mut slaves = SlaveSet::from_indices(particles.iter().map(|&i| i as usize));
    for k in 0..ns {
        let b = body[k];
        let vertices = bodies.get(b as usize).map_or(0, |rb| rb.vertex_count());
        let pairing = match kind[k] {
            0 => None,
            1 | 2 if (feature[k] as usize) < vertices => Some(Pairing {
                body: b,
                feature: if kind[k] == 1 {
                    MasterFeature::Segment(feature[k])
                } else {
                    MasterFeature::Vertex(feature[k])
                },
            }),
            _ => return Err(format!("slave {k} has an invalid pairing")),
        };
        slaves.set_pairing(k, pairing);
    }
    let acc = ContactAccumulators {
        work_on_particles: d.f64s()?,
        work_on_body: d.f64s()?,
        reaction: d.v2s()?,
        active_per_body: d.usizes()?,
    };
    d.finish()?;
    let mut c = ContactSystem::new(bodies, slaves, case.contact).map_err(|e| e.to_string())?;
    c.restore_accumulators(acc).map_err(|e| e.to_string())?;
    Ok(Some(c))
}

/// Most cells of the segment bins one restored crack segment may span: a
/// real segment spans a few supports, so this only stops a damaged file
/// from making the binning loop over an absurd range.
const MAX_SEGMENT_CELLS: Real = 1e4;

fn restore_cracks(all: &Sections, case: &Case, model: &Model) -> Result<Option<CrackGrowth>, String> {
    let stored = all.iter().any(|(t, _)| t == b"CRAK");
    if case.fracture.criterion == Criterion::None {
        return if stored { Err("crack state, but the case has no fracture criterion".into()) } else { Ok(None) };
    }
    let (n, nq) = (model.particles.len(), model.quad.len());
    let mut d = section(all, b"CRAK", "CRAK")?;
    let criterion = match d.u32()? {
        0 => Criterion::EffectiveStrain,
        1 => Criterion::Damage,
        2 => Criterion::None,
        t => return Err(format!("unknown fracture criterion tag {t}")),
    };
    let mut v = [0.0; 6];
    for x in &mut v {
        *x = d.f64()?;
    }
    let [critical_effective_strain, critical_damage, radius_factor, fan_angle, offset_ratio, nucleation_distance_factor] =
        v;
    let erode_inverted = match d.u32()? {
        0 => false,
        1 => true,
        other => return Err(format!("erosion flag {other} is neither 0 nor 1")),
    };
    let params = FractureParameters {
        criterion,
        critical_effective_strain,
        critical_damage,
        radius_factor,
        fan_angle,
        offset_ratio,
        nucleation_distance_factor,
        erode_inverted,
    };
    if params != case.fracture {
        return Err("the fracture parameters do not match the case".into());
    }
    let count = d.usize()?;
    let mut cracks = Vec::with_capacity(count.min(1024));
    for k in 0..count {
        let id = d.usize()?;
        let tip = match d.u64()? {
            u64::MAX => None,
            t if t < n as u64 => Some(t as usize),
            t => return Err(format!("crack {k}: tip particle {t} of {n}")),
        };
        let offset = d.f64()?;
        let nucleated = (d.f64()?, d.u64()?);
        let arrested_flag = d.u32()?;
        let arrested_at = (d.f64()?, d.u64()?);
        let arrested = match arrested_flag {
            0 => None,
            1 => Some(arrested_at),
            f => return Err(format!("crack {k}: arrest flag {f}")),
        };
        let (x0, tag, left, right) = (d.v2s()?, d.u8s()?, d.u32s()?, d.u32s()?);
        let m = x0.len();
        if id != k
            || m < 2
            || [tag.len(), left.len(), right.len()] != [m; 3]
            || !(offset.is_finite() && offset >= 0.0)
            || !nucleated.0.is_finite()
            || arrested.is_some_and(|a| !a.0.is_finite())
            || x0.iter().any(|p| !(p.x.is_finite() && p.y.is_finite()))
        {
            return Err(format!("crack {k} is inconsistent"));
        }
        let vertices = (0..m)
            .map(|j| match tag[j] {
                0 => Ok(CrackVertex { x0: x0[j], faces: None }),
                1 if (left[j] as usize) < n && (right[j] as usize) < n => {
                    Ok(CrackVertex { x0: x0[j], faces: Some((left[j], right[j])) })
                }
                _ => Err(format!("crack {k}: vertex {j} has invalid faces")),
            })
            .collect::<Result<Vec<_>, String>>()?;
        cracks.push(Crack { id, vertices, tip, offset, nucleated, arrested });
    }
    let (time, step, crack, kind) = (d.f64s()?, d.u64s()?, d.usizes()?, d.u8s()?);
    let (offsets, particles, value) = (d.usizes()?, d.usizes()?, d.f64s()?);
    let ne = time.len();
    let events_ok = [step.len(), crack.len(), kind.len(), value.len()] == [ne; 4]
        && offsets.len() == ne + 1
        && offsets.first() == Some(&0)
        && offsets.last() == Some(&particles.len())
        && offsets.windows(2).all(|w| w[0] <= w[1])
        && crack.iter().all(|&c| c < cracks.len())
        && particles.iter().all(|&i| i < n);
    if !events_ok {
        return Err("the crack event log is inconsistent".into());
    }
    let events = (0..ne)
        .map(|k| {
            let kind = match kind[k] {
                0 => EventKind::Nucleate,
                1 => EventKind::Propagate,
                2 => EventKind::Arrest,
                t => return Err(format!("crack event {k}: unknown kind {t}")),
            };
            Ok(CrackEvent {
                time: time[k],
                step: step[k],
                crack: crack[k],
                kind,
                particles: particles[offsets[k]..offsets[k + 1]].to_vec(),
                value: value[k],
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut reduced = [Default::default(), Default::default()];
    for (map, (what, rows)) in reduced.iter_mut().zip([("quadrature", nq), ("particle", n)]) {
        let (keys, bases) = (d.usizes()?, d.u8s()?);
        if keys.len() != bases.len() || keys.iter().any(|&k| k >= rows) {
            return Err(format!("the reduced {what} rows are inconsistent"));
        }
        *map = keys
            .into_iter()
            .zip(bases)
            .map(|(k, b)| match b {
                0 => Ok((k, Basis::Bilinear)),
                1 => Ok((k, Basis::Linear)),
                2 => Ok((k, Basis::Constant)),
                t => Err(format!("reduced {what} row {k}: unknown basis tag {t}")),
            })
            .collect::<Result<_, String>>()?;
    }
    d.finish()?;
    // The segments are binned in cells of the largest support (as
    // `CrackGrowth::refresh_segments` does).
    let cell = model.particles.support.iter().cloned().fold(0.0, Real::max);
    let cell = if cell > 0.0 && cell.is_finite() { cell } else { 1.0 };
    for c in &cracks {
        for (a, b) in c.segments() {
            let span = (a - b).abs() / cell;
            if span.iter().any(|&s| s > MAX_SEGMENT_CELLS) {
                return Err(format!("crack {}: a segment spans more than {MAX_SEGMENT_CELLS} cells", c.id));
            }
        }
    }
    let [reduced_quadrature_rows, reduced_particle_rows] = reduced;
    Ok(Some(CrackGrowth::from_state(params, cracks, events, reduced_quadrature_rows, reduced_particle_rows, model)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoder_refuses_lengths_beyond_the_data() {
        let mut bytes = Vec::new();
        bytes.extend_from_slice(&(u64::MAX / 2).to_le_bytes());
        let mut d = Dec::new(&bytes, "test");
        assert!(d.f64s().unwrap_err().contains("test"));
        let mut d = Dec::new(&bytes[..4], "test");
        assert!(d.u64().is_err());
    }

    #[test]
    fn columns_round_trip_bit_for_bit() {
        let reals = [0.0, -0.0, 1.5e-300, Real::MAX, Real::NAN, Real::INFINITY, 1.0 / 3.0];
        let v2: Vec<Vec2> = reals.iter().map(|&x| Vec2::new(x, -x)).collect();
        let t3: Vec<Tensor3> =
            reals.iter().map(|&x| Tensor3::from_fn(|i, j| x * (i as Real + 3.0 * j as Real))).collect();
        let mut e = Enc { w: Vec::new() };
        e.col(&Col::F64(&reals)).unwrap();
        e.col(&Col::V2(&v2)).unwrap();
        e.col(&Col::T3(&t3)).unwrap();
        e.col(&Col::U32(&[1, u32::MAX])).unwrap();
        let mut d = Dec::new(&e.w, "test");
        let bits = |v: &[Real]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&d.f64s().unwrap()), bits(&reals));
        let back = d.v2s().unwrap();
        assert_eq!(
            bits(&back.iter().flat_map(|p| [p.x, p.y]).collect::<Vec<_>>()),
            bits(&v2.iter().flat_map(|p| [p.x, p.y]).collect::<Vec<_>>())
        );
        let back = d.t3s().unwrap();
        assert_eq!(
            bits(&back.iter().flat_map(|t| t.as_slice().to_vec()).collect::<Vec<_>>()),
            bits(&t3.iter().flat_map(|t| t.as_slice().to_vec()).collect::<Vec<_>>())
        );
        assert_eq!(d.u32s().unwrap(), vec![1, u32::MAX]);
        d.finish().unwrap();
    }

    #[test]
    fn listing_orders_by_step_and_rotation_keeps_the_newest() {
        let dir = std::env::temp_dir().join(format!("plugsim-ckpt-list-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for s in [30, 4, 200] {
            std::fs::write(dir.join(file_name(s)), b"x").unwrap();
        }
        std::fs::write(dir.join(".checkpoint-000000000001.ckpt.tmp1-0"), b"x").unwrap();
        std::fs::write(dir.join("notes.txt"), b"x").unwrap();
        let steps: Vec<u64> = list(&dir).iter().map(|(s, _)| *s).collect();
        assert_eq!(steps, vec![4, 30, 200]);
        rotate(&dir, 2).unwrap();
        let steps: Vec<u64> = list(&dir).iter().map(|(s, _)| *s).collect();
        assert_eq!(steps, vec![30, 200]);
        assert!(!dir.join(".checkpoint-000000000001.ckpt.tmp1-0").exists());
        assert!(dir.join("notes.txt").exists());
        remove_all(&dir).unwrap();
        assert!(list(&dir).is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
