//! Running a case end to end: output directory, model, time loop, snapshots,
//! history, summary. The library never prints: progress goes to a callback.

use crate::case::Case;
use crate::checkpoint::{CheckpointError, RunProgress};
use crate::contact::{ContactSystem, DeformableMasters, DeformableSwitches, SlaveSet, SurfaceDetection};
use crate::io::IoError;
use crate::math::{Real, Vec2};
use crate::memory::{Footprint, MemoryError};
use crate::model::{Model, ModelError};
use crate::output::{OutputWriter, ParticleTrace};
use crate::step::{Simulation, SolverError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Provenance written beside every run's output.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunInfo {
    /// plugsim version.
    pub version: String,
    /// Git commit the binary was built from (`unknown` outside a checkout).
    pub commit: String,
    /// Worker threads used.
    pub threads: usize,
    /// Case file the run came from.
    pub case_file: String,
    /// `--set` overrides applied.
    pub overrides: Vec<String>,
}

impl RunInfo {
    /// Provenance of this build and process.
    pub fn current(case_file: &str, overrides: &[String]) -> Self {
        RunInfo {
            version: env!("CARGO_PKG_VERSION").to_string(),
            commit: option_env!("PLUGSIM_COMMIT").unwrap_or("unknown").to_string(),
            threads: rayon::current_num_threads(),
            case_file: case_file.to_string(),
            overrides: overrides.to_vec(),
        }
    }
}

/// Where and how to write.
#[derive(Clone, Debug)]
pub struct RunConfig {
    pub out_dir: PathBuf,
    /// Allow writing into an existing non-empty directory (a fresh run;
    /// [`resume`] ignores it).
    pub force: bool,
    pub info: RunInfo,
    /// When set (by a Ctrl-C / SIGTERM handler, or a test), the run writes a
    /// checkpoint at the end of the current step and stops with
    /// [`RunError::Interrupted`].
    pub interrupt: Option<Arc<AtomicBool>>,
}

impl RunConfig {
    /// Write into `out_dir`, without an interrupt flag.
    pub fn new(out_dir: PathBuf, force: bool, info: RunInfo) -> Self {
        RunConfig { out_dir, force, info, interrupt: None }
    }
}

/// Most steps a run may take: beyond this, `time.end / Δt` comes from a
/// typo (a `fixed_dt` of 1e-15 s, an end time of 1 s for a 30 µs impact),
/// and the run would not finish in any useful time.
pub const MAX_STEPS: Real = 1e9;

/// A particle detached from its body (`fracture.detach_below`,
/// [`crate::fracture::CrackGrowth::detach_isolated`]): which, when, and
/// where its material came from, so that a study can say which particles
/// left and a run can be traced from them (docs/validation.md, "Detaching
/// made the default model's").
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DetachedParticle {
    pub particle: usize,
    /// When, s.
    pub time: Real,
    /// Its reference position `X_I`, m.
    pub reference: Vec2,
    /// Its lumped mass, kg (kg/m in plane strain): a detached particle
    /// keeps the mass it had when it left.
    pub mass: Real,
    /// Whether it lay on a crack face (a split's child or parent).
    pub crack_face: bool,
}

impl DetachedParticle {
    /// The records of `detached` ((particle, time) in the order detached,
    /// [`crate::fracture::CrackGrowth::detached`]) in `model`.
    pub fn of(model: &Model, detached: &[(usize, Real)]) -> Vec<DetachedParticle> {
        let p = &model.particles;
        detached
            .iter()
            .map(|&(i, time)| DetachedParticle {
                particle: i,
                time,
                reference: p.x0[i],
                mass: p.mass[i],
                crack_face: p.flags[i].has(crate::particles::ParticleFlags::CRACK_FACE),
            })
            .collect()
    }

    /// For a run summary: "23040 at 48.312 us (a crack-face particle from
    /// (9.917, 11.100) mm, 6.914e-6 kg)".
    pub fn describe(&self) -> String {
        format!(
            "{} at {:.3} us ({}, {:.3e} kg)",
            self.particle,
            self.time * 1e6,
            crate::step::particle_origin(self.crack_face, self.reference),
            self.mass
        )
    }
}

