//! `plugsim validate`: run Børvik's plugging cases (the built-in `borvik-*`
//! family, [`crate::cases::borvik_family`]) and compare the projectile's
//! residual velocity with the experiments and with \[RL10\]'s simulations
//! (shared/reference/ren-li-2010.toml, Tables 1 and 3).
//!
//! What each row measures, as experimenters do:
//! - **Residual velocity**: the projectile's speed along its flight
//!   direction once the contact force along that direction has vanished
//!   ([`crate::residual`]): from the run's `history.csv`, the projectile is
//!   *released* once its `projectile_f_axial` has stayed below 0.1 % of its
//!   peak for at least [`FREE_FLIGHT`] before the end of the run, with a plug
//!   cut out; the residual is its speed along the flight at the end. A touch
//!   on the side wall of the hole does not count (it pushes across the
//!   flight). A projectile that stopped or bounced back reports 0, "held".
//!   Otherwise the row says "in contact at the end" with the final speed
//!   along the flight in brackets.
//! - **Perforation time**: when the plate is first completely severed — the
//!   time of the step after which the flood fill of [`crate::plug`] first
//!   finds a plug (it runs after every step that changed the cracks; the
//!   `perforation_time` column of `history.csv`,
//!   [`crate::output::perforation_time`]).
//! - **Plug mass and velocity**: at the end of the run, the particles that
//!   the through-cracks cut out under the projectile, found by a flood fill
//!   the cracks block ([`crate::plug`]); mass in g (g/mm of depth in plane
//!   strain), velocity the mass average of its particles along the impact
//!   direction.

use crate::case::Case;
use crate::cases::{borvik_family, builtin_case, resolve_alias, BorvikCase};
use crate::io::{HistoryTable, LinePlot, Series};
use crate::math::Real;
use crate::residual::Verdict;
use crate::run::{execute, RunConfig, RunError, RunInfo, RunSummary};
use std::path::{Path, PathBuf};

pub use crate::residual::FREE_FLIGHT;

/// One of Børvik's experiments as printed in \[RL10\] (reference file).
#[derive(Clone, Debug)]
pub struct Experiment {
    pub name: &'static str,
    /// Plate thickness, m.
    pub thickness: Real,
    /// Impact velocity, m/s.
    pub impact_velocity: Real,
    /// Measured residual velocity, m/s.
    pub residual: Real,
    /// Time simulated by \[RL10\], s.
    pub simulated_time: Real,
    /// Perforation time in \[RL10\]'s simulation (a crack through the plate), s.
    pub perforation_time: Real,
    /// \[RL10\]'s simulated residuals: (particles, criterion, m/s).
    pub paper: &'static [(usize, &'static str, Real)],
    /// \[RL10\]'s published wall-clock times of its runs over
    /// `simulated_time`: (particles, s), on an Intel Core 2 Duo (2 cores,
    /// 2.83 GHz), effective-strain criterion (the damage criterion "very
    /// close").
    pub paper_wall: &'static [(usize, Real)],
}

/// Tables 1 and 3 of \[RL10\] (`shared/reference/ren-li-2010.toml`).
pub const EXPERIMENTS: &[Experiment] = &[
    Experiment {
        name: "case-1",
        thickness: 0.0111,
        impact_velocity: 298.0,
        residual: 241.4,
        simulated_time: 118.0e-6,
        perforation_time: 28.0e-6,
        paper: &[
            (11496, "damage", 238.5),
            (11496, "effective_strain", 246.7),
            (45984, "damage", 239.6),
            (45984, "effective_strain", 246.1),
        ],
        paper_wall: &[(11496, 0.92 * 3600.0), (45984, 3.80 * 3600.0)],
    },
    Experiment {
        name: "case-2",
        thickness: 0.0102,
        impact_velocity: 173.7,
        residual: 112.0,
        simulated_time: 216.0e-6,
        perforation_time: 46.0e-6,
        paper: &[
            (11496, "damage", 123.0),
            (11496, "effective_strain", 121.8),
            (45984, "damage", 116.1),
            (45984, "effective_strain", 109.4),
        ],
        paper_wall: &[(11496, 1.86 * 3600.0), (45984, 7.1 * 3600.0)],
    },
];

