//! Checkpoints: the complete state of a running simulation in one versioned
//! binary file, so that a run stopped at any point (Ctrl-C, SIGTERM, a
//! crash, a full queue slot) continues from its last checkpoint and
//! produces, bit for bit, what the uninterrupted run would have.
//!
//! # What is stored
//! The [`Simulation`] itself, through its serde derive: every field of
//! every type it holds (the particle and quadrature-point stores, both
//! shape-function tables, the force gather, the bodies, the clocks and the
//! energy account, the contact system with its rigid bodies, slaves,
//! pairings and running sums, the crack growth with its polylines, event
//! log and reduced rows), except the fields marked `#[serde(skip)]`, each
//! with a comment saying why and where it is rebuilt on reading:
//! the materials and the heat conduction (from the case, as a fresh run
//! builds them), the gather's copies of the table entries (from the table),
//! the crack segments and search grid (from the cracks and the particles),
//! the wall-clock stage timers and per-step scratch. Beside the simulation
//! the payload holds the case as resolved TOML text with the built-in
//! materials written out (so a checkpoint resumes without the case file
//! and without depending on the built-in material library of the reading
//! binary) and where the run's outputs stand ([`RunProgress`]).
//!
//! A field added to a store, or to any type the simulation holds, is
//! therefore in the next checkpoint without anyone editing this module; a
//! type that cannot be serialized fails to compile, and so does the length
//! check of a store read back (`Particles::columns_agree`,
//! `QuadraturePoints::columns_agree`) until the new column is listed
//! there. `checkpoint_round_trip_restores_every_field`
//! (`tests/checkpoint.rs`) takes a simulation with contact, a crack,
//! carried jumps and heat pending, writes and reads it, checks that the
//! model reads back printing (`Debug`) exactly as written and that both
//! copies, stepped on, stay equal in every field, so a field skipped by
//! mistake (and not at its default there) fails it; the kill-and-resume
//! tests compare the whole `Simulation` and every output file of a resumed
//! run with an uninterrupted one.
//!
//! The derived data (shape tables, gather, lumped masses) are stored rather
//! than rebuilt: a rebuild is deterministic today, but after a crack the
//! tables are patched locally and a global rebuild need not sum in the same
//! order, so only stored tables guarantee a bit-identical continuation. The
//! cost is size: about 32 to 35 bytes per quadrature-table entry
//! ([`crate::memory::Footprint::checkpoint_bytes`]).
//!
//! # File format
//! ```text
//! header   magic "PLUGCKPT" (8 bytes) | format version u32 | writer length u32
//!          | writer (UTF-8: "plugsim VERSION (COMMIT)") | payload length u64
//!          | CRC-32 of the payload u32                    (little-endian)
//! payload  postcard encoding of (case text, RunProgress, Simulation)
//! ```
//! The magic, the version and the writer come first in every format version,
//! so a reader can always say which version and which plugsim wrote a file
//! it cannot read; the length and the checksum are checked before anything
//! is decoded. A reader refuses every version but its own
//! ([`CheckpointError::Version`]): versions 1 to 3 were hand-written
//! sections of columns, versions 4 to 8 the postcard encoding (5 adds the
//! run's fastest particle, 6 the crack-tip allowance, the crack stage's last
//! time and the non-local fracture parameters, issue #19; 7 the adaptive
//! stable step and the deformable contact, issues #19 and #20; 8 the crack
//! events' own damage, [`crate::fracture::CrackEvent::damage`]; 9 their
//! adiabatic hardening; 10 the quadrature points' cell length; 11 the mass
//! scaling's added mass and its account; 12 the quadrature points'
//! triaxiality integrated over the plastic strain; 13 the count of points
//! eroded at the step's floor). The payload is
//! [postcard](https://docs.rs/postcard) 1.x, whose wire format is stable
//! within the major version: fields in declaration order, no names; an
//! `f64` as its eight IEEE-754 bytes, so values (NaN payloads, −0.0)
//! round-trip exactly; integers, lengths and enum tags as varints;
//! nalgebra's vectors and matrices (feature `serde-serialize-no-std`) as
//! their components without a length. Because fields carry no names, adding,
//! removing or reordering a field of any stored type changes the format:
//! bump [`FORMAT_VERSION`] with it.
//!
//! Postcard rather than bincode: bincode's last release (3.0.0) is a
//! tombstone that says the project has ended and fails to compile; postcard
//! is maintained, small (serde and `cobs` besides its own code) and its `to_io`
//! writes straight into the file's buffered writer. Hand-written sections
//! (formats 1 to 3) named every field of the stores once to write and once
//! to read; the derive names them nowhere.
//!
//! Measured on the coarse Børvik Case I at 10 µs (step 243: 11,520
//! particles, 43,976 points, 817,220 quadrature-table entries; release
//! build; timings are the best of five on a shared 2-core machine, so
//! approximate), format 3 → 4: file 49.6 → 40.3 MB (the crack-face side
//! is one byte for a particle off the cracks, `F`, `τ` and `P w` keep their
//! five block entries rather than nine, integers are varints); write, with
//! its `fsync`, about 156 → 80 ms; read with the checks about 80 → 75–110
//! ms; [`state_bytes`] about 42 → 65–70 ms; peak RSS of the run that writes
//! one checkpoint 159 → 151 MB (153 → 150 MB writing none), of a resume
//! 122 → 109 MB. Reading holds the file and the decoded state at once, as
//! format 3 did.
//!
//! # Reading
//! The file is read whole, its header and checksum checked, the payload
//! decoded (a damaged length or tag gives an error, and serde never
//! preallocates more than a bounded amount from a stored length), then the
//! decoded state is checked against the case and itself before anything
//! is rebuilt: every index the time loop follows (bodies, table columns,
//! gather entries, carried jumps, slaves and their pairings, crack tips and
//! faces) must be in range and the columns of a store of one length, so a
//! damaged file that still decodes gives an error, never a panic
//! (`altered_checkpoints_never_panic_the_reader`).
//!
//! # Writing
//! The payload streams through a 1 MiB buffer into the file while its
//! length and CRC are taken; no serialized copy of the state is held in
//! memory. The file is written to a hidden temporary sibling, `fsync`ed,
//! renamed over its final name and the directory `fsync`ed ([`write()`]): a
//! crash leaves either no new checkpoint or a complete one, and the older
//! checkpoints are untouched until the new one is safe ([`rotate`]).

