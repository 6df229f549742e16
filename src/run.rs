//! Running a case end to end: output directory, model, time loop, snapshots,
//! history, summary. The library never prints: progress goes to a callback.

use crate::case::Case;
use crate::io::IoError;
use crate::math::Real;
use crate::contact::{ContactSystem, SlaveSet, SurfaceDetection};
use crate::model::{Model, ModelError};
use crate::output::OutputWriter;
use crate::step::{Simulation, SolverError};
use crate::thermal::HeatConduction;
use std::path::{Path, PathBuf};
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
    /// Allow writing into an existing non-empty directory.
    pub force: bool,
    pub info: RunInfo,
}

/// What a finished run reports.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub particles: usize,
    pub quadrature_points: usize,
    pub steps: u64,
    pub time: Real,
    pub dt: Real,
    pub snapshots: usize,
    pub setup_wall: Duration,
    pub loop_wall: Duration,
    pub output_wall: Duration,
    pub stage_timers: Vec<(&'static str, Duration)>,
    pub energies: crate::step::Energies,
    /// Largest |energy drift| seen at a history row.
    pub max_drift: Real,
    pub out_dir: PathBuf,
    /// PNG plots written at the end.
    pub plots: Vec<PathBuf>,
    /// Each crack: id, nucleation time (s), arrest time (s) if it arrested.
    pub cracks: Vec<(usize, Real, Option<Real>)>,
    /// When the plug separated (all cracks that cut it out arrested), s.
    pub separation: Option<Real>,
    /// Velocity of each rigid body at the end, (name, (vx, vy)) m/s.
    pub rigid_velocities: Vec<(String, [Real; 2])>,
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
    #[error("{error}\n  the state at failure is in {}; all earlier output is kept in {}", last_snapshot.display(), dir.display())]
    Unstable { error: SolverError, last_snapshot: PathBuf, dir: PathBuf },
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
    }
    let probe = dir.join(".plugsim-write-test");
    std::fs::write(&probe, b"").map_err(|e| err(format!("not writable: {e}")))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// The simulation of a (resolved) case at t = 0: discretization, and
/// contact with its rigid bodies if it has any (slaves: the surface
/// particles, found geometrically), and heat conduction if the case asks
/// for it ([`Case::heat_conduction`]).
pub fn build_simulation(case: &Case) -> Result<Simulation, RunError> {
    let mut sim = build_simulation_without_cracks(case)?;
    if case.heat_conduction() {
        sim.heat = Some(HeatConduction::new(&sim.model, case.heat.safety_factor)?);
        sim.heat_every = case.heat.every;
    }
    if case.fracture.criterion != crate::fracture::Criterion::None {
        sim.cracks = Some(crate::fracture::CrackGrowth::new(case.fracture));
    }
    Ok(sim)
}

/// The simulation without heat conduction and cracks.
fn build_simulation_without_cracks(case: &Case) -> Result<Simulation, RunError> {
    let model = Model::build(case.geometry.mode, &case.body_setups())?;
    let rule = case.time_step_rule();
    if case.rigid_bodies.is_empty() {
        return Ok(Simulation::new(model, rule));
    }
    let bodies = case.rigid_bodies()?;
    let slaves = SlaveSet::detect(&model.particles.x0, &model.particles.spacing, &SurfaceDetection::default())?;
    let mut model = model;
    slaves.mark_flags(&mut model.particles.flags)?;
    let contact = ContactSystem::new(bodies, slaves, case.contact)?;
    Ok(Simulation::with_contact(model, rule, contact))
}

/// Progress reports to the caller.
pub enum Progress<'a> {
    /// The model is built; the loop is about to start.
    Started { sim: &'a Simulation, steps_estimate: u64 },
    /// Periodic, during the loop.
    Step { sim: &'a Simulation },
}

/// Build the model of `case`, run it to `time.end` writing into `cfg.out_dir`.
pub fn execute(case: &Case, cfg: &RunConfig, progress: &mut dyn FnMut(Progress)) -> Result<RunSummary, RunError> {
    let case = case.resolved();
    let t_setup = Instant::now();
    // Build before touching the disk: a case that cannot be discretized leaves nothing behind.
    let mut sim = build_simulation(&case)?;
    prepare_output_dir(&cfg.out_dir, cfg.force)?;
    let write = |name: &str, text: String| -> Result<(), RunError> {
        let path = cfg.out_dir.join(name);
        std::fs::write(&path, text).map_err(|source| RunError::Io(IoError::Write { path, source }))
    };
    write("case.resolved.toml", case.resolved_toml())?;
    write("run_info.toml", toml::to_string_pretty(&cfg.info).unwrap_or_default())?;
    let rigid_names: Vec<String> = case.rigid_bodies.iter().map(|r| r.name.clone()).collect();
    let mut out = OutputWriter::create(&cfg.out_dir, &case.output.fields, &rigid_names)?;
    let setup_wall = t_setup.elapsed();

    let end = case.time.end;
    let interval = case.output.interval.expect("resolved");
    let steps_estimate = (end / sim.dt).ceil() as u64;
    progress(Progress::Started { sim: &sim, steps_estimate });
    let t_loop = Instant::now();
    let mut output_wall = Duration::ZERO;
    let mut next_snapshot = 0.0;
    let mut max_drift: Real = 0.0;
    let report_every = (steps_estimate / 200).max(1);
    loop {
        let done = sim.time >= end - 0.5 * sim.dt;
        if sim.time >= next_snapshot - 0.5 * sim.dt || done {
            let t = Instant::now();
            out.snapshot(&sim)?;
            next_snapshot += interval;
            output_wall += t.elapsed();
        }
        if sim.step % case.output.history_every == 0 || done {
            let t = Instant::now();
            out.history_row(&sim)?;
            max_drift = max_drift.max(sim.energies.drift().abs());
            output_wall += t.elapsed();
        }
        if done {
            break;
        }
        let stepped = sim.step();
        out.crack_events(&sim)?;
        if let Err(error) = stepped {
            let last = out.snapshot(&sim)?;
            out.history_row(&sim)?;
            return Err(RunError::Unstable { error, last_snapshot: last, dir: cfg.out_dir.clone() });
        }
        if sim.step % report_every == 0 {
            progress(Progress::Step { sim: &sim });
        }
    }
    let loop_wall = t_loop.elapsed() - output_wall;
    let t = Instant::now();
    let plots = crate::output::plot_history(&cfg.out_dir)?;
    output_wall += t.elapsed();
    let (cracks, separation) = match &sim.cracks {
        Some(c) => (
            c.cracks.iter().map(|k| (k.id, k.nucleated.0, k.arrested.map(|a| a.0))).collect(),
            c.separation_time(sim.model.mode),
        ),
        None => (Vec::new(), None),
    };
    let rigid_velocities = sim
        .contact
        .as_ref()
        .map(|c| c.bodies.iter().map(|b| (b.name.clone(), [b.velocity.x, b.velocity.y])).collect())
        .unwrap_or_default();
    Ok(RunSummary {
        cracks,
        separation,
        rigid_velocities,
        plots,
        particles: sim.model.particles.len(),
        quadrature_points: sim.model.quad.len(),
        steps: sim.step,
        time: sim.time,
        dt: sim.dt,
        snapshots: out.snapshots,
        setup_wall,
        loop_wall,
        output_wall,
        stage_timers: sim.timers.list(),
        energies: sim.energies,
        max_drift,
        out_dir: cfg.out_dir.clone(),
    })
}