/// \[RL10\]'s published run of the built-in case `name` (or of the case
/// an alias names): `(wall time, s; simulated time, s)`, for its own model
/// only (plane strain, its material, effective-strain cracks, the coarse
/// or fine discretization: the runs the paper timed). `None` for any other
/// case. What `plugsim bench --whole` compares with (issue #7).
pub fn published_run(name: &str) -> Option<(Real, Real)> {
    let name = resolve_alias(name);
    let case = borvik_family().into_iter().find(|c| c.name() == name)?;
    if !case.is_papers_model() || case.criterion != "effective_strain" {
        return None;
    }
    let experiment = &EXPERIMENTS[case.experiment as usize - 1];
    let wall = experiment.paper_wall.iter().find(|p| p.0 == case.paper_particles())?.1;
    Some((wall, experiment.simulated_time))
}

/// A validation row: a built-in case of the Børvik family and its experiment.
#[derive(Clone, Debug)]
pub struct Row {
    /// The built-in case's name (also the run's directory).
    pub id: String,
    pub experiment: &'static Experiment,
    pub case: BorvikCase,
}

impl Row {
    fn of(case: BorvikCase) -> Row {
        Row { id: case.name(), experiment: &EXPERIMENTS[case.experiment as usize - 1], case }
    }
}

/// Every row: the whole family, in its order (24 rows).
pub fn all_rows() -> Vec<Row> {
    borvik_family().into_iter().map(Row::of).collect()
}

/// The coarse rows (what `plugsim validate` runs by default): both cases,
/// both geometries, both of \[RL10\]'s criteria, and the default model in
/// axisymmetry (10 rows).
pub fn coarse_rows() -> Vec<Row> {
    all_rows().into_iter().filter(|r| r.case.discretization == "coarse").collect()
}

/// The rows `--only TEXT` selects from `rows`: the row named exactly `TEXT`
/// (or the case an alias such as `borvik-1` names) if there is one, else
/// every row whose name contains `TEXT`.
pub fn select(rows: Vec<Row>, only: &str) -> Vec<Row> {
    let target = resolve_alias(only);
    if rows.iter().any(|r| r.id == target) {
        rows.into_iter().filter(|r| r.id == target).collect()
    } else {
        rows.into_iter().filter(|r| r.id.contains(only)).collect()
    }
}

/// What a row produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub row: Row,
    pub result: Result<RunSummary, String>,
    /// Wall time of the run, s.
    pub wall: Real,
    /// How the projectile's flight ended ([`crate::residual`]).
    pub verdict: Option<Verdict>,
    /// Time of its last contact (any, side wall included), s.
    pub last_contact: Option<Real>,
    pub out_dir: PathBuf,
}

impl Outcome {
    /// The residual velocity: the speed along the flight at the end once
    /// the axial force has vanished for [`FREE_FLIGHT`] with a plug cut out;
    /// 0 if the plate held (module doc, [`crate::residual`]).
    pub fn residual(&self) -> Option<Real> {
        self.result.as_ref().ok()?;
        self.verdict?.residual()
    }

    /// \[RL10\]'s value for this row: its own model (plane strain, its
    /// material) only; coarse = 11,496 particles, fine = 45,984.
    pub fn paper(&self) -> Option<Real> {
        if !self.row.case.is_papers_model() {
            return None;
        }
        let particles = self.row.case.paper_particles();
        self.row.experiment.paper.iter().find(|p| p.0 == particles && p.1 == self.row.case.criterion).map(|p| p.2)
    }

    /// Perforation time, s.
    pub fn perforation(&self) -> Option<Real> {
        self.result.as_ref().ok()?.perforation
    }

    /// Plug mass at the end: g in axisymmetry, g per mm of depth in plane
    /// strain (numerically the kg/m of the run).
    pub fn plug_mass(&self) -> Option<Real> {
        let plug = self.result.as_ref().ok()?.plug.as_ref()?;
        Some(if self.row.case.geometry == "axisymmetric" { plug.mass * 1e3 } else { plug.mass })
    }

    /// The largest physical particle speed of the run, m/s
    /// ([`crate::step::FastestParticle`]).
    pub fn fastest(&self) -> Option<Real> {
        Some(self.result.as_ref().ok()?.fastest.speed)
    }

    /// First and last time (s) that particles admitted to the contact slaves
    /// by exposure touched the projectile (history rows), if they did
    /// ([`crate::contact::ContactSystem::admit_exposed`]).
    pub fn exposed_contacts(&self) -> Option<(Real, Real)> {
        self.result.as_ref().ok()?.exposed.contacts.map(|(a, b, _)| (a, b))
    }

