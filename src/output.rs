//! What a run writes: VTU snapshots in a `.pvd` series, the CSV time
//! history, the resolved case and the run's provenance.
//!
//! Particle fields are written at the particles' current physical positions
//! `x = X + u(X)` with `u(X_I) = Σ_J N_J(X_I) U_J` (SPEC §2: RK particles
//! are not interpolating); quadrature fields are projected onto the
//! particles with the lumped weights `N_I(X_q) w_q` (see
//! [`Model::project`]).

use crate::io::{write_vtu, DataArray, HistoryWriter, IoError, PvdSeries, VtuPiece};
use crate::math::{mean_stress, von_mises, Block2, Real, Tensor3, Vec2};
use crate::model::Model;
use crate::step::Simulation;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Why a plot of a run's results could not be made: its history could not
/// be read, or the image could not be drawn. Its own type, so that `output`
/// needs nothing of `run`, which drives it ([`crate::run::RunError::Output`]
/// wraps it).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Plot(#[from] crate::io::PlotError),
}

/// Columns of the history CSV that every run has, in order: time, step,
/// energies, and the plug once cracks have cut one out under the first
/// rigid body (`plug_mass`, kg or kg/m in plane strain, and its
/// mass-averaged velocity `plug_vx, plug_vy`, m/s; all 0 before, see
/// [`crate::plug`]) with `perforation_time`, the time of the step after
/// which it was first found (s; 0 before), and `eroded_points`, the number
/// of quadrature points eroded so far (inverted after failing, see
/// [`crate::fracture`]), `exposed_slaves`, the particles that joined the
/// contact slaves by exposure so far, and `exposed_contacts`, how many of
/// them touched a rigid body in the last step (see
/// [`crate::contact::ContactSystem::admit_exposed`]), and
/// `max_particle_speed`, the largest physical particle speed `max_I |v(X_I)|`
/// at that step, m/s ([`crate::step::fastest_particle`]);
/// `max_coefficient_gap`, the largest distance between a particle's own
/// coefficient `X_I + U_I` and the field at it, `x(X_I)`, in its spacings
/// ([`crate::step::coefficient_gap`]). Each rigid body `NAME` adds `NAME_x, NAME_y` (m), `NAME_vx, NAME_vy` (m/s),
/// `NAME_fx, NAME_fy` (contact force on the body, N), `NAME_contacts` and
/// `NAME_f_axial`, the contact force along its flight direction (the
/// direction of its initial velocity; negative while braked; 0 for a body
/// that started at rest), N ([`crate::residual`]).
pub const HISTORY_COLUMNS: &[&str] = &[
    "time",
    "step",
    "dt",
    "kinetic_energy",
    "internal_energy",
    "rigid_kinetic_energy",
    "contact_work",
    "contact_dissipation",
    "total_energy",
    "energy_drift",
    "plug_mass",
    "plug_vx",
    "plug_vy",
    "perforation_time",
    "eroded_points",
    "exposed_slaves",
    "exposed_contacts",
    "max_particle_speed",
    "max_coefficient_gap",
];

/// Columns of `cracks.csv`: one row per crack event; `particles` lists the
/// split particle (left child), the new right child and, for nucleate and
/// propagate, the new tip, separated by spaces; `value` is the criterion
/// value of the new tip (of the split tip at arrest; empty for an inserted
/// pre-crack), `damage` that particle's own damage (the material's law)
/// ([`crate::fracture::CrackEvent::damage`]; empty likewise) and
/// `hardening` its adiabatic hardening, ≤ 0 past the onset of shear
/// localization ([`crate::fracture::CrackEvent::hardening`]; empty likewise
/// and in an elastic body).
pub const CRACK_COLUMNS: &[&str] = &["time", "step", "crack", "kind", "particles", "value", "damage", "hardening"];

/// Per-rigid-body history column suffixes.
pub const RIGID_COLUMNS: &[&str] = &["x", "y", "vx", "vy", "fx", "fy", "contacts", "f_axial"];

/// All history columns for a run with the given rigid bodies.
pub fn history_columns(rigid_names: &[String]) -> Vec<String> {
    let mut c: Vec<String> = HISTORY_COLUMNS.iter().map(|s| s.to_string()).collect();
    for n in rigid_names {
        c.extend(RIGID_COLUMNS.iter().map(|s| format!("{n}_{s}")));
    }
    c
}

/// Writes the snapshots and the history of one run into a directory.
#[derive(Debug)]
pub struct OutputWriter {
    dir: PathBuf,
    fields: Vec<String>,
    series: PvdSeries,
    history: HistoryWriter,
    /// Number of snapshots written so far.
    pub snapshots: usize,
    /// `cracks.csv`, opened at the first crack event.
    crack_log: Option<std::io::BufWriter<std::fs::File>>,
    /// Crack events written so far.
    crack_events_written: usize,
    /// The plug, followed from step to step.
    plug: crate::plug::PlugTracker,
    /// Each flight's body: the rigid bodies, then the deformable
    /// projectiles (`Case::flights`).
    names: Vec<String>,
    /// Each flight's initial velocity, m/s.
    flights: Vec<Vec2>,
    /// Each flight's release, followed every step ([`crate::residual`]).
    release: Vec<crate::residual::ReleaseTracker>,
    /// Where each flight is through its target ([`through_positions`]),
    /// found at the first use (the reference configuration does not change).
    through: Option<Vec<Option<Real>>>,
    /// Step of the last history row (a step gets at most one).
    last_row_step: Option<u64>,
    /// The last snapshot, while its files are written on a thread of their
    /// own ([`OutputWriter::snapshot`]).
    pending: Option<PendingSnapshot>,
}

/// A snapshot being written beside the time loop: the writing thread and
/// the series entries (time, file, part) to add once its files are on disk.
#[derive(Debug)]
struct PendingSnapshot {
    writer: std::thread::JoinHandle<Result<(), IoError>>,
    entries: Vec<(Real, String, u32)>,
}

impl OutputWriter {
    /// Start the series `results.pvd` and `history.csv` in `dir` (which
    /// must exist); `rigid` names each rigid body with its initial velocity.
    /// Temporary files a killed earlier run left in `dir` are removed.
    pub fn create(dir: &Path, fields: &[String], rigid: &[(String, Vec2)]) -> Result<Self, IoError> {
        crate::io::remove_temporaries(dir);
        let rigid_names: Vec<String> = rigid.iter().map(|r| r.0.clone()).collect();
        let cols = history_columns(&rigid_names);
        let cols: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
        let history = HistoryWriter::create(&dir.join("history.csv"), &cols)?;
        Ok(OutputWriter {
            dir: dir.to_path_buf(),
            fields: fields.to_vec(),
            series: PvdSeries::create(&dir.join("results.pvd"))?,
            history,
            snapshots: 0,
            crack_log: None,
            crack_events_written: 0,
            plug: Default::default(),
            names: rigid_names,
            flights: rigid.iter().map(|r| r.1).collect(),
            release: vec![Default::default(); rigid.len()],
            through: None,
            last_row_step: None,
            pending: None,
        })
    }