use crate::case::{Case, MaterialSpec};
use crate::contact::ContactSystem;
use crate::fracture::{CrackGrowth, CrackVertex, Criterion};
use crate::material::Material;
use crate::math::{Real, Vec2};
use crate::model::{BodySetup, Model};
use crate::shape::ShapeTable;
use crate::step::Simulation;
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// First bytes of every checkpoint file.
pub const MAGIC: [u8; 8] = *b"PLUGCKPT";
/// The format this build writes and the only one it reads.
///
/// Versions 1 to 3 were hand-written sections of columns (version 1 before
/// heat conduction and crack growth were carried, version 2 adding them,
/// version 3 the deformation-gradient jumps carried over crack changes);
/// version 4 is the postcard encoding of the serde-derived state, version
/// 5 adds the run's fastest particle (`Simulation::fastest`), version 6 the
/// crack-tip allowance and the non-local fracture parameters, version 7
/// the adaptive stable step (`Simulation::stable`, `dt_previous`) and the
/// deformable contact (its masters, persistent pairs and work, the
/// `deformable` and `self_contact` switches; issue #20), version 8 the
/// crack events' own damage ([`crate::fracture::CrackEvent::damage`]),
/// version 9 their adiabatic hardening
/// ([`crate::fracture::CrackEvent::hardening`]), version 10 the
/// quadrature points' cell length
/// ([`crate::quadrature::QuadraturePoints::length`], the bulk viscosity's),
/// version 11 the mass scaling's added mass
/// ([`crate::particles::Particles::added_mass`],
/// [`crate::stability::AddedMass`], [`crate::step::Energies::mass_scaling`]),
/// version 12 the quadrature points' triaxiality integrated over the
/// plastic strain ([`crate::quadrature::QuadraturePoints::triaxiality_strain`]),
/// version 13 the count of points eroded at the step's floor
/// ([`crate::stability::StableStep::eroded`]), version 14 the fastest
/// particle's reference position, mass and crack-face flag
/// ([`crate::step::FastestParticle`]) and the non-local average's weight
/// ([`crate::fracture::FractureParameters::nonlocal_weight`]), version 15
/// the detached particles and the points their search has seen eroded
/// ([`crate::fracture::CrackGrowth::detach_isolated`]) and the kinetic
/// energy the crack changes moved ([`crate::step::Energies::crack_changes`]),
/// version 16 the axis as a wall of the contact
/// ([`crate::contact::ContactSystem::with_axis`]: its switch, last forces
/// and work), version 17 the fastest particle's live share of material
/// ([`crate::step::FastestParticle::live_share`]), version 18 no field of
/// its own: the history's new column `max_coefficient_gap`
/// ([`crate::output::HISTORY_COLUMNS`]; a checkpoint continues its
/// directory's `history.csv`, so an older one, whose file lacks the
/// column, is refused by its version rather than by the file's header).
pub const FORMAT_VERSION: u32 = 18;
/// Subdirectory of a run's output directory that holds its checkpoints.
pub const DIRECTORY: &str = "checkpoints";
/// File name extension of a checkpoint.
pub const EXTENSION: &str = "ckpt";