    /// Plug speed along the impact direction (−y) at the end, m/s.
    pub fn plug_speed(&self) -> Option<Real> {
        Some(-self.result.as_ref().ok()?.plug.as_ref()?.velocity().y)
    }
}

/// A row's run stops once a plug is cut out and the projectile has flown
/// free of force along its flight for this long (or has stopped for this
/// long), s (`time.stop_after_release`, [`crate::residual`]), unless
/// `plugsim validate --full-time`: its speed no longer changes, and the
/// fine rows take a third of the time. Long enough for the plug, thrown
/// ahead at the first impact, to be caught again (in the Borvik runs
/// contacts resume after gaps of up to ~15 µs).
pub const RELEASE_WAIT: Real = 20.0e-6;

/// Run one row into `out/ROW_ID`, to the case's end time if `full_time`,
/// else until [`RELEASE_WAIT`] after the projectile's release.
pub fn run_row(row: &Row, out: &Path, full_time: bool) -> Outcome {
    run_row_with(row, &out.join(&row.id), full_time, &[])
}

/// [`run_row`] into `dir`, with the overrides `extra` applied to the
/// row's case after the stop rule.
pub fn run_row_with(row: &Row, dir: &Path, full_time: bool, extra: &[String]) -> Outcome {
    let dir = dir.to_path_buf();
    let t = std::time::Instant::now();
    let text = builtin_case(&row.id).expect("validation rows name built-in cases");
    let mut set: Vec<String> =
        if full_time { Vec::new() } else { vec![format!("time.stop_after_release={RELEASE_WAIT:e}")] };
    set.extend_from_slice(extra);
    let result = Case::from_str_with(text, &row.id, &set).map_err(|e| e.to_string()).and_then(|case| {
        let cfg = RunConfig::new(dir.clone(), true, RunInfo::current(&row.id, &set));
        execute(&case, &cfg, &mut |_| {}).map_err(|e: RunError| e.to_string())
    });
    let wall = t.elapsed().as_secs_f64();
    let (verdict, last_contact) = match &result {
        Ok(s) => (s.flights.first().map(|(_, v)| *v), s.contacts.first().and_then(|c| c.last)),
        Err(_) => (None, None),
    };
    Outcome { row: row.clone(), result, wall, verdict, last_contact, out_dir: dir }
}

/// Particle rows through the thickness of the convergence study's three
/// resolutions (issue #19; `plugsim validate --family convergence`): the
/// coarse case with 12 rows (its coarsest spacing along the plate doubled
/// with them, as the fine case halves it), the coarse case (24 rows) and
/// the fine case (48 rows). Nothing else changes.
pub const LADDER: [usize; 3] = [12, 24, 48];

/// The convergence study's rows: every coarse axisymmetric member
/// (both experiments; the default model and \[RL10\]'s two criteria with
/// \[RL10\]'s material), each the 24-row rung of its ladder.
pub fn convergence_rows() -> Vec<Row> {
    coarse_rows()
        .into_iter()
        .filter(|r| r.case.geometry == "axisymmetric" && r.case.material != crate::cases::MATERIAL_MODIFIED)
        .collect()
}

/// The row and the overrides of `coarse`'s ladder at `layers` rows
/// ([`LADDER`]): its fine sibling at 48, else the coarse case refined by
/// [`crate::ballistic::at_rows`] (the refinement of `plugsim ballistic
/// --rows`, which at 48 rows gives the fine case file).
pub fn rung(coarse: &Row, layers: usize) -> (Row, Vec<String>) {
    match layers {
        48 => (Row::of(BorvikCase { discretization: "fine", ..coarse.case }), Vec::new()),
        n => {
            let text = builtin_case(&coarse.id).expect("validation rows name built-in cases");
            let case = Case::from_str_with(text, &coarse.id, &[]).expect("built-in cases parse");
            let (_, set) =
                crate::ballistic::at_rows(&case, n).expect("the ladder's row counts refine the coarse plate");
            (coarse.clone(), set)
        }
    }
}

/// One ladder: its coarse row and the outcome at each of [`LADDER`]'s
/// resolutions, in that order.
pub type Ladder = (Row, Vec<Outcome>);

/// The residual velocities over a ladder, if every rung perforated.
fn perforating_residuals(outcomes: &[Outcome]) -> Option<Vec<Real>> {
    outcomes.iter().map(|o| o.residual().filter(|&r| r > 0.0)).collect()
}