    /// Continue the outputs of a resumed run in `dir`: the series holds the
    /// snapshots at `snapshot_times` (`particles_00000.vtu`, ...; with
    /// `cracks`, also their part-1 crack files `cracks_00000.vtu`, ...),
    /// snapshot files after them are removed, `history.csv` is cut to its
    /// first `history_bytes` bytes (the rows up to the checkpoint) and
    /// continued, and `cracks.csv` is rewritten with the events of `cracks`
    /// (those up to the checkpoint; removed if there are none) and continued.
    /// The rigid bodies' releases are followed on from the rows kept.
    pub fn resume(
        dir: &Path,
        fields: &[String],
        rigid: &[(String, Vec2)],
        snapshot_times: &[Real],
        history_bytes: u64,
        cracks: Option<&crate::fracture::CrackGrowth>,
    ) -> Result<Self, IoError> {
        let rigid_names: Vec<String> = rigid.iter().map(|r| r.0.clone()).collect();
        let cols = history_columns(&rigid_names);
        let cols: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
        let history = HistoryWriter::continue_at(&dir.join("history.csv"), &cols, history_bytes)?;
        // The perforation time so far is in the rows kept (the last row's
        // column: the row of the step that cut the plug out is always written).
        let kept = crate::io::HistoryTable::read(&dir.join("history.csv"))?;
        let first_cut = kept.column("perforation_time").and_then(|c| c.last().copied()).filter(|&t| t > 0.0);
        let last_row_step = kept.column("step").and_then(|c| c.last().copied()).map(|s| s as u64);
        // In the order `snapshot` appends them: by time, then part.
        let entries = snapshot_times
            .iter()
            .enumerate()
            .flat_map(|(k, &time)| {
                let particles = crate::io::PvdEntry { time, file: snapshot_name(k), part: 0 };
                let crack = cracks.map(|_| crate::io::PvdEntry { time, file: crack_snapshot_name(k), part: 1 });
                std::iter::once(particles).chain(crack)
            })
            .collect();
        let series = PvdSeries::with_entries(&dir.join("results.pvd"), entries)?;
        let n = snapshot_times.len();
        crate::io::remove_temporaries(dir);
        if let Ok(listing) = std::fs::read_dir(dir) {
            for e in listing.flatten() {
                let name = e.file_name().to_string_lossy().to_string();
                let index = ["particles_", "cracks_"]
                    .iter()
                    .find_map(|prefix| name.strip_prefix(prefix))
                    .and_then(|r| r.strip_suffix(".vtu"))
                    .and_then(|k| k.parse::<usize>().ok());
                if index.is_some_and(|k| k >= n) {
                    std::fs::remove_file(e.path()).map_err(|source| IoError::Write { path: e.path(), source })?;
                }
            }
        }
        let mut out = OutputWriter {
            dir: dir.to_path_buf(),
            fields: fields.to_vec(),
            series,
            history,
            snapshots: n,
            crack_log: None,
            crack_events_written: 0,
            plug: crate::plug::PlugTracker::continuing(first_cut),
            names: rigid_names,
            flights: rigid.iter().map(|r| r.1).collect(),
            release: replay_releases(&kept, rigid),
            through: None,
            last_row_step,
            pending: None,
        };
        let log = dir.join("cracks.csv");
        match cracks {
            Some(c) if !c.events.is_empty() => out.write_crack_events(c)?,
            _ if log.exists() => {
                std::fs::remove_file(&log).map_err(|source| IoError::Write { path: log.clone(), source })?
            }
            _ => {}
        }
        Ok(out)
    }

    /// Simulated times of the snapshots written so far, s.
    pub fn snapshot_times(&self) -> Vec<Real> {
        self.series.entries().iter().filter(|e| e.part == 0).map(|e| e.time).collect()
    }

    /// Length of `history.csv` so far, bytes.
    pub fn history_bytes(&self) -> u64 {
        self.history.bytes()
    }

    /// `fsync` the history, so that a checkpoint never counts rows that a
    /// power loss could take back.
    pub fn sync(&self) -> Result<(), IoError> {
        self.history.sync()
    }

    /// The output directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Write `particles_NNNNN.vtu` (and `cracks_NNNNN.vtu`) for the current
    /// state and add them to the series.
    ///
    /// The fields are gathered here, from the state as it is now; the files
    /// are encoded and written on a thread of their own while the run goes
    /// on (the time loop's serial stages leave a core free for it). One
    /// snapshot is in flight at a time: the next snapshot, a checkpoint
    /// ([`OutputWriter::flush`]) and the end of the run wait for it, and a
    /// file joins `results.pvd` only once it is on disk, so an interrupted
    /// or failed run lists only complete files. Returns the particle file's path.
    pub fn snapshot(&mut self, sim: &Simulation) -> Result<PathBuf, IoError> {
        self.flush()?;
        let name = snapshot_name(self.snapshots);
        let path = self.dir.join(&name);
        let mut files = vec![(path.clone(), particle_piece(&sim.model, &self.fields))];
        let mut entries = vec![(sim.time, name, 0)];
        if let Some(cracks) = &sim.cracks {
            let crack_name = crack_snapshot_name(self.snapshots);
            files.push((self.dir.join(&crack_name), crack_piece(&sim.model, cracks)));
            entries.push((sim.time, crack_name, 1));
        }
        let writer = std::thread::Builder::new()
            .name("plugsim-snapshot".into())
            .spawn(move || files.iter().try_for_each(|(path, piece)| write_vtu(path, piece)))
            .map_err(|source| IoError::Write { path: path.clone(), source })?;
        self.pending = Some(PendingSnapshot { writer, entries });
        self.snapshots += 1;
        Ok(path)
    }

    /// The newest snapshot's particle file (`particles_00000.vtu` before
    /// any).
    pub fn last_snapshot(&self) -> PathBuf {
        self.dir.join(snapshot_name(self.snapshots.saturating_sub(1)))
    }

    /// When the cracks first cut a plug out (s; the `perforation_time`
    /// column), `None` before.
    pub fn perforation(&self) -> Option<Real> {
        self.plug.first_cut
    }

    /// Wait for the snapshot being written, if any, and add its files to
    /// `results.pvd`.
    pub fn flush(&mut self) -> Result<(), IoError> {
        let Some(PendingSnapshot { writer, entries }) = self.pending.take() else {
            return Ok(());
        };
        let written = writer.join().unwrap_or_else(|_| {
            Err(IoError::Write {
                path: self.dir.join(&entries[0].1),
                source: std::io::Error::other("the snapshot writer panicked"),
            })
        });
        written?;
        for (time, file, part) in entries {
            self.series.append(time, &file, part)?;
        }
        Ok(())
    }