/// Where a run's outputs stood when the checkpoint was taken (the run
/// loop's own state besides the simulation).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    crate::io::remove_temporaries(dir);
    Ok(())
}

/// Remove every checkpoint of `dir` (a checkpoint directory): a fresh run
/// into a reused output directory must not leave the old run's checkpoints
/// for `plugsim resume` to find.
pub fn remove_all(dir: &Path) -> Result<(), CheckpointError> {
    for (_, path) in list(dir) {
        std::fs::remove_file(&path).map_err(|source| CheckpointError::Io { path: path.clone(), source })?;
    }
    crate::io::remove_temporaries(dir);
    Ok(())
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

/// A writer that counts and checksums what passes through it, and keeps
/// the first I/O error (postcard reports any as a full buffer).
struct Checksummed<W: Write> {
    inner: W,
    hasher: crc32fast::Hasher,
    len: u64,
    error: Option<std::io::Error>,
}

impl<W: Write> Write for Checksummed<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self.inner.write(buf) {
            Ok(n) => {
                self.hasher.update(&buf[..n]);
                self.len += n as u64;
                Ok(n)
            }
            Err(e) => {
                if e.kind() != std::io::ErrorKind::Interrupted {
                    self.error.get_or_insert_with(|| std::io::Error::new(e.kind(), e.to_string()));
                }
                Err(e)
            }
        }
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// The case with its built-in materials written out, as TOML text.
fn case_text(case: &Case) -> Result<String, toml::ser::Error> {
    toml::to_string_pretty(&self_contained(case))
}

/// The payload: the case text, the run's progress and the simulation, in
/// this order (read back as [`Payload`]).
fn payload<'a>(case_text: &'a str, progress: &'a RunProgress, sim: &'a Simulation) -> PayloadRef<'a> {
    (case_text, progress, sim)
}
type PayloadRef<'a> = (&'a str, &'a RunProgress, &'a Simulation);
/// The payload as decoded: the same shape owned.
type Payload = (String, RunProgress, Simulation);