/// `(max − min) / mean` of the residual velocities over a ladder, if every
/// rung perforated.
pub fn residual_spread(outcomes: &[Outcome]) -> Option<Real> {
    crate::convergence::spread(&perforating_residuals(outcomes)?)
}

/// What the ladder's residual velocities say of the answer at zero spacing
/// ([`crate::convergence::richardson`]; the rungs' spacings halve, as
/// their rows double), if every rung perforated.
pub fn residual_richardson(outcomes: &[Outcome]) -> Option<crate::convergence::Asymptotic> {
    let v = perforating_residuals(outcomes)?;
    let rungs: Vec<_> = LADDER
        .iter()
        .zip(v)
        .map(|(&rows, value)| crate::convergence::Rung { spacing: 1.0 / rows as Real, value, half_width: 0.0 })
        .collect();
    crate::convergence::richardson(&rungs)
}

/// The convergence table as Markdown and CSV: per ladder, the residual
/// velocity, perforation time, plug mass and fastest particle at each
/// resolution, the spread of the residuals, what they say of the answer at
/// zero spacing ([`residual_richardson`]) and the finest one's error
/// against the experiment.
pub fn convergence_table(ladders: &[Ladder]) -> (String, String) {
    let rows = |f: &dyn Fn(&Outcome) -> String, os: &[Outcome]| os.iter().map(f).collect::<Vec<_>>().join(" / ");
    let mut md = String::from(
        "| case | criterion | residual at 12 / 24 / 48 rows (m/s) | spread % | Richardson: order, extrapolated (m/s), GCI | experiment (m/s) | error at 48 rows % | perforation (µs) | plug (g) | fastest particle (m/s) | smallest step / spacing step | wall (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "case,criterion,rows,residual_m_s,outcome,experiment_m_s,perforation_us,plug_g,fastest_m_s,smallest_step_ratio,wall_s\n",
    );
    let residual = |o: &Outcome| match (&o.result, o.residual()) {
        (Err(e), _) => format!("failed ({})", e.split(';').next().unwrap_or("")),
        (Ok(_), Some(r)) if r > 0.0 => format!("{r:.1}"),
        (Ok(_), Some(_)) => "held".into(),
        (Ok(_), None) => match o.verdict {
            Some(Verdict::Undecided { speed, .. }) => format!("undecided ({speed:.1})"),
            _ => "—".into(),
        },
    };
    let step_ratio = |o: &Outcome| {
        o.result.as_ref().ok().and_then(|s| s.stable_step).map(|(base, (smallest, _, _))| smallest / base)
    };
    for (row, os) in ladders {
        let e = row.experiment;
        let finest = os.last().and_then(|o| o.residual()).filter(|&r| r > 0.0);
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.1} | {} | {} | {} | {} | {} | {} |\n",
            e.name,
            row.case.criterion,
            rows(&residual, os),
            residual_spread(os).map_or_else(|| "—".into(), |s| format!("{:.1}", 100.0 * s)),
            crate::convergence::describe(residual_richardson(os)),
            e.residual,
            finest.map_or_else(|| "—".into(), |r| format!("{:+.1}", 100.0 * (r - e.residual) / e.residual)),
            rows(&|o| fmt_opt(o.perforation().map(|t| t * 1e6), 1), os),
            rows(&|o| fmt_opt(o.plug_mass(), 1), os),
            rows(&|o| fmt_opt(o.fastest(), 0), os),
            rows(&|o| fmt_opt(step_ratio(o), 2), os),
            rows(&|o| format!("{:.0}", o.wall), os),
        ));
        for (layers, o) in LADDER.iter().zip(os) {
            csv.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{:.1}\n",
                e.name,
                row.case.criterion,
                layers,
                fmt_csv(o.residual(), 2),
                residual(o).replace(',', ";"),
                e.residual,
                fmt_csv(o.perforation().map(|t| t * 1e6), 3),
                fmt_csv(o.plug_mass(), 2),
                fmt_csv(o.fastest(), 1),
                fmt_csv(step_ratio(o), 3),
                o.wall,
            ));
        }
    }
    (md, csv)
}

fn fmt_opt(v: Option<Real>, digits: usize) -> String {
    v.map_or_else(|| "—".to_string(), |v| format!("{v:.digits$}"))
}