    /// Append one history row (none if this step has one already).
    pub fn history_row(&mut self, sim: &Simulation) -> Result<(), IoError> {
        if self.last_row_step == Some(sim.step) {
            return Ok(());
        }
        self.last_row_step = Some(sim.step);
        let e = &sim.energies;
        let mut row = vec![
            sim.time,
            sim.step as Real,
            sim.dt,
            e.kinetic,
            e.internal,
            e.rigid_kinetic,
            e.contact_work,
            e.contact_dissipation(),
            e.total(),
            e.drift(),
        ];
        let plug = match (&sim.cracks, self.impact_line(sim)) {
            (Some(cracks), Some(axis_x)) => self.plug.update(&sim.model, cracks, axis_x, sim.time),
            _ => None,
        };
        match plug {
            Some(p) => row.extend([p.mass, p.velocity().x, p.velocity().y]),
            None => row.extend([0.0; 3]),
        }
        row.push(self.plug.first_cut.unwrap_or(0.0));
        row.push(sim.model.quad.eroded.iter().filter(|&&e| e).count() as Real);
        let (admitted, touching) =
            sim.contact.as_ref().map_or((0, 0), |c| c.exposed_counts(&sim.model.particles.flags));
        row.extend([admitted as Real, touching as Real]);
        row.push(crate::step::fastest_particle(&sim.model).0);
        row.push(crate::step::coefficient_gap(&sim.model).0);
        for b in 0..self.names.len() {
            if let Some(s) = self.flight_sample(sim, b) {
                row.extend([
                    s.position.x,
                    s.position.y,
                    s.velocity.x,
                    s.velocity.y,
                    s.contact_force.x,
                    s.contact_force.y,
                    s.active_contacts as Real,
                    s.contact_force.dot(&self.flight_direction(b)),
                ]);
            }
        }
        self.history.write_row(&row)
    }
}

impl Drop for OutputWriter {
    /// A run that ends by an error elsewhere still finishes (and lists) the
    /// snapshot it started.
    fn drop(&mut self) {
        let _ = self.flush();
    }
}

impl OutputWriter {
    /// After every step: append the crack events not yet written to
    /// `cracks.csv` (created at the first event, with the header
    /// [`CRACK_COLUMNS`]) and, if the cracks changed, look for the plug, so
    /// that the perforation time is that of the step that cut it out; that
    /// step gets a history row of its own (so a resumed run finds the
    /// perforation time in the rows before its checkpoint).
    pub fn crack_events(&mut self, sim: &Simulation) -> Result<(), IoError> {
        let Some(cracks) = &sim.cracks else {
            return Ok(());
        };
        self.write_crack_events(cracks)?;
        if let Some(axis_x) = self.impact_line(sim) {
            let before = self.plug.first_cut;
            self.plug.refresh(&sim.model, cracks, axis_x, sim.time);
            if before.is_none() && self.plug.first_cut.is_some() {
                self.history_row(sim)?;
            }
        }
        Ok(())
    }

    /// The impact line under which the plug is looked for: that of the
    /// first rigid body ([`impact_line`]), else the x-centre of the first
    /// deformable projectile's particles as generated (its side on the
    /// axis, x = 0, in axisymmetry, where the rigid outlines are full
    /// sections centred on the axis).
    pub fn impact_line(&self, sim: &Simulation) -> Option<Real> {
        impact_line(sim).or_else(|| {
            let rigid = sim.contact.as_ref().map_or(0, |c| c.bodies.len());
            let name = self.names.get(rigid)?;
            let body = sim.model.bodies.iter().find(|b| &b.name == name)?;
            let x0 = sim.model.particles.x0.get(body.particles.clone())?;
            let (lo, hi) =
                x0.iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
            let on_axis = sim.model.mode == crate::geometry::GeometryMode::Axisymmetric && lo <= 0.0;
            (lo <= hi).then_some(if on_axis { 0.0 } else { 0.5 * (lo + hi) })
        })
    }

    /// Flight `b`'s sample now: rigid body `b` of the contact, or after
    /// them the deformable projectile of that name, its mass-averaged
    /// motion and the contact force on it
    /// ([`crate::contact::ContactSystem::deformable_sample`]).
    fn flight_sample(&self, sim: &Simulation, b: usize) -> Option<crate::contact::BodySample> {
        let rigid = sim.contact.as_ref().map_or(0, |c| c.bodies.len());
        flight_sample(sim, (b < rigid).then_some(b), self.names.get(b).map_or("", String::as_str))
    }

    /// Where each flight is through its target ([`through_positions`]).
    pub fn through(&mut self, sim: &Simulation) -> &[Option<Real>] {
        self.through.get_or_insert_with(|| through_positions(sim, &self.names, &self.flights))
    }

    /// Whether every moving body's flight is over, by the definitions
    /// of [`crate::residual`] held for `wait` (s): stopped or moving back,
    /// slowed with no plug cut out, or
    /// free of force along its flight with a plug cut out (both for `wait`:
    /// the plug, thrown ahead, may still be caught again) or through its
    /// target (free for `wait`). Call
    /// at the steps the history records, so that it and the verdict read
    /// from the history sample the same states (`time.stop_after_release`,
    /// [`crate::run`]); false without a
    /// moving body (a rigid one with an initial velocity, not prescribed, or
    /// a deformable projectile).
    pub fn flights_over(&mut self, sim: &Simulation, wait: Real) -> bool {
        let cut = self.plug.first_cut;
        self.through(sim);
        let mut moving = 0;
        let mut over = 0;
        for b in 0..self.names.len().min(self.release.len()) {
            let impact = self.flights[b].norm();
            let prescribed =
                sim.contact.as_ref().and_then(|c| c.bodies.get(b)).is_some_and(|r| r.prescribed_velocity.is_some());
            if impact == 0.0 || prescribed {
                continue;
            }
            let Some(s) = self.flight_sample(sim, b) else {
                continue;
            };
            let dir = self.flight_direction(b);
            let through = self.through.as_ref().and_then(|t| t.get(b).copied().flatten());
            let tracker = &mut self.release[b];
            tracker.observe(sim.time, s.contact_force.dot(&dir), s.velocity.dot(&dir), impact);
            let stopped = tracker.stopped_for(sim.time).is_some_and(|t| t >= wait);
            // Free for `wait` since the later of the release and the cut, or
            // since the release once through the target.
            let passed = crate::residual::is_through(s.position.dot(&dir), through);
            let free = (passed || cut.is_some_and(|c| sim.time - c >= wait))
                && tracker.free_for(sim.time).is_some_and(|t| t >= wait);
            // Slowed with no plug cut out, for `wait`.
            let slow = cut.is_none() && !passed && tracker.slow_for(sim.time).is_some_and(|t| t >= wait);
            moving += 1;
            over += usize::from(stopped || free || slow);
        }
        moving > 0 && over == moving
    }

    /// Unit vector along rigid body `b`'s initial velocity (zero if it
    /// started at rest).
    fn flight_direction(&self, b: usize) -> Vec2 {
        self.flights.get(b).map_or_else(Vec2::zeros, |&v| crate::residual::flight_direction(v))
    }

