//! The `plugsim` command line.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use plugsim::case::Case;
use plugsim::cases::{builtin_case, ALIASES, BUILTIN_CASES};
use plugsim::run::{execute, resume, Progress, RunConfig, RunError, RunInfo, RunSummary};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

#[derive(Parser)]
#[command(name = "plugsim", version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("PLUGSIM_COMMIT"), ")"),
          about = "Meshfree (RKPM) simulation of high-speed impact, plugging and ductile fracture")]
struct Cli {
    /// Worker threads (default, or 0: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case file (or a built-in case with --case).
    Run {
        /// Case file (TOML).
        case_file: Option<PathBuf>,
        /// A built-in case by name (see `plugsim cases`).
        #[arg(long, conflicts_with = "case_file")]
        case: Option<String>,
        /// Output directory (default: the case's output.directory, else runs/<case name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a case value, e.g. --set time.end=2e-5 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Write into an existing non-empty output directory.
        #[arg(long)]
        force: bool,
    },
    /// Continue an interrupted run in its output directory from its newest checkpoint.
    Resume {
        /// The run's output directory (holding `checkpoints/`).
        dir: PathBuf,
    },
    /// Why the growing crack tips of a run stand where they are: every particle within
    /// reach of each tip, its criterion value, its rank, the tip's gate reading there and
    /// the first check of the crack-growth stage that turns it down, read from a checkpoint.
    CrackTips {
        /// A run's output directory (its newest checkpoint) or a checkpoint file (.ckpt).
        path: PathBuf,
        /// Read the tips with other crack-tip parameters than the run's, e.g.
        /// --set fracture.nonlocal_tip_triaxiality=false (fracture.* keys only; repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// List the particles outside the tip's fan too (their criterion and gate
        /// readings: what a wider fan would find).
        #[arg(long)]
        all: bool,
    },
    /// What a run's stable time step is waiting on: the particles that allow the smallest
    /// steps in a checkpoint's state, with their mass, the distortion of their points and
    /// what is left of their material.
    TimeStep {
        /// A run's output directory (its newest checkpoint) or a checkpoint file (.ckpt).
        path: PathBuf,
        /// How many particles to list.
        #[arg(long, default_value_t = 10)]
        top: usize,
    },
    /// Check a case file without running it: validation, particle counts, time step.
    Check {
        case_file: Option<PathBuf>,
        #[arg(long, conflicts_with = "case_file")]
        case: Option<String>,
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// List the built-in cases.
    Cases,
    /// Run Borvik's plugging cases and compare residual velocities with the
    /// experiments and the paper (writes validation.md, validation.csv, plots).
    Validate {
        /// Output directory for the runs and the report.
        #[arg(long, default_value = "runs/validation")]
        out: PathBuf,
        /// Run every row: fine discretizations and Borvik's modified material too.
        #[arg(long)]
        all: bool,
        /// Only this row (a built-in case name such as borvik-1-axisymmetric, or
        /// the alias borvik-1), else the rows whose name contains this text
        /// (e.g. borvik-2, damage, fine); chosen among all rows.
        #[arg(long)]
        only: Option<String>,
        /// Run every row to the paper's simulated time (118 or 216 us) instead
        /// of stopping 20 us after the projectile's release.
        #[arg(long)]
        full_time: bool,
        /// Which family: borvik (the plugging cases), convergence (the
        /// axisymmetric Borvik cases at 12, 24 and 48 rows through the
        /// thickness, for the default fracture model and [RL10]'s criteria;
        /// --only selects among the coarse rows' names) or taylor (the Taylor
        /// anvil tests, taylor-*: coarse and medium resolutions, fine with --all;
        /// --only selects among their case names).
        #[arg(long, default_value = "borvik")]
        family: String,
        /// Override a value of every Taylor run (taylor family only), e.g.
        /// time.safety_factor=0.1; written into the report.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Run a case with a projectile (rigid or deformable) at several impact speeds and/or find
    /// its ballistic limit by bisection; writes ballistic.csv, ballistic.md
    /// (table, Recht-Ipson fit) and ballistic.png, and each run's directory.
    Ballistic {
        /// Case file (TOML).
        case_file: Option<PathBuf>,
        /// A built-in case by name (see `plugsim cases`).
        #[arg(long, conflicts_with = "case_file")]
        case: Option<String>,
        /// Override a case value, e.g. --set time.end=2e-4 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Output directory (default: runs/ballistic-<case name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Boxed: the study's options are the largest of the commands'.
        #[command(flatten)]
        args: Box<BallisticArgs>,
    },
    /// Benchmark fixed workloads: shape functions, material kernel, force
    /// assembly, whole steps (1 and all threads), optionally whole cases.
    Bench {
        /// Built-in case used for the step workloads.
        #[arg(long, default_value = "borvik-1-nofracture")]
        case: String,
        /// Steps per whole-step measurement.
        #[arg(long, default_value_t = 50)]
        steps: usize,
        /// Also run the whole case to this end time, s, with output every 1 us
        /// (e.g. 118e-6 for the paper's Case I), with 1 and all threads.
        #[arg(long)]
        whole: Option<f64>,
        /// Extra `--set` overrides for the case (e.g. a fine discretization).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Drive one material point through a deformation history and write
    /// stress-strain-temperature-damage curves (CSV + PNG): the calibration tool.
    MaterialPoint {
        /// A built-in material name, or NAME from --case-file's [materials].
        #[arg(long, default_value = "weldox_460e")]
        material: String,
        /// Take the material from this case file's [materials] table.
        #[arg(long)]
        case_file: Option<PathBuf>,
        /// Deformation path.
        #[arg(long, value_enum, default_value = "simple-shear")]
        path: PathArg,
        /// Strain rate magnitude, 1/s.
        #[arg(long, default_value_t = 1.0e4)]
        rate: f64,
        /// Final strain (shear strain gamma for simple shear); its sign sets the direction.
        #[arg(long, default_value_t = 1.0)]
        strain: f64,
        /// Largest time step, s (default: 1/2000 of the loading time).
        #[arg(long)]
        dt: Option<f64>,
        /// Output file stem: writes STEM.csv and STEM_*.png.
        #[arg(long, default_value = "material_point")]
        out: PathBuf,
    },
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum PathArg {
    UniaxialStrain,
    UniaxialStress,
    SimpleShear,
}

/// Load a case from a file or the built-in set; returns the case and a name for it.
fn load(case_file: &Option<PathBuf>, builtin: &Option<String>, set: &[String]) -> Result<(Case, String, String)> {
    match (case_file, builtin) {
        (Some(path), None) => {
            let case = Case::load(path, set)?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "case".into());
            Ok((case, stem, path.display().to_string()))
        }
        (None, Some(name)) => {
            let Some(text) = builtin_case(name) else {
                bail!(
                    "unknown built-in case '{name}'; available: {}",
                    BUILTIN_CASES.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
                )
            };
            let file = format!("<built-in {name}>");
            let case = Case::from_str_with(text, &file, set)?;
            Ok((case, name.clone(), file))
        }
        _ => bail!("give a case file or --case NAME (see `plugsim cases`)"),
    }
}

fn main() {
    let cli = Cli::parse();
    // The command runs on a worker of the pool, not on the main thread: a
    // parallel loop started from a worker runs there at once, while one
    // started from outside the pool is queued, wakes a worker and puts the
    // caller to sleep until it is done (tens of such round trips a step).
    // `0`: rayon's default (RAYON_NUM_THREADS, else one per core).
    let threads = cli.threads.unwrap_or(0);
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("error: cannot set up {threads} threads: {e}");
            std::process::exit(2);
        }
    };
    let code = match pool.install(|| dispatch(cli.command)) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            // 130 = 128 + SIGINT, the shell's code for a run stopped by Ctrl-C.
            if matches!(e.downcast_ref::<RunError>(), Some(RunError::Interrupted { .. })) {
                130
            } else {
                1
            }
        }
    };
    std::process::exit(code);
}

/// `plugsim cases`: one line per built-in case and alias. A reader that
/// stops early (`plugsim cases | head`) ends the listing quietly, as with
/// other command-line tools, instead of a panic on the closed pipe.
fn list_cases() -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let lines = BUILTIN_CASES
        .iter()
        .map(|(name, _, about)| format!("{name:44} {about}"))
        .chain(ALIASES.iter().map(|(alias, name)| format!("{alias:44} = {name}")));
    for line in lines {
        match writeln!(out, "{line}") {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
            r => r?,
        }
    }
    match out.flush() {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}