fn fmt_csv(v: Option<Real>, digits: usize) -> String {
    v.map_or_else(String::new, |v| format!("{v:.digits$}"))
}

/// Short name of a row's material.
fn material_label(case: &BorvikCase) -> &'static str {
    match case.material {
        crate::cases::MATERIAL_MODIFIED => "modified",
        crate::cases::MATERIAL_DEFAULT_MODEL => "RL10 Cockcroft–Latham",
        _ => "RL10",
    }
}

/// The table as Markdown and CSV.
pub fn table(outcomes: &[Outcome]) -> (String, String) {
    let mut md = String::from(
        "| case | geometry | discretization | criterion | material | particles | steps | wall (s) | residual (m/s) | experiment (m/s) | error % | [RL10] (m/s) | perforation (µs) | [RL10] perforation (µs) | plug mass (g; g/mm in plane strain) | plug velocity (m/s) | last contact (µs) | exposed contacts (µs) | fastest particle (m/s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "row,case,geometry,discretization,criterion,material,particles,steps,wall_s,residual_m_s,experiment_m_s,error_percent,paper_m_s,perforation_us,paper_perforation_us,plug_mass,plug_velocity_m_s,last_contact_us,exposed_first_us,exposed_last_us,fastest_particle_m_s,status\n",
    );
    for o in outcomes {
        let (r, c) = (&o.row, &o.row.case);
        let residual = o.residual();
        let err = residual.map(|v| 100.0 * (v - r.experiment.residual) / r.experiment.residual);
        let (particles, steps, status) = match &o.result {
            Ok(s) => (s.particles.to_string(), s.steps.to_string(), "ok".to_string()),
            Err(e) => ("—".into(), "—".into(), format!("failed: {}", e.lines().next().unwrap_or(""))),
        };
        let residual_md = match (&o.result, residual) {
            (Err(_), _) => format!("failed ({})", status.trim_start_matches("failed: ")),
            (Ok(_), None) => match o.verdict {
                Some(Verdict::Undecided { speed, free: true, .. }) => format!("free, no plug cut out ({speed:.1} m/s)"),
                Some(Verdict::Undecided { speed, .. }) => format!("in contact at the end ({speed:.1} m/s)"),
                _ => "—".to_string(),
            },
            (Ok(_), Some(_)) if matches!(o.verdict, Some(Verdict::Held { .. })) => "0 (held)".to_string(),
            (Ok(_), Some(v)) => format!("{v:.1}"),
        };
        let paper_perforation = r.experiment.perforation_time * 1e6;
        let perforation = o.perforation().map(|t| t * 1e6);
        let last_contact = o.last_contact.map(|t| t * 1e6);
        let exposed = o.exposed_contacts();
        let fastest = o.fastest();
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {} | {:.1} | {} | {} | {} | {:.0} | {} | {} | {} | {} | {} |\n",
            r.experiment.name,
            c.geometry,
            c.discretization,
            c.criterion,
            material_label(c),
            particles,
            steps,
            o.wall,
            residual_md,
            r.experiment.residual,
            fmt_opt(err, 1),
            fmt_opt(o.paper(), 1),
            fmt_opt(perforation, 1),
            paper_perforation,
            fmt_opt(o.plug_mass(), 2),
            fmt_opt(o.plug_speed(), 1),
            fmt_opt(last_contact, 1),
            exposed.map_or_else(|| "—".to_string(), |(a, b)| format!("{:.1}–{:.1}", a * 1e6, b * 1e6)),
            fmt_opt(fastest, 0),
        ));
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.id,
            r.experiment.name,
            c.geometry,
            c.discretization,
            c.criterion,
            material_label(c),
            particles.replace('—', ""),
            steps.replace('—', ""),
            o.wall,
            fmt_csv(residual, 3),
            r.experiment.residual,
            fmt_csv(err, 3),
            fmt_csv(o.paper(), 1),
            fmt_csv(perforation, 3),
            paper_perforation,
            fmt_csv(o.plug_mass(), 4),
            fmt_csv(o.plug_speed(), 3),
            fmt_csv(last_contact, 3),
            fmt_csv(exposed.map(|e| e.0 * 1e6), 3),
            fmt_csv(exposed.map(|e| e.1 * 1e6), 3),
            fmt_csv(fastest, 1),
            status.replace(',', ";"),
        ));
    }
    (md, csv)
}