    /// Append the events of `cracks` not yet written to `cracks.csv`.
    fn write_crack_events(&mut self, cracks: &crate::fracture::CrackGrowth) -> Result<(), IoError> {
        use std::io::Write;
        if cracks.events.len() == self.crack_events_written {
            return Ok(());
        }
        let path = self.dir.join("cracks.csv");
        let err = |source| IoError::Write { path: path.clone(), source };
        if self.crack_log.is_none() {
            let mut f = std::io::BufWriter::new(std::fs::File::create(&path).map_err(err)?);
            writeln!(f, "{}", CRACK_COLUMNS.join(",")).map_err(err)?;
            self.crack_log = Some(f);
        }
        let f = self.crack_log.as_mut().expect("opened");
        for e in &cracks.events[self.crack_events_written..] {
            let ids: Vec<String> = e.particles.iter().map(|i| i.to_string()).collect();
            let num = |v: Real| if v.is_finite() { format!("{v:.6e}") } else { String::new() };
            let (value, damage, hardening) = (num(e.value), num(e.damage), num(e.hardening));
            writeln!(
                f,
                "{:.9e},{},{},{},{},{},{},{}",
                e.time,
                e.step,
                e.crack,
                e.kind.name(),
                ids.join(" "),
                value,
                damage,
                hardening
            )
            .map_err(err)?;
        }
        f.flush().map_err(err)?;
        self.crack_events_written = cracks.events.len();
        Ok(())
    }
}

/// Columns of `trace.csv` ([`ParticleTrace`]).
pub const TRACE_COLUMNS: &[&str] = &[
    "time",
    "step",
    "particle",
    "x",
    "y",
    "vx",
    "vy",
    "coefficient_x",
    "coefficient_y",
    "coefficient_vx",
    "coefficient_vy",
    "ax",
    "ay",
    "f_int_x",
    "f_int_y",
    "f_contact_x",
    "f_contact_y",
    "f_ext_x",
    "f_ext_y",
    "mass",
    "live_share",
    "flags",
];

/// `trace.csv`: the forces on chosen particles at every step
/// (`output.trace_particles`), to find what accelerates a particle (a
/// particle thrown off, one squeezed out of a crack's mouth) step by step.
///
/// One row per traced particle and step, written after the step: the time
/// and step reached; the particle's physical position `x = X_I + u(X_I)`
/// and velocity `v(X_I) = Σ_J N_J(X_I) V_J` after it (SPEC §2: RK particles
/// are not interpolating; the snapshots' positions and the fastest
/// particle's speed are these); its own coefficients, `X_I + U_I` and
/// `V_I^{n+½}`, the ones the step integrates (where they part from the
/// physical values, the field hides the particle's own motion: a change
/// of its shape functions, at a split or a detachment, shows it at once);
/// and the acceleration the step applied to that
/// coefficient with its three terms, `m a = f_ext + f_contact − f_int`
/// ([`Simulation::step`], a held component's acceleration being zero;
/// `m` the mass it integrated with),
/// so that `V^{n+½} − V^{n−½} = ½ (Δt_{n−½} + Δt_{n+½}) a`: `f_int` is the internal force the
/// step integrated (formed at the end of the step before, after any crack
/// change, so it is read before the step), `f_contact` the contact force of
/// the step (the rigid bodies', the deformable bodies' and the axis's, on
/// the particle as a slave and as a neighbour a slave's force is spread
/// to). Then its mass (the step's; a crack change at the step's end
/// lumps the masses anew, which the next row shows), its live share of material
/// ([`crate::fracture::growth::live_share`]) and its flags
/// ([`crate::particles::ParticleFlags`]) after the step.
pub struct ParticleTrace {
    /// The particles traced, in the case's order.
    particles: Vec<usize>,
    /// `trace.csv`; `None` when no particle is traced.
    writer: Option<HistoryWriter>,
    /// Each traced particle's internal force and mass before the step
    /// (`None` while it does not exist): the ones the step integrates
    /// with (a crack change at its end forms both anew).
    f_int: Vec<Option<(Vec2, Real)>>,
}

impl ParticleTrace {
    /// Start `dir/trace.csv` for `particles` (no file without any).
    pub fn create(dir: &Path, particles: &[usize]) -> Result<Self, IoError> {
        let writer = match particles.is_empty() {
            true => None,
            false => Some(HistoryWriter::create(&dir.join("trace.csv"), TRACE_COLUMNS)?),
        };
        Ok(Self::writing(particles, writer))
    }

    fn writing(particles: &[usize], writer: Option<HistoryWriter>) -> Self {
        ParticleTrace { particles: particles.to_vec(), writer, f_int: vec![None; particles.len()] }
    }

    /// Continue `dir/trace.csv` of a run resumed at step `step`: the rows
    /// of the steps after it are dropped (the resumed run writes them
    /// again); a missing file is started anew.
    pub fn resume(dir: &Path, particles: &[usize], step: u64) -> Result<Self, IoError> {
        let path = dir.join("trace.csv");
        if particles.is_empty() || !path.exists() {
            return Self::create(dir, particles);
        }
        let text = std::fs::read_to_string(&path).map_err(|source| IoError::Read { path: path.clone(), source })?;
        // The header, then the rows up to the first of a later step.
        let mut keep = 0;
        for (k, line) in text.split_inclusive('\n').enumerate() {
            let row_step = line.split(',').nth(1).and_then(|f| f.trim().parse::<f64>().ok());
            let later = k > 0 && row_step.is_none_or(|s| s > step as f64);
            if later || !line.ends_with('\n') {
                break;
            }
            keep += line.len() as u64;
        }
        let writer = HistoryWriter::continue_at(&path, TRACE_COLUMNS, keep)?;
        Ok(Self::writing(particles, Some(writer)))
    }

    /// Before a step: keep the internal force the step will integrate
    /// (`None` for a particle a crack split has not made yet).
    pub fn before_step(&mut self, sim: &Simulation) {
        if self.writer.is_some() {
            for (f, &i) in self.f_int.iter_mut().zip(&self.particles) {
                let p = &sim.model.particles;
                *f = p.f_int.get(i).map(|&f| (f, p.mass[i]));
            }
        }
    }