/// An error and its causes on one line, each cause once: most of the
/// crate's errors already end with their source's text (`"checkpoint X:
/// {source}"`), which anyhow's `{:#}` would print a second time.
fn error_line(e: &anyhow::Error) -> String {
    let mut line = e.to_string();
    for cause in e.chain().skip(1) {
        let text = cause.to_string();
        if !line.ends_with(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
    }
    line
}

/// A run's newest checkpoint (`path` its output directory) or the
/// checkpoint file `path`, with a first line saying which and when.
fn read_checkpoint(path: &Path) -> Result<plugsim::checkpoint::Restored> {
    let restored = if path.is_dir() {
        let (r, warnings) = plugsim::checkpoint::read_latest(path)?;
        for w in warnings {
            eprintln!("warning: {w}");
        }
        r
    } else {
        plugsim::checkpoint::read(path)?
    };
    println!("{} at t = {:.3} us (step {})", restored.path.display(), restored.sim.time * 1e6, restored.sim.step);
    Ok(restored)
}

/// `plugsim time-step`: the `top` particles that allow the smallest steps
/// in a checkpoint's state ([`plugsim::stability::step_setters`]).
fn time_step(path: &Path, top: usize) -> Result<()> {
    use plugsim::particles::ParticleFlags;
    let sim = read_checkpoint(path)?.sim;
    let Some(stable) = sim.stable.as_ref() else {
        println!("the run has a fixed step ({:.4e} s): nothing sets it", sim.dt);
        return Ok(());
    };
    let m = &sim.model;
    let (p, base) = (&m.particles, stable.base);
    println!(
        "step {:.4e} s = {:.3} of the spacing step {:.4e} s; smallest so far {:.4e} s at {:.3} us (particle {})",
        sim.dt,
        sim.dt / base,
        base,
        stable.smallest.0,
        stable.smallest.1 * 1e6,
        stable.smallest.2
    );
    println!(
        "step alone: the elastic step the particle allows (the run takes the least, times the bulk viscosity's factor); \
         distortion: its bound over the same with undeformed gradients; J, stretch: least det F and largest in-plane \
         stretch ratio of its live points; points: all / eroded / fractured"
    );
    println!(
        "{:>9} {:>11} {:>7} {:>11} {:>10} {:>11} {:>6} {:>9} {:>9} {:>12} {:>24} {:>24}  kind",
        "particle",
        "step alone",
        "/ dt0",
        "distortion",
        "mass (kg)",
        "added (kg)",
        "share",
        "least J",
        "stretch",
        "points",
        "X (mm)",
        "x now (mm)"
    );
    for s in plugsim::stability::step_setters(m, stable, sim.fractures_points(), top) {
        let i = s.particle;
        let x = p.x0[i] + m.particle_shape.interpolate(i, &p.u);
        let flags = p.flags[i];
        let kind: Vec<&str> = [
            (ParticleFlags::CRACK_FACE, "crack face"),
            (ParticleFlags::DETACHED, "detached"),
            (ParticleFlags::SLAVE, "slave"),
            (ParticleFlags::ON_AXIS, "on the axis"),
        ]
        .iter()
        .filter(|(f, _)| flags.has(*f))
        .map(|&(_, name)| name)
        .collect();
        println!(
            "{i:>9} {:>11.4e} {:>7.3} {:>11.3} {:>10.3e} {:>11.3e} {:>6.3} {:>9.4} {:>9.3} {:>12} {:>24} {:>24}  {}",
            s.step,
            s.step / base,
            s.distortion,
            s.mass,
            s.added_mass,
            plugsim::fracture::growth::live_share(m, i),
            s.least_j,
            s.largest_stretch,
            format!("{} / {} / {}", s.points, s.eroded, s.fractured),
            format!("({:.4}, {:.4})", p.x0[i].x * 1e3, p.x0[i].y * 1e3),
            format!("({:.4}, {:.4})", x.x * 1e3, x.y * 1e3),
            if kind.is_empty() { "-".to_string() } else { kind.join(", ") }
        );
    }
    Ok(())
}

/// `plugsim crack-tips`: the candidates of every growing tip of the
/// checkpoint at `path` (a file, or a run directory's newest), those
/// outside the fan too with `all`.
fn crack_tips(path: &Path, set: &[String], all: bool) -> Result<()> {
    use plugsim::fracture::CandidateCheck;
    if let Some(key) = set.iter().find(|s| !s.starts_with("fracture.")) {
        bail!("--set {key}: crack-tips reads the tips again with other fracture.* parameters only");
    }
    let restored = read_checkpoint(path)?;
    let mut sim = restored.sim;
    let Some(cracks) = sim.cracks.as_mut() else {
        println!("the case grows no cracks");
        return Ok(());
    };
    if !set.is_empty() {
        let text = toml::to_string(&restored.case).context("writing the checkpoint's case back")?;
        let case = Case::from_str_with(&text, &restored.path.display().to_string(), set)?;
        // the caches the parameters shape (the circle grid, the average's
        // bins) are not in checkpoints: built at first use, with these
        cracks.params = case.fracture;
        println!("read with {}", set.join(" "));
    }
    let model = &sim.model;
    let growing: Vec<usize> = (0..cracks.cracks.len()).filter(|&c| cracks.cracks[c].growing()).collect();
    println!(
        "{} cracks, {} growing; tip gate {:?}, read {}",
        cracks.cracks.len(),
        growing.len(),
        cracks.params.tip_gate,
        if cracks.params.nonlocal_tip_triaxiality { "over the nonlocal radius" } else { "at the particle" }
    );
    for c in growing {
        let crack = &cracks.cracks[c];
        let tip = crack.tip.expect("growing");
        // where the material is now: the field at the tip, not its coefficient
        let x0 = model.particles.x0[tip];
        let x = x0 + model.particle_shape.interpolate(tip, &model.particles.u);
        let last = crack.vertices.len();
        println!(
            "\ncrack {c}: tip particle {tip} at X = ({:.4}, {:.4}) mm (now ({:.4}, {:.4}) mm), {} vertices, direction ({:.3}, {:.3})",
            x0.x * 1e3,
            x0.y * 1e3,
            x.x * 1e3,
            x.y * 1e3,
            last,
            crack.direction().x,
            crack.direction().y
        );
        let path: Vec<String> =
            crack.vertices.iter().map(|v| format!("({:.3}, {:.3})", v.x0.x * 1e3, v.x0.y * 1e3)).collect();
        println!("  path (reference, mm): {}", path.join(" "));
        let report = cracks.tip_candidates(model, c);
        if let Some(h) = report.heading {
            println!("  heading ({:.3}, {:.3}): a candidate's rank is minus its angle to it, rad", h.x, h.y);
        }
        let mut rows = report.candidates;
        rows.sort_by(|a, b| a.rank.is_nan().cmp(&b.rank.is_nan()).then(b.rank.total_cmp(&a.rank)));
        let chosen = rows.iter().find(|r| r.check == CandidateCheck::Eligible).map(|r| r.particle);
        println!(
            "  {:>8} {:>9} {:>9} {:>10} {:>9} {:>12}  check",
            "particle", "dX mm", "dY mm", "criterion", "rank", "gate"
        );
        for r in rows.iter().filter(|r| all || r.check != CandidateCheck::OutsideFan) {
            println!(
                "  {:>8} {:>9.4} {:>9.4} {:>10.4} {:>9.4} {:>12.4e}  {}{}",
                r.particle,
                r.offset.x * 1e3,
                r.offset.y * 1e3,
                r.value,
                r.rank,
                r.gate,
                r.check.name(),
                if Some(r.particle) == chosen { " (the step)" } else { "" }
            );
        }
    }
    Ok(())
}

fn dispatch(cmd: Command) -> Result<()> {
    match cmd {
        Command::Cases => list_cases(),
        Command::Ballistic { case_file, case, set, out, args } => {
            let (loaded, name, file) = load(&case_file, &case, &set)?;
            ballistic(loaded, &name, &file, case.as_deref(), &set, out, *args)
        }
        Command::Bench { case, steps, whole, set } => bench(&case, steps, whole, &set),
        Command::Validate { out, all, only, full_time, family, set } => match family.as_str() {
            "borvik" if set.is_empty() => validate(&out, all, only.as_deref(), full_time),
            "borvik" => bail!("--set applies to the taylor family only"),
            "taylor" => validate_taylor(&out, all, only.as_deref(), &set),
            "convergence" if set.is_empty() => validate_convergence(&out, only.as_deref()),
            "convergence" => bail!("--set applies to the taylor family only"),
            other => bail!("unknown validation family `{other}` (borvik, convergence or taylor)"),
        },
        Command::MaterialPoint { material, case_file, path, rate, strain, dt, out } => {
            material_point(&material, case_file.as_deref(), path, rate, strain, dt, &out)
        }
        Command::Check { case_file, case, set } => {
            let (case, _, file) = load(&case_file, &case, &set)?;
            check(&case, &file)
        }
        Command::Run { case_file, case, out, set, force } => {
            let (case, name, file) = load(&case_file, &case, &set)?;
            let out_dir = out
                .or_else(|| case.output.directory.as_ref().map(PathBuf::from))
                .unwrap_or_else(|| Path::new("runs").join(&name));
            let cfg = RunConfig {
                out_dir,
                force,
                info: RunInfo::current(&file, &set),
                interrupt: install_interrupt_handler(),
            };
            // Stated once the run starts (after its output directory is
            // accepted), before the run's own header.
            let rim = rim_phase(&case);
            drive(&cfg, |cfg, report| {
                execute(&case, cfg, &mut |p| {
                    if let (Progress::Started { .. }, Some(rim)) = (&p, &rim) {
                        eprintln!("plugsim: {rim}");
                    }
                    report(p)
                })
            })
        }
        Command::CrackTips { path, set, all } => crack_tips(&path, &set, all),
        Command::TimeStep { path, top } => time_step(&path, top),
        Command::Resume { dir } => {
            let cfg = RunConfig {
                out_dir: dir.clone(),
                force: false,
                info: RunInfo::current(&dir.display().to_string(), &[]),
                interrupt: install_interrupt_handler(),
            };
            drive(&cfg, |cfg, report| resume(cfg, report))
        }
    }
}

/// Catch Ctrl-C and SIGTERM: the first sets the returned flag (the run
/// finishes its step, writes a checkpoint and stops), the second stops at
/// once (the checkpoints written so far are intact).
fn install_interrupt_handler() -> Option<Arc<AtomicBool>> {
    let flag = Arc::new(AtomicBool::new(false));
    let seen = flag.clone();
    let handler = move || {
        if seen.swap(true, Ordering::SeqCst) {
            eprintln!("\nplugsim: second interrupt: stopping now, without a new checkpoint");
            std::process::exit(130);
        }
        eprintln!(
            "\nplugsim: interrupted: finishing this step and writing a checkpoint (interrupt again to stop at once)"
        );
    };
    match ctrlc::set_handler(handler) {
        Ok(()) => Some(flag),
        Err(e) => {
            eprintln!("warning: cannot catch Ctrl-C / SIGTERM ({e}); an interrupted run will not write a checkpoint");
            None
        }
    }
}

fn material_point(
    name: &str,
    case_file: Option<&Path>,
    path: PathArg,
    rate: f64,
    strain: f64,
    dt: Option<f64>,
    out: &Path,
) -> Result<()> {
    use plugsim::material_point::{run, save_csv, save_plots, DriverConfig, LoadPath};
    let mat = match case_file {
        Some(f) => Case::load(f, &[])?.material(name),
        None => plugsim::material::builtin(name),
    }
    .with_context(|| {
        format!("unknown material '{name}' (built-in: {})", plugsim::material::builtin_names().join(", "))
    })?;
    let load = match path {
        PathArg::UniaxialStrain => LoadPath::UniaxialStrain,
        PathArg::UniaxialStress => LoadPath::UniaxialStress,
        PathArg::SimpleShear => LoadPath::SimpleShear,
    };
    let dt = dt.unwrap_or((strain / rate).abs() / 2000.0);
    let cfg = DriverConfig { path: load, rate, final_strain: strain, dt, initial_temperature: None };
    let records = run(&mat, &cfg)?;
    let csv = out.with_extension("csv");
    save_csv(&csv, &records)?;
    let plots = save_plots(out, &records, load)?;
    let last = records.last().context("no records")?;
    println!("material point: {} steps to strain {:.4}", records.len() - 1, last.strain);
    println!(
        "  final: equivalent stress {:.4e} Pa, plastic strain {:.4}, temperature {:.1} K, damage {:.4}",
        last.equivalent_stress, last.eps_p, last.temperature, last.damage
    );
    println!("  wrote {}", csv.display());
    for p in plots {
        println!("  wrote {}", p.display());
    }
    Ok(())
}

fn validate(out: &Path, all: bool, only: Option<&str>, full_time: bool) -> Result<()> {
    use plugsim::validation::{all_rows, coarse_rows, report, run_row, select, table, velocity_plot, EXPERIMENTS};
    let rows = match only {
        Some(o) => select(all_rows(), o),
        None if all => all_rows(),
        None => coarse_rows(),
    };
    if rows.is_empty() {
        bail!("no validation row matches {only:?} (see `plugsim cases`, the borvik-* names)");
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    eprintln!("plugsim validate: {} runs into {}", rows.len(), out.display());
    let mut outcomes = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        eprintln!("  [{}/{}] {} ...", k + 1, rows.len(), row.id);
        let o = run_row(row, out, full_time);
        eprintln!(
            "        {:.1} s{}",
            o.wall,
            o.result.as_ref().err().map(|e| format!(", failed: {e}")).unwrap_or_default()
        );
        outcomes.push(o);
    }
    let (_, csv) = table(&outcomes);
    let mut velocity_plots = Vec::new();
    for e in EXPERIMENTS {
        let plot = velocity_plot(&outcomes, e);
        if !plot.series.is_empty() {
            let name = format!("velocity_{}.png", e.name);
            plugsim::io::save_line_plot(&out.join(&name), &plot)?;
            velocity_plots.push(name);
        }
    }
    let commit = env!("PLUGSIM_COMMIT");
    let cpu = cpu_name();
    let header = format!(
        "Produced by `plugsim validate` ({} {commit}) on {cpu}, {} threads.",
        env!("CARGO_PKG_VERSION"),
        rayon::current_num_threads()
    );
    let md = report(&header, &outcomes, &velocity_plots);
    std::fs::write(out.join("validation.md"), &md)?;
    std::fs::write(out.join("validation.csv"), &csv)?;
    println!("{md}");
    println!("written: {0}/validation.md, {0}/validation.csv and the plots beside them", out.display());
    Ok(())
}

/// `plugsim validate --family convergence`: each axisymmetric Børvik row
/// with [RL10]'s material at the three resolutions of the ladder, the
/// convergence table (Markdown, CSV) into `out`.
fn validate_convergence(out: &Path, only: Option<&str>) -> Result<()> {
    use plugsim::validation::{convergence_rows, convergence_table, run_row_with, rung, select, LADDER, METHODS};
    let rows = match only {
        Some(o) => select(convergence_rows(), o),
        None => convergence_rows(),
    };
    if rows.is_empty() {
        bail!("no convergence row matches {only:?} (the coarse axisymmetric borvik-* names)");
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let total = rows.len() * LADDER.len();
    eprintln!("plugsim validate --family convergence: {total} runs into {}", out.display());
    let mut ladders = Vec::new();
    for row in rows {
        let mut outcomes = Vec::new();
        for layers in LADDER {
            let (r, set) = rung(&row, layers);
            let dir = out.join(format!("{}-{layers}rows", row.id));
            eprintln!(
                "  [{}/{total}] {} at {layers} rows ...",
                ladders.len() * LADDER.len() + outcomes.len() + 1,
                row.id
            );
            let o = run_row_with(&r, &dir, false, &set);
            eprintln!(
                "        {:.1} s{}",
                o.wall,
                o.result.as_ref().err().map(|e| format!(", failed: {e}")).unwrap_or_default()
            );
            outcomes.push(o);
        }
        ladders.push((row, outcomes));
    }
    let (md, csv) = convergence_table(&ladders);
    let header = format!(
        "Produced by `plugsim validate --family convergence` ({} {}) on {}, {} threads: each row at 12, 24 and 48 particle rows through the thickness (the coarse case with `layers = 12` and its coarsest spacing doubled, the coarse case, the fine case); spread = (max - min) / mean of the three residual velocities.",
        env!("CARGO_PKG_VERSION"),
        env!("PLUGSIM_COMMIT"),
        cpu_name(),
        rayon::current_num_threads()
    );
    let report = format!("{header}\n\n{md}\n{METHODS}\n");
    std::fs::write(out.join("convergence.md"), &report)?;
    std::fs::write(out.join("convergence.csv"), &csv)?;
    println!("{report}");
    println!("written: {0}/convergence.md, {0}/convergence.csv", out.display());
    Ok(())
}

/// `plugsim validate --family taylor`: the Taylor anvil tests at two (three
/// with `--all`) resolutions, table, CSV and profile plots into `out`.
fn validate_taylor(out: &Path, all: bool, only: Option<&str>, set: &[String]) -> Result<()> {
    use plugsim::taylor::{methods, profile_plot, run_test, symmetry_table, table, RESOLUTIONS, TAYLOR_TESTS};
    let picked = |case: &str| only.is_none_or(|o| case.contains(o));
    // A rod-on-rod case brings its anvil twin, which it is compared with.
    let tests: Vec<_> = TAYLOR_TESTS
        .iter()
        .filter(|t| picked(t.case) || TAYLOR_TESTS.iter().any(|r| picked(r.case) && r.anvil_twin == Some(t.case)))
        .collect();
    if tests.is_empty() {
        bail!("no Taylor test matches {only:?} (see `plugsim cases`, the taylor-* names)");
    }
    let resolutions = if all { &RESOLUTIONS[..] } else { &RESOLUTIONS[..2] };
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let total = tests.len() * resolutions.len();
    eprintln!("plugsim validate --family taylor: {total} runs into {}", out.display());
    let mut outcomes = Vec::new();
    for t in &tests {
        for &r in resolutions {
            eprintln!("  [{}/{total}] {} {} ...", outcomes.len() + 1, t.case, r.0);
            let o = run_test(t, r, set);
            eprintln!(
                "        {:.1} s{}",
                o.wall,
                o.failure.as_ref().map(|(t, e)| format!(", stopped at {:.2} us: {e}", t * 1e6)).unwrap_or_default()
            );
            outcomes.push(o);
        }
    }
    let (md, csv) = table(&outcomes);
    let mut plots = String::new();
    for t in &tests {
        let name = format!("profile_{}.png", t.case);
        plugsim::io::save_line_plot(&out.join(&name), &profile_plot(&outcomes, t))?;
        plots.push_str(&format!("![{}]({name})\n", t.case));
    }
    let header = format!(
        "Produced by `plugsim validate --family taylor` ({} {}) on {}, {} threads; overrides: {}.",
        env!("CARGO_PKG_VERSION"),
        env!("PLUGSIM_COMMIT"),
        cpu_name(),
        rayon::current_num_threads(),
        if set.is_empty() { "none (the case files' settings)".to_string() } else { set.join(" ") }
    );
    let symmetry = symmetry_table(&outcomes);
    let symmetry = if symmetry.lines().count() > 2 {
        format!("Rod on rod against rod on anvil (the symmetric impact must reproduce the anvil):\n\n{symmetry}\n")
    } else {
        String::new()
    };
    let report = format!("{header}\n\n{md}\n{symmetry}{}\n\n{plots}", methods());
    std::fs::write(out.join("taylor.md"), &report)?;
    std::fs::write(out.join("taylor.csv"), &csv)?;
    println!("{report}");
    println!("written: {0}/taylor.md, {0}/taylor.csv and the profile plots beside them", out.display());
    Ok(())
}

/// One item of `--speeds` (a speed or a range), read by
/// [`plugsim::ballistic::parse_speeds`].
#[derive(Clone, Debug)]
struct SpeedItem(Vec<f64>);

fn speed_item(item: &str) -> Result<SpeedItem, String> {
    plugsim::ballistic::parse_speeds(item).map(SpeedItem)
}

/// `--jobs`: a whole number of runs side by side, at least one.
fn jobs_count(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("at least 1 run side by side (got 0)".into()),
        Ok(n) => Ok(n),
        Err(_) => Err(format!("a whole number of runs side by side, at least 1 (got '{text}')")),
    }
}

/// `plugsim ballistic`'s options besides the case, the overrides and the
/// output directory.
#[derive(clap::Args)]
struct BallisticArgs {
    /// Impact speeds to run, m/s: comma-separated, each a speed or an inclusive range
    /// LO:HI:STEP (e.g. --speeds 116:134:1,140,150); each under the elastic wave speed of
    /// every body (a faster impact is a shock the model does not describe).
    #[arg(long, value_delimiter = ',', value_parser = speed_item)]
    speeds: Vec<SpeedItem>,
    /// Find the ballistic limit by bisection.
    #[arg(long)]
    limit: bool,
    /// Lower end of the search, m/s (default: half the case's impact speed).
    #[arg(long, requires = "limit")]
    lo: Option<f64>,
    /// Upper end of the search, m/s (default: the case's impact speed).
    #[arg(long, requires = "limit")]
    hi: Option<f64>,
    /// Tolerance of the limit, +- m/s.
    #[arg(long, default_value_t = 1.0, requires = "limit")]
    tol: f64,
    /// Let a run still undecided at the case's end time (the plate neither held the projectile
    /// nor let it go) go on up to this simulated time, s (default: 3 times the case's end time;
    /// the case's end time to stop there).
    #[arg(long)]
    max_time: Option<f64>,
    /// The body to fire, rigid or deformable (default: the case's only moving one).
    #[arg(long)]
    projectile: Option<String>,
    /// Runs side by side, at least 1 (default: one per core, one thread
    /// each). With --rows or --phases and fewer speeds than jobs (no
    /// --limit), whole rungs run side by side.
    #[arg(long, value_parser = jobs_count)]
    jobs: Option<usize>,
    /// Experimental points to plot: a CSV with header v_i,v_r (m/s). Default: a built-in
    /// Borvik case's own tests (cases/reference/), unless --set changed its plate's thickness
    /// or its projectile.
    #[arg(long)]
    experiments: Option<PathBuf>,
    /// Run the whole study at each of these resolutions: particle rows
    /// through the first deformable body's thickness (comma-separated,
    /// e.g. 12,24,48; every deformable body refined by the same factor),
    /// each into rows-N/, and write convergence.md/.csv/.png with the
    /// limit and the residuals side by side, their spread and the last
    /// refinement's step (coarsest first, each resolution once).
    #[arg(long, value_delimiter = ',')]
    rows: Vec<usize>,
    /// Run the whole study at K lattice phases at the rim, at each
    /// resolution: the target's columns shifted so that the projectile's
    /// edge lies 0, 1/K, ... of a spacing from the nearest one, each into
    /// [rows-N/]phase-+0.25/; convergence.md gives each resolution's
    /// envelope over its phases (near a limit the rim crack's first steps
    /// can depend on the phase). Needs the projectile's edge over the
    /// target's uniform fine zone.
    #[arg(long, value_parser = clap::value_parser!(u64).range(2..=16), conflicts_with = "phase")]
    phases: Option<u64>,
    /// Run the whole study at these lattice phases at the rim only, in
    /// spacings from the nearest column, each in [-0.5, 0.5]
    /// (comma-separated, e.g. --phase 0.5 or --phase=-0.25,0.25), as
    /// --phases does at its K: one phase of an ensemble, or a rung's
    /// missing one.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    phase: Vec<f64>,
    /// Continue a study in --out: a speed whose run finished there with the same case (its
    /// case.resolved.toml) is taken back as it is, a run an interrupt stopped there continues
    /// from its checkpoint; every other speed runs afresh (without --resume every speed runs
    /// afresh).
    #[arg(long)]
    resume: bool,
    /// Each run writes a snapshot (ParaView) at most this often, s, and always its last state;
    /// the case's own output.interval where that is coarser; 0, or an explicit --set
    /// output.interval=..., keeps the case's. A study of dozens of runs at the Borvik cases'
    /// 1 us would fill a disk.
    #[arg(long, default_value_t = plugsim::ballistic::SNAPSHOT_EVERY)]
    snapshot_every: f64,
}

impl BallisticArgs {
    /// The limit search's bounds for a case fired at `impact` m/s:
    /// `--lo` (default half of it) and `--hi` (default all of it).
    fn bounds(&self, impact: f64) -> (f64, f64) {
        (self.lo.unwrap_or(0.5 * impact), self.hi.unwrap_or(impact))
    }

    /// `--speeds`, the ranges spelt out, in the order given.
    fn speeds(&self) -> Vec<f64> {
        self.speeds.iter().flat_map(|s| s.0.iter().copied()).collect()
    }
}

/// The directory of a study at lattice phase `p`: `phase-+0.25` (two
/// decimals).
fn phase_dir(p: f64) -> String {
    format!("phase-{p:+.2}")
}

/// `--phase`'s list, each phase with a directory of its own ([`phase_dir`]),
/// in the order given; `ballistic::at_phase` checks each phase's range.
fn distinct_phases(given: &[f64]) -> Result<Vec<f64>> {
    let mut dirs: Vec<String> = Vec::new();
    for &p in given {
        let dir = phase_dir(p);
        if dirs.contains(&dir) {
            bail!("--phase: two phases share the directory {dir}; give each phase once, to two decimals");
        }
        dirs.push(dir);
    }
    Ok(given.to_vec())
}

/// The experimental points of a study and what they are, for its report.
struct Tests {
    points: Vec<(f64, f64)>,
    /// A clause for the report's header: where the points come from, or
    /// why a built-in case's tests are not plotted; empty where none.
    note: String,
}

/// The tests on a study's plot: `--experiments FILE` where given, else the
/// built-in case's own (`cases::builtin_experiments`) unless the overrides
/// made it another experiment (`ballistic::tests_differ`: another plate
/// thickness or projectile).
fn study_tests(given: Option<&Path>, builtin: Option<&str>, case: &Case) -> Result<Tests> {
    use plugsim::ballistic::{parse_experiments, read_experiments, tests_differ};
    if let Some(path) = given {
        let points = read_experiments(path)?;
        let note = format!("; experiments on the plot: {} ({} points)", path.display(), points.len());
        return Ok(Tests { points, note });
    }
    let none = Tests { points: Vec::new(), note: String::new() };
    let Some(name) = builtin else { return Ok(none) };
    let (Some((path, text)), Some(shipped)) = (plugsim::cases::builtin_experiments(name), builtin_case(name)) else {
        return Ok(none);
    };
    let shipped = Case::from_str_with(shipped, &format!("<built-in {name}>"), &[])?;
    if let Some(why) = tests_differ(&shipped, case) {
        eprintln!("plugsim ballistic: the built-in case's tests ({path}) are not plotted: {why}");
        return Ok(Tests {
            points: Vec::new(),
            note: format!("; the built-in case's tests ({path}) not plotted: {why}"),
        });
    }
    let points = parse_experiments(text, path)?;
    let note = format!("; experiments on the plot: the built-in case's tests, {path} ({} points)", points.len());
    Ok(Tests { points, note })
}

fn ballistic(
    case: Case,
    name: &str,
    file: &str,
    builtin: Option<&str>,
    set: &[String],
    out: Option<PathBuf>,
    args: BallisticArgs,
) -> Result<()> {
    use plugsim::ballistic::{at_phase, at_rows, select_projectile, write_ladder_files, Rung};
    let projectile = select_projectile(&case, file, args.projectile.as_deref())?;
    let speeds = args.speeds();
    if speeds.is_empty() && !args.limit {
        bail!("give --speeds V1,V2,... and/or --limit");
    }
    if let Some(t) = args.max_time {
        if !(t.is_finite() && t >= case.time.end) {
            bail!(
                "--max-time must be at least the case's end time, {:e} s (got {t:e}); shorten a case with --set time.end=...",
                case.time.end
            );
        }
    }
    let bounds = args.limit.then(|| args.bounds(plugsim::ballistic::flight(&case, projectile).1));
    if let Some(bounds) = bounds {
        plugsim::ballistic::check_search(bounds, args.tol)?;
    }
    // The speeds as the case's own velocity is checked (`Case::speed_problem`);
    // the search's bounds are the highest speeds it asks for.
    let asked = speeds.iter().map(|&v| ("--speeds", v));
    let searched = bounds.into_iter().flat_map(|(lo, hi)| [("--lo", lo), ("--hi", hi)]);
    if let Some((option, problem)) = asked.chain(searched).find_map(|(o, v)| Some((o, case.speed_problem(v)?))) {
        bail!("{option}: {problem}");
    }
    if !(args.snapshot_every.is_finite() && args.snapshot_every >= 0.0) {
        bail!("--snapshot-every must be a time >= 0 s (got {})", args.snapshot_every);
    }
    // An explicit `--set output.interval=...` is the user's choice: it wins.
    let every =
        if set.iter().any(|s| s.trim_start().starts_with("output.interval")) { 0.0 } else { args.snapshot_every };
    let case = plugsim::ballistic::with_snapshots_every(case, every);
    // Every resolution is checked before the first run starts; the coarsest
    // runs first (its answer comes soonest), each once.
    let mut rows = args.rows.clone();
    rows.sort_unstable();
    rows.dedup();
    let mut resolutions = rows.iter().map(|&r| Ok((r, at_rows(&case, r)?))).collect::<Result<Vec<_>>>()?;
    let phases = match args.phases {
        Some(k) => plugsim::ballistic::phases(k as usize),
        None => distinct_phases(&args.phase)?,
    };
    if resolutions.is_empty() && !phases.is_empty() {
        let own = plugsim::ballistic::target(&case).map_or(0, |b| case.bodies[b].rectangle.layers);
        resolutions.push((own, (case.clone(), Vec::new())));
    }
    // Each resolution at each phase (or at its own columns), every one
    // checked before the first run.
    let mut grids = Vec::new();
    for (rows, (refined, extra)) in resolutions {
        for &phase in &phases {
            let (shifted, more) = at_phase(&refined, projectile, phase)?;
            grids.push((rows, Some(phase), shifted, extra.iter().chain(&more).cloned().collect()));
        }
        if phases.is_empty() {
            grids.push((rows, None, refined, extra));
        }
    }
    let tests = study_tests(args.experiments.as_deref(), builtin, &case)?;
    let out_dir = out.unwrap_or_else(|| Path::new("runs").join(format!("ballistic-{name}")));
    let interrupt = install_interrupt_handler();
    let started = Instant::now();
    let cores = rayon::current_num_threads().max(1);
    let jobs = args.jobs.unwrap_or(cores).max(1);
    let alone = Lane { jobs, threads_per_run: (cores / jobs).max(1), tag: String::new() };
    if grids.is_empty() {
        let (study, _) = one_study(case, file, set, projectile, &out_dir, &args, &tests, &interrupt, started, &alone)?;
        return finish(&study);
    }
    // A study with fewer speeds than jobs (and no limit search, whose
    // rounds use every job) leaves jobs idle: run that many rungs side by
    // side instead, each with the jobs its speeds use, their progress lines
    // tagged with the rung. The results are the same bits either way.
    let per_study = if args.limit { jobs } else { jobs.min(args.speeds().len()).max(1) };
    let side_by_side = (jobs / per_study).clamp(1, grids.len());
    let lane = match side_by_side {
        1 => alone,
        n => Lane { jobs: per_study, threads_per_run: (cores / (per_study * n)).max(1), tag: String::new() },
    };
    let run_rung = |(rows, phase, refined, extra): Grid| -> Result<Rung> {
        let tag = match side_by_side {
            1 => String::new(),
            _ => format!("{}: ", plugsim::ballistic::rung_label(rows, phase)),
        };
        let mine = Lane { tag, ..lane.clone() };
        let body = &refined.bodies[plugsim::ballistic::target(&refined).unwrap_or(0)].rectangle;
        let spacing = (body.y_max - body.y_min) / rows as f64;
        let mut dir = out_dir.clone();
        if !args.rows.is_empty() {
            dir.push(format!("rows-{rows}"));
        }
        if let Some(p) = phase {
            dir.push(phase_dir(p));
        }
        eprintln!(
            "plugsim ballistic: {rows} rows ({:.3} mm){}{}",
            spacing * 1e3,
            phase.map_or(String::new(), |p| format!(", lattice phase {p:+.2}")),
            if extra.is_empty() { String::new() } else { format!(": {}", extra.join(" ")) }
        );
        let all: Vec<String> = set.iter().chain(&extra).cloned().collect();
        let (study, edge) =
            one_study(refined, file, &all, projectile, &dir, &args, &tests, &interrupt, started, &mine)?;
        Ok(Rung { rows, spacing, overrides: extra, edge, phase, study })
    };
    let mut rungs = Vec::new();
    let mut queue = grids.into_iter().peekable();
    while queue.peek().is_some() {
        let batch: Vec<Grid> = queue.by_ref().take(side_by_side).collect();
        let done: Vec<Result<Rung>> = if batch.len() == 1 {
            batch.into_iter().map(&run_rung).collect()
        } else {
            std::thread::scope(|s| {
                let running: Vec<_> = batch.into_iter().map(|g| s.spawn(|| run_rung(g))).collect();
                running.into_iter().map(|h| h.join().unwrap_or_else(|_| bail!("a rung's study panicked"))).collect()
            })
        };
        let mut stop = false;
        for rung in done {
            let rung = rung?;
            stop |= rung.study.interrupted;
            rungs.push(rung);
        }
        if stop {
            break;
        }
    }
    let header = format!(
        "Case {file}{}{}, produced by `plugsim ballistic{}{}` ({} {}) on {}; total wall time {:.0} s{}.",
        if set.is_empty() { String::new() } else { format!(" with {}", set.join(" ")) },
        tests.note,
        if args.rows.is_empty() { "" } else { " --rows" },
        match (args.phases, phases.is_empty()) {
            (Some(_), _) => " --phases",
            (None, false) => " --phase",
            (None, true) => "",
        },
        env!("CARGO_PKG_VERSION"),
        env!("PLUGSIM_COMMIT"),
        cpu_name(),
        started.elapsed().as_secs_f64(),
        if args.resume {
            " (this command's; the runs taken back by --resume count in the wall column only)"
        } else {
            ""
        }
    );
    let title = plugsim::ballistic::study_title(
        &case.title,
        set,
        &format!("v_r against v_i at {}", plugsim::ballistic::ladder_extent(&rungs)),
    );
    let files = write_ladder_files(&out_dir, &header, &title, &rungs, &speeds, &tests.points)?;
    println!("{}", plugsim::ballistic::ladder_table(&rungs, &speeds).0);
    for f in files {
        println!("written: {}", f.display());
    }
    match rungs.last() {
        Some(r) if r.study.interrupted => finish(&r.study),
        _ => Ok(()),
    }
}

/// Stop with an error if the study was interrupted.
fn finish(study: &plugsim::ballistic::Study) -> Result<()> {
    if study.interrupted {
        bail!(
            "interrupted: the table keeps the {} runs finished before it; {} stopped with their checkpoints \
             and {} not started (--resume continues them)",
            study.shots.len(),
            study.paused.len(),
            study.not_started.len()
        );
    }
    Ok(())
}

/// A resolution and lattice phase of a ladder, to run as one study: its
/// rows, its phase (`None`: the case's own columns), the case at it and
/// the overrides that give it.
type Grid = (usize, Option<f64>, Case, Vec<String>);

/// How one study shares the machine: its runs side by side, the threads
/// each, and what its progress lines start with ("24 rows, phase +0.25: "
/// where rungs run side by side, else nothing).
#[derive(Clone, Debug)]
struct Lane {
    jobs: usize,
    threads_per_run: usize,
    tag: String,
}

/// One ballistic study of `case` (the speeds, then the limit if asked) into
/// `out_dir`: its table, report and plot, printed and written; with the
/// projectile's edge against the target's columns that its header states
/// (a ladder's rung reports the same).
#[allow(clippy::too_many_arguments)]
fn one_study(
    case: Case,
    file: &str,
    set: &[String],
    projectile: plugsim::ballistic::Projectile,
    out_dir: &Path,
    args: &BallisticArgs,
    tests: &Tests,
    interrupt: &Option<Arc<AtomicBool>>,
    started: Instant,
    lane: &Lane,
) -> Result<(plugsim::ballistic::Study, Option<plugsim::ballistic::EdgePhase>)> {
    use plugsim::ballistic::{find_limit, flight, run_speeds, write_files};
    use plugsim::ballistic::{Event, Setup, Study};
    let (_, impact) = flight(&case, projectile);
    let (jobs, threads_per_run, tag) = (lane.jobs, lane.threads_per_run, &lane.tag);
    let max_time = args.max_time.unwrap_or_else(|| plugsim::ballistic::default_max_time(&case));
    std::fs::create_dir_all(out_dir).with_context(|| format!("cannot create {}", out_dir.display()))?;
    let setup = Setup {
        case,
        label: file.to_string(),
        overrides: set.to_vec(),
        projectile,
        jobs,
        threads_per_run,
        out_dir: out_dir.to_path_buf(),
        max_time,
        interrupt: interrupt.clone(),
        resume: args.resume,
    };
    let body = projectile.name(&setup.case);
    let kind = match projectile {
        plugsim::ballistic::Projectile::Rigid(_) => "",
        plugsim::ballistic::Projectile::Deformable(_) => ", deformable: v_r its mass-averaged velocity",
    };
    let snapshots = setup.case.resolved().output.interval.unwrap_or(0.0);
    let edge_phase = plugsim::ballistic::edge_phase(&setup.case, projectile);
    let edge = edge_phase.map_or(String::new(), |e| format!("; {}", e.describe()));
    let header = format!(
        "Case {file}{}; projectile `{body}` (case impact speed {impact:.1} m/s{kind}){edge}{}; {jobs} runs side by side, {threads_per_run} thread(s) each, \
         a snapshot every {:.3} us; produced by `plugsim ballistic` ({} {}) on {}.",
        if set.is_empty() { String::new() } else { format!(" with {}", set.join(" ")) },
        tests.note,
        snapshots * 1e6,
        env!("CARGO_PKG_VERSION"),
        env!("PLUGSIM_COMMIT"),
        cpu_name()
    );
    let title = plugsim::ballistic::study_title(&setup.case.title, set, "residual against impact velocity");
    let mut report = |study: &Study| write_files(out_dir, &header, &title, study, &tests.points).map(|_| ());
    let study_started = Instant::now();
    let mut progress = |e: Event| {
        let at = started.elapsed().as_secs_f64();
        match e {
            Event::Round { label, speeds } => {
                let v: Vec<String> = speeds.iter().map(|v| format!("{v:.2}")).collect();
                eprintln!("[{at:6.0} s] {tag}{label}: {} m/s", v.join(", "));
            }
            Event::Started { speed } => eprintln!("[{at:6.0} s]   {tag}{speed:.2} m/s started"),
            Event::Advanced { speed, time, end, along, perforation } => {
                // what decides a held run (`residual`): the end time is only a bound
                let held = plugsim::residual::held_below(speed, perforation.is_some());
                let (cut, rule) = match perforation {
                    None => (String::new(), " with no plug"),
                    Some(t) => (format!(", plug cut at {:.1} us", t * 1e6), ""),
                };
                let along = along
                    .map(|v| format!(", projectile at {v:.1} m/s{cut} (held once under {held:.1}{rule})"))
                    .unwrap_or_default();
                eprintln!("[{at:6.0} s]   {tag}{speed:.2} m/s at {:.1} of {:.1} us{along}", time * 1e6, end * 1e6)
            }
            Event::Finished { shot } => eprintln!(
                "[{at:6.0} s]   {tag}{:.2} m/s: {}{} ({:.1} s)",
                shot.speed,
                shot.outcome(),
                shot.residual().map(|v| format!(", v_r = {v:.2} m/s")).unwrap_or_default(),
                shot.wall
            ),
            Event::Failed { speed, message } => eprintln!("[{at:6.0} s]   {tag}{speed:.2} m/s failed: {message}"),
            Event::Interrupted { paused } => {
                let along = paused
                    .along
                    .map(|a| {
                        format!(", projectile at {:.1} m/s held back by {:.1} kN", a.speed, a.holding_back() * 1e-3)
                    })
                    .unwrap_or_default();
                let cut = paused.perforation.map(|t| format!(", plug cut at {:.1} us", t * 1e6)).unwrap_or_default();
                eprintln!(
                    "[{at:6.0} s]   {tag}{:.2} m/s interrupted at {:.1} us{along}{cut} (its checkpoint is kept: --resume continues it)",
                    paused.speed,
                    paused.time * 1e6
                )
            }
            Event::Reused { shot, note } => eprintln!(
                "[{at:6.0} s]   {tag}{:.2} m/s: {}{}, finished before: taken back{}",
                shot.speed,
                shot.outcome(),
                shot.residual().map(|v| format!(", v_r = {v:.2} m/s")).unwrap_or_default(),
                note.map(|n| format!(" ({n})")).unwrap_or_default()
            ),
            Event::Resumed { speed, time, warnings } => {
                eprintln!("[{at:6.0} s]   {tag}{speed:.2} m/s continues from its checkpoint at {:.1} us", time * 1e6);
                for w in warnings {
                    eprintln!("[{at:6.0} s]   {tag}{speed:.2} m/s: warning: {w}");
                }
            }
        }
    };
    eprintln!(
        "plugsim ballistic: {jobs} runs side by side ({threads_per_run} thread(s) each) into {}",
        out_dir.display()
    );
    let mut study = Study::default();
    run_speeds(&setup, &args.speeds(), &mut study, &mut report, &mut progress)?;
    if args.limit && !study.interrupted {
        find_limit(&setup, args.bounds(impact), args.tol, &mut study, &mut report, &mut progress)?;
    }
    let files = write_files(out_dir, &header, &title, &study, &tests.points)?;
    println!("{}", plugsim::ballistic::report(&header, &study));
    println!("total wall time {:.1} s", study_started.elapsed().as_secs_f64());
    for f in files {
        println!("written: {}", f.display());
    }
    Ok((study, edge_phase))
}

/// The CPU's model name from `/proc/cpuinfo`, for the provenance lines of
/// `validate` and `bench`.
fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn bench(name: &str, steps: usize, whole: Option<f64>, set: &[String]) -> Result<()> {
    use plugsim::bench;
    let text = builtin_case(name).with_context(|| format!("unknown built-in case '{name}'"))?;
    let case = Case::from_str_with(text, name, set)?.resolved();
    let all = rayon::current_num_threads();
    let cpu = cpu_name();
    println!(
        "plugsim bench {} ({}) on {cpu}, {all} threads available",
        env!("CARGO_PKG_VERSION"),
        env!("PLUGSIM_COMMIT")
    );
    println!("case {name}: {}", case.title);
    let show = |f: &bench::Figure| println!("  {:70} {:>12.4e} {}", f.name, f.value, f.unit);
    let material = plugsim::material::builtin("weldox_460e").context("built-in material")?;
    for f in bench::material_kernel(&material, 200_000) {
        show(&f);
    }
    for threads in [1, all] {
        show(&bench::shape_build(&case, threads)?);
    }
    for threads in [1, all] {
        for f in bench::force_assembly(&case, threads, 200)? {
            show(&f);
        }
    }
    for threads in [1, all] {
        for f in bench::gather_update(&case, threads, 20)? {
            show(&f);
        }
    }
    for threads in [1, all] {
        for f in bench::diagnostics(&case, threads, steps)? {
            show(&f);
        }
    }
    // Timed 5 us into the impact, when the zone under the projectile flows and heats.
    for f in bench::material_floor(&case, 1, 5e-6, steps.min(50))? {
        show(&f);
    }
    let mut rates = Vec::new();
    for threads in [1, all] {
        let f = bench::steps(&case, threads, steps)?;
        rates.push(f[0].value);
        for x in &f {
            show(x);
        }
    }
    println!("  speed-up 1 -> {all} threads (whole steps): {:.2}x", rates[1] / rates[0]);
    if all > 1 {
        let ceiling = bench::independent_copies(&case, all, steps)?;
        show(&ceiling);
        println!(
            "  the machine's ceiling for that speed-up ({all} independent copies against 1 thread): {:.2}x",
            ceiling.value / rates[0]
        );
    }
    if let Some(end) = whole {
        let mut walls = Vec::new();
        for threads in [1, all] {
            let dir = std::env::temp_dir().join(format!("plugsim-bench-{}-{threads}", std::process::id()));
            let mut c = case.clone();
            c.time.end = end;
            c.output.interval = Some(1e-6);
            let cfg = RunConfig::new(dir.clone(), true, RunInfo::current(name, set));
            let t = Instant::now();
            let s = bench::with_threads(threads, || execute(&c, &cfg, &mut |_| {}))?;
            let wall = t.elapsed().as_secs_f64();
            walls.push(wall);
            let _ = std::fs::remove_dir_all(&dir);
            println!(
                "  whole case to {:.1} us, {threads} thread(s): {wall:.2} s wall ({} steps, {} particles, {} qps, {} snapshots; {:.3e} qp-updates/s)",
                end * 1e6,
                s.steps,
                s.particles,
                s.quadrature_points,
                s.snapshots,
                s.quadrature_points as f64 * s.steps as f64 / s.loop_wall.as_secs_f64()
            );
            if let Some(line) = bench::against_paper(name, end, wall) {
                println!("    {line}");
            }
        }
        println!("  whole-case speed-up 1 -> {all} threads: {:.2}x", walls[0] / walls[1]);
    }
    Ok(())
}

/// Where the projectile's edge lies against the target's particle
/// columns ([`plugsim::ballistic::edge_phase`]), for a case with one
/// projectile whose edge lies over its target: what `plugsim ballistic`
/// states in every study's header, said by `check` and `run` too, since the
/// lattice's phase at the rim can pick a crack's first steps
/// (docs/validation.md, "Case II's plate on the 48 / 72 / 96 ladder").
fn rim_phase(case: &Case) -> Option<String> {
    let projectile = plugsim::ballistic::select_projectile(case, "", None).ok()?;
    plugsim::ballistic::edge_phase(case, projectile).map(|e| e.describe())
}

fn check(case: &Case, file: &str) -> Result<()> {
    let resolved = case.resolved();
    let t = Instant::now();
    let footprint = plugsim::run::preflight(&resolved)?;
    let sim = plugsim::run::build_simulation(&resolved).context("building the discretization")?;
    println!("{file}: OK ({})", if case.title.is_empty() { "untitled" } else { &case.title });
    println!("  geometry        {:?}", resolved.geometry.mode);
    for b in &sim.model.bodies {
        println!(
            "  body {:10} {} particles ({} x {}), {} quadrature points",
            b.name,
            b.particles.len(),
            b.columns,
            b.rows,
            b.quad_points.len()
        );
    }
    if let Some(c) = &sim.contact {
        for b in &c.bodies {
            println!(
                "  rigid body {:10} mass {:.6e} kg, velocity ({:.2}, {:.2}) m/s",
                b.name, b.mass, b.velocity.x, b.velocity.y
            );
        }
        println!("  contact slaves  {} surface particles", c.slaves.len());
    }
    if let Some(rim) = rim_phase(case) {
        println!("  rim             {rim}");
    }
    println!(
        "  time step       {:.3e} s ({} steps to {:.3e} s)",
        sim.dt,
        (resolved.time.end / sim.dt).ceil(),
        resolved.time.end
    );
    let cfl = sim.model.min_spacing() / sim.model.max_wave_speed();
    if sim.dt > cfl {
        println!(
            "  WARNING: the time step is {:.1} times the CFL limit {cfl:.3e} s; the run may go unstable",
            sim.dt / cfl
        );
    }
    let (available, origin) = plugsim::memory::available_memory();
    println!(
        "  memory          about {} ({} available: {origin}); a checkpoint about {}",
        plugsim::memory::human_bytes(footprint.bytes()),
        plugsim::memory::human_bytes(available as f64),
        plugsim::memory::human_bytes(footprint.checkpoint_bytes())
    );
    let entries: usize = sim.model.qp_shape.nnz() + sim.model.particle_shape.nnz();
    println!(
        "  shape entries   {entries} (estimated {:.0}); built with a peak resident memory of {}",
        footprint.quadrature_entries + footprint.particle_entries,
        plugsim::memory::peak_resident().map_or("(unknown)".into(), |b| plugsim::memory::human_bytes(b as f64))
    );
    println!("  mass            {:.6e} kg", sim.model.particles.total_mass());
    println!("  built in        {:.2} s", t.elapsed().as_secs_f64());
    Ok(())
}

/// Run `job` (a fresh run or a resume) with a progress bar or progress lines,
/// then print the summary.
fn drive(
    cfg: &RunConfig,
    job: impl FnOnce(&RunConfig, &mut dyn FnMut(Progress)) -> Result<RunSummary, RunError>,
) -> Result<()> {
    let out_dir = cfg.out_dir.clone();
    let tty = std::io::stderr().is_terminal();
    let bar = ProgressBar::hidden();
    let started = Instant::now();
    let (mut end, mut first_step) = (0.0, 0u64);
    let mut last_line = 0u64;
    let mut report = |p: Progress| match p {
        Progress::Resumed { sim, checkpoint, warnings } => {
            for w in warnings {
                eprintln!("warning: {w}");
            }
            eprintln!("plugsim: resuming from {} at step {} (t = {:.4e} s)", checkpoint.display(), sim.step, sim.time);
        }
        Progress::Checkpoint { sim, path, .. } => {
            let line = format!("  checkpoint at step {} (t = {:.4e} s): {}", sim.step, sim.time, path.display());
            if tty {
                bar.println(line);
            } else {
                eprintln!("{line}");
            }
        }
        Progress::Finished { .. } => {}
        Progress::Started { sim, steps_estimate, end: run_end } => {
            (end, first_step) = (run_end, sim.step);
            eprintln!(
                "plugsim: {} particles, {} quadrature points, dt = {:.3e} s, {} steps, {} threads -> {}",
                sim.model.particles.len(),
                sim.model.quad.len(),
                sim.dt,
                steps_estimate,
                rayon::current_num_threads(),
                out_dir.display()
            );
            if tty {
                bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                bar.set_length(steps_estimate);
                bar.set_style(
                    ProgressStyle::with_template("{bar:40.cyan/blue} {percent:>3}% {msg} | {per_sec} | ETA {eta}")
                        .expect("valid template")
                        .progress_chars("=> "),
                );
            }
        }
        Progress::Step { sim, perforation } => {
            let cut = perforation.map(|t| format!(", plug cut at {:.2} us", t * 1e6)).unwrap_or_default();
            let msg = format!("t = {:.3} us / {:.3} us, step {}{cut}", sim.time * 1e6, end * 1e6, sim.step);
            if tty {
                bar.set_position(sim.step);
                bar.set_message(msg);
            } else {
                let pct = (100.0 * sim.time / end) as u64;
                if pct >= last_line + 10 {
                    last_line = pct - pct % 10;
                    let rate = (sim.step - first_step) as f64 / started.elapsed().as_secs_f64();
                    eprintln!("  {pct:3}%  {msg}  ({rate:.0} steps/s)");
                }
            }
        }
    };
    let result = job(cfg, &mut report);
    bar.finish_and_clear();
    let s = result?;
    let total = s.setup_wall + s.loop_wall + s.output_wall;
    println!("plugsim run finished: {} steps to t = {:.4e} s (dt = {:.3e} s)", s.steps, s.time, s.dt);
    println!("  particles / quadrature points  {} / {}", s.particles, s.quadrature_points);
    if let Some((base, (smallest, at, particle))) = s.stable_step {
        if smallest < base {
            println!(
                "  time step: {base:.3e} s from the spacing, down to {smallest:.3e} s at {:.3} us for particle {particle}'s stiffness (history.csv: dt)",
                at * 1e6
            );
        }
    }
    if let Some(a) = s.mass_scaling {
        let own = (s.total_mass - a.mass).max(f64::MIN_POSITIVE);
        println!(
            "  mass scaling (not in SPEC §5): {:.4e} kg added at rest ({:.4} % of the bodies' mass) in {} evaluations, at most {:.2}x one particle's mass at once; {:.4e} J of kinetic energy taken out (in the energy balance)",
            a.mass,
            100.0 * a.mass / own,
            a.evaluations,
            a.largest_factor,
            s.energies.mass_scaling
        );
        if a.mass > 0.01 * own {
            println!("  WARNING: mass scaling added more than 1 % of the bodies' mass: the dynamics are no longer the model's; lower time.mass_scaling");
        }
    }
    println!(
        "  energy: kinetic {:.4e} J (rigid {:.4e} J), internal {:.4e} J, contact dissipation {:.4e} J, drift {:+.3} % (max {:.3} %)",
        s.energies.kinetic,
        s.energies.rigid_kinetic,
        s.energies.internal,
        s.energies.contact_dissipation(),
        100.0 * s.energies.drift(),
        100.0 * s.max_drift
    );
    if s.energies.crack_changes != 0.0 {
        println!(
            "  crack changes: the splits' and detachments' re-lumped masses and momentum correction took out {:.4e} J of kinetic energy (in the energy balance)",
            s.energies.crack_changes
        );
    }
    if s.bulk_viscosity.is_active() {
        println!(
            "  bulk viscosity: linear {}, quadratic {} (not in SPEC §5; its work is in the internal energy)",
            s.bulk_viscosity.linear, s.bulk_viscosity.quadratic
        );
    }
    if s.max_drift > 0.05 {
        println!("  WARNING: the energy balance drifted by more than 5 % of the input energy");
    }
    println!("  fastest particle: {} (history.csv: max_particle_speed)", s.fastest.describe());
    if let Some((gap, t)) = s.coefficient_gap {
        let (end, i, origin) = &s.coefficient_gap_at_end;
        println!(
            "  coefficients apart from the field: at most {gap:.2} spacings, at t = {:.3} us; {end:.2} at the end, \
             particle {i} ({origin}) (history.csv: max_coefficient_gap; the snapshots show the field, and a split or \
             a detachment beside such a particle shows its coefficient at once)",
            t * 1e6
        );
    }
    if !s.untraced.is_empty() {
        let list: Vec<String> = s.untraced.iter().map(|i| i.to_string()).collect();
        println!(
            "  WARNING: output.trace_particles: particle(s) {} never came to exist (the run ended with {} particles), so trace.csv has no rows of them",
            list.join(", "),
            s.particles
        );
    }
    println!(
        "  wall time {:.2} s: setup {:.2} s, time loop {:.2} s, output {:.2} s",
        total.as_secs_f64(),
        s.setup_wall.as_secs_f64(),
        s.loop_wall.as_secs_f64(),
        s.output_wall.as_secs_f64()
    );
    for (name, d) in &s.stage_timers {
        println!("    {name:30} {:8.3} s", d.as_secs_f64());
    }
    if let Some(peak) = s.peak_resident {
        println!(
            "  memory: peak resident {} (estimated {})",
            plugsim::memory::human_bytes(peak as f64),
            plugsim::memory::human_bytes(s.memory_estimate)
        );
    }
    let qp_rate = s.quadrature_points as f64 * s.steps as f64 / s.loop_wall.as_secs_f64().max(1e-9);
    println!(
        "  throughput {:.3e} quadrature-point updates/s, {:.1} steps/s",
        qp_rate,
        s.steps as f64 / s.loop_wall.as_secs_f64().max(1e-9)
    );
    for ((name, v), contacts) in s.rigid_velocities.iter().zip(&s.contacts) {
        let contact = match contacts.last {
            Some(t) if s.time - t > 1e-9 => format!("last contact of any kind at {:.2} us", t * 1e6),
            Some(_) => "in contact at the end".to_string(),
            None => "never in contact".to_string(),
        };
        println!("  rigid body {name}: final velocity ({:.2}, {:.2}) m/s; {contact}", v[0], v[1]);
        if let Some((_, verdict)) = s.flights.iter().find(|(n, _)| n == name) {
            if *verdict != plugsim::residual::Verdict::NotMoving {
                println!("    {}", verdict.describe());
            }
        }
    }
    for (name, verdict) in s.flights.iter().filter(|(n, _)| !s.rigid_velocities.iter().any(|(r, _)| r == n)) {
        println!("  deformable projectile {name} (mass-averaged velocity): {}", verdict.describe());
    }
    for (id, nucleated, arrested) in &s.cracks {
        match arrested {
            Some(a) => println!("  crack {id}: nucleated at {:.3} us, arrested at {:.3} us", nucleated * 1e6, a * 1e6),
            None => println!("  crack {id}: nucleated at {:.3} us, still growing", nucleated * 1e6),
        }
    }
    if let Some(d) = s.tip_damage {
        println!(
            "  crack tips grew into material at damage D = {:.3} / {:.3} / {:.3} (min / median / max of {} events; the locus is D = 1)",
            d.min, d.median, d.max, d.count
        );
    }
    if let Some(h) = s.tip_hardening {
        println!(
            "  and at adiabatic hardening (1/stress) d stress/d plastic strain = {:.3} / {:.3} / {:.3} (<= 0: the material had localized)",
            h.min, h.median, h.max
        );
    }
    if let Some(t) = s.separation {
        println!("  plug separated at {:.3} us (its cracks arrested through the thickness)", t * 1e6);
    }
    if let Some(t) = s.perforation {
        println!("  plate perforated at {:.3} us (plug first cut out)", t * 1e6);
    }
    if s.eroded_points > 0 {
        println!(
            "  eroded: {} quadrature points inverted after meeting the crack criterion, were torn open after fracturing, or were eroded at the step's floor, and carry no stress (history.csv: eroded_points)",
            s.eroded_points
        );
    }
    if !s.detached.is_empty() {
        let shown: Vec<String> = s.detached.iter().take(8).map(|d| d.describe()).collect();
        let more = if s.detached.len() > 8 { ", ..." } else { "" };
        println!(
            "  detached: {} particles (erosion or a crack split left them less than fracture.detach_below of their material; they fly free with their mass): {}{more}",
            s.detached.len(),
            shown.join(", ")
        );
    }
    if let Some(n) = s.floor_eroded {
        println!(
            "  erosion at the step's floor (time.erode_failed_below, not in SPEC §5): {n} fractured points eroded, of those above"
        );
    }
    if s.axis_energy != 0.0 {
        println!(
            "  axis: particles reached the axis and were held on it (contact.axis); it took {:.4e} J of their radial kinetic energy",
            s.axis_energy
        );
    }
    match s.exposed.contacts {
        Some((first, last, most)) => println!(
            "  contact: {} interior particles joined the slaves when the projectile reached them; they carried contact force from {:.3} to {:.3} us (at most {} at once; history.csv: exposed_contacts)",
            s.exposed.admitted,
            first * 1e6,
            last * 1e6,
            most
        ),
        None if s.exposed.admitted > 0 => println!(
            "  contact: {} interior particles joined the slaves when the projectile came within a spacing; none was pushed",
            s.exposed.admitted
        ),
        None => {}
    }
    match &s.plug {
        Some(p) => {
            let v = p.velocity();
            println!(
                "  plug at the end: {} particles, mass {:.4e} kg (per metre of depth in plane strain), velocity ({:.2}, {:.2}) m/s",
                p.particles.len(),
                p.mass,
                v.x,
                v.y
            );
        }
        None if !s.cracks.is_empty() => println!("  no plug cut out"),
        None => {}
    }
    println!("  output: {} snapshots in {}/results.pvd, history in history.csv", s.snapshots, s.out_dir.display());
    for p in &s.plots {
        println!("  plot: {}", p.display());
    }
    Ok(())
}