/// What a finished run reports.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub particles: usize,
    pub quadrature_points: usize,
    pub steps: u64,
    pub time: Real,
    pub dt: Real,
    /// The adaptive step ([`crate::stability::StableStep`]): the rule's
    /// step and the smallest taken (step, time, particle); `None` with a
    /// fixed step.
    pub stable_step: Option<(Real, (Real, Real, usize))>,
    /// Mass scaling's account ([`crate::stability::AddedMass`]); `None`
    /// without it.
    pub mass_scaling: Option<crate::stability::AddedMass>,
    /// The deformable bodies' mass at the end, added mass included, kg
    /// (kg/m in plane strain).
    pub total_mass: Real,
    pub snapshots: usize,
    pub setup_wall: Duration,
    pub loop_wall: Duration,
    pub output_wall: Duration,
    pub stage_timers: Vec<(&'static str, Duration)>,
    pub energies: crate::step::Energies,
    /// The artificial bulk viscosity the run used ([`crate::bulk_viscosity`];
    /// its work is in the internal energy).
    pub bulk_viscosity: crate::bulk_viscosity::BulkViscosity,
    /// Largest |energy drift| seen at a history row.
    pub max_drift: Real,
    /// The fastest particle of the run ([`crate::step::Simulation::fastest`]).
    pub fastest: crate::step::FastestParticle,
    /// The largest gap between a particle's coefficients and the field at
    /// it over the history's rows, in its spacings, and when
    /// ([`crate::step::coefficient_gap`], `history.csv`'s
    /// `max_coefficient_gap`); `None` without a row.
    pub coefficient_gap: Option<(Real, Real)>,
    /// The largest gap at the end, in spacings, its particle and where
    /// that particle's material came from (`step::particle_origin`).
    pub coefficient_gap_at_end: (Real, usize, String),
    /// The entries of `output.trace_particles` that never came to exist: a
    /// run with a fracture criterion accepts an index past the generated
    /// particles (a crack-face child to come),
    /// and `trace.csv` has no row of one no split made.
    pub untraced: Vec<usize>,
    /// Estimated peak memory of the case, bytes
    /// ([`crate::memory::Footprint::bytes`]).
    pub memory_estimate: Real,
    /// Peak resident memory of the process at the end of the run, bytes
    /// ([`crate::memory::peak_resident`]; the whole process, so a second run
    /// in the same process reports the larger of the two).
    pub peak_resident: Option<u64>,
    pub out_dir: PathBuf,
    /// PNG plots written at the end.
    pub plots: Vec<PathBuf>,
    /// Each crack: id, nucleation time (s), arrest time (s) if it arrested.
    pub cracks: Vec<(usize, Real, Option<Real>)>,
    /// The own damage of the particles the cracks grew into
    /// ([`crate::fracture::CrackGrowth::tip_damage`]).
    pub tip_damage: Option<crate::fracture::TipValues>,
    /// The adiabatic hardening of the particles the cracks grew into
    /// ([`crate::fracture::CrackGrowth::tip_hardening`]; ≤ 0 past the
    /// onset of shear localization).
    pub tip_hardening: Option<crate::fracture::TipValues>,
    /// When the plug separated (all cracks that cut it out arrested), s.
    pub separation: Option<Real>,
    /// Perforation: when the plug was first cut out of the plate (see
    /// [`crate::output::perforation_time`]), s.
    pub perforation: Option<Real>,
    /// The plug at the end of the run, if the cracks cut one out under the
    /// first rigid body ([`crate::plug`]).
    pub plug: Option<crate::plug::Plug>,
    /// Quadrature points eroded by the end (inverted after failing, torn
    /// open, or at the step's floor; [`crate::fracture`]).
    pub eroded_points: usize,
    /// Of those, the fractured points eroded at the step's floor
    /// (`[time] erode_failed_below`, [`crate::stability::StableStep::eroded`]);
    /// `None` without it.
    pub floor_eroded: Option<u64>,
    /// Particles that erosion or a crack split left with less than
    /// `fracture.detach_below` of their material and that were detached
    /// from their body ([`crate::fracture::CrackGrowth::detach_isolated`]),
    /// in the order detached.
    pub detached: Vec<DetachedParticle>,
    /// The radial kinetic energy the axis took from particles that reached
    /// it, J (`−`[`crate::contact::ContactSystem::axis_work`]; 0 where none
    /// did, or without a contact stage).
    pub axis_energy: Real,
    /// Particles that joined the contact slaves by exposure, and when they
    /// touched a rigid body ([`crate::contact::ContactSystem::admit_exposed`]).
    pub exposed: crate::output::ExposedSummary,
    /// Velocity of each rigid body at the end, (name, (vx, vy)) m/s.
    pub rigid_velocities: Vec<(String, [Real; 2])>,
    /// When each rigid body first and last touched anything (history rows),
    /// s ([`crate::output::contact_times`]).
    pub contacts: Vec<crate::output::ContactTimes>,
    /// How each rigid body's flight ended: perforated with its residual
    /// velocity, held, or undecided ([`crate::residual`], from the history).
    pub flights: Vec<(String, crate::residual::Verdict)>,
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("output directory {}: {message}", path.display())]
    OutputDir { path: PathBuf, message: String },
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("heat conduction setup: {0}")]
    Heat(#[from] crate::thermal::HeatError),
    #[error("contact setup: {0}")]
    Contact(#[from] crate::contact::ContactError),
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Plot(#[from] crate::io::PlotError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error("{error}\n  {}; all earlier output is kept in {}", state_note(last_snapshot, *at_failure), dir.display())]
    Unstable { error: Box<SolverError>, last_snapshot: PathBuf, at_failure: bool, dir: PathBuf },
    #[error(transparent)]
    Memory(#[from] MemoryError),
    #[error("output.trace_particles[{entry}]: particle {particle} does not exist (the model has {count} particles, 0 to {}, and no fracture criterion to split more off)", count.saturating_sub(1))]
    TracedParticle { entry: usize, particle: usize, count: usize },
    #[error("time step {dt:e} s: {message}")]
    TimeStep { dt: Real, message: String },
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(
        "interrupted at step {step} (t = {time:.6e} s); the state is saved in {}; continue with `plugsim resume {}`",
        checkpoint.display(), dir.display()
    )]
    Interrupted { step: u64, time: Real, checkpoint: PathBuf, dir: PathBuf },
}

/// What [`RunError::Unstable`] says of the state at failure.
fn state_note(last_snapshot: &Path, at_failure: bool) -> String {
    match at_failure {
        true => format!("the state at failure is in {}", last_snapshot.display()),
        false => format!(
            "the failing step stopped between a crack split and the rebuild of its rows, so its state cannot be \
             written; the last snapshot before it is {}",
            last_snapshot.display()
        ),
    }
}

/// Make sure `dir` can take a run: create it, or refuse if it holds files
/// and `force` is not set.
pub fn prepare_output_dir(dir: &Path, force: bool) -> Result<(), RunError> {
    let err = |message: String| RunError::OutputDir { path: dir.to_path_buf(), message };
    if dir.exists() {
        if !dir.is_dir() {
            return Err(err("exists and is not a directory".into()));
        }
        let non_empty = std::fs::read_dir(dir).map_err(|e| err(e.to_string()))?.next().is_some();
        if non_empty && !force {
            return Err(err("exists and is not empty; choose another --out or pass --force to overwrite".into()));
        }
    } else {
        std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create: {e}")))?;
        let probe = dir.join(".plugsim-write-test");
        if let Err(e) = std::fs::write(&probe, b"") {
            let _ = std::fs::remove_dir(dir); // leave nothing behind
            return Err(err(format!("not writable: {e}")));
        }
        let _ = std::fs::remove_file(probe);
        return Ok(());
    }
    let probe = dir.join(".plugsim-write-test");
    std::fs::write(&probe, b"").map_err(|e| err(format!("not writable: {e}")))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// What must hold before a case is discretized: its estimated memory fits
/// in the memory available (see [`crate::memory`]). Cheap: nothing is
/// generated, so absurd grids are refused at once. Returns the estimate.
pub fn preflight(case: &Case) -> Result<Footprint, RunError> {
    let bodies = case.bodies.iter().map(|b| (b.name.as_str(), &b.rectangle));
    Ok(crate::memory::guard(bodies, crate::memory::available_memory())?)
}

/// The simulation of a (resolved) case at t = 0: discretization, and
/// contact with its rigid bodies if it has any (slaves: the surface
/// particles, found geometrically), and heat conduction if the case asks
/// for it ([`Case::heat_conduction`]).
pub fn build_simulation(case: &Case) -> Result<Simulation, RunError> {
    let mut sim = build_simulation_without_cracks(case)?;
    case.apply_unstored_settings(&mut sim)?;
    sim.heat_every = case.heat.every;
    if case.fracture.criterion != crate::fracture::Criterion::None {
        sim.cracks = Some(crate::fracture::CrackGrowth::new(case.fracture));
    }
    Ok(sim)
}

/// The simulation without heat conduction and cracks.
fn build_simulation_without_cracks(case: &Case) -> Result<Simulation, RunError> {
    preflight(case)?;
    let model = Model::build(case.geometry.mode, &case.body_setups())?;
    let rule = case.time_step_rule();
    let sim = if !case.has_contact() {
        Simulation::new(model, rule)
    } else {
        let bodies = case.rigid_bodies()?;
        let p = &model.particles;
        let slaves = SlaveSet::detect_per_body(&p.x0, &p.spacing, &p.body, &SurfaceDetection::default())?;
        let mut model = model;
        slaves.mark_flags(&mut model.particles.flags)?;
        let switches = DeformableSwitches { bodies: case.contact.deformable, self_contact: case.contact.self_contact };
        let ranges: Vec<_> = model.bodies.iter().map(|b| b.particles.clone()).collect();
        let masters = DeformableMasters::of_bodies(&model.particles, &ranges, switches);
        let axis = case.geometry.mode == crate::geometry::GeometryMode::Axisymmetric && case.contact.axis;
        let contact = ContactSystem::new(bodies, slaves, case.contact)?.with_deformable(masters).with_axis(axis);
        Simulation::with_contact(model, rule, contact)
    };
    check_time_step(&sim, case.time.end)?;
    Ok(sim)
}

/// Every particle of `output.trace_particles` must exist (`0..count`):
/// checked where no crack can split one off.
fn check_traced_particles(traced: &[usize], count: usize) -> Result<(), RunError> {
    match traced.iter().enumerate().find(|&(_, &i)| i >= count) {
        Some((j, &particle)) => Err(RunError::TracedParticle { entry: j, particle, count }),
        None => Ok(()),
    }
}

/// The step must be a positive number and the run must end in at most
/// [`MAX_STEPS`] steps.
fn check_time_step(sim: &Simulation, end: Real) -> Result<(), RunError> {
    let dt = sim.dt;
    if !(dt.is_finite() && dt > 0.0) {
        let message = format!(
            "not a positive number (wave speed {:e} m/s, smallest spacing {:e} m); check the materials' moduli and densities",
            sim.model.max_wave_speed(),
            sim.model.min_spacing()
        );
        return Err(RunError::TimeStep { dt, message });
    }
    let steps = end / dt;
    if steps > MAX_STEPS {
        let message = format!("{steps:.3e} steps to time.end = {end:e} s, more than the {MAX_STEPS:e} a run may take");
        return Err(RunError::TimeStep { dt, message });
    }
    Ok(())
}

/// Progress reports to the caller.
pub enum Progress<'a> {
    /// A run continues from a checkpoint (before `Started`); `warnings`
    /// says what the reader skipped or could not guarantee.
    Resumed { sim: &'a Simulation, checkpoint: &'a Path, warnings: &'a [String] },
    /// The model is built; the loop is about to start (or continue).
    Started { sim: &'a Simulation, steps_estimate: u64, end: Real },
    /// Periodic, during the loop; `perforation` is when the cracks first
    /// cut a plug out (s; the history's `perforation_time`, [`crate::plug`]),
    /// `None` before.
    Step { sim: &'a Simulation, perforation: Option<Real> },
    /// A checkpoint was written; `perforation` as in `Step`.
    Checkpoint { sim: &'a Simulation, path: &'a Path, perforation: Option<Real> },
    /// The loop reached `time.end`; `sim` is the final state.
    Finished { sim: &'a Simulation },
}

/// Build the model of `case`, run it to `time.end` writing into `cfg.out_dir`.
pub fn execute(case: &Case, cfg: &RunConfig, progress: &mut dyn FnMut(Progress)) -> Result<RunSummary, RunError> {
    let case = case.resolved();
    let t_setup = Instant::now();
    // Build before touching the disk: a case that cannot be discretized leaves nothing behind.
    let sim = build_simulation(&case)?;
    // Crack splits add particles after the generated ones.
    if sim.cracks.as_ref().is_none_or(|c| c.params.critical_value().is_none()) {
        check_traced_particles(&case.output.trace_particles, sim.model.particles.len())?;
    }
    prepare_output_dir(&cfg.out_dir, cfg.force)?;
    // A reused directory must not keep another run's checkpoints for `resume` to find.
    crate::checkpoint::remove_all(&crate::checkpoint::directory(&cfg.out_dir))?;
    let write = |name: &str, text: String| -> Result<(), RunError> {
        let path = cfg.out_dir.join(name);
        std::fs::write(&path, text).map_err(|source| RunError::Io(IoError::Write { path, source }))
    };
    write("case.resolved.toml", case.resolved_toml())?;
    write("run_info.toml", toml::to_string_pretty(&cfg.info).unwrap_or_default())?;
    let out = OutputWriter::create(&cfg.out_dir, &case.output.fields, &case.flights())?;
    let trace = ParticleTrace::create(&cfg.out_dir, &case.output.trace_particles)?;
    let schedule = Schedule {
        next_snapshot: 0.0,
        next_checkpoint: case.checkpoint.interval.unwrap_or(Real::INFINITY),
        max_drift: 0.0,
    };
    time_loop(&case, sim, (out, trace), schedule, false, cfg, t_setup, progress)
}

/// Continue the run in `cfg.out_dir` from its newest readable checkpoint to
/// `time.end`. The case is the one stored in the checkpoint; the snapshot
/// series and `history.csv` continue where the checkpoint left them (rows and
/// snapshots written after it are dropped), so the finished directory is the
/// one an uninterrupted run would have written.
pub fn resume(cfg: &RunConfig, progress: &mut dyn FnMut(Progress)) -> Result<RunSummary, RunError> {
    let t_setup = Instant::now();
    let (restored, mut warnings) = crate::checkpoint::read_latest(&cfg.out_dir)?;
    let crate::checkpoint::Restored { path, writer, case, sim, progress: saved } = restored;
    let this = crate::checkpoint::this_writer();
    if writer != this {
        warnings.push(format!(
            "the checkpoint was written by {writer} and is continued by {this}: the result is bit-identical \
             to an uninterrupted run only with the same build"
        ));
    }
    let out = OutputWriter::resume(
        &cfg.out_dir,
        &case.output.fields,
        &case.flights(),
        &saved.snapshot_times,
        saved.history_bytes,
        sim.cracks.as_ref(),
    )?;
    let trace = ParticleTrace::resume(&cfg.out_dir, &case.output.trace_particles, sim.step)?;
    append_resume_record(cfg, &path, sim.step)?;
    progress(Progress::Resumed { sim: &sim, checkpoint: &path, warnings: &warnings });
    let schedule = Schedule {
        next_snapshot: saved.next_snapshot,
        next_checkpoint: saved.next_checkpoint,
        max_drift: saved.max_drift,
    };
    time_loop(&case, sim, (out, trace), schedule, true, cfg, t_setup, progress)
}

/// Add a `[[resumed]]` record (provenance of the continuing process) to
/// `run_info.toml`.
fn append_resume_record(cfg: &RunConfig, checkpoint: &Path, step: u64) -> Result<(), RunError> {
    #[derive(serde::Serialize)]
    struct Record<'a> {
        checkpoint: String,
        step: u64,
        #[serde(flatten)]
        info: &'a RunInfo,
    }
    #[derive(serde::Serialize)]
    struct Resumed<'a> {
        resumed: [Record<'a>; 1],
    }
    let record = Resumed { resumed: [Record { checkpoint: checkpoint.display().to_string(), step, info: &cfg.info }] };
    let text = toml::to_string(&record).unwrap_or_default();
    let path = cfg.out_dir.join("run_info.toml");
    let fail = |source| RunError::Io(IoError::Write { path: path.clone(), source });
    let mut file = std::fs::OpenOptions::new().append(true).create(true).open(&path).map_err(fail)?;
    std::io::Write::write_all(&mut file, format!("\n{text}").as_bytes()).map_err(fail)
}

/// The run loop's own clocks, carried by checkpoints.
struct Schedule {
    /// Time of the next snapshot, s.
    next_snapshot: Real,
    /// Time of the next checkpoint by simulated time, s (infinite: none).
    next_checkpoint: Real,
    /// Largest |drift| at a history row so far.
    max_drift: Real,
}

/// Write a checkpoint of the current state into the run's checkpoint
/// directory (after the outputs of this step) and drop the oldest.
fn save_checkpoint(
    case: &Case,
    sim: &Simulation,
    out: &mut OutputWriter,
    schedule: &Schedule,
    dir: &Path,
) -> Result<PathBuf, RunError> {
    out.flush()?;
    out.sync()?;
    let progress = RunProgress {
        snapshot_times: out.snapshot_times(),
        history_bytes: out.history_bytes(),
        next_snapshot: schedule.next_snapshot,
        next_checkpoint: schedule.next_checkpoint,
        max_drift: schedule.max_drift,
    };
    let dir = crate::checkpoint::directory(dir);
    let path = dir.join(crate::checkpoint::file_name(sim.step));
    crate::checkpoint::write(&path, sim, case, &progress)?;
    crate::checkpoint::rotate(&dir, case.checkpoint.keep as usize)?;
    Ok(path)
}

/// The time loop: outputs of the current state, then a checkpoint if one is
/// due (or the run is interrupted), then a step. With `outputs_done`, the
/// outputs of the first state are already on disk (a resumed run).
#[allow(clippy::too_many_arguments)]
fn time_loop(
    case: &Case,
    mut sim: Simulation,
    (mut out, mut trace): (OutputWriter, ParticleTrace),
    mut schedule: Schedule,
    mut outputs_done: bool,
    cfg: &RunConfig,
    t_setup: Instant,
    progress: &mut dyn FnMut(Progress),
) -> Result<RunSummary, RunError> {
    let setup_wall = t_setup.elapsed();
    let end = case.time.end;
    let interval = case.output.interval.expect("resolved");
    let steps_estimate = (end / sim.dt).ceil() as u64;
    progress(Progress::Started { sim: &sim, steps_estimate, end });
    let t_loop = Instant::now();
    let mut output_wall = Duration::ZERO;
    let report_every = (steps_estimate / 200).max(1);
    let (ckpt_interval, wall_interval) = (case.checkpoint.interval, case.checkpoint.wall_interval);
    let mut last_checkpoint = Instant::now();
    let mut plots = Vec::new();
    // Plot times still to draw (a resumed run drew those up to its checkpoint state).
    let mut plot_times: Vec<Real> =
        case.output.plot_times.iter().cloned().filter(|&t| !outputs_done || t - 0.5 * sim.dt > sim.time).collect();
    plot_times.sort_by(|a, b| b.total_cmp(a));
    let mut released = false;
    // The steps whose state the history records (and the early stop reads).
    let records_history = |step: u64| step.is_multiple_of(case.output.history_every);
    loop {
        let done = released || sim.time >= end - 0.5 * sim.dt;
        if !outputs_done {
            if sim.time >= schedule.next_snapshot - 0.5 * sim.dt || done {
                let t = Instant::now();
                out.snapshot(&sim)?;
                schedule.next_snapshot += interval;
                output_wall += t.elapsed();
            }
            if records_history(sim.step) || done {
                let t = Instant::now();
                out.history_row(&sim)?;
                schedule.max_drift = schedule.max_drift.max(sim.energies.drift().abs());
                output_wall += t.elapsed();
            }
            while let Some(&at) = plot_times.last().filter(|&&at| sim.time >= at - 0.5 * sim.dt) {
                let t = Instant::now();
                plots.extend(crate::output::plot_fields_at(&sim, &cfg.out_dir, at)?);
                plot_times.pop();
                output_wall += t.elapsed();
            }
        }
        outputs_done = false;
        if done {
            break;
        }
        let interrupted = cfg.interrupt.as_ref().is_some_and(|f| f.load(Ordering::SeqCst));
        let by_time = sim.time >= schedule.next_checkpoint - 0.5 * sim.dt;
        let by_wall = wall_interval > 0.0 && last_checkpoint.elapsed().as_secs_f64() >= wall_interval;
        if interrupted || by_time || by_wall {
            if by_time {
                let every = ckpt_interval.unwrap_or(Real::INFINITY);
                schedule.next_checkpoint += every;
                if schedule.next_checkpoint <= sim.time {
                    schedule.next_checkpoint = sim.time + every;
                }
            }
            let t = Instant::now();
            trace.sync()?;
            let path = save_checkpoint(case, &sim, &mut out, &schedule, &cfg.out_dir)?;
            output_wall += t.elapsed();
            last_checkpoint = Instant::now();
            progress(Progress::Checkpoint { sim: &sim, path: &path, perforation: out.perforation() });
            if interrupted {
                return Err(RunError::Interrupted {
                    step: sim.step,
                    time: sim.time,
                    checkpoint: path,
                    dir: cfg.out_dir.clone(),
                });
            }
        }
        trace.before_step(&sim);
        let stepped = sim.step();
        // A crack stage that failed between a split and its rows leaves
        // no state that fields can be drawn from (nor the plug found, nor
        // a particle traced): the last snapshot is then the one before.
        let drawable = stepped.is_ok() || sim.model.tables_match();
        if drawable {
            trace.after_step(&sim)?;
            out.crack_events(&sim)?;
        }
        if let Err(error) = stepped {
            let last = match drawable {
                true => out.snapshot(&sim)?,
                false => out.last_snapshot(),
            };
            out.flush()?;
            if drawable {
                out.history_row(&sim)?;
            }
            return Err(RunError::Unstable {
                error: Box::new(error),
                last_snapshot: last,
                at_failure: drawable,
                dir: cfg.out_dir.clone(),
            });
        }
        // The early stop samples the states the history records (the next
        // row is this state), so it and the verdict read from the history
        // (`crate::residual`) see the same forces and the same peak: sampled
        // every step, the peak could be higher than the rows', the threshold
        // with it, and a run stopped as released read "in contact at the
        // end" (Case II, 24 rows, bulk viscosity, at 72.8 us).
        if let Some(wait) = case.time.stop_after_release {
            if records_history(sim.step) {
                released = out.flights_over(&sim, wait);
            }
        }
        if sim.step.is_multiple_of(report_every) {
            progress(Progress::Step { sim: &sim, perforation: out.perforation() });
        }
    }
    let t = Instant::now();
    out.flush()?;
    output_wall += t.elapsed();
    let loop_wall = t_loop.elapsed().saturating_sub(output_wall);
    progress(Progress::Finished { sim: &sim });
    let t = Instant::now();
    plots.extend(crate::output::plot_history(&cfg.out_dir)?);
    plots.extend(crate::output::plot_fields(&sim, &cfg.out_dir)?);
    output_wall += t.elapsed();
    let (cracks, separation, tip_damage, tip_hardening) = match &sim.cracks {
        Some(c) => (
            c.cracks.iter().map(|k| (k.id, k.nucleated.0, k.arrested.map(|a| a.0))).collect(),
            c.separation_time(sim.model.mode),
            c.tip_damage(),
            c.tip_hardening(),
        ),
        None => (Vec::new(), None, None, None),
    };
    let rigid_velocities: Vec<(String, [Real; 2])> = sim
        .contact
        .as_ref()
        .map(|c| c.bodies.iter().map(|b| (b.name.clone(), [b.velocity.x, b.velocity.y])).collect())
        .unwrap_or_default();
    let names: Vec<String> = rigid_velocities.iter().map(|(n, _)| n.clone()).collect();
    let history = crate::output::read_history(&cfg.out_dir)?;
    let coefficient_gap = history.column("max_coefficient_gap").zip(history.column("time")).and_then(|(g, t)| {
        g.iter().zip(t).fold(None, |best: Option<(Real, Real)>, (&g, &t)| match best {
            Some((b, _)) if b >= g => best,
            _ => Some((g, t)),
        })
    });
    let contacts = crate::output::contact_times(&history, &names);
    let perforation = crate::output::perforation_time(&history);
    let through = out.through(&sim).to_vec();
    let flights = case
        .flights()
        .into_iter()
        .enumerate()
        .filter_map(|(b, (name, v0))| {
            let dir = crate::residual::flight_direction(v0);
            let plug = perforation.is_some();
            let through = through.get(b).copied().flatten();
            let verdict = crate::residual::verdict_from_history(&history, &name, dir, v0.norm(), plug, through)?;
            Some((name, verdict))
        })
        .collect();
    let plug = match (&sim.cracks, out.impact_line(&sim)) {
        (Some(c), Some(axis_x)) => crate::plug::find_plug(&sim.model, c, axis_x),
        _ => None,
    };
    Ok(RunSummary {
        perforation,
        plug,
        eroded_points: sim.model.quad.eroded.iter().filter(|&&e| e).count(),
        floor_eroded: sim.floors.erosion.and(sim.stable.as_ref()).map(|s| s.eroded),
        detached: sim.cracks.as_ref().map_or_else(Vec::new, |c| DetachedParticle::of(&sim.model, &c.detached)),
        exposed: crate::output::exposed_contact_summary(&history),
        axis_energy: sim.contact.as_ref().map_or(0.0, |c| -c.axis_work()),
        cracks,
        tip_damage,
        tip_hardening,
        separation,
        rigid_velocities,
        contacts,
        flights,
        plots,
        particles: sim.model.particles.len(),
        quadrature_points: sim.model.quad.len(),
        steps: sim.step,
        time: sim.time,
        dt: sim.dt,
        stable_step: sim.stable.as_ref().map(|s| (s.base, s.smallest)),
        mass_scaling: sim.floors.mass_scaling.and(sim.stable.as_ref()).map(|s| s.added),
        total_mass: sim.model.particles.total_mass(),
        snapshots: out.snapshots,
        setup_wall,
        loop_wall,
        output_wall,
        stage_timers: sim.timers.list(),
        energies: sim.energies,
        bulk_viscosity: sim.bulk_viscosity,
        max_drift: schedule.max_drift,
        fastest: sim.fastest,
        coefficient_gap,
        coefficient_gap_at_end: {
            let (gap, i) = crate::step::coefficient_gap(&sim.model);
            let p = &sim.model.particles;
            let crack_face = p.flags.get(i).is_some_and(|f| f.has(crate::particles::ParticleFlags::CRACK_FACE));
            (gap, i, crate::step::particle_origin(crack_face, p.x0.get(i).copied().unwrap_or_default()))
        },
        untraced: case.output.trace_particles.iter().copied().filter(|&i| i >= sim.model.particles.len()).collect(),
        memory_estimate: preflight(case)?.bytes(),
        peak_resident: crate::memory::peak_resident(),
        out_dir: cfg.out_dir.clone(),
    })
}