    /// After a step: one row per traced particle.
    pub fn after_step(&mut self, sim: &Simulation) -> Result<(), IoError> {
        let Some(writer) = self.writer.as_mut() else {
            return Ok(());
        };
        let p = &sim.model.particles;
        for (&i, fi) in self.particles.iter().zip(&self.f_int) {
            // From the first step that integrates it on.
            let Some((fi, mass)) = fi else {
                continue;
            };
            let shape = &sim.model.particle_shape;
            let (x, v) = (p.x0[i] + shape.interpolate(i, &p.u), shape.interpolate(i, &p.v));
            let (coefficient, a, fe) = (p.v[i], p.a[i], p.f_ext[i]);
            let fc = sim.f_contact.get(i).copied().unwrap_or_else(Vec2::zeros);
            let share = crate::fracture::growth::live_share(&sim.model, i);
            writer.write_row(&[
                sim.time,
                sim.step as Real,
                i as Real,
                x.x,
                x.y,
                v.x,
                v.y,
                p.x0[i].x + p.u[i].x,
                p.x0[i].y + p.u[i].y,
                coefficient.x,
                coefficient.y,
                a.x,
                a.y,
                fi.x,
                fi.y,
                fc.x,
                fc.y,
                fe.x,
                fe.y,
                *mass,
                share,
                p.flags[i].0 as Real,
            ])?;
        }
        Ok(())
    }

    /// `fsync` the rows written so far (at a checkpoint).
    pub fn sync(&self) -> Result<(), IoError> {
        self.writer.as_ref().map_or(Ok(()), HistoryWriter::sync)
    }
}

/// The rigid bodies' release trackers after the rows of `table` (a resumed
/// run continues them; the live ones see every step, these every history row).
fn replay_releases(table: &crate::io::HistoryTable, rigid: &[(String, Vec2)]) -> Vec<crate::residual::ReleaseTracker> {
    let time = table.column("time").unwrap_or_default();
    rigid
        .iter()
        .map(|(name, v0)| {
            let mut tracker = crate::residual::ReleaseTracker::default();
            let dir = crate::residual::flight_direction(*v0);
            let col = |c: &str| table.column(&format!("{name}_{c}")).unwrap_or_default();
            let (f, vx, vy) = (col("f_axial"), col("vx"), col("vy"));
            for k in 0..time.len().min(f.len()).min(vx.len()).min(vy.len()) {
                tracker.observe(time[k], f[k], vx[k] * dir.x + vy[k] * dir.y, v0.norm());
            }
            tracker
        })
        .collect()
}

/// The cracks as poly-lines in the current configuration: two per crack
/// (its left and right faces, which coincide until the crack opens), with
/// cell data `crack` (id) and `face` (0 left, 1 right of the direction of
/// growth).
pub fn crack_piece(model: &Model, cracks: &crate::fracture::CrackGrowth) -> VtuPiece {
    let (mut points, mut lines, mut ids, mut faces) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for c in &cracks.cracks {
        for (f, line) in c.face_polylines(model).iter().enumerate() {
            let start = points.len() as u32;
            points.extend(line.iter().map(v3));
            lines.push((start..points.len() as u32).collect());
            ids.push(c.id as i32);
            faces.push(f as i32);
        }
    }
    VtuPiece::poly_lines(points, lines)
        .with_cell_data(DataArray::integers("crack", ids))
        .with_cell_data(DataArray::integers("face", faces))
}

/// The impact line `x = x_c` of the first rigid body (the x-centre of its
/// outline), under which [`crate::plug`] looks for the plug.
pub fn impact_line(sim: &Simulation) -> Option<Real> {
    projectile_extent(sim).map(|(lo, hi)| 0.5 * (lo + hi))
}

/// Where each flight (`names` with their initial velocities `flights`:
/// the rigid bodies, then the deformable projectiles) has passed through
/// its target ([`crate::residual::through_at`]): for a rigid body, from
/// its outline's forward-most vertex and the extent along its flight of
/// the bodies that are not flights, in the reference configuration. `None`
/// for a deformable projectile (its nose is not fixed in a body frame), a
/// body at rest or a run without a target.
pub fn through_positions(sim: &Simulation, names: &[String], flights: &[Vec2]) -> Vec<Option<Real>> {
    let p = &sim.model.particles;
    let target: Vec<bool> = sim.model.bodies.iter().map(|b| !names.contains(&b.name)).collect();
    let rigid = sim.contact.as_ref().map_or(&[][..], |c| &c.bodies[..]);
    flights
        .iter()
        .enumerate()
        .map(|(b, &v0)| {
            let d = crate::residual::flight_direction(v0);
            let body = rigid.get(b).filter(|_| d != Vec2::zeros())?;
            let nose = body.outline().iter().map(|v| v.dot(&d)).fold(Real::NEG_INFINITY, Real::max);
            let (near, far) = (0..p.len())
                .filter(|&i| target.get(p.body[i] as usize).copied().unwrap_or(false))
                .map(|i| p.x0[i].dot(&d))
                .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), s| (lo.min(s), hi.max(s)));
            (near <= far).then(|| crate::residual::through_at(nose, (near, far)))
        })
        .collect()
}

/// File name of snapshot `k`.
pub fn snapshot_name(k: usize) -> String {
    format!("particles_{k:05}.vtu")
}

/// File name of the cracks of snapshot `k` (part 1 of the series).
pub fn crack_snapshot_name(k: usize) -> String {
    format!("cracks_{k:05}.vtu")
}

fn v3(v: &Vec2) -> [f64; 3] {
    [v.x, v.y, 0.0]
}

/// Per-point values projected together by [`particle_piece`]: the five
/// entries of the Cauchy stress's block form (`xx, xy, yx, yy, zz`), then
/// the five quadrature-point scalars a snapshot can carry, then `∫ η dε̄`
/// (the numerator of `average_triaxiality`, whose denominator is the
/// plastic strain's slot).
const PROJECTED: usize = 5 + 5 + 1;

/// Several quadrature fields projected in one pass over the gather table
/// ([`Model::project`] of a fixed-size row): each entry gets the same
/// operations, in the same order, as projecting it on its own.
#[derive(Clone, Copy, Debug)]
struct Row<const N: usize>([Real; N]);

impl<const N: usize> Default for Row<N> {
    fn default() -> Self {
        Row([0.0; N])
    }
}

impl<const N: usize> std::ops::Add for Row<N> {
    type Output = Row<N>;
    #[inline]
    fn add(self, b: Row<N>) -> Row<N> {
        Row(std::array::from_fn(|k| self.0[k] + b.0[k]))
    }
}

impl<const N: usize> std::ops::Mul<Real> for Row<N> {
    type Output = Row<N>;
    #[inline]
    fn mul(self, s: Real) -> Row<N> {
        Row(self.0.map(|x| x * s))
    }
}

impl<const N: usize> std::ops::Div<Real> for Row<N> {
    type Output = Row<N>;
    #[inline]
    fn div(self, s: Real) -> Row<N> {
        Row(self.0.map(|x| x / s))
    }
}