/// Projectile speed against time for every row of one experiment, with the
/// measured residual as a line.
pub fn velocity_plot(outcomes: &[Outcome], experiment: &Experiment) -> LinePlot {
    let series = outcomes
        .iter()
        .filter(|o| o.row.experiment.name == experiment.name && o.result.is_ok())
        .filter_map(|o| {
            let h = HistoryTable::read(&o.out_dir.join("history.csv")).ok()?;
            let (t, vx, vy) = (h.column("time")?, h.column("projectile_vx")?, h.column("projectile_vy")?);
            let c = &o.row.case;
            let material = if c.material == crate::cases::MATERIAL_MODIFIED { " modified" } else { "" };
            Some(Series {
                name: format!("{} {} {}{material}", c.geometry, c.discretization, c.criterion),
                points: t.iter().zip(vx.iter().zip(vy)).map(|(t, (x, y))| (t * 1e6, (x * x + y * y).sqrt())).collect(),
            })
        })
        .collect();
    LinePlot {
        title: format!(
            "{}: {} mm plate, {} m/s impact",
            experiment.name,
            crate::io::short_number(experiment.thickness * 1e3),
            crate::io::short_number(experiment.impact_velocity)
        ),
        x_label: "time (us)".into(),
        y_label: "projectile speed (m/s)".into(),
        series,
        hlines: vec![(format!("experiment {} m/s", experiment.residual), experiment.residual)],
    }
}

/// The field plots each row's run drew at \[RL10\]'s perforation time
/// (`output.plot_times` of the case): `(row id, file)` relative to the
/// validation directory, for the rows whose files exist.
pub fn field_plots(outcomes: &[Outcome]) -> Vec<(String, String)> {
    let mut v = Vec::new();
    for o in outcomes.iter().filter(|o| o.result.is_ok()) {
        let label = crate::output::time_label(o.row.experiment.perforation_time);
        for field in ["effective_stress", "temperature"] {
            let file = format!("{field}_{label}.png");
            if o.out_dir.join(&file).exists() {
                v.push((o.row.id.clone(), format!("{}/{file}", o.row.id)));
            }
        }
    }
    v
}

/// The Markdown report: `header` (provenance), how the columns are
/// measured, the table, and the plots (`velocity_plots`: files relative to
/// the validation directory).
pub fn report(header: &str, outcomes: &[Outcome], velocity_plots: &[String]) -> String {
    let (md, _) = table(outcomes);
    let mut s = format!("{header}\n\n{md}\n{METHODS}\n\n");
    for p in velocity_plots {
        s.push_str(&format!("![projectile speed]({p})\n"));
    }
    let plots = field_plots(outcomes);
    if !plots.is_empty() {
        s.push_str(
            "\nDeformed plate with its cracks at [RL10]'s perforation time, coloured by effective stress, \
             and the temperature of the shear band at the projectile's corner:\n\n",
        );
        for (row, file) in plots {
            s.push_str(&format!("![{row}]({file})\n"));
        }
    }
    s
}