/// The simulation state as checkpoint payload bytes, without the header:
/// two simulations in the same state give the same bytes (tests compare a
/// resumed run with an uninterrupted one this way).
pub fn state_bytes(sim: &Simulation, case: &Case, progress: &RunProgress) -> Vec<u8> {
    let text = case_text(case).unwrap_or_default();
    postcard::to_stdvec(&payload(&text, progress, sim)).expect("the state serializes to memory")
}

/// Write a checkpoint of `sim` (a run of `case` with outputs at `progress`)
/// to `path`, atomically: temporary sibling, `fsync`, rename, directory
/// `fsync`. Returns the file size in bytes.
pub fn write(path: &Path, sim: &Simulation, case: &Case, progress: &RunProgress) -> Result<u64, CheckpointError> {
    let io_err = |source| CheckpointError::Io { path: path.to_path_buf(), source };
    let text =
        case_text(case).map_err(|e| io_err(std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string())))?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io_err)?;
    }
    let tmp = crate::io::temporary_sibling(path, "").map_err(io_err)?;
    let result = (|| -> std::io::Result<u64> {
        let writer = this_writer();
        let mut file = File::create(&tmp)?;
        file.write_all(&MAGIC)?;
        file.write_all(&FORMAT_VERSION.to_le_bytes())?;
        file.write_all(&(writer.len() as u32).to_le_bytes())?;
        file.write_all(writer.as_bytes())?;
        // Payload length and CRC, filled in once the payload is written.
        let len_at = 16 + writer.len() as u64;
        file.write_all(&[0; 12])?;
        let mut body = BufWriter::with_capacity(
            1 << 20,
            Checksummed { inner: file, hasher: crc32fast::Hasher::new(), len: 0, error: None },
        );
        if let Err(e) = postcard::to_io(&payload(&text, progress, sim), &mut body) {
            return Err(body.get_mut().error.take().unwrap_or_else(|| {
                std::io::Error::new(std::io::ErrorKind::InvalidData, format!("the state does not serialize: {e}"))
            }));
        }
        let Checksummed { inner: mut file, hasher, len, .. } = body.into_inner().map_err(|e| e.into_error())?;
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

/// Read a checkpoint file: header, version, checksum, then the state.
pub fn read(path: &Path) -> Result<Restored, CheckpointError> {
    let bytes = std::fs::read(path).map_err(|source| CheckpointError::Io { path: path.to_path_buf(), source })?;
    let damaged = |reason: String| CheckpointError::Damaged { path: path.to_path_buf(), reason };
    if bytes.len() < 8 || bytes[..8] != MAGIC {
        return Err(CheckpointError::NotACheckpoint { path: path.to_path_buf() });
    }
    let field = |at: usize, len: usize| {
        bytes.get(at..at + len).ok_or_else(|| damaged(format!("the header ends early (at byte {})", bytes.len())))
    };
    let u32_at = |at: usize| field(at, 4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")));
    let version = u32_at(8)?;
    let writer_len = u32_at(12)? as usize;
    let writer = String::from_utf8_lossy(field(16, writer_len.min(4096))?).to_string();
    if version != FORMAT_VERSION {
        return Err(CheckpointError::Version {
            path: path.to_path_buf(),
            found: version,
            supported: FORMAT_VERSION,
            writer,
        });
    }
    let len_at = 16 + writer_len;
    let payload_len = u64::from_le_bytes(field(len_at, 8)?.try_into().expect("8 bytes"));
    let crc = u32_at(len_at + 8)?;
    let payload = &bytes[len_at + 12..];
    if payload.len() as u64 != payload_len {
        return Err(damaged(format!("{} payload bytes, the header says {payload_len} (truncated?)", payload.len())));
    }
    if crc32fast::hash(payload) != crc {
        return Err(damaged("checksum mismatch".into()));
    }
    let (case_text, progress, sim) = match postcard::take_from_bytes::<Payload>(payload) {
        Ok((decoded, [])) => decoded,
        Ok((_, rest)) => return Err(damaged(format!("{} bytes after the state", rest.len()))),
        Err(e) => return Err(damaged(format!("the state does not decode: {e}"))),
    };
    let case = Case::from_str_with(&case_text, &format!("<case in {}>", path.display()), &[])
        .map_err(|e| CheckpointError::Case { path: path.to_path_buf(), message: e.to_string() })?;
    let sim = restore(sim, &case).map_err(damaged)?;
    Ok(Restored { path: path.to_path_buf(), writer, case, sim, progress })
}

/// A decoded simulation checked against the case and itself, then made
/// whole: what checkpoints do not store (the fields marked
/// `#[serde(skip)]`) rebuilt as a fresh run builds it.
fn restore(mut sim: Simulation, case: &Case) -> Result<Simulation, String> {
    if sim.heat_every == 0 || !(sim.heat_pending.is_finite() && sim.heat_pending >= 0.0) {
        return Err(format!(
            "conduction every {} steps with {} s pending is not usable",
            sim.heat_every, sim.heat_pending
        ));
    }
    if !(sim.dt.is_finite() && sim.dt > 0.0 && sim.time.is_finite()) {
        return Err(format!("time {} s or step {} s is not usable", sim.time, sim.dt));
    }
    let setups = case.body_setups();
    check_model(&sim.model, case, &setups)?;
    let n = sim.model.particles.len();
    if sim.f_contact.len() != n {
        return Err(format!("{} contact forces for {n} particles", sim.f_contact.len()));
    }
    check_contact(sim.contact.as_ref(), case, n)?;
    check_cracks(sim.cracks.as_ref(), case, &sim.model)?;

    let m = &mut sim.model;
    m.materials = setups.into_iter().map(|s| s.material).collect();
    m.gather.copy_entries(&m.qp_shape);
    case.apply_unstored_settings(&mut sim).map_err(|e| format!("heat conduction: {e}"))?;
    if let Some(c) = sim.cracks.as_mut() {
        c.refresh_segments(&sim.model);
    }
    Ok(sim)
}

/// The stores, tables, gather and bodies: columns of one length, every
/// index in range, the bodies those of the case.
fn check_model(m: &Model, case: &Case, setups: &[BodySetup]) -> Result<(), String> {
    let (p, q) = (&m.particles, &m.quad);
    let (n, nq) = (p.len(), q.len());
    if m.mode != case.geometry.mode {
        return Err("the geometry mode does not match the case".into());
    }
    if !p.columns_agree() {
        return Err(format!("the particle columns differ in length ({n} particles)"));
    }
    if !q.columns_agree() {
        return Err(format!("the quadrature-point columns differ in length ({nq} points) or name missing jumps"));
    }
    if p.mass.iter().any(|m| !(m.is_finite() && *m > 0.0)) {
        return Err("a particle mass is not positive".into());
    }
    check_table(&m.qp_shape, nq, n, "quadrature")?;
    check_table(&m.particle_shape, n, n, "particle")?;
    let g = &m.gather;
    let nnz = m.qp_shape.nnz();
    let gather_ok = g.offsets.len() == n + 1
        && g.offsets.first() == Some(&0)
        && g.offsets.last() == Some(&g.entry.len())
        && g.offsets.windows(2).all(|w| w[0] <= w[1])
        && g.point.len() == g.entry.len()
        && g.entry.iter().all(|&k| (k as usize) < nnz)
        && g.point.iter().all(|&q| (q as usize) < nq);
    if !gather_ok {
        return Err("the force gather is inconsistent with the tables".into());
    }
    if m.bodies.len() != setups.len() {
        return Err(format!("{} bodies, but the case has {}", m.bodies.len(), setups.len()));
    }
    for (b, s) in m.bodies.iter().zip(setups) {
        let (pr, qr) = (&b.particles, &b.quad_points);
        if b.name != s.name || pr.start > pr.end || pr.end > n || qr.start > qr.end || qr.end > nq {
            return Err(format!("body '{}' does not match the case or the stores", b.name));
        }
    }
    if p.body.iter().chain(&q.body).any(|&b| b as usize >= setups.len()) {
        return Err("a particle or quadrature point names a body that does not exist".into());
    }
    Ok(())
}

fn check_table(t: &ShapeTable, rows: usize, columns: usize, what: &str) -> Result<(), String> {
    let nnz = t.index.len();
    let ok = t.offsets.len() == rows + 1
        && t.offsets.first() == Some(&0)
        && t.offsets.last() == Some(&nnz)
        && t.offsets.windows(2).all(|w| w[0] <= w[1])
        && t.value.len() == nnz
        && t.grad.len() == nnz
        && t.index.iter().all(|&i| (i as usize) < columns);
    if ok {
        Ok(())
    } else {
        Err(format!("{what} shape table is inconsistent with {rows} rows and {columns} particles"))
    }
}

/// The contact: present exactly when the case has a contact stage
/// ([`Case::has_contact`]), its bodies the case's (outline, mass,
/// prescribed motion) at their stored position and velocity, its
/// parameters the case's, its lists whole.
fn check_contact(c: Option<&ContactSystem>, case: &Case, n: usize) -> Result<(), String> {
    let c = match (c, case.has_contact()) {
        (None, false) => return Ok(()),
        (Some(_), false) => return Err("contact state, but the case has no contact".into()),
        (None, true) => return Err("no contact state, but the case has contact".into()),
        (Some(c), true) => c,
    };
    let expected = case.rigid_bodies().map_err(|e| e.to_string())?;
    if expected.len() != c.bodies.len() {
        return Err("the number of rigid bodies does not match the case".into());
    }
    for (mut e, b) in expected.into_iter().zip(&c.bodies) {
        (e.position, e.velocity) = (b.position, b.velocity);
        if e != *b {
            return Err(format!("rigid body '{}' does not match the case", b.name));
        }
    }
    if *c.parameters() != case.contact {
        return Err("the contact parameters do not match the case".into());
    }
    c.check_state(n).map_err(|e| format!("contact: {e}"))
}

/// Most cells of the segment bins one restored crack segment may span: a
/// real segment spans a few supports, so this only stops a damaged file
/// from making the binning loop over an absurd range.
const MAX_SEGMENT_CELLS: Real = 1e4;

/// The crack growth: present exactly when the case has a fracture
/// criterion, with the case's parameters; every crack, event and reduced
/// row naming particles and points that exist.
fn check_cracks(c: Option<&CrackGrowth>, case: &Case, model: &Model) -> Result<(), String> {
    let c = match (c, case.fracture.criterion == Criterion::None) {
        (None, true) => return Ok(()),
        (Some(_), true) => return Err("crack state, but the case has no fracture criterion".into()),
        (None, false) => return Err("no crack state, but the case has a fracture criterion".into()),
        (Some(c), false) => c,
    };
    if c.params != case.fracture {
        return Err("the fracture parameters do not match the case".into());
    }
    let (n, nq) = (model.particles.len(), model.quad.len());
    let finite = |p: &Vec2| p.x.is_finite() && p.y.is_finite();
    for (k, crack) in c.cracks.iter().enumerate() {
        let faces_ok = |v: &CrackVertex| v.faces.is_none_or(|(l, r)| (l as usize) < n && (r as usize) < n);
        if crack.id != k
            || crack.vertices.len() < 2
            || crack.tip.is_some_and(|t| t >= n)
            || !(crack.offset.is_finite() && crack.offset >= 0.0)
            || !crack.nucleated.0.is_finite()
            || crack.arrested.is_some_and(|a| !a.0.is_finite())
            || !crack.vertices.iter().all(|v| finite(&v.x0) && faces_ok(v))
        {
            return Err(format!("crack {k} is inconsistent"));
        }
    }
    if !c.events.iter().all(|e| e.crack < c.cracks.len() && e.particles.iter().all(|&i| i < n)) {
        return Err("the crack event log is inconsistent".into());
    }
    for (what, rows, reduced) in
        [("quadrature", nq, &c.reduced_quadrature_rows), ("particle", n, &c.reduced_particle_rows)]
    {
        if reduced.keys().any(|&k| k >= rows) {
            return Err(format!("the reduced {what} rows are inconsistent"));
        }
    }
    // The segments are binned in cells of the largest support (as
    // `CrackGrowth::refresh_segments` does).
    let cell = model.particles.support.iter().cloned().fold(0.0, Real::max);
    let cell = if cell > 0.0 && cell.is_finite() { cell } else { 1.0 };
    for crack in &c.cracks {
        for (a, b) in crack.segments() {
            let span = (a - b).abs() / cell;
            if span.iter().any(|&s| s > MAX_SEGMENT_CELLS) {
                return Err(format!("crack {}: a segment spans more than {MAX_SEGMENT_CELLS} cells", crack.id));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Block2, Tensor3};

    /// Odd values (NaN with a payload, −0.0, infinities, subnormals) in the
    /// types the stores hold come back with the same bits.
    #[test]
    fn stored_values_round_trip_bit_for_bit() {
        type Columns = (Vec<Real>, Vec<Vec2>, Vec<Tensor3>, Vec<Block2>, Vec<u32>, Vec<usize>);
        fn bits(c: &Columns) -> Vec<u64> {
            let mut out: Vec<u64> = c.0.iter().map(|v| v.to_bits()).collect();
            out.extend(c.1.iter().flat_map(|p| [p.x, p.y]).map(Real::to_bits));
            out.extend(c.2.iter().flat_map(|t| t.iter().copied().collect::<Vec<_>>()).map(Real::to_bits));
            out.extend(c.3.iter().flat_map(|b| [b.xx, b.xy, b.yx, b.yy, b.zz]).map(Real::to_bits));
            out.extend(c.4.iter().map(|&v| u64::from(v)));
            out.extend(c.5.iter().map(|&v| v as u64));
            out
        }
        let reals = [0.0, -0.0, 1.5e-300, 5e-324, Real::MAX, f64::from_bits(0x7ff8_dead_beef_0001), Real::INFINITY];
        let t3: Vec<Tensor3> =
            reals.iter().map(|&x| Tensor3::from_fn(|i, j| x * (i as Real + 3.0 * j as Real))).collect();
        let columns: Columns = (
            reals.to_vec(),
            reals.iter().map(|&x| Vec2::new(x, -x)).collect(),
            t3.clone(),
            t3.iter().map(Block2::block_part).collect(),
            vec![1, u32::MAX],
            vec![usize::MAX],
        );
        let back: Columns = postcard::from_bytes(&postcard::to_stdvec(&columns).unwrap()).unwrap();
        assert_eq!(bits(&back), bits(&columns));
        // A vector is its components and nothing else (no length).
        assert_eq!(postcard::to_stdvec(&Vec2::new(1.0, 2.0)).unwrap().len(), 16);
    }

    /// A length beyond the data is an error, not a huge allocation.
    #[test]
    fn decoder_refuses_lengths_beyond_the_data() {
        let bytes = postcard::to_stdvec(&u64::MAX).unwrap();
        assert!(postcard::from_bytes::<Vec<Real>>(&bytes).is_err());
        assert!(postcard::from_bytes::<Vec<Real>>(&bytes[..4]).is_err());
    }

    #[test]
    fn listing_orders_by_step_and_rotation_keeps_the_newest() {
        let dir = crate::io::test_util::scratch_dir("ckpt-list");
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