/// The particle cloud with the requested fields.
///
/// The quadrature fields a snapshot asks for are projected in one pass
/// over the gather table, with each point's Cauchy stress `τ/J` formed
/// once (not once per particle it reaches): the same bits as projecting
/// each field on its own, in a fifth of the passes.
pub fn particle_piece(model: &Model, fields: &[String]) -> VtuPiece {
    let p = &model.particles;
    let u = model.physical(&p.u);
    let points = (0..p.len()).map(|i| v3(&(p.x0[i] + u[i]))).collect();
    let mut piece = VtuPiece::point_cloud(points);
    let q = &model.quad;
    let want = |name: &str| fields.iter().any(|f| f == name);
    if want("displacement") {
        piece = piece.with_point_data(DataArray::vectors("displacement", &u.iter().map(v3).collect::<Vec<_>>()));
    }
    if want("velocity") {
        let v = model.physical(&p.v);
        piece = piece.with_point_data(DataArray::vectors("velocity", &v.iter().map(v3).collect::<Vec<_>>()));
    }
    // The scalars' slots follow the stress's five in each projected row.
    let hardening = if want("adiabatic_hardening") { adiabatic_hardening(model) } else { vec![0.0; q.len()] };
    // The last slot is `∫ η dε̄`, written as `average_triaxiality`.
    let scalar_fields: [(&str, &[Real]); PROJECTED - 5] = [
        ("plastic_strain", &q.eps_p),
        ("plastic_strain_rate", &q.eps_p_rate),
        ("temperature", &q.temperature),
        ("damage", &q.damage),
        ("adiabatic_hardening", &hardening),
        ("average_triaxiality", &q.triaxiality_strain),
    ];
    let stress_wanted = want("stress") || want("effective_stress") || want("pressure");
    if stress_wanted || scalar_fields.iter().any(|(f, _)| want(f)) {
        // Per point: Cauchy `τ/J` entry by entry (as `Tensor3 / J`), then the scalars.
        let values: Vec<Row<PROJECTED>> = (0..q.len())
            .into_par_iter()
            .map(|k| {
                let (t, j) = (&q.tau[k], q.f[k].determinant());
                let mut row = [0.0; PROJECTED];
                row[..5].copy_from_slice(&[t.xx / j, t.xy / j, t.yx / j, t.yy / j, t.zz / j]);
                for (slot, (_, col)) in row[5..].iter_mut().zip(&scalar_fields) {
                    *slot = col[k];
                }
                Row(row)
            })
            .collect();
        let projected = model.project(|k| values[k]);
        if stress_wanted {
            let s: Vec<Tensor3> = projected
                .iter()
                .map(|r| Block2 { xx: r.0[0], xy: r.0[1], yx: r.0[2], yy: r.0[3], zz: r.0[4] }.to_tensor())
                .collect();
            if want("stress") {
                let six: Vec<[f64; 6]> =
                    s.iter().map(|t| [t[(0, 0)], t[(1, 1)], t[(2, 2)], t[(0, 1)], t[(1, 2)], t[(0, 2)]]).collect();
                piece = piece.with_point_data(DataArray::symmetric_tensors("stress", &six));
            }
            if want("effective_stress") {
                piece =
                    piece.with_point_data(DataArray::scalars("effective_stress", s.iter().map(von_mises).collect()));
            }
            if want("pressure") {
                piece =
                    piece.with_point_data(DataArray::scalars("pressure", s.iter().map(|t| -mean_stress(t)).collect()));
            }
        }
        let (last, eps_p) = (PROJECTED - 6, 0);
        for (c, (name, _)) in scalar_fields.iter().enumerate().take(last) {
            if want(name) {
                piece =
                    piece.with_point_data(DataArray::scalars(*name, projected.iter().map(|r| r.0[5 + c]).collect()));
            }
        }
        if want(scalar_fields[last].0) {
            // The ratio of the projections: the particle's points'
            // `∫ η dε̄` over their `ε̄`, strain-weighted; 0 where nothing
            // has flowed.
            let ratio = |r: &Row<PROJECTED>| {
                let (num, den) = (r.0[5 + last], r.0[5 + eps_p]);
                if den > 0.0 {
                    num / den
                } else {
                    0.0
                }
            };
            piece =
                piece.with_point_data(DataArray::scalars(scalar_fields[last].0, projected.iter().map(ratio).collect()));
        }
    }
    if want("mass") {
        piece = piece.with_point_data(DataArray::scalars("mass", p.mass.clone()));
    }
    if want("body") {
        piece = piece.with_point_data(DataArray::integers("body", p.body.iter().map(|&b| b as i32).collect()));
    }
    if want("flags") {
        piece = piece.with_point_data(DataArray::integers("flags", p.flags.iter().map(|f| f.0 as i32).collect()));
    }
    piece
}

/// Every quadrature point's [`Model::adiabatic_hardening`], the output
/// field `adiabatic_hardening`.
pub fn adiabatic_hardening(model: &Model) -> Vec<Real> {
    (0..model.quad.len()).into_par_iter().map(|k| model.adiabatic_hardening(k)).collect()
}

/// Plot the energy history of the run in `dir` (`energy.png`) from its
/// `history.csv`; returns the files written.
pub fn plot_history(dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    let table = crate::io::HistoryTable::read(&dir.join("history.csv"))?;
    let t: Vec<Real> = table.column("time").unwrap_or_default().iter().map(|t| t * 1e6).collect();
    let series = |col: &str, label: &str| crate::io::Series {
        name: label.to_string(),
        points: t.iter().cloned().zip(table.column(col).unwrap_or_default().iter().cloned()).collect(),
    };
    let plot = crate::io::LinePlot {
        title: "Energy balance".into(),
        x_label: "time (us)".into(),
        y_label: "energy (J)".into(),
        series: vec![
            series("kinetic_energy", "kinetic"),
            series("internal_energy", "internal (stress work)"),
            series("rigid_kinetic_energy", "rigid bodies kinetic"),
            series("contact_dissipation", "dissipated by contact"),
            series("total_energy", "total (should stay constant)"),
        ],
        hlines: vec![],
    };
    let path = dir.join("energy.png");
    crate::io::save_line_plot(&path, &plot)?;
    Ok(vec![path])
}