/// How the columns are measured (printed under the table).
pub const METHODS: &str = "Residual velocity: the projectile's speed along its flight direction (that \
of its initial velocity) at the end of the run, once a plug is cut out and the contact force along \
that direction (`projectile_f_axial` in `history.csv`) has stayed below 0.1 % of its peak for at \
least 1 µs; a touch on the side wall of the hole pushes across the flight and does not count. A \
projectile that stopped or bounced back reports 0 (held); \"in contact at the end\" otherwise. \
Perforation: the first time the cracks cut a plug out of the plate. Each run stops 20 µs after the \
projectile's release so defined, or 20 µs after it stopped (`--full-time`: at the paper's simulated time). Plug: the particles the through-cracks separate from the clamped plate (a flood fill over \
the particles that the cracks do not separate), its mass (g; g per mm of depth in plane strain) \
and mass-averaged velocity along the impact direction at the end of the run. Exposed contacts: \
when particles that started in the interior, and joined the contact slaves once the projectile came \
within a spacing of them, were pushed by it (first and last history row; — if never). [RL10]'s values \
exist for its own model only (plane strain, its material).";

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's timings (`shared/reference/ren-li-2010.toml`) belong to
    /// its own models with the effective-strain criterion, and to each
    /// discretization its own.
    #[test]
    fn published_runs_are_the_papers_timed_models_only() {
        assert_eq!(published_run("borvik-1-plane-strain"), Some((0.92 * 3600.0, 118.0e-6)));
        assert_eq!(published_run("borvik-1"), published_run("borvik-1-plane-strain"));
        assert_eq!(published_run("borvik-1-plane-strain-fine"), Some((3.80 * 3600.0, 118.0e-6)));
        assert_eq!(published_run("borvik-2-plane-strain"), Some((1.86 * 3600.0, 216.0e-6)));
        assert_eq!(published_run("borvik-2-plane-strain-fine"), Some((7.1 * 3600.0, 216.0e-6)));
        for other in
            ["borvik-1-plane-strain-damage", "borvik-1-axisymmetric", "borvik-2-axisymmetric-fine", "elastic-strike"]
        {
            assert_eq!(published_run(other), None, "{other}");
        }
    }

    #[test]
    fn every_row_is_a_built_in_case_of_its_experiment() {
        assert_eq!(coarse_rows().len(), 10);
        let rows = all_rows();
        assert_eq!(rows.len(), 24);
        for r in &rows {
            let text = builtin_case(&r.id).unwrap();
            let case = Case::from_str_with(text, &r.id, &[]).unwrap_or_else(|e| panic!("{}: {e}", r.id));
            let plate = &case.bodies[0].rectangle;
            assert_eq!(plate.y_max - plate.y_min, r.experiment.thickness, "{}", r.id);
            assert_eq!(plate.layers, if r.case.discretization == "coarse" { 24 } else { 48 }, "{}", r.id);
            assert_eq!(case.bodies[0].material, r.case.material, "{}", r.id);
            let p = &case.rigid_bodies[0];
            assert_eq!(p.velocity[1], -r.experiment.impact_velocity);
            let nose = p.rectangle.as_ref().unwrap().center[1] - 0.04;
            assert!(nose > plate.y_max && nose - plate.y_max < 1e-4, "{}: nose {nose}", r.id);
            assert_eq!(case.time.end, r.experiment.simulated_time, "{}", r.id);
            assert_eq!(case.output.plot_times, vec![r.experiment.perforation_time], "{}", r.id);
            let fracture = toml::to_string(&case.fracture).unwrap();
            assert!(fracture.contains(&format!("criterion = \"{}\"", r.case.criterion)), "{}: {fracture}", r.id);
            for s in &case.bodies[0].supports {
                assert_eq!(s.region.y_max, r.experiment.thickness, "{}: support spans the thickness", r.id);
            }
        }
    }

    /// The ladder: 12 rows by overrides of the coarse case (its coarsest
    /// spacing doubled), the coarse case, the fine sibling; and the spread.
    #[test]
    fn convergence_ladder_rungs() {
        let rows = convergence_rows();
        assert_eq!(rows.len(), 6, "two experiments x three criteria, axisymmetric");
        let r = rows.iter().find(|r| r.id == "borvik-2-axisymmetric-nonlocal").unwrap();
        let (a, set) = rung(r, 12);
        assert_eq!(a.id, r.id);
        let case = Case::from_str_with(builtin_case(&a.id).unwrap(), &a.id, &set).unwrap();
        assert_eq!(case.bodies[0].rectangle.layers, 12);
        assert!((case.bodies[0].rectangle.coarse_spacing.unwrap() - 1.2e-3).abs() < 1e-15);
        let (b, set) = rung(r, 24);
        assert_eq!((b.id.as_str(), set.len()), (r.id.as_str(), 0));
        let (c, set) = rung(r, 48);
        assert_eq!((c.id.as_str(), set.len()), ("borvik-2-axisymmetric-fine-nonlocal", 0));
    }

    #[test]
    fn only_selects_a_name_an_alias_or_every_name_containing_the_text() {
        let ids = |v: Vec<Row>| v.into_iter().map(|r| r.id).collect::<Vec<_>>();
        assert_eq!(ids(select(all_rows(), "borvik-1-axisymmetric")), ["borvik-1-axisymmetric"]);
        assert_eq!(ids(select(all_rows(), "borvik-2")), ["borvik-2-plane-strain"]);
        assert_eq!(select(all_rows(), "modified").len(), 4);
        assert_eq!(select(all_rows(), "fine").len(), 14);
        assert_eq!(select(coarse_rows(), "damage").len(), 4);
        assert_eq!(select(all_rows(), "nonlocal").len(), 4);
        assert!(select(all_rows(), "nosuch").is_empty());
    }
}