/// A field plot of the deformed bodies (particles at `x = X + u(X)`, in mm),
/// coloured by a projected quadrature field, with the crack faces drawn over
/// them; `window` limits the view to `[x_min, x_max, y_min, y_max]` (m) in
/// the reference configuration.
pub fn field_plot(sim: &Simulation, field: &str, window: Option<[Real; 4]>) -> Option<crate::io::FieldPlot> {
    let m = &sim.model;
    let q = &m.quad;
    // (values, label, physical lower bound of the colour scale)
    let (values, label, floor): (Vec<Real>, &str, Option<Real>) = match field {
        "effective_stress" => (
            m.project(|k| von_mises(&(q.tau[k].to_tensor() / q.f[k].determinant())) * 1e-6),
            "effective stress (MPa)",
            Some(0.0),
        ),
        "temperature" => (m.project(|k| q.temperature[k]), "temperature (K)", None),
        "plastic_strain" => (m.project(|k| q.eps_p[k]), "effective plastic strain", Some(0.0)),
        "damage" => (m.project(|k| q.damage[k]), "damage D", Some(0.0)),
        _ => return None,
    };
    let u = m.physical(&m.particles.u);
    let keep = |i: usize| {
        let x = m.particles.x0[i];
        window.is_none_or(|w| x.x >= w[0] && x.x <= w[1] && x.y >= w[2] && x.y <= w[3])
    };
    let idx: Vec<usize> = (0..m.particles.len()).filter(|&i| keep(i)).collect();
    let lines = sim
        .cracks
        .as_ref()
        .map(|c| {
            c.cracks
                .iter()
                .flat_map(|k| {
                    let reference: Vec<Vec2> = k.vertices.iter().map(|v| v.x0).collect();
                    k.face_polylines(m)
                        .into_iter()
                        .flat_map(move |face| clip_stretched(&reference, &face, MAX_DRAWN_STRETCH))
                })
                .map(|l| l.iter().map(|p| (p.x * 1e3, p.y * 1e3)).collect())
                .collect()
        })
        .unwrap_or_default();
    Some(crate::io::FieldPlot {
        title: format!("{label} at t = {:.1} us", sim.time * 1e6),
        x_label: "x (mm)".into(),
        y_label: "y (mm)".into(),
        points: idx
            .iter()
            .map(|&i| ((m.particles.x0[i].x + u[i].x) * 1e3, (m.particles.x0[i].y + u[i].y) * 1e3))
            .collect(),
        values: idx.iter().map(|&i| values[i]).collect(),
        value_label: label.into(),
        value_floor: floor,
        lines,
    })
}

/// Longest a crack-face segment is drawn, as a multiple of its length in
/// the reference configuration: a face particle thrown off the plate would
/// otherwise pull a line from the plate to wherever it flew.
pub const MAX_DRAWN_STRETCH: Real = 4.0;

/// The polyline `current` (the deformed positions of the vertices
/// `reference`) cut into runs at every segment stretched beyond
/// `max_stretch` times its reference length; runs of one vertex are
/// dropped.
pub fn clip_stretched(reference: &[Vec2], current: &[Vec2], max_stretch: Real) -> Vec<Vec<Vec2>> {
    let mut runs: Vec<Vec<Vec2>> = Vec::new();
    let mut run: Vec<Vec2> = Vec::new();
    for (k, p) in current.iter().enumerate() {
        if k > 0 {
            let (lr, lc) = ((reference[k] - reference[k - 1]).norm(), (p - current[k - 1]).norm());
            if lc > max_stretch * lr {
                runs.push(std::mem::take(&mut run));
            }
        }
        run.push(*p);
    }
    runs.push(run);
    runs.retain(|r| r.len() > 1);
    runs
}

/// Extent `(x_min, x_max)` of the first rigid body's outline now, m.
fn projectile_extent(sim: &Simulation) -> Option<(Real, Real)> {
    let b = sim.contact.as_ref()?.bodies.first()?;
    let (lo, hi) =
        b.outline().iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| (lo.min(v.x), hi.max(v.x)));
    Some((b.position.x + lo, b.position.x + hi))
}

/// The view around the first rigid body: ±1.5 projectile widths about its
/// centre line, the whole thickness.
fn impact_window(sim: &Simulation) -> Option<[Real; 4]> {
    projectile_extent(sim).map(|(lo, hi)| {
        let (w, cx) = (hi - lo, 0.5 * (lo + hi));
        [cx - 1.5 * w, cx + 1.5 * w, Real::NEG_INFINITY, Real::INFINITY]
    })
}

/// The view of the shear band at the projectile's right-hand corner: a
/// quarter of the projectile's width on either side of its edge, the whole
/// thickness (in axisymmetry the right-hand edge is the rim, r = radius).
fn shear_band_window(sim: &Simulation) -> Option<[Real; 4]> {
    projectile_extent(sim).map(|(lo, hi)| {
        let q = 0.25 * (hi - lo);
        [hi - q, hi + q, Real::NEG_INFINITY, Real::INFINITY]
    })
}

/// End-of-run field plots (`effective_stress.png`, `temperature.png`) of the
/// region around the first rigid body (±1.5 projectile widths), or of
/// everything without one.
pub fn plot_fields(sim: &Simulation, dir: &Path) -> Result<Vec<PathBuf>, OutputError> {
    let window = impact_window(sim);
    let mut written = Vec::new();
    for field in ["effective_stress", "temperature"] {
        if let Some(plot) = field_plot(sim, field, window) {
            let path = dir.join(format!("{field}.png"));
            crate::io::save_field_plot(&path, &plot)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// Label of a plot time in file names: `28us`, `28.5us` (to 0.1 µs).
pub fn time_label(t: Real) -> String {
    let tenths = (t * 1e7).round();
    if tenths % 10.0 == 0.0 {
        format!("{:.0}us", tenths / 10.0)
    } else {
        format!("{:.1}us", tenths / 10.0)
    }
}

/// The field plots asked for at time `at` (`output.plot_times`), drawn from
/// the current state (the first at or after `at`): the deformed bodies
/// around the first rigid body coloured by effective stress, with the
/// cracks (`effective_stress_<at>.png`), and the temperature of the shear
/// band at the projectile's corner (`temperature_<at>.png`, see
/// [`time_label`]); both fields over everything without a rigid body.
pub fn plot_fields_at(sim: &Simulation, dir: &Path, at: Real) -> Result<Vec<PathBuf>, OutputError> {
    let label = time_label(at);
    let mut written = Vec::new();
    for (field, window) in [("effective_stress", impact_window(sim)), ("temperature", shear_band_window(sim))] {
        if let Some(plot) = field_plot(sim, field, window) {
            let path = dir.join(format!("{field}_{label}.png"));
            crate::io::save_field_plot(&path, &plot)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// A run's `history.csv` in `dir`, read once for the functions below.
pub fn read_history(dir: &Path) -> Result<crate::io::HistoryTable, IoError> {
    crate::io::HistoryTable::read(&dir.join("history.csv"))
}

/// The perforation time of a run, from its history: when the plug was first
/// cut out (the `perforation_time` column of the last row; the plug is
/// looked for after every step that changed the cracks). `None` if no plug
/// was cut out.
pub fn perforation_time(table: &crate::io::HistoryTable) -> Option<Real> {
    table.column("perforation_time").and_then(|c| c.last().copied()).filter(|&t| t > 0.0)
}

/// When a rigid body touched anything, read from the run's `history.csv`
/// (its `NAME_contacts` column) by [`contact_times`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactTimes {
    /// The rigid body's name.
    pub name: String,
    /// The last history row before its first row in contact (no later than
    /// the touch), s; 0 if the first row is in contact, `None` if no row is.
    pub first: Option<Real>,
    /// The last history row in contact, s; `None` if no row is. The velocity
    /// a body keeps once its contacts have vanished is what experimenters
    /// call its residual velocity.
    pub last: Option<Real>,
}

/// When each rigid body of `rigid_names` first and last touched anything,
/// from the run's `history.csv` ([`ContactTimes`]). Read from the history
/// rather than tracked in the loop, so it is right for resumed runs too.
pub fn contact_times(table: &crate::io::HistoryTable, rigid_names: &[String]) -> Vec<ContactTimes> {
    let time = table.column("time").unwrap_or_default();
    rigid_names
        .iter()
        .map(|n| {
            let column = table.column(&format!("{n}_contacts"));
            let first = column.and_then(|c| c.iter().position(|&c| c > 0.0));
            let last = column.and_then(|c| c.iter().rposition(|&c| c > 0.0));
            ContactTimes {
                name: n.clone(),
                first: first.map(|k| if k == 0 { 0.0 } else { time[k - 1] }),
                last: last.map(|k| time[k]),
            }
        })
        .collect()
}

/// Slaves by exposure, from the run's `history.csv`: the particles admitted
/// by the end (`exposed_slaves` of the last row) and, if any of them
/// touched a rigid body in a history row, the first and last such row's
/// time, s, and the most in one row (`exposed_contacts`).
pub fn exposed_contact_summary(table: &crate::io::HistoryTable) -> ExposedSummary {
    let time = table.column("time").unwrap_or_default();
    let admitted = table.column("exposed_slaves").and_then(|c| c.last().copied()).unwrap_or(0.0) as usize;
    let touching: Vec<(Real, Real)> = table
        .column("exposed_contacts")
        .map(|c| c.iter().zip(time).filter(|(n, _)| **n > 0.0).map(|(n, t)| (*t, *n)).collect())
        .unwrap_or_default();
    let contacts = match (touching.first(), touching.last()) {
        (Some(first), Some(last)) => {
            Some((first.0, last.0, touching.iter().map(|(_, n)| *n as usize).max().unwrap_or(0)))
        }
        _ => None,
    };
    ExposedSummary { admitted, contacts }
}

/// What [`exposed_contact_summary`] reads off the history.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExposedSummary {
    /// Particles admitted to the contact slaves by exposure by the end.
    pub admitted: usize,
    /// First and last history row with admitted particles in contact (s),
    /// and the most in contact in one row.
    pub contacts: Option<(Real, Real, usize)>,
}

/// A moving body's sample now, as the history records it: rigid body
/// `rigid` of the contact, else the deformable body named `name`, its
/// mass-averaged motion and the contact force on it
/// ([`crate::contact::deformable_sample`]); `None` where
/// there is no such body.
pub fn flight_sample(sim: &Simulation, rigid: Option<usize>, name: &str) -> Option<crate::contact::BodySample> {
    if let Some(k) = rigid {
        return sim.contact.as_ref()?.sample(k);
    }
    let body = sim.model.bodies.iter().position(|i| i.name == name)? as u32;
    let p = &sim.model.particles;
    Some(crate::contact::deformable_sample(p, &sim.f_contact, body, sim.contact.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crack face whose middle vertex flew off is drawn as the two runs
    /// either side of it; faces that only deform stay whole.
    #[test]
    fn crack_faces_are_cut_where_a_vertex_flew_off() {
        let reference: Vec<Vec2> = (0..5).map(|k| Vec2::new(0.0, -1e-3 * k as Real)).collect();
        let sheared: Vec<Vec2> = reference.iter().map(|p| p + Vec2::new(0.5 * p.y, 0.0)).collect();
        assert_eq!(clip_stretched(&reference, &sheared, MAX_DRAWN_STRETCH), vec![sheared.clone()]);
        let mut thrown = sheared.clone();
        thrown[2] = Vec2::new(0.0, 0.08);
        let runs = clip_stretched(&reference, &thrown, MAX_DRAWN_STRETCH);
        assert_eq!(runs, vec![thrown[..2].to_vec(), thrown[3..].to_vec()]);
        thrown[4] = Vec2::new(0.0, 0.08);
        assert_eq!(clip_stretched(&reference, &thrown, MAX_DRAWN_STRETCH), vec![thrown[..2].to_vec()]);
    }

    #[test]
    fn contact_times_are_the_rows_around_the_first_and_last_contact() {
        let dir = crate::io::test_util::scratch_dir("last-contact");
        let mut h = HistoryWriter::create(&dir.join("history.csv"), &["time", "p_contacts", "q_contacts"]).unwrap();
        for (t, p) in [(0.0, 0.0), (1.0, 3.0), (2.0, 0.0), (3.0, 2.0), (4.0, 0.0)] {
            h.write_row(&[t, p, 0.0]).unwrap();
        }
        drop(h);
        let got = contact_times(&read_history(&dir).unwrap(), &["p".into(), "q".into()]);
        let times = |name: &str, first, last| ContactTimes { name: name.into(), first, last };
        assert_eq!(got, vec![times("p", Some(0.0), Some(3.0)), times("q", None, None)]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn perforation_time_is_read_from_the_last_history_row() {
        let dir = crate::io::test_util::scratch_dir("perforation");
        let mut h = HistoryWriter::create(&dir.join("history.csv"), &["time", "perforation_time"]).unwrap();
        for (t, p) in [(0.0, 0.0), (1.0, 0.0), (2.0, 1.7), (3.0, 1.7)] {
            h.write_row(&[t, p]).unwrap();
        }
        drop(h);
        assert_eq!(perforation_time(&read_history(&dir).unwrap()), Some(1.7));
        let mut h = HistoryWriter::create(&dir.join("history.csv"), &["time", "perforation_time"]).unwrap();
        h.write_row(&[0.0, 0.0]).unwrap();
        drop(h);
        assert_eq!(perforation_time(&read_history(&dir).unwrap()), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn exposed_contacts_span_the_rows_with_pushed_admitted_particles() {
        let dir = crate::io::test_util::scratch_dir("exposed");
        let mut h =
            HistoryWriter::create(&dir.join("history.csv"), &["time", "exposed_slaves", "exposed_contacts"]).unwrap();
        for (t, a, n) in
            [(0.0, 0.0, 0.0), (1.0, 4.0, 0.0), (2.0, 6.0, 2.0), (3.0, 7.0, 0.0), (4.0, 7.0, 3.0), (5.0, 9.0, 0.0)]
        {
            h.write_row(&[t, a, n]).unwrap();
        }
        drop(h);
        let got = exposed_contact_summary(&read_history(&dir).unwrap());
        assert_eq!(got, ExposedSummary { admitted: 9, contacts: Some((2.0, 4.0, 3)) });
        let mut h =
            HistoryWriter::create(&dir.join("history.csv"), &["time", "exposed_slaves", "exposed_contacts"]).unwrap();
        h.write_row(&[0.0, 5.0, 0.0]).unwrap();
        drop(h);
        let got = exposed_contact_summary(&read_history(&dir).unwrap());
        assert_eq!(got, ExposedSummary { admitted: 5, contacts: None });
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn plot_time_labels() {
        assert_eq!(time_label(28e-6), "28us");
        assert_eq!(time_label(46.0e-6 + 1e-12), "46us");
        assert_eq!(time_label(28.5e-6), "28.5us");
    }
}
