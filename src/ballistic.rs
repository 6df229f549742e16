//! `plugsim ballistic`: a case with a projectile run at several impact
//! speeds, side by side, and its ballistic limit found by bisection; the
//! `v_i → v_r` table, the Recht–Ipson fit and its plot (SPEC §10).
//!
//! - **Impact speed**: the projectile's initial velocity keeps its direction
//!   and takes the given magnitude. The projectile ([`Projectile`]) is the
//!   case's one moving body — a rigid body with a non-zero initial velocity,
//!   or a deformable body given one over its whole body (issue #20) — or
//!   the one named.
//! - **Outcome** of a run ([`crate::residual`]): *perforated* (a plug cut
//!   out and the force along the flight vanished: `v_r` its speed along the
//!   flight at the end), *held* (stopped or bounced back: `v_r = 0`), or
//!   undecided at the end of the run. For the search an undecided run counts
//!   as perforating if a plug has been cut out (the projectile is still
//!   pushing it), else as held; the table says which runs were undecided.
//!   Runs stop early by `time.stop_after_release` ([`STOP_AFTER`]).
//! - **Run until decided**: a run still undecided at the case's end time
//!   goes on, up to [`Setup::max_time`] (by default [`DECIDE_FACTOR`]
//!   times the case's end time, [`default_max_time`]); the early stop ends
//!   it 20 µs after the plate held it or released it. Near the limit a
//!   slow plug is still being pushed at the end time \[RL10\] simulated (the
//!   Case I plate at 12 / 24 / 48 rows: every run counted held next to the
//!   limit still moved at 7–16 m/s at 118 µs), so the limit within the
//!   case's end time is not the ballistic limit; docs/validation.md
//!   measures the difference.
//! - **Ballistic limit** `v_bl`: between the highest speed the plate held
//!   and the lowest that perforated it. The search first checks the bracket
//!   (`lo` must hold, `hi` perforate; otherwise it moves `lo` down to half
//!   or `hi` up by half, up to [`WIDEN_TRIES`] times each, running `jobs`
//!   speeds spread over the new part of the range at once), then each round
//!   runs `jobs` speeds evenly spaced inside the bracket at once (two jobs
//!   split it in three) and keeps the sub-bracket where the outcome changes,
//!   until it is at most `2·tol` wide; `v_bl` is its middle, `± tol`. Once
//!   three runs have perforated, one round spreads its speeds over
//!   `± 0.9·tol` around the Recht–Ipson fit's `v_bl` instead
//!   ([`next_round`]): where the fit is right the bracket closes in that
//!   round.
//! - **Recht–Ipson**: `v_r = a (v_iᵖ − v_blᵖ)^(1/p)` fitted by least squares
//!   to the perforating points ([`fit_recht_ipson`]), `v_bl` kept inside the
//!   bracket.
//!
//! - **Resolutions** ([`at_rows`], [`Rung`]): the same study at several
//!   particle spacings, a uniform refinement of every deformable body, and
//!   the table of the limit and the residuals across them with their spread
//!   ([`ladder_table`]; "converged or it doesn't count"), and how much each
//!   residual moves with its rung's limit ([`limit_sensitivity`]): a
//!   residual a few per cent above the limits cannot agree better than
//!   they do, many times over.
//!
//! Runs go side by side on threads of their own, each with its own pool of
//! worker threads (the solver's results do not depend on the thread count).
//! The table is rewritten after every finished run, so an interrupt keeps
//! every run finished before it, and each run in flight writes a
//! checkpoint; the report lists those runs where their checkpoints left
//! them ([`Paused`], [`paused_table`]) and the speeds not started. The
//! library never prints: progress goes to a callback.
//!
//! - **Resume** ([`Setup::resume`], `--resume`): the same study run again
//!   into the same directory takes back every run that finished there
//!   ([`SHOT_FILE`], [`finished_run`]) and continues every run an
//!   interrupt stopped from its checkpoint (bit-identical to a run never
//!   stopped, as `plugsim resume`), where the run's `case.resolved.toml` is
//!   the one this study would run at that speed (same case, overrides,
//!   resolution and max time); any other speed runs afresh. A limit search
//!   resumed with the same bounds, tolerance and jobs asks for the same
//!   speeds, so a 48-row search stopped after hours loses only the runs in
//!   flight, and those only up to their checkpoint.

use crate::case::Case;
use crate::convergence::{self, richardson, spread_within, step};
use crate::io::{IoError, LinePlot, PlotError, Series};
use crate::math::{Real, Vec2};
use crate::residual::Verdict;
use crate::run::{execute, Progress, RunConfig, RunError, RunInfo};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};

/// The speed, in impact speeds, that the impact's waves give a particle
/// at most: a free face doubles the particle velocity of the wave that
/// meets it. The report names every run whose fastest particle went
/// faster ([`outran_doubling`]).
pub const FREE_SURFACE_DOUBLING: Real = 2.0;

/// `time.stop_after_release` of every run, s, unless the case sets one:
/// long enough for a plug thrown ahead to be caught again (as
/// [`crate::validation::RELEASE_WAIT`]).
pub const STOP_AFTER: Real = 20.0e-6;

/// By default a run still undecided at the case's end time goes on to this
/// multiple of it ([`default_max_time`]): the held runs next to every
/// reported limit (Case I's, Case II's and the 12 mm plate at 12 / 24 / 48
/// rows) were decided by 1.15–1.5 times their case's end time
/// (docs/validation.md), so 3 leaves room, and the early stop ends a
/// decided run at once. [`DEFINITIONS`] states it.
pub const DECIDE_FACTOR: Real = 3.0;

/// The default [`Setup::max_time`] of `case`: [`DECIDE_FACTOR`] times its
/// end time, s.
pub fn default_max_time(case: &Case) -> Real {
    DECIDE_FACTOR * case.time.end
}

/// The most speeds one `LO:HI:STEP` item of [`parse_speeds`] may give.
pub const MAX_SPEEDS_PER_RANGE: usize = 1000;

/// One comma-separated item of `plugsim ballistic --speeds`: a speed, or an
/// inclusive range `LO:HI:STEP` (`116:134:1`: 116, 117, …, 134 m/s; the
/// last speed is the highest `LO + k STEP` not above `HI`, to within 10⁻⁹
/// of STEP, each rounded to 10⁻⁶ m/s so that a run's directory name is the
/// speed typed). Every speed must be a positive number; a range needs
/// `HI ≥ LO`, `STEP > 0` and at most [`MAX_SPEEDS_PER_RANGE`] speeds. The
/// error names the item, for the command line.
pub fn parse_speeds(item: &str) -> Result<Vec<Real>, String> {
    let number = |t: &str| -> Result<Real, String> {
        t.trim()
            .parse::<Real>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{t}' in '{item}' is not a number"))
    };
    let speeds = match item.split(':').collect::<Vec<_>>()[..] {
        [v] => vec![number(v)?],
        [lo, hi, step] => {
            let (lo, hi, step) = (number(lo)?, number(hi)?, number(step)?);
            if step <= 0.0 || hi < lo {
                return Err(format!("range '{item}' needs LO <= HI and STEP > 0 (LO:HI:STEP)"));
            }
            let n = ((hi - lo) / step + 1e-9).floor();
            if n >= MAX_SPEEDS_PER_RANGE as Real {
                return Err(format!("range '{item}' gives more than {MAX_SPEEDS_PER_RANGE} speeds"));
            }
            (0..=n as usize).map(|k| ((lo + k as Real * step) * 1e6).round() / 1e6).collect()
        }
        _ => return Err(format!("'{item}' is neither a speed nor a range LO:HI:STEP")),
    };
    match speeds.iter().find(|v| **v <= 0.0) {
        Some(v) => Err(format!("impact speeds must be positive (got {v} in '{item}')")),
        None => Ok(speeds),
    }
}

/// How many times the search moves a bound that does not bracket the limit.
pub const WIDEN_TRIES: usize = 3;

/// Why a ballistic study cannot start or stopped.
#[derive(Debug, thiserror::Error)]
pub enum BallisticError {
    #[error("case {case} has no moving body to use as the projectile: no rigid body with an initial velocity (rigid bodies: {}), no deformable body given one over its whole body", list(.bodies))]
    NoProjectile { case: String, bodies: Vec<String> },
    #[error("case {case} has several moving bodies ({}); name the projectile with --projectile", list(.names))]
    SeveralProjectiles { case: String, names: Vec<String> },
    #[error("case {case} has no moving body named '{name}' (moving bodies: {})", list(.bodies))]
    UnknownProjectile { case: String, name: String, bodies: Vec<String> },
    #[error("rigid body '{name}' of case {case} is prescribed (it moves at its velocity whatever the forces): it has no residual velocity")]
    Prescribed { case: String, name: String },
    #[error("{0}")]
    Settings(String),
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error("experimental points {path}: {message}")]
    Experiments { path: String, message: String },
}

fn list(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

/// What a study runs and where.
#[derive(Clone, Debug)]
pub struct Setup {
    /// The case (with its `--set` overrides), unresolved.
    pub case: Case,
    /// Its name or file, for errors and the report.
    pub label: String,
    /// The `--set` overrides, for the report and each run's provenance.
    pub overrides: Vec<String>,
    /// The body the study fires.
    pub projectile: Projectile,
    /// Runs at once.
    pub jobs: usize,
    /// Worker threads of each run.
    pub threads_per_run: usize,
    pub out_dir: PathBuf,
    /// The latest simulated time a run may go on to while undecided, s (at
    /// least the case's end time; module doc, [`default_max_time`]).
    pub max_time: Real,
    /// Set by Ctrl-C (or a test): runs in flight stop (each writes a
    /// checkpoint), no new run starts, the finished ones are kept.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Continue a study in `out_dir` (`--resume`, module doc): a speed whose
    /// run finished there with the same case is taken back, one
    /// interrupted there continues from its checkpoint; without it every
    /// speed runs afresh, over whatever its directory holds.
    pub resume: bool,
}

/// The body a study fires.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projectile {
    /// A rigid body, by its index among the case's rigid bodies.
    Rigid(usize),
    /// A deformable body flying as a whole (an `initial_velocity` entry
    /// without a region, [`Case::deformable_flights`]), by its index among
    /// the case's bodies.
    Deformable(usize),
}

impl Projectile {
    /// Its name in `case` (that of its history columns and flight).
    pub fn name(self, case: &Case) -> &str {
        match self {
            Projectile::Rigid(k) => &case.rigid_bodies[k].name,
            Projectile::Deformable(b) => &case.bodies[b].name,
        }
    }

    /// Its initial velocity in `case`, m/s (a deformable body's: the last
    /// entry over the whole body, as [`Case::deformable_flights`] reads it).
    pub fn velocity(self, case: &Case) -> Vec2 {
        let v = match self {
            Projectile::Rigid(k) => case.rigid_bodies[k].velocity,
            Projectile::Deformable(b) => case.bodies[b].whole_body_velocity().unwrap_or([0.0; 2]),
        };
        Vec2::new(v[0], v[1])
    }

    /// Set its initial velocity in `case` to `v` (m/s); what a run's
    /// provenance records of it: a `--set` override that gives the same
    /// change (`plugsim run --set` with a run's recorded overrides
    /// reruns it).
    fn set_velocity(self, case: &mut Case, v: [Real; 2]) -> String {
        match self {
            Projectile::Rigid(k) => {
                let body = &mut case.rigid_bodies[k];
                body.velocity = v;
                format!("rigid_bodies.{}.velocity={v:?}", body.name)
            }
            Projectile::Deformable(b) => {
                // a deformable projectile flies as a whole: it has that entry
                let body = &mut case.bodies[b];
                let j = body.whole_body_entry();
                if let Some(velocity) = body.whole_body_velocity_mut() {
                    *velocity = v;
                }
                let j = j.map_or_else(|| "(none)".to_string(), |j| j.to_string());
                format!("bodies.{}.initial_velocity.{j}.velocity={v:?}", body.name)
            }
        }
    }
}

/// The projectile of `case`: the moving body named `name`, else its only
/// moving body — a rigid body with a non-zero initial velocity (not
/// prescribed), or a deformable body flying as a whole.
pub fn select_projectile(case: &Case, label: &str, name: Option<&str>) -> Result<Projectile, BallisticError> {
    let bodies: Vec<String> = case.rigid_bodies.iter().map(|r| r.name.clone()).collect();
    let moving: Vec<Projectile> = (0..case.rigid_bodies.len())
        .filter(|&k| case.rigid_bodies[k].velocity.iter().any(|&v| v != 0.0))
        .map(Projectile::Rigid)
        .chain(case.deformable_flights().into_iter().map(|(_, b, _)| Projectile::Deformable(b)))
        .collect();
    let names = |list: &[Projectile]| list.iter().map(|p| p.name(case).to_string()).collect::<Vec<_>>();
    let projectile = match name {
        Some(n) => {
            // a rigid body of that name, moving or not (a still one is refused below)
            let rigid = bodies.iter().position(|b| b == n).map(Projectile::Rigid);
            rigid.or_else(|| moving.iter().copied().find(|p| p.name(case) == n)).ok_or_else(|| {
                BallisticError::UnknownProjectile { case: label.into(), name: n.into(), bodies: names(&moving) }
            })?
        }
        None => match moving.as_slice() {
            [p] => *p,
            [] => return Err(BallisticError::NoProjectile { case: label.into(), bodies }),
            _ => return Err(BallisticError::SeveralProjectiles { case: label.into(), names: names(&moving) }),
        },
    };
    if let Projectile::Rigid(k) = projectile {
        let spec = &case.rigid_bodies[k];
        if spec.prescribed {
            return Err(BallisticError::Prescribed { case: label.into(), name: spec.name.clone() });
        }
    }
    if projectile.velocity(case) == Vec2::zeros() {
        return Err(BallisticError::NoProjectile { case: label.into(), bodies });
    }
    Ok(projectile)
}

/// The projectile's flight direction (unit) and the case's own impact
/// speed, m/s.
pub fn flight(case: &Case, projectile: Projectile) -> (Vec2, Real) {
    let v = projectile.velocity(case);
    (crate::residual::flight_direction(v), v.norm())
}

/// The target of `case`: its first deformable body that does not fly as a
/// whole (not a deformable projectile, [`Case::deformable_flights`]), by
/// index; the body whose rows `--rows` counts.
pub fn target(case: &Case) -> Option<usize> {
    let flying = flying_bodies(case);
    (0..case.bodies.len()).find(|b| !flying.contains(b))
}

/// Where the projectile's edge lies against the target's particle columns
/// ([`edge_phase`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePhase {
    /// The projectile's edge: the largest x of its outline (in axisymmetry
    /// its radius), m.
    pub edge: Real,
    /// The target's particle column nearest to it, m.
    pub column: Real,
    /// `(edge − column) / h` in [−½, ½], `h` the gap to the next column on
    /// the edge's side ([`crate::discretize::RectangleGrid::column_offset`]).
    pub offset: Real,
}

/// The projectile's edge against the particle columns of `case`'s target
/// ([`target`]): the lattice's phase at the rim of a flat-nosed
/// projectile, which can pick the rim crack's first steps and, near a
/// fork, the failure mode (docs/validation.md, "A particle column on the
/// projectile's edge" and "Case II's plate on the 48 / 72 / 96 ladder";
/// Case II's plate at 72 rows, where it is −0.39).
/// Every study and every rung of a ladder reports it. `None` when the
/// edge lies outside the target.
pub fn edge_phase(case: &Case, projectile: Projectile) -> Option<EdgePhase> {
    let case = case.resolved();
    let grid = &case.bodies.get(target(&case)?)?.rectangle;
    let edge = match projectile {
        Projectile::Rigid(k) => {
            case.rigid_body(case.rigid_bodies.get(k)?).ok()?.outline_global().map(|p| p.x).reduce(Real::max)?
        }
        Projectile::Deformable(b) => case.bodies.get(b)?.rectangle.x_max,
    };
    let (column, offset) = grid.column_offset(edge)?;
    Some(EdgePhase { edge, column, offset })
}

impl EdgePhase {
    /// For a report: "the projectile's edge (x = 10.000 mm) lies −0.39 of
    /// a spacing from the target's nearest particle column (x = 10.056
    /// mm)".
    pub fn describe(&self) -> String {
        format!(
            "the projectile's edge (x = {:.3} mm) lies {} of a spacing from the target's nearest particle column (x = {:.3} mm)",
            self.edge * 1e3,
            self.offset_text(),
            self.column * 1e3
        )
    }

    /// The offset as the reports print it, "+0.18": signed, two decimals,
    /// and "+0.00" for one that rounds to zero whatever its sign (a column
    /// on the edge up to round-off).
    pub fn offset_text(&self) -> String {
        format!("{:+.2}", self.offset_rounding_to(2))
    }

    /// The offset, or 0 where it rounds to zero at `decimals` decimals (so
    /// that round-off never prints as "−0.00"): for the reports' text and
    /// `convergence.csv`.
    pub fn offset_rounding_to(&self, decimals: i32) -> Real {
        if self.offset.abs() < 0.5 * (10.0 as Real).powi(-decimals) {
            0.0
        } else {
            self.offset
        }
    }
}

/// `plugsim ballistic --phases K`: `K` lattice phases at the rim, evenly
/// over one spacing, `k/K` for `k = 0 … K−1` written in (−½, ½] (4: 0,
/// +0.25, +0.5, −0.25). The first is a column on the projectile's edge.
pub fn phases(count: usize) -> Vec<Real> {
    (0..count)
        .map(|k| {
            let p = k as Real / count as Real;
            if p > 0.5 {
                p - 1.0
            } else {
                p
            }
        })
        .collect()
}

/// `case` with its target's particle columns shifted so that the
/// projectile's edge lies `phase` spacings (in [−½, ½]) from the nearest
/// one ([`edge_phase`]). The fine zone's columns stand at `x_f + k h'`
/// from `refine_at` (`x_f`); with the edge at distance `d` from it, `h' =
/// d / (n + φ)`, `n` the nearest whole number to `d/h − φ` (at least 1,
/// `h` the fine spacing the case resolves to, `φ` the phase signed toward
/// `x_f`), puts the edge exactly `φ` spacings past column `n`. The fine
/// spacing changes by at most half a spacing over `d` (2.3 % at 24 rows on
/// the built-in plates); the rows through the thickness do not change. A
/// `column_at` of the case moves to column `n`. The edge must lie in the
/// uniform fine zone. Returns the case and the `--set` overrides that give
/// it.
///
/// Why: near a limit the rim crack's first steps, and with them the limit,
/// can depend on which fraction of a spacing the edge lies from a column
/// (docs/validation.md, "Case II's plate on the 48 / 72 / 96 ladder"),
/// and that fraction changes from one resolution to the next. A study over
/// several phases at each resolution measures that dependence instead of
/// sampling it once ([`ladder_table`]'s envelope).
pub fn at_phase(case: &Case, projectile: Projectile, phase: Real) -> Result<(Case, Vec<String>), BallisticError> {
    if !(phase.is_finite() && phase.abs() <= 0.5) {
        return Err(BallisticError::Settings(format!("a lattice phase lies in [-0.5, 0.5] spacings, got {phase}")));
    }
    let no_edge = || {
        BallisticError::Settings(
            "lattice phase (--phases, --phase): the projectile's edge does not lie over the target's particle columns, so it has no phase"
                .into(),
        )
    };
    let b = target(case).ok_or_else(no_edge)?;
    let edge = edge_phase(case, projectile).ok_or_else(no_edge)?.edge;
    let resolved = case.resolved();
    let grid = &resolved.bodies[b].rectangle;
    let (x_f, h) = (grid.refine_at.ok_or_else(no_edge)?, grid.fine_spacing.ok_or_else(no_edge)?);
    let (d, toward) = ((edge - x_f).abs(), if edge >= x_f { 1.0 } else { -1.0 });
    let signed = toward * phase;
    let n = (d / h - signed).round().max(1.0);
    let fine = d / (n + signed);
    let name = &case.bodies[b].name;
    let mut c = case.clone();
    let r = &mut c.bodies[b].rectangle;
    r.fine_spacing = Some(fine);
    let mut set = vec![format!("bodies.{name}.rectangle.fine_spacing={fine:e}")];
    if r.column_at.is_some() {
        let column = x_f + toward * n * fine;
        r.column_at = Some(column);
        set.push(format!("bodies.{name}.rectangle.column_at={column:e}"));
    }
    if let Some(p) = c.validate().into_iter().find(|p| p.key.starts_with(&format!("bodies[{b}].rectangle"))) {
        return Err(BallisticError::Settings(format!("lattice phase {phase:+.2}: {}: {}", p.key, p.message)));
    }
    let got = edge_phase(&c, projectile).ok_or_else(no_edge)?.offset;
    // ±½ are one phase (the edge midway between two columns)
    if ((got - phase + 0.5).rem_euclid(1.0) - 0.5).abs() > 1e-6 {
        return Err(BallisticError::Settings(format!(
            "lattice phase {phase:+.2}: the edge (x = {:.4} mm) lies outside the target's uniform fine zone (within \
             fine_half_width = {} m of refine_at = {x_f} m), whose columns the phase shifts",
            edge * 1e3,
            grid.fine_half_width
        )));
    }
    Ok((c, set))
}

/// The deformable projectiles of `case` by index among its bodies.
fn flying_bodies(case: &Case) -> Vec<usize> {
    case.deformable_flights().into_iter().map(|(_, b, _)| b).collect()
}

/// `case` refined uniformly so that its target — its first deformable body
/// that does not fly as a whole (not a deformable projectile,
/// [`Case::deformable_flights`]) — has `rows` particle rows through its
/// thickness: every deformable body's `layers` (a deformable
/// projectile's too, rounded to the nearest whole number) is multiplied by
/// `k = rows / layers₀` (`layers₀` the target's), its
/// `fine_spacing` and `coarse_spacing` (where given) divided by `k`;
/// nothing else changes (the fine zone's width and the grading ratio are
/// geometry, `fracture.nonlocal_radius` and `band_width` material lengths,
/// the time step follows the spacing). Each body's new row count must be a
/// whole number of at least 2. Returns the case and the `--set` overrides
/// that give it from the original (for the report and to rerun one rung):
/// at `k = 2` a built-in coarse Børvik case becomes its fine sibling.
pub fn at_rows(case: &Case, rows: usize) -> Result<(Case, Vec<String>), BallisticError> {
    let flying = flying_bodies(case);
    let first = target(case)
        .map(|b| &case.bodies[b])
        .ok_or_else(|| BallisticError::Settings("the case has no deformable target to refine".into()))?;
    if rows < 2 {
        return Err(BallisticError::Settings(format!("--rows: at least 2 rows through the thickness, got {rows}")));
    }
    let k = rows as Real / first.rectangle.layers as Real;
    let mut c = case.clone();
    let mut set = Vec::new();
    for (index, b) in c.bodies.iter_mut().enumerate() {
        let r = &mut b.rectangle;
        let mut layers = r.layers as Real * k;
        if flying.contains(&index) {
            // a projectile's rows need not be exact: the nearest whole number
            layers = layers.round().max(2.0);
        }
        if (layers - layers.round()).abs() > 1e-9 || layers.round() < 2.0 {
            return Err(BallisticError::Settings(format!(
                "--rows {rows}: body '{}' has {} rows where '{}' has {}, so it would get {layers:.3} (not a whole number of at least 2)",
                b.name, r.layers, first.name, first.rectangle.layers
            )));
        }
        if k == 1.0 {
            continue;
        }
        r.layers = layers.round() as usize;
        set.push(format!("bodies.{}.rectangle.layers={}", b.name, r.layers));
        for (key, value) in [("fine_spacing", &mut r.fine_spacing), ("coarse_spacing", &mut r.coarse_spacing)] {
            if let Some(h) = value {
                *h /= k;
                set.push(format!("bodies.{}.rectangle.{key}={h:e}", b.name));
            }
        }
    }
    Ok((c, set))
}

/// Default of `plugsim ballistic --snapshot-every`, s: 10 µs, a tenth of the
/// Borvik cases' 1 µs. A held run at 24 rows goes on for up to ~650 µs of
/// simulated time, ~360 MB of snapshots at 1 µs; a scan of twenty speeds
/// would take 7 GB.
pub const SNAPSHOT_EVERY: Real = 1.0e-5;

/// `case` writing its snapshots at most every `every` s: its own
/// `output.interval` (resolved: `time.end / 50` where it gives none) where
/// that is coarser; `every = 0` leaves it as it is. A run writes its last
/// state whatever the interval.
pub fn with_snapshots_every(mut case: Case, every: Real) -> Case {
    let own = case.resolved().output.interval.unwrap_or(every);
    case.output.interval = Some(own.max(every));
    case
}

/// `case` with the projectile at `speed` m/s along its flight direction,
/// stopping early by [`STOP_AFTER`] unless the case sets its own and going
/// on, while undecided, to `max_time` (s) where that is later than the
/// case's end time; and what a run's provenance records of the changes.
pub fn at_speed(case: &Case, projectile: Projectile, speed: Real, max_time: Real) -> (Case, Vec<String>) {
    let mut c = case.clone();
    let (dir, _) = flight(case, projectile);
    let mut set = vec![projectile.set_velocity(&mut c, [dir.x * speed, dir.y * speed])];
    if c.time.stop_after_release.is_none() {
        c.time.stop_after_release = Some(STOP_AFTER);
        set.push(format!("time.stop_after_release={STOP_AFTER:e}"));
    }
    if max_time > c.time.end {
        c.time.end = max_time;
        set.push(format!("time.end={max_time:e}"));
    }
    (c, set)
}

/// One run of the study (a run's directory keeps it as [`SHOT_FILE`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shot {
    /// Impact speed, m/s.
    pub speed: Real,
    pub verdict: Verdict,
    /// When the plug was first cut out, s.
    pub perforation: Option<Real>,
    /// Plug mass at the end, kg (kg per metre of depth in plane strain).
    pub plug_mass: Option<Real>,
    /// Simulated time at the end, s.
    pub end_time: Real,
    /// The largest physical particle speed of the run, m/s
    /// ([`crate::step::FastestParticle`]).
    pub fastest: Real,
    /// Median own damage of the particles the cracks grew into
    /// ([`crate::fracture::CrackGrowth::tip_damage`]; the locus is 1).
    pub tip_damage: Option<Real>,
    /// Least adiabatic hardening of the particles the cracks grew into
    /// ([`crate::fracture::CrackGrowth::tip_hardening`]; ≤ 0: some tip
    /// entered material past the onset of shear localization).
    pub tip_hardening: Option<Real>,
    pub steps: u64,
    /// Wall time, s.
    pub wall: Real,
    /// The run's directory.
    pub dir: PathBuf,
    /// Mass added by mass scaling, kg (kg/m in plane strain; 0 without it,
    /// `[time] mass_scaling`).
    #[serde(default)]
    pub added_mass: Real,
    /// Fractured points eroded at the step's floor (0 without it, `[time]
    /// erode_failed_below`).
    #[serde(default)]
    pub floor_eroded: u64,
    /// The radial kinetic energy the axis took from particles that reached
    /// it, J (0 where none did, or in plane strain; `contact.axis`,
    /// [`crate::run::RunSummary::axis_energy`]).
    #[serde(default)]
    pub axis_energy: Real,
    /// How many particles were detached from their body (0 without it,
    /// `fracture.detach_below`).
    #[serde(default)]
    pub detached: usize,
    /// Which, when and from where, in the order detached (empty in a
    /// record written before they were kept, which has the count alone).
    #[serde(default)]
    pub detached_particles: Vec<crate::run::DetachedParticle>,
    /// The fastest particle: which, where from, its mass, when and whether
    /// it lay on a crack face (`None` in a run finished by a build that did
    /// not record it).
    #[serde(default)]
    pub fastest_particle: Option<crate::step::FastestParticle>,
    /// The fastest a particle could be thrown when the run's fastest was
    /// set, m/s, under a rounded, conical or ogival rigid nose: its jet
    /// bound ([`crate::contact::projectile::Projectile::jet_speed_bound`])
    /// at the depth `v_i (t − t₀)`, `t₀` the history's last row before the
    /// first contact (so no shallower than the nose was, and the bound no
    /// larger than the nose's), where the particle was at least half the
    /// contact's radius from the flight's line (a jet leaves at the
    /// contact's edge). `None` for a flat nose, a deformable projectile, a
    /// particle nearer the line (under the nose, on the axis), or a run
    /// finished by a build that did not record it: the bound is then the
    /// free-surface doubling `2 v_i`.
    #[serde(default)]
    pub speed_bound: Option<Real>,
    /// The projectile's speed along its flight when the cracks first cut
    /// a piece out (`perforation`; the first history row at or after it,
    /// [`crate::residual::speed_along_at`]), m/s; `None` without a cut.
    /// Not a residual: what the projectile loses after it (to a plug
    /// still in its way, or a cap of plate it carries) is in `v_r` and not
    /// here. The ladder table compares it across the rungs beside `v_r`,
    /// which tells a cut that converges from what follows it
    /// (docs/validation.md, "The hemispherical residual parted at the cut
    /// and after it"). A run taken back from a build that did not record
    /// it reads it from its history ([`finished_run`]).
    #[serde(default)]
    pub cut_speed: Option<Real>,
}

impl Shot {
    /// Whether the run counts as a perforation (module doc).
    pub fn perforated(&self) -> bool {
        match self.verdict {
            Verdict::Perforated { .. } => true,
            Verdict::Undecided { plug, .. } => plug,
            _ => false,
        }
    }

    /// Residual velocity, m/s: 0 when held, `None` when undecided.
    pub fn residual(&self) -> Option<Real> {
        self.verdict.residual()
    }

    /// The outcome in a word or two.
    pub fn outcome(&self) -> String {
        match self.verdict {
            Verdict::Perforated { .. } => "perforated".into(),
            Verdict::Held { .. } => "held".into(),
            Verdict::Undecided { speed, plug: true, .. } => {
                format!("plug cut, in contact at the end ({speed:.1} m/s): counted perforated")
            }
            Verdict::Undecided { speed, .. } => format!("undecided at the end ({speed:.1} m/s): counted held"),
            Verdict::NotMoving => "not moving".into(),
        }
    }
}

/// Progress reports to the caller.
#[derive(Clone, Debug)]
pub enum Event {
    /// A search round (or the bracket check) is about to run these speeds.
    Round { label: String, speeds: Vec<Real> },
    /// A run started.
    Started { speed: Real },
    /// A run reached `time` of at most `end` (s): at every 10 % of `end`,
    /// and at the first step report (1/200 of the run's estimated steps)
    /// after each [`PROGRESS_WALL_INTERVAL`] of wall time; `along`
    /// is the projectile's speed along its flight then (m/s; the history's
    /// sample, [`along_flight`]), `perforation` when the cracks first cut a
    /// plug out (s; `None` before), which sets the speed under which the
    /// run counts as held ([`crate::residual::held_below`]).
    Advanced { speed: Real, time: Real, end: Real, along: Option<Real>, perforation: Option<Real> },
    /// A run finished; the table on disk includes it.
    Finished { shot: Shot },
    /// A run failed (the study goes on without it).
    Failed { speed: Real, message: String },
    /// A run stopped by the interrupt (its checkpoint is in its directory).
    Interrupted { paused: Paused },
    /// `--resume`: a run finished before with the same case, taken back
    /// as it is (the table on disk includes it); `note` when another build
    /// wrote it.
    Reused { shot: Shot, note: Option<String> },
    /// `--resume`: an interrupted run continues from its checkpoint at
    /// `time` (s), with the checkpoint's warnings.
    Resumed { speed: Real, time: Real, warnings: Vec<String> },
}

/// A run the interrupt stopped, as the checkpoint it wrote then left it
/// (`--resume` continues it from there).
#[derive(Clone, Debug, PartialEq)]
pub struct Paused {
    /// Impact speed, m/s.
    pub speed: Real,
    /// Simulated time of the checkpoint, s.
    pub time: Real,
    /// The projectile's motion along its flight then ([`along_flight`]);
    /// `None` where the body was not found.
    pub along: Option<AlongFlight>,
    /// When the cracks first cut a plug out, s; `None` if none was by then.
    pub perforation: Option<Real>,
    /// The run's directory (its history, snapshots and checkpoint).
    pub dir: PathBuf,
}

/// What a study found.
#[derive(Clone, Debug, Default)]
pub struct Study {
    /// Finished runs, by speed.
    pub shots: Vec<Shot>,
    /// Runs that failed: speed, error.
    pub failures: Vec<(Real, String)>,
    /// Whether the interrupt stopped the study.
    pub interrupted: bool,
    /// The runs the interrupt stopped, by speed.
    pub paused: Vec<Paused>,
    /// The speeds (m/s) the interrupt came before, in the order asked.
    pub not_started: Vec<Real>,
    /// The bisection's result, if it was asked for.
    pub limit: Option<Limit>,
    /// Recht–Ipson fit of the perforating points.
    pub fit: Option<RechtIpson>,
}

impl Study {
    /// The run at `speed` (m/s), if the study has one.
    pub fn shot_at(&self, speed: Real) -> Option<&Shot> {
        self.shots.iter().find(|s| s.speed == speed)
    }

    /// The limit as the runs read it: the search's, or in a study of
    /// speeds alone (no `--limit`) the bracket its runs give ([`bracket`];
    /// `tol` NaN: no tolerance was asked for). A side is missing where no
    /// run gives it (every run held, or none held below the perforating
    /// ones); `None` only without a finished run.
    ///
    /// [`Study::fit_unbounded`] tells whether the fit's `v_bl` has a held
    /// run below it.
    pub fn limit_reading(&self) -> Option<Limit> {
        self.limit.clone().or_else(|| {
            let (held, perforated, above) = bracket(&self.shots);
            (held.is_some() || perforated.is_some()).then_some(Limit {
                held,
                perforated,
                tol: Real::NAN,
                non_monotonic: above,
            })
        })
    }

    /// Whether no run held below the perforating ones, so that nothing but
    /// zero bounds the Recht–Ipson fit's `v_bl` from below: the fit then
    /// extrapolates the curve and its `v_bl` is not a limit.
    pub fn fit_unbounded(&self) -> bool {
        self.limit_reading().is_none_or(|l| l.held.is_none())
    }
}

/// The ballistic limit from the search.
#[derive(Clone, Debug, PartialEq)]
pub struct Limit {
    /// Highest speed held and lowest speed perforating (either may be
    /// missing when the search could not bracket the limit), m/s.
    pub held: Option<Real>,
    pub perforated: Option<Real>,
    /// The tolerance asked for, m/s.
    pub tol: Real,
    /// A held speed above the lowest perforating one (the outcome is not
    /// monotonic in the speed there).
    pub non_monotonic: Option<Real>,
}

impl Limit {
    /// `v_bl` and its half-width, m/s, once bracketed.
    pub fn estimate(&self) -> Option<(Real, Real)> {
        let (lo, hi) = (self.held?, self.perforated?);
        Some((0.5 * (lo + hi), 0.5 * (hi - lo)))
    }

    /// The limit for a table cell: `v ± h` once bracketed, else the side
    /// the runs give (`< v`: nothing held below the lowest perforating
    /// speed; `> v`: every speed held).
    pub fn cell(&self) -> String {
        match (self.estimate(), self.held, self.perforated) {
            (Some((v, h)), _, _) => format!("{v:.2} ± {h:.2}"),
            (None, _, Some(p)) => format!("< {p:.2}"),
            (None, Some(h), None) => format!("> {h:.2}"),
            (None, None, None) => "—".into(),
        }
    }
}

/// The Recht–Ipson curve `v_r = a (v_iᵖ − v_blᵖ)^(1/p)` (0 below `v_bl`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RechtIpson {
    pub a: Real,
    pub p: Real,
    pub v_bl: Real,
    /// Root-mean-square residual of the fit, m/s.
    pub rms: Real,
    /// Points fitted.
    pub points: usize,
    /// `p` held at 2 (fewer than three points).
    pub p_fixed: bool,
}

impl RechtIpson {
    /// `v_r` at impact speed `v_i`, m/s.
    pub fn at(&self, v_i: Real) -> Real {
        recht_ipson(v_i, self.a, self.p, self.v_bl)
    }
}

/// How much the residual velocity at impact speed `v_i` moves with the
/// ballistic limit on a Recht–Ipson curve of exponent `p` and limit `v_bl`:
/// the per cent `v_r` changes by when `v_bl` changes by 1 %,
/// `κ = −(v_bl / v_r) ∂v_r/∂v_bl = v_blᵖ / (v_iᵖ − v_blᵖ)` (the factor `a`
/// cancels); `None` at or below the limit, where there is no residual.
///
/// Near the limit `κ ≈ 1 / (p ε)` at `v_i = v_bl (1 + ε)`: it grows
/// without bound, so a residual measured a few per cent above a limit
/// cannot agree across resolutions better than `κ` times their limits do.
/// At 292.1 m/s on a limit of 285.5 (`p` = 2) `κ` = 21: limits 1 % apart
/// put the residuals 21 % apart. The ladder table gives it beside each
/// speed's residuals ([`ladder_table`]), so that a residual's spread is
/// read against its limit's. Test: `the_residuals_sensitivity_to_the_limit`
/// (the closed form against a finite difference of the curve, and the
/// asymptote).
pub fn limit_sensitivity(v_i: Real, p: Real, v_bl: Real) -> Option<Real> {
    let (vi, vb) = (v_i.powf(p), v_bl.powf(p));
    (v_i > v_bl && vi > vb).then(|| vb / (vi - vb))
}

fn recht_ipson(v_i: Real, a: Real, p: Real, v_bl: Real) -> Real {
    if v_i <= v_bl {
        0.0
    } else {
        a * (v_i.powf(p) - v_bl.powf(p)).powf(1.0 / p)
    }
}

/// Range of the exponent `p` searched by [`fit_recht_ipson`].
pub const P_RANGE: (Real, Real) = (1.0, 6.0);

/// Least-squares Recht–Ipson fit to perforating points `(v_i, v_r)` (`v_r >
/// 0`), with `v_bl` in `[v_min, min v_i]` (`v_min`: the highest speed the
/// plate held, or 0). For given `p` and `v_bl` the best `a` is linear least
/// squares, `a = Σ v_r g / Σ g²` with `g = (v_iᵖ − v_blᵖ)^(1/p)`; `p` (in
/// [`P_RANGE`]) and `v_bl` are found on a 41 × 41 grid refined six times
/// around its best point. With fewer than three points `p` is held at 2 (the
/// classic rigid-plug value); with fewer than two there is no fit.
pub fn fit_recht_ipson(points: &[(Real, Real)], v_min: Real) -> Option<RechtIpson> {
    let pts: Vec<(Real, Real)> = points.iter().copied().filter(|p| p.1 > 0.0 && p.0 > 0.0).collect();
    if pts.len() < 2 {
        return None;
    }
    let v_max = pts.iter().map(|p| p.0).fold(Real::INFINITY, Real::min);
    let v_min = v_min.clamp(0.0, v_max);
    let p_fixed = pts.len() < 3;
    let best_a = |p: Real, v_bl: Real| -> (Real, Real) {
        let g: Vec<Real> = pts.iter().map(|q| recht_ipson(q.0, 1.0, p, v_bl)).collect();
        let gg: Real = g.iter().map(|g| g * g).sum();
        let a = if gg > 0.0 { pts.iter().zip(&g).map(|(q, g)| q.1 * g).sum::<Real>() / gg } else { 0.0 };
        let sse = pts.iter().zip(&g).map(|(q, g)| (q.1 - a * g).powi(2)).sum();
        (a, sse)
    };
    const N: usize = 41;
    let (mut p_lo, mut p_hi) = if p_fixed { (2.0, 2.0) } else { P_RANGE };
    let (mut b_lo, mut b_hi) = (v_min, v_max);
    let mut best = (Real::INFINITY, 2.0, v_min, 0.0);
    for _ in 0..7 {
        for i in 0..N {
            let p = p_lo + (p_hi - p_lo) * i as Real / (N - 1) as Real;
            for j in 0..N {
                let v_bl = b_lo + (b_hi - b_lo) * j as Real / (N - 1) as Real;
                let (a, sse) = best_a(p, v_bl);
                if sse < best.0 {
                    best = (sse, p, v_bl, a);
                }
            }
        }
        let (dp, db) = (2.0 * (p_hi - p_lo) / (N - 1) as Real, 2.0 * (b_hi - b_lo) / (N - 1) as Real);
        if !p_fixed {
            (p_lo, p_hi) = ((best.1 - dp).max(P_RANGE.0), (best.1 + dp).min(P_RANGE.1));
        }
        (b_lo, b_hi) = ((best.2 - db).max(v_min), (best.2 + db).min(v_max));
    }
    let (sse, p, v_bl, a) = best;
    Some(RechtIpson { a, p, v_bl, rms: (sse / pts.len() as Real).sqrt(), points: pts.len(), p_fixed })
}

/// Run every speed of `speeds` not run yet, `setup.jobs` at once, adding
/// the finished runs to `study` (rewriting the table files after each).
pub fn run_speeds(
    setup: &Setup,
    speeds: &[Real],
    study: &mut Study,
    report: &mut dyn FnMut(&Study) -> Result<(), BallisticError>,
    progress: &mut dyn FnMut(Event),
) -> Result<(), BallisticError> {
    let todo: Vec<Real> = {
        let mut v: Vec<Real> = Vec::new();
        for &s in speeds {
            if !study.shots.iter().any(|x| x.speed == s) && !v.contains(&s) {
                v.push(s);
            }
        }
        v
    };
    if todo.is_empty() || study.interrupted {
        return Ok(());
    }
    let mut result = Ok(());
    let mut take = |event: Event, study: &mut Study| {
        match &event {
            Event::Finished { shot } | Event::Reused { shot, .. } => {
                study.shots.push(shot.clone());
                study.shots.sort_by(|a, b| a.speed.total_cmp(&b.speed));
                refit(study);
                if result.is_ok() {
                    result = report(study);
                }
            }
            Event::Failed { speed, message } => study.failures.push((*speed, message.clone())),
            Event::Interrupted { paused } => {
                study.interrupted = true;
                study.paused.push(paused.clone());
                study.paused.sort_by(|a, b| a.speed.total_cmp(&b.speed));
            }
            _ => {}
        }
        progress(event);
    };
    let mut queue = std::collections::VecDeque::new();
    for speed in todo {
        match setup.resume.then(|| finished_run(setup, speed)).flatten() {
            Some((shot, note)) => take(Event::Reused { shot, note }, study),
            None => queue.push_back(speed),
        }
    }
    let queue = Mutex::new(queue);
    let stop = setup.interrupt.clone().unwrap_or_else(|| Arc::new(AtomicBool::new(false)));
    let (tx, rx) = mpsc::channel::<Event>();
    std::thread::scope(|scope| {
        for _ in 0..setup.jobs.max(1) {
            let (tx, queue, stop) = (tx.clone(), &queue, stop.clone());
            scope.spawn(move || worker(setup, queue, &stop, &tx));
        }
        drop(tx);
        for event in rx {
            take(event, study);
        }
    });
    if stop.load(Ordering::SeqCst) {
        study.interrupted = true;
        study.not_started.extend(queue.into_inner().unwrap_or_else(|e| e.into_inner()));
    }
    result
}

/// One side-by-side slot: take speeds off the queue until it is empty or
/// the study is interrupted, running each on this thread's own pool.
fn worker(
    setup: &Setup,
    queue: &Mutex<std::collections::VecDeque<Real>>,
    stop: &Arc<AtomicBool>,
    tx: &mpsc::Sender<Event>,
) {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(setup.threads_per_run.max(1)).build() {
        Ok(p) => p,
        Err(e) => {
            while let Some(speed) = queue.lock().map(|mut q| q.pop_front()).unwrap_or(None) {
                let _ = tx.send(Event::Failed { speed, message: format!("cannot start worker threads: {e}") });
            }
            return;
        }
    };
    loop {
        if stop.load(Ordering::SeqCst) {
            return;
        }
        let Some(speed) = queue.lock().map(|mut q| q.pop_front()).unwrap_or(None) else {
            return;
        };
        let _ = tx.send(Event::Started { speed });
        let event = pool.install(|| run_one(setup, speed, stop, tx));
        let _ = tx.send(event);
    }
}

/// Directory of the run at `speed` inside the study's directory.
pub fn run_dir(out_dir: &Path, speed: Real) -> PathBuf {
    out_dir.join(format!("v{speed:.2}"))
}

/// The file in each run's directory that keeps its row of the table
/// ([`Shot`]) and the build that wrote it, written when the run finishes:
/// what `--resume` takes back ([`finished_run`]).
pub const SHOT_FILE: &str = "shot.toml";

/// What [`SHOT_FILE`] holds.
#[derive(serde::Serialize, serde::Deserialize)]
struct FinishedRun {
    /// [`crate::checkpoint::this_writer`] of the build that ran it.
    writer: String,
    shot: Shot,
}

/// Whether the run directory `dir` was started with `case` (the one
/// [`at_speed`] gives for its speed): its `case.resolved.toml` is that
/// case's, to the byte (every material constant, setting and the time it
/// may run to).
fn started_with(case: &Case, dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("case.resolved.toml")).is_ok_and(|text| text == case.resolved_toml())
}

/// `--resume`: the run at `speed` as it finished in the study's directory,
/// if it finished there with the case this study runs at that speed
/// (`None` otherwise: it runs again); with a note when another build wrote
/// it (its result is that build's).
pub fn finished_run(setup: &Setup, speed: Real) -> Option<(Shot, Option<String>)> {
    let dir = run_dir(&setup.out_dir, speed);
    let (case, _) = at_speed(&setup.case, setup.projectile, speed, setup.max_time);
    if !started_with(&case, &dir) {
        return None;
    }
    let run: FinishedRun = toml::from_str(&std::fs::read_to_string(dir.join(SHOT_FILE)).ok()?).ok()?;
    if run.shot.speed != speed {
        return None;
    }
    let this = crate::checkpoint::this_writer();
    let note = (run.writer != this).then(|| format!("written by {}, taken back by {this}", run.writer));
    // recorded since the cut speed was: else read from the run's history
    let cut_speed = run.shot.cut_speed.or_else(|| cut_speed(&dir, &case, setup.projectile, run.shot.perforation));
    Some((Shot { dir, cut_speed, ..run.shot }, note))
}

/// The wall time after which a run reports its progress at its next step
/// report even between two 10 % marks ([`Event::Advanced`]): a 72-row run
/// takes tens of minutes per 10 % of its end time.
pub const PROGRESS_WALL_INTERVAL: std::time::Duration = std::time::Duration::from_secs(120);

/// A projectile's motion along its flight direction, as the history
/// samples it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlongFlight {
    /// Its speed along the flight, m/s.
    pub speed: Real,
    /// The contact force on it along the flight, N: negative while the
    /// target holds it back (`NAME_f_axial` in `history.csv`).
    pub force: Real,
}

impl AlongFlight {
    /// The force holding it back, N: `-force`, and 0 (not −0) when free.
    pub fn holding_back(&self) -> Real {
        -self.force + 0.0
    }
}

/// The motion of `projectile` (named `name`) along its flight direction
/// `dir` in `sim`: a rigid body's, or a deformable one's mass-averaged
/// velocity and the contact force on it, the history's sample
/// ([`crate::output::flight_sample`]); `None` where the body is not found.
pub fn along_flight(
    sim: &crate::step::Simulation,
    projectile: Projectile,
    name: &str,
    dir: &Vec2,
) -> Option<AlongFlight> {
    let rigid = match projectile {
        Projectile::Rigid(k) => Some(k),
        Projectile::Deformable(_) => None,
    };
    let s = crate::output::flight_sample(sim, rigid, name)?;
    Some(AlongFlight { speed: s.velocity.dot(dir), force: s.contact_force.dot(dir) })
}

/// Run the case at `speed` (with `--resume`, continue it from the
/// checkpoint an interrupt left in its directory when that run had the same
/// case); the event that ends it.
fn run_one(setup: &Setup, speed: Real, stop: &Arc<AtomicBool>, tx: &mpsc::Sender<Event>) -> Event {
    let t = std::time::Instant::now();
    let (case, set) = at_speed(&setup.case, setup.projectile, speed, setup.max_time);
    let dir = run_dir(&setup.out_dir, speed);
    let mut overrides = setup.overrides.clone();
    overrides.extend(set);
    let cfg = RunConfig {
        interrupt: Some(stop.clone()),
        ..RunConfig::new(dir.clone(), true, RunInfo::current(&setup.label, &overrides))
    };
    let (direction, _) = flight(&case, setup.projectile);
    let name = setup.projectile.name(&case).to_string();
    let mut next = 0.1;
    let mut reported = std::time::Instant::now();
    // the state at the last checkpoint: where an interrupt leaves the run
    let mut saved: Option<(Real, Option<AlongFlight>, Option<Real>)> = None;
    let mut report = |p: Progress| match p {
        Progress::Step { sim, perforation } => {
            let end = case.time.end;
            let mark = sim.time >= next * end;
            if mark || reported.elapsed() >= PROGRESS_WALL_INTERVAL {
                if mark {
                    next = (sim.time / end * 10.0).floor() / 10.0 + 0.1;
                }
                reported = std::time::Instant::now();
                let along = along_flight(sim, setup.projectile, &name, &direction).map(|a| a.speed);
                let _ = tx.send(Event::Advanced { speed, time: sim.time, end, along, perforation });
            }
        }
        Progress::Checkpoint { sim, perforation, .. } => {
            saved = Some((sim.time, along_flight(sim, setup.projectile, &name, &direction), perforation));
        }
        Progress::Resumed { sim, warnings, .. } => {
            next = (sim.time / case.time.end * 10.0).floor() / 10.0 + 0.1;
            let _ = tx.send(Event::Resumed { speed, time: sim.time, warnings: warnings.to_vec() });
        }
        _ => {}
    };
    let interrupted = || !crate::checkpoint::list(&crate::checkpoint::directory(&dir)).is_empty();
    let result = if setup.resume && interrupted() && started_with(&case, &dir) {
        crate::run::resume(&cfg, &mut report)
    } else {
        // a fresh run: no earlier result may stand for it
        let _ = std::fs::remove_file(dir.join(SHOT_FILE));
        execute(&case, &cfg, &mut report)
    };
    match result {
        Ok(s) => {
            let name = setup.projectile.name(&case);
            let verdict = s.flights.iter().find(|(n, _)| n == name).map_or(Verdict::NotMoving, |(_, v)| *v);
            let touched = s.contacts.iter().find(|c| c.name == name).and_then(|c| c.first);
            let speed_bound = jet_bound(&case, setup.projectile, speed, &s.fastest, touched);
            let cut_speed = cut_speed(&dir, &case, setup.projectile, s.perforation);
            let shot = Shot {
                speed,
                verdict,
                perforation: s.perforation,
                plug_mass: s.plug.as_ref().map(|p| p.mass),
                end_time: s.time,
                fastest: s.fastest.speed,
                tip_damage: s.tip_damage.map(|d| d.median),
                tip_hardening: s.tip_hardening.map(|h| h.min),
                steps: s.steps,
                wall: t.elapsed().as_secs_f64(),
                dir,
                added_mass: s.mass_scaling.map_or(0.0, |a| a.mass),
                floor_eroded: s.floor_eroded.unwrap_or(0),
                axis_energy: s.axis_energy,
                detached: s.detached.len(),
                detached_particles: s.detached,
                fastest_particle: Some(s.fastest),
                speed_bound,
                cut_speed,
            };
            let kept = FinishedRun { writer: crate::checkpoint::this_writer(), shot: shot.clone() };
            // Not written (a full disk): `--resume` runs it again; the table has it.
            if let Ok(text) = toml::to_string(&kept) {
                let _ = std::fs::write(shot.dir.join(SHOT_FILE), text);
            }
            Event::Finished { shot }
        }
        Err(RunError::Interrupted { time, dir, .. }) => {
            let (along, perforation) = saved.filter(|(t, ..)| *t == time).map_or((None, None), |(_, a, p)| (a, p));
            Event::Interrupted { paused: Paused { speed, time, along, perforation, dir } }
        }
        Err(e) => Event::Failed { speed, message: e.to_string() },
    }
}

/// [`Shot::cut_speed`] of the run of `case` in `dir` (its `history.csv`)
/// whose cracks first cut a piece out at `perforation` (s).
fn cut_speed(dir: &Path, case: &Case, projectile: Projectile, perforation: Option<Real>) -> Option<Real> {
    let history = crate::output::read_history(dir).ok()?;
    let (direction, _) = flight(case, projectile);
    crate::residual::speed_along_at(&history, projectile.name(case), direction, perforation?)
}

/// [`Shot::speed_bound`] of a run of `case` at `speed` (m/s) whose fastest
/// particle is `fastest` and whose projectile first touched at `touched`
/// (s; [`crate::run::RunSummary::contacts`], `None`: never).
fn jet_bound(
    case: &Case,
    projectile: Projectile,
    speed: Real,
    fastest: &crate::step::FastestParticle,
    touched: Option<Real>,
) -> Option<Real> {
    let Projectile::Rigid(k) = projectile else {
        return None;
    };
    let spec = case.rigid_bodies[k].projectile.as_ref()?;
    let nose = spec.projectile()?;
    let touched = touched?;
    let depth = speed * (fastest.time - touched).max(0.0);
    // A jet leaves at the contact's edge: a particle nearer the flight's
    // line than half the contact's radius (under the nose, on the axis)
    // is held to the doubling.
    let (line, _) = flight(case, projectile);
    let off = fastest.position - Vec2::new(spec.tip[0], spec.tip[1]);
    let from_line = (off - line * off.dot(&line)).norm();
    (from_line >= 0.5 * nose.contact_radius(depth)?).then(|| nose.jet_speed_bound(speed, depth))
}

/// The bracket the finished runs give: the lowest perforating speed, the
/// highest held speed below it, and a held speed above it if any.
pub fn bracket(shots: &[Shot]) -> (Option<Real>, Option<Real>, Option<Real>) {
    let hi = shots
        .iter()
        .filter(|s| s.perforated())
        .map(|s| s.speed)
        .fold(None, |m: Option<Real>, v| Some(m.map_or(v, |m| m.min(v))));
    let below = |s: &&Shot| hi.is_none_or(|h| s.speed < h);
    let lo = shots
        .iter()
        .filter(|s| !s.perforated())
        .filter(below)
        .map(|s| s.speed)
        .fold(None, |m: Option<Real>, v| Some(m.map_or(v, |m| m.max(v))));
    let above =
        shots.iter().filter(|s| !s.perforated() && hi.is_some_and(|h| s.speed > h)).map(|s| s.speed).reduce(Real::max);
    (lo, hi, above)
}

/// Find the ballistic limit between `lo` and `hi` to `± tol` m/s (module
/// doc), using the runs already in `study` too.
pub fn find_limit(
    setup: &Setup,
    bounds: (Real, Real),
    tol: Real,
    study: &mut Study,
    report: &mut dyn FnMut(&Study) -> Result<(), BallisticError>,
    progress: &mut dyn FnMut(Event),
) -> Result<(), BallisticError> {
    let mut round = |label: String, speeds: Vec<Real>, study: &mut Study| -> Result<(), BallisticError> {
        progress(Event::Round { label, speeds: speeds.clone() });
        run_speeds(setup, &speeds, study, report, progress)
    };
    search_limit(bounds, tol, setup.jobs, study, &mut round)
}

/// Whether a limit search between `lo` and `hi` to `± tol` m/s can run:
/// `0 < lo < hi` and `tol > 0` (checked before any run starts).
pub fn check_search((lo, hi): (Real, Real), tol: Real) -> Result<(), BallisticError> {
    if lo > 0.0 && hi > lo && tol > 0.0 {
        Ok(())
    } else {
        Err(BallisticError::Settings(format!(
            "the limit search needs 0 < --lo < --hi and --tol > 0 (lo = {lo}, hi = {hi}, tol = {tol} m/s)"
        )))
    }
}

/// How a limit search runs a round: `round(label, speeds, study)` runs
/// the speeds and adds them to `study` ([`search_limit`]).
pub type RunRound<'a> = dyn FnMut(String, Vec<Real>, &mut Study) -> Result<(), BallisticError> + 'a;

/// The limit search of [`find_limit`] (module doc), with `round(label,
/// speeds, study)` running a round's speeds (`jobs` at most) and adding
/// them to `study`: the bracket check, its widening, then rounds until
/// the bracket is at most `2·tol` wide ([`next_round`] places them).
pub fn search_limit(
    (lo, hi): (Real, Real),
    tol: Real,
    jobs: usize,
    study: &mut Study,
    round: &mut RunRound<'_>,
) -> Result<(), BallisticError> {
    check_search((lo, hi), tol)?;
    round("bracket".into(), vec![lo, hi], study)?;
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..WIDEN_TRIES {
        if study.interrupted {
            break;
        }
        let outcome = |v: Real, study: &Study| study.shot_at(v).map(Shot::perforated);
        // The `jobs` runs of a round spread over the new half of the range.
        let n = jobs.max(1);
        let mut more = Vec::new();
        if outcome(lo, study) == Some(true) {
            more.extend((1..=n).map(|k| lo * (1.0 - 0.5 * k as Real / n as Real)));
            lo *= 0.5;
        }
        if outcome(hi, study) == Some(false) {
            more.extend((1..=n).map(|k| hi * (1.0 + 0.5 * k as Real / n as Real)));
            hi *= 1.5;
        }
        let more = more.into_iter().map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>();
        let (lo_now, hi_now) = (lo, hi);
        lo = more.iter().copied().filter(|&v| v <= lo_now * 1.000_001).fold(lo_now, Real::min);
        hi = more.iter().copied().filter(|&v| v >= hi_now * 0.999_999).fold(hi_now, Real::max);
        if more.is_empty() {
            break;
        }
        round("widening the bracket".into(), more, study)?;
    }
    let mut guided = false;
    loop {
        let (held, perforated, above) = bracket(&study.shots);
        study.limit = Some(Limit { held, perforated, tol, non_monotonic: above });
        let (Some(lo), Some(hi)) = (held, perforated) else {
            break;
        };
        if hi - lo <= 2.0 * tol || study.interrupted {
            break;
        }
        refit(study);
        let (speeds, guess) = next_round(study, (lo, hi), tol, jobs, guided);
        guided |= guess.is_some();
        let label = match guess {
            Some(v) => format!("bracket {lo:.2}–{hi:.2} m/s, around the Recht–Ipson fit's v_bl = {v:.2}"),
            None => format!("bracket {lo:.2}–{hi:.2} m/s"),
        };
        round(label, speeds, study)?;
        if study.shots.len() + study.failures.len() > 200 {
            break;
        }
    }
    Ok(())
}

/// Half the width, in tolerances, of the speeds a round guided by the
/// Recht–Ipson fit spreads around its `v_bl` ([`next_round`]): two runs
/// `1.8·tol` apart that straddle the limit close the bracket (`≤ 2·tol`),
/// with room for the speeds' rounding to 0.01 m/s.
pub const GUIDED_HALF_WIDTH: Real = 0.9;

/// Where a limit search's next round runs, given the finished runs in
/// `study` (with its Recht–Ipson fit, [`refit`]), the bracket `(lo, hi)`
/// they give (held at `lo`, perforated at `hi`), the tolerance and the runs
/// side by side: `jobs` speeds spread over `v_bl ± GUIDED_HALF_WIDTH·tol`
/// around the fit's `v_bl` when the fit has its exponent free (three
/// perforating runs or more), its `v_bl` lies more than that inside the
/// bracket (a fit held at the edge of its range, the highest held speed,
/// fits no curve), and the search has not run such a round yet
/// (`guided`); else `jobs` speeds evenly
/// spaced inside the bracket (two split it in three). Above the limit the
/// residual follows Recht and Ipson's curve closely (rms 0.02 m/s over
/// four runs of Case I's plate, docs/validation.md), so a fit right to
/// within the spread closes the bracket in that round; where the curve
/// has another shape the fit's `v_bl` can miss, and the one round it cost
/// still moved a side of the bracket. Returns the speeds, rounded to 0.01
/// m/s, and the fit's `v_bl` where it placed them.
pub fn next_round(
    study: &Study,
    (lo, hi): (Real, Real),
    tol: Real,
    jobs: usize,
    guided: bool,
) -> (Vec<Real>, Option<Real>) {
    let n = jobs.max(1);
    let round = |v: Real| (v * 100.0).round() / 100.0;
    let even = || (1..=n).map(|k| round(lo + (hi - lo) * k as Real / (n + 1) as Real)).collect();
    let fit = study.fit.as_ref().filter(|f| !f.p_fixed && f.v_bl.is_finite());
    let (Some(fit), false) = (fit, guided) else {
        return (even(), None);
    };
    // a fit whose v_bl sits at the edge of its range (the held speed) or
    // outside the bracket knows no better than the even split
    let (half, margin) = (GUIDED_HALF_WIDTH * tol, 0.01);
    let centre = fit.v_bl;
    if !(centre - half - margin > lo && centre + half + margin < hi) {
        return (even(), None);
    }
    let speeds: Vec<Real> = match n {
        1 => vec![round(centre)],
        _ => (0..n).map(|k| round(centre - half + 2.0 * half * k as Real / (n - 1) as Real)).collect(),
    };
    let inside = speeds.windows(2).all(|w| w[1] > w[0]) && speeds.iter().all(|&v| v > lo && v < hi);
    if inside {
        (speeds, Some(fit.v_bl))
    } else {
        (even(), None)
    }
}

/// Refit Recht–Ipson to the perforating runs of `study`, with `v_bl` above
/// the highest held speed below them.
pub fn refit(study: &mut Study) {
    let (held, _, _) = bracket(&study.shots);
    let points: Vec<(Real, Real)> = study
        .shots
        .iter()
        .filter_map(|s| match s.verdict {
            Verdict::Perforated { residual, .. } if residual > 0.0 => Some((s.speed, residual)),
            _ => None,
        })
        .collect();
    study.fit = fit_recht_ipson(&points, held.unwrap_or(0.0));
}

/// Experimental points `(v_i, v_r)` from a CSV file with header `v_i,v_r`
/// (m/s; `#` starts a comment; `v_r = 0`: the plate held).
pub fn read_experiments(path: &Path) -> Result<Vec<(Real, Real)>, BallisticError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| BallisticError::Experiments { path: path.display().to_string(), message: e.to_string() })?;
    parse_experiments(&text, &path.display().to_string())
}

/// [`read_experiments`]'s reading of the CSV `text`; `source` names it in
/// an error.
pub fn parse_experiments(text: &str, source: &str) -> Result<Vec<(Real, Real)>, BallisticError> {
    let err = |message: String| BallisticError::Experiments { path: source.to_string(), message };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    match lines.next() {
        Some((_, h)) if h.replace(' ', "") == "v_i,v_r" => {}
        other => {
            return Err(err(format!("the first line must be the header `v_i,v_r`, found {:?}", other.map(|o| o.1))))
        }
    }
    lines
        .map(|(k, l)| {
            let v: Vec<Real> = l
                .split(',')
                .map(|x| x.trim().parse::<Real>())
                .collect::<Result<_, _>>()
                .map_err(|e| err(format!("line {k}: {e}")))?;
            match v.as_slice() {
                [a, b] if *a > 0.0 && *b >= 0.0 => Ok((*a, *b)),
                _ => Err(err(format!("line {k}: expected two numbers v_i > 0, v_r >= 0"))),
            }
        })
        .collect()
}

/// Why the tests of a built-in case (`reference`, as shipped) do not belong
/// on the curve of `case` (the same case after `--set`), or `None` where
/// they do: the target's thickness, and the projectile's shape, size and
/// mass, must be the tests'. What the overrides may change is the model
/// (materials, fracture, contact, resolution, numerical parameters) and the
/// impact speed, which a study sets itself; a plate of another thickness
/// or another projectile is another experiment, whose tests these are not.
pub fn tests_differ(reference: &Case, case: &Case) -> Option<String> {
    let thickness = |c: &Case| target(c).map(|b| c.bodies[b].rectangle.y_max - c.bodies[b].rectangle.y_min);
    let (t0, t) = (thickness(reference), thickness(case));
    if let (Some(t0), Some(t)) = (t0, t) {
        if (t - t0).abs() > 1e-9 * t0 {
            return Some(format!("the target is {:.3} mm thick, the tests' {:.3} mm", t * 1e3, t0 * 1e3));
        }
    } else if t0 != t {
        return Some("the case has another target".into());
    }
    // The projectiles, their initial velocities aside (a study sets them).
    let still = |c: &Case| {
        let mut r = c.rigid_bodies.clone();
        r.iter_mut().for_each(|b| b.velocity = [0.0; 2]);
        r
    };
    if still(reference) != still(case) {
        return Some("the rigid projectile's shape, size or mass is not the tests'".into());
    }
    let flights = |c: &Case| {
        flying_bodies(c)
            .into_iter()
            .map(|b| {
                let r = &c.bodies[b].rectangle;
                (r.x_min, r.x_max, r.y_min, r.y_max)
            })
            .collect::<Vec<_>>()
    };
    if flights(reference) != flights(case) {
        return Some("the deformable projectile's size is not the tests'".into());
    }
    None
}

/// The table as (Markdown, CSV).
pub fn table(study: &Study) -> (String, String) {
    let mut md = String::from("| v_i (m/s) | v_r (m/s) | outcome | perforation (us) | v at the cut (m/s) | plug mass (kg; kg/m in plane strain) | end (us) | fastest particle (m/s) | crack-tip damage (median) | crack-tip hardening (least) | steps | wall (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    let mut csv = String::from(
        "v_i_m_s,v_r_m_s,perforated,outcome,perforation_us,cut_speed_m_s,plug_mass,end_us,fastest_particle_m_s,fastest_bound_m_s,tip_damage_median,tip_hardening_min,steps,wall_s,dir\n",
    );
    let opt = |v: Option<Real>, f: &dyn Fn(Real) -> String| v.map_or_else(String::new, f);
    for s in &study.shots {
        let vr = opt(s.residual(), &|v| format!("{v:.2}"));
        let perf = opt(s.perforation, &|t| format!("{:.2}", t * 1e6));
        let cut = opt(s.cut_speed, &|v| format!("{v:.2}"));
        let mass = opt(s.plug_mass, &|m| format!("{m:.5}"));
        let tip = opt(s.tip_damage, &|d| format!("{d:.3}"));
        let hardening = opt(s.tip_hardening, &|h| format!("{h:.3}"));
        md.push_str(&format!(
            "| {:.2} | {} | {} | {} | {} | {} | {:.1} | {:.0} | {} | {} | {} | {:.1} |\n",
            s.speed,
            if vr.is_empty() { "—".into() } else { vr.clone() },
            s.outcome(),
            if perf.is_empty() { "—".into() } else { perf.clone() },
            if cut.is_empty() { "—".into() } else { cut.clone() },
            if mass.is_empty() { "—".into() } else { mass.clone() },
            s.end_time * 1e6,
            s.fastest,
            if tip.is_empty() { "—".into() } else { tip.clone() },
            if hardening.is_empty() { "—".into() } else { hardening.clone() },
            s.steps,
            s.wall
        ));
        csv.push_str(&format!(
            "{:.2},{vr},{},{},{perf},{cut},{mass},{:.3},{:.1},{:.1},{tip},{hardening},{},{:.2},{}\n",
            s.speed,
            s.perforated(),
            s.outcome().replace(',', ";"),
            s.end_time * 1e6,
            s.fastest,
            speed_bound(s),
            s.steps,
            s.wall,
            s.dir.display()
        ));
    }
    for (v, e) in &study.failures {
        md.push_str(&format!(
            "| {v:.2} | — | failed: {} | | | | | | | | | |\n",
            e.lines().next().unwrap_or("").replace('|', "/")
        ));
    }
    (md, csv)
}

/// How the outcome is read (printed in the report).
pub const DEFINITIONS: &str = "Residual velocity v_r: the projectile's speed along its flight direction (that \
of its initial velocity) at the end of the run, once a plug has been cut out (or the projectile's nose is \
one target thickness past the target's far face) and the contact force along \
that direction (`NAME_f_axial` in each run's `history.csv`) has stayed below 0.1 % of its peak for at least \
1 us; a touch on the side wall of the hole pushes across the flight and does not count. Held: the \
projectile's speed along its flight fell to 1 % of the impact speed or below (stopped or bounced back), \
or to 5 % or below with no plug cut out (at most 0.25 % of its energy left): v_r = 0. Each run stops 20 us \
after either (`time.stop_after_release`); one still undecided at the case's \
end time goes on, up to `--max-time` (default 3 times the case's end time). A run still undecided at its end \
counts as perforating if a plug was cut out, else as held. v at the cut: the projectile's speed along its \
flight when the cracks first cut a piece out (the first history row at or after the perforation time); \
not a residual: what the projectile loses after it, to a plug still in its way or to plate it carries, is \
in v_r only. Ballistic limit: \
between the lowest perforating speed and the highest speed held below it (one held above it marks a zone of \
mixed results); each search round runs as many speeds as run side by side, evenly spaced inside the \
bracket, except one round, once three runs perforated, that spreads them over +-0.9 tol around the \
Recht-Ipson fit's v_bl. A search assumes the outcome changes once with the speed; a scan at small steps \
(`--speeds LO:HI:STEP`) shows whether it does. Recht-Ipson: v_r = a (v_i^p - v_bl^p)^(1/p), least squares \
over the perforating runs with v_bl within the limit's bracket (p = 2 with fewer than three points).";

/// The runs the interrupt stopped, where their checkpoints left them, as a
/// Markdown table ("" without any): how far each got and whether the
/// projectile was still held back, for deciding which to resume.
pub fn paused_table(paused: &[Paused]) -> String {
    if paused.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "Stopped with their checkpoints (`--resume` with the same command continues each from there):\n\n\
         | v_i (m/s) | reached (us) | projectile along its flight (m/s) | force holding it back (kN) | plug cut at (us) | directory |\n\
         |---|---|---|---|---|---|\n",
    );
    for p in paused {
        let (v, f) = p.along.map_or(("—".into(), "—".into()), |a| {
            (format!("{:.2}", a.speed), format!("{:.1}", a.holding_back() * 1e-3))
        });
        let cut = p.perforation.map_or("—".into(), |t| format!("{:.2}", t * 1e6));
        s.push_str(&format!("| {:.2} | {:.1} | {v} | {f} | {cut} | {} |\n", p.speed, p.time * 1e6, p.dir.display()));
    }
    s.push('\n');
    s
}

/// The Markdown report: `header` (case, settings, provenance), the table,
/// the limit, the fit, the definitions and the plot.
pub fn report(header: &str, study: &Study) -> String {
    let (md, _) = table(study);
    let mut s = format!("# Ballistic study\n\n{header}\n\n{md}\n");
    if study.interrupted {
        s.push_str("**Interrupted**: the table holds the runs finished before the interrupt.\n\n");
        s.push_str(&paused_table(&study.paused));
        if !study.not_started.is_empty() {
            let v: Vec<String> = study.not_started.iter().map(|v| format!("{v:.2}")).collect();
            s.push_str(&format!("Not started before the interrupt (`--resume` runs them): {} m/s.\n\n", v.join(", ")));
        }
    }
    if let Some(l) = &study.limit_reading() {
        match (l.estimate(), l.held, l.perforated) {
            (Some((v, h)), _, _) if l.tol.is_nan() => s.push_str(&format!(
                "Ballistic limit from the speeds run (no search): **v_bl = {v:.2} ± {h:.2} m/s** (held at {:.2}, \
                 perforated at {:.2} m/s).\n\n",
                l.held.unwrap_or(0.0),
                l.perforated.unwrap_or(0.0),
            )),
            (Some((v, h)), _, _) => s.push_str(&format!(
                "Ballistic limit: **v_bl = {v:.2} ± {h:.2} m/s** (held at {:.2}, perforated at {:.2} m/s; tolerance ±{} m/s{}).\n\n",
                l.held.unwrap_or(0.0),
                l.perforated.unwrap_or(0.0),
                l.tol,
                if h > l.tol { ", not reached" } else { "" }
            )),
            (None, Some(lo), None) => s.push_str(&format!("Ballistic limit not bracketed: every speed held, up to {lo:.2} m/s.\n\n")),
            (None, None, Some(hi)) => s.push_str(&format!(
                "Ballistic limit not bracketed: no speed held below {hi:.2} m/s, the lowest perforating one; the \
                 limit is below it.\n\n"
            )),
            _ => s.push_str("Ballistic limit: no finished runs.\n\n"),
        }
        let undecided = study
            .shots
            .iter()
            .find(|x| Some(x.speed) == l.held)
            .filter(|x| matches!(x.verdict, Verdict::Undecided { .. }));
        if let Some(x) = undecided {
            s.push_str(&format!(
                "Warning: the held side of the bracket ({:.2} m/s) is a run still moving along its flight at its end \
                 ({:.1} us) without a plug cut out: this is the limit of perforation within that time; raise \
                 `--max-time` for the physical limit.\n\n",
                x.speed,
                x.end_time * 1e6
            ));
        }
        if let Some(v) = l.non_monotonic {
            s.push_str(&format!(
                "Zone of mixed results: the plate held at {v:.2} m/s, above the lowest perforating speed ({:.2} m/s): \
                 the outcome is not monotone in the speed between them, and v_bl above is the lower edge of that \
                 zone (near the limit a crack tip that waits at the threshold may run or stall; docs/validation.md).\n\n",
                l.perforated.unwrap_or(0.0)
            ));
        }
    }
    let unbounded = study.fit_unbounded();
    match &study.fit {
        Some(f) => s.push_str(&format!(
            "Recht–Ipson fit over {} perforating runs: a = {:.4}, p = {:.3}{}, v_bl = {:.2} m/s (rms residual {:.2} m/s){}.\n\n",
            f.points,
            f.a,
            f.p,
            if f.p_fixed { " (held)" } else { "" },
            f.v_bl,
            f.rms,
            if unbounded {
                "; no run held below the perforating ones, so this v_bl extrapolates the curve (bounded by 0 only) \
                 and is not a ballistic limit: run slower speeds to bracket it"
            } else {
                ""
            }
        )),
        None => s.push_str("Recht–Ipson fit: fewer than two perforating runs.\n\n"),
    }
    if let Some(most) = largest(&study.shots, |x| x.added_mass) {
        s.push_str(&format!(
            "Mass scaling (`time.mass_scaling`, not in SPEC §5) added mass at rest to hold the step: at most {:.4e} kg \
             (kg/m in plane strain), in the run at {:.2} m/s; each run's summary gives its own.\n\n",
            most.added_mass, most.speed
        ));
    }
    if let Some(most) = largest(&study.shots, |x| x.floor_eroded as Real) {
        s.push_str(&format!(
            "Erosion at the step's floor (`time.erode_failed_below`, not in SPEC §5) eroded fractured points to hold \
             the step: at most {} in one run, at {:.2} m/s; each run's summary gives its own.\n\n",
            most.floor_eroded, most.speed
        ));
    }
    if let Some(most) = largest(&study.shots, |x| x.detached as Real) {
        s.push_str(&format!(
            "Detached particles (`fracture.detach_below`, not in SPEC §9): erosion or a crack split left particles \
             with little material, and they left their body's shape functions: at most {} in one run, at {:.2} m/s; \
             each run's summary and its `{SHOT_FILE}` name them.\n\n",
            most.detached, most.speed
        ));
    }
    if let Some(most) = largest(&study.shots, |x| x.axis_energy) {
        s.push_str(&format!(
            "The axis (`contact.axis`, not in SPEC §8) held particles that reached it, taking their radial kinetic \
             energy: at most {:.4e} J in one run, at {:.2} m/s; each run's summary gives its own.\n\n",
            most.axis_energy, most.speed
        ));
    }
    if let Some(note) = outran_doubling(&study.shots) {
        s.push_str(&note);
    }
    s.push_str(&format!("{DEFINITIONS}\n\n![v_r against v_i](ballistic.png)\n"));
    s
}

/// The bound a run's fastest particle is held to: the larger of the
/// free-surface doubling `2 v_i` and the nose's jet bound
/// ([`Shot::speed_bound`]), m/s.
pub fn speed_bound(shot: &Shot) -> Real {
    let doubling = FREE_SURFACE_DOUBLING * shot.speed;
    shot.speed_bound.map_or(doubling, |b| b.max(doubling))
}

/// The report's note on the runs whose fastest particle outran
/// [`FREE_SURFACE_DOUBLING`] times the impact speed (issue #19 item 5: a
/// particle faster than that was thrown by something other than the
/// impact's waves; docs/validation.md, "Fastest particle"), naming each
/// particle and saying which of them stayed within the rounded nose's jet
/// bound ([`speed_bound`]); `None` where no run's did.
pub fn outran_doubling(shots: &[Shot]) -> Option<String> {
    let line = |x: &Shot| {
        let who = x.fastest_particle.map_or_else(|| format!("{:.1} m/s", x.fastest), |f| f.describe());
        let jet = match x.speed_bound {
            Some(b) if x.fastest <= speed_bound(x) => format!(" (within the nose's jet bound, {b:.1} m/s)"),
            Some(b) => format!(" (past the nose's jet bound too, {b:.1} m/s)"),
            None => String::new(),
        };
        format!("- at {:.2} m/s ({:.2} v_i): {who}{jet}\n", x.speed, x.fastest / x.speed)
    };
    let fast: Vec<String> = shots.iter().filter(|x| x.fastest > FREE_SURFACE_DOUBLING * x.speed).map(line).collect();
    (!fast.is_empty()).then(|| {
        format!(
            "Particles faster than the free-surface doubling 2 v_i (an elastic wave at a free face doubles the \
             particle speed, so a particle past it was thrown by something else: a crack-face particle squeezed \
             out, a light particle ringing under a contact; docs/validation.md, \"Fastest particle\"; each run's \
             `history.csv` has `max_particle_speed`, and `output.trace_particles` writes the forces on a particle \
             at every step). Under a rounded, conical or ogival nose the first contact throws a jet ahead of its \
             edge, bounded by twice the edge's speed rather than 2 v_i (`Projectile::jet_speed_bound`, taken at \
             the depth the nose had when the record was set; docs/validation.md, \"Three throws traced with \
             `output.trace_particles`\"). A particle within that bound, off the flight's line by half the \
             contact's radius or more, is the jet; one nearer the line (under the nose, on the axis) is held to \
             2 v_i, and its line names no jet bound:\n\n{}\n",
            fast.concat()
        )
    })
}

/// The run with the largest positive `value` (the last of equal ones), for
/// the report's notes on what acted in which run; `None` where it acted in
/// none.
fn largest(shots: &[Shot], value: impl Fn(&Shot) -> Real) -> Option<&Shot> {
    shots.iter().filter(|x| value(x) > 0.0).max_by(|a, b| value(a).total_cmp(&value(b)))
}

/// Points drawn apart: a lone point between non-finite ones is a dot.
fn dots(points: impl Iterator<Item = (Real, Real)>) -> Vec<(Real, Real)> {
    points.flat_map(|q| [q, (Real::NAN, Real::NAN)]).collect()
}

/// Longest `--set` override a plot's title spells out; more or longer
/// ones are counted, their text being in the report's header.
const TITLE_OVERRIDE_CHARS: usize = 60;

/// A study plot's title: the case's own title, then what the `--set`
/// overrides changed, then `what`. A built-in's title names its fracture
/// model and material, which an override may have swapped, so a plot
/// without that mark would say what was not run.
pub fn study_title(case_title: &str, overrides: &[String], what: &str) -> String {
    let with = match overrides {
        [] => String::new(),
        [one] if one.chars().count() <= TITLE_OVERRIDE_CHARS => format!(", with {one}"),
        many => {
            format!(", with {} --set override{} (see the report)", many.len(), if many.len() == 1 { "" } else { "s" })
        }
    };
    format!("{case_title}{with}: {what}")
}

/// The `v_r(v_i)` plot: the runs as points, the fit as a curve, the
/// experimental points if any.
pub fn plot(study: &Study, title: &str, experiments: &[(Real, Real)]) -> LinePlot {
    let mut series = vec![Series {
        name: "simulated".into(),
        // Runs counted held (stopped, or undecided without a plug) at 0.
        points: dots(
            study.shots.iter().filter_map(|s| s.residual().or((!s.perforated()).then_some(0.0)).map(|v| (s.speed, v))),
        ),
    }];
    if let Some(f) = &study.fit {
        let v_max = study
            .shots
            .iter()
            .map(|s| s.speed)
            .fold(f.v_bl, Real::max)
            .max(experiments.iter().map(|e| e.0).fold(0.0, Real::max));
        let v_min = (0.8 * f.v_bl).min(study.shots.iter().map(|s| s.speed).fold(f.v_bl, Real::min));
        let points = (0..=200).map(|k| v_min + (v_max - v_min) * k as Real / 200.0).map(|v| (v, f.at(v))).collect();
        series.push(Series {
            name: format!("Recht-Ipson a = {:.3}, p = {:.2}, v_bl = {:.1} m/s", f.a, f.p, f.v_bl),
            points,
        });
    }
    if !experiments.is_empty() {
        series.push(Series { name: "experiments".into(), points: dots(experiments.iter().copied()) });
    }
    LinePlot {
        title: title.to_string(),
        x_label: "impact velocity v_i (m/s)".into(),
        y_label: "residual velocity v_r (m/s)".into(),
        series,
        hlines: vec![],
    }
}

/// One resolution of a study at several ([`at_rows`]).
#[derive(Clone, Debug)]
pub struct Rung {
    /// Particle rows through the first deformable body's thickness.
    pub rows: usize,
    /// Particle spacing through that thickness, m.
    pub spacing: Real,
    /// The `--set` overrides that give this resolution.
    pub overrides: Vec<String>,
    /// The projectile's edge against this resolution's columns
    /// ([`edge_phase`]).
    pub edge: Option<EdgePhase>,
    /// The lattice phase asked for with `--phases` ([`at_phase`]); `None`
    /// for the case's own columns.
    pub phase: Option<Real>,
    pub study: Study,
}

impl Rung {
    /// "24 rows", or "24 rows, phase +0.25" with `--phases` ([`rung_label`]).
    pub fn label(&self) -> String {
        rung_label(self.rows, self.phase)
    }
}

/// A rung's name: "24 rows", or "24 rows, phase +0.25" at a lattice phase.
pub fn rung_label(rows: usize, phase: Option<Real>) -> String {
    match phase {
        Some(p) => format!("{rows} rows, phase {p:+.2}"),
        None => format!("{rows} rows"),
    }
}

/// How many resolutions and lattice phases `rungs` span: "3 resolutions",
/// "1 resolution at 4 lattice phases".
pub fn ladder_extent(rungs: &[Rung]) -> String {
    let resolutions = levels(rungs, &[]).len();
    let res = format!("{resolutions} resolution{}", if resolutions == 1 { "" } else { "s" });
    match rungs.iter().filter(|r| r.phase.is_some()).count() {
        0 => res,
        n => format!("{res} at {} lattice phases", n / resolutions.max(1)),
    }
}

/// What a ladder compares at one resolution ([`levels`]): the limit and,
/// at each speed, the residual and the speed at the cut as (value,
/// half-width).
#[derive(Clone, Debug)]
struct Level<'a> {
    /// The rungs at this resolution (several with `--phases`).
    members: Vec<&'a Rung>,
    /// The bracketed limit: a rung's own, or over the phases their
    /// envelope (the lowest held bound to the highest perforating one).
    limit: Option<(Real, Real)>,
    /// Per [`column`]: the residual where every member perforated, then
    /// the projectile's speed at the cut ([`Shot::cut_speed`]) where every
    /// member cut a piece out; a rung's own (half-width 0), or over the
    /// phases their mean with half their range.
    values: Vec<Option<(Real, Real)>>,
}

/// The speed-dependent columns of the ladder table, in order: `v_r` at
/// each of the `n` speeds, then the speed at the cut at each. Column `k`
/// is (speed index, whether it is the cut's).
fn column(k: usize, n: usize) -> (usize, bool) {
    (k % n, k >= n)
}

impl Level<'_> {
    fn rows(&self) -> usize {
        self.members[0].rows
    }

    fn spacing(&self) -> Real {
        self.members[0].spacing
    }
}

/// The rungs grouped by resolution, in the order given ([`Level`]).
/// A resolution's limit counts only if every member's is bracketed, a
/// residual only if every member perforated at that speed.
fn levels<'a>(rungs: &'a [Rung], speeds: &[Real]) -> Vec<Level<'a>> {
    let mut rows: Vec<usize> = Vec::new();
    for r in rungs {
        if !rows.contains(&r.rows) {
            rows.push(r.rows);
        }
    }
    let envelope = |pairs: Vec<(Real, Real)>| {
        let lo = pairs.iter().map(|&(v, h)| v - h).fold(Real::INFINITY, Real::min);
        let hi = pairs.iter().map(|&(v, h)| v + h).fold(Real::NEG_INFINITY, Real::max);
        (0.5 * (lo + hi), 0.5 * (hi - lo))
    };
    rows.into_iter()
        .map(|n| {
            let members: Vec<&Rung> = rungs.iter().filter(|r| r.rows == n).collect();
            let limits: Option<Vec<(Real, Real)>> =
                members.iter().map(|r| r.study.limit_reading().and_then(|l| l.estimate())).collect();
            let values = (0..2 * speeds.len())
                .map(|k| {
                    let (i, cut) = column(k, speeds.len());
                    let value = |s: &Shot| if cut { s.cut_speed } else { s.residual().filter(|&x| x > 0.0) };
                    let at: Option<Vec<Real>> =
                        members.iter().map(|r| r.study.shot_at(speeds[i]).and_then(value)).collect();
                    at.map(|x| {
                        let mean = x.iter().sum::<Real>() / x.len() as Real;
                        (mean, envelope(x.iter().map(|&y| (y, 0.0)).collect()).1)
                    })
                })
                .collect();
            Level { members, limit: limits.map(envelope), values }
        })
        .collect()
}

/// The resolutions side by side, as (Markdown, CSV): per rung the ballistic
/// limit, the Recht–Ipson fit, the residual velocity at each of `speeds`,
/// then the projectile's speed at the cut at each ([`Shot::cut_speed`],
/// compared like the residuals; it has no sensitivity row) and the
/// projectile's edge against its columns ([`edge_phase`]), then
/// the spread of each across the rungs (with, for values that are
/// brackets, the least and most it can be within them: [`spread_within`]),
/// each residual's sensitivity to its rung's limit (Markdown only: the
/// least and largest over the rungs of [`limit_sensitivity`], from each
/// bracket's middle and fitted exponent, and the rungs whose limit is at or
/// above the speed), the last refinement's [`step`] (from the
/// second-finest rung to the finest: what one more refinement moved, the
/// usual test of a converged result)
/// and, with three rungs or more, what the three finest say of the answer
/// at zero spacing ([`richardson`]: the observed order, the extrapolated
/// value and the finest rung's grid convergence index, or why there is
/// none); the limit's spread, step and extrapolation count only bracketed
/// limits (with their brackets), a residual's only if every rung
/// perforated at that speed (a held run is 0 m/s, which no spread
/// describes: the Markdown says "held"). With several lattice phases at a
/// resolution (`--phases`, [`at_phase`]) each rung is a line of its own
/// and a line per resolution gives their envelope (the limit
/// from the lowest held bound to the highest perforating one, a residual's
/// mean ± half its range), which the spread, the step and Richardson then
/// compare: the answer whatever the phase.
pub fn ladder_table(rungs: &[Rung], speeds: &[Real]) -> (String, String) {
    let mut md = String::from("| rows | spacing (mm) | v_bl (m/s) | Recht–Ipson a, p, v_bl |");
    let mut csv = String::from("rows,spacing_mm,v_bl_m_s,v_bl_half_width_m_s,a,p,fit_v_bl_m_s");
    for v in speeds {
        md.push_str(&format!(" v_r at {v:.1} m/s |"));
        csv.push_str(&format!(",v_r_at_{v:.1}"));
    }
    for v in speeds {
        md.push_str(&format!(" v at the cut at {v:.1} m/s |"));
        csv.push_str(&format!(",v_cut_at_{v:.1}"));
    }
    md.push_str(" runs | wall (s) | edge − column (spacings) |\n|---|---|---|---|");
    md.push_str(&"---|".repeat(2 * speeds.len() + 3));
    md.push('\n');
    csv.push_str(",runs,wall_s,edge_offset\n");
    for r in rungs {
        let st = &r.study;
        let reading = st.limit_reading();
        let limit = reading.as_ref().and_then(Limit::estimate);
        // folded from +0: `sum` of no runs is −0.0, which printed "-0"
        let wall: Real = st.shots.iter().map(|s| s.wall).fold(0.0, |t, w| t + w);
        md.push_str(&format!(
            "| {} | {:.3} | {} | {} |",
            r.rows,
            r.spacing * 1e3,
            reading.as_ref().map_or("—".into(), Limit::cell),
            st.fit.map_or("—".into(), |f| format!(
                "{:.3}, {:.2}, {:.2}{}",
                f.a,
                f.p,
                f.v_bl,
                if st.fit_unbounded() { " (extrapolated: no run held below)" } else { "" }
            )),
        ));
        csv.push_str(&format!(
            "{},{:.6},{},{},{},{},{}",
            r.rows,
            r.spacing * 1e3,
            limit.map_or(String::new(), |l| format!("{:.3}", l.0)),
            limit.map_or(String::new(), |l| format!("{:.3}", l.1)),
            st.fit.map_or(String::new(), |f| format!("{:.5}", f.a)),
            st.fit.map_or(String::new(), |f| format!("{:.4}", f.p)),
            st.fit.map_or(String::new(), |f| format!("{:.3}", f.v_bl)),
        ));
        for &v in speeds {
            let vr = st.shot_at(v).and_then(Shot::residual);
            md.push_str(&match vr {
                Some(x) if x > 0.0 => format!(" {x:.2} |"),
                Some(_) => " held |".into(),
                None => " — |".into(),
            });
            csv.push_str(&format!(",{}", vr.map_or(String::new(), |x| format!("{x:.3}"))));
        }
        for &v in speeds {
            let cut = st.shot_at(v).and_then(|s| s.cut_speed);
            md.push_str(&cut.map_or(" — |".into(), |x| format!(" {x:.2} |")));
            csv.push_str(&format!(",{}", cut.map_or(String::new(), |x| format!("{x:.3}"))));
        }
        md.push_str(&format!(
            " {} | {wall:.0} | {} |\n",
            st.shots.len(),
            r.edge.map_or("—".into(), |e| e.offset_text())
        ));
        let edge = r.edge.map_or(String::new(), |e| format!("{:.4}", e.offset_rounding_to(4)));
        csv.push_str(&format!(",{},{wall:.2},{edge}\n", st.shots.len()));
    }
    let levels = levels(rungs, speeds);
    // With --phases: each resolution's envelope over its phases, the value
    // that the spread, the step and Richardson compare.
    for l in levels.iter().filter(|l| l.members.len() > 1) {
        md.push_str(&format!(
            "| {} rows, {} phases | {:.3} | {} | |",
            l.rows(),
            l.members.len(),
            l.spacing() * 1e3,
            l.limit.map_or("—".into(), |(v, h)| format!("{v:.2} ± {h:.2}"))
        ));
        for x in &l.values {
            md.push_str(&x.map_or(" — |".into(), |(v, h)| format!(" {v:.2} ± {h:.2} |")));
        }
        let runs: usize = l.members.iter().map(|r| r.study.shots.len()).sum();
        let wall: Real = l.members.iter().flat_map(|r| &r.study.shots).map(|s| s.wall).fold(0.0, |t, w| t + w);
        md.push_str(&format!(" {runs} | {wall:.0} | all |\n"));
    }
    let pct = |x: Real| format!("{:.1} %", 100.0 * x);
    // The spread of the values, and within their brackets where they have
    // some (as the step's cell gives it).
    let spread_cell = |f: &dyn Fn(&Level) -> Option<(Real, Real)>| -> String {
        let values: Option<Vec<(Real, Real)>> = levels.iter().map(f).collect();
        match values.as_deref().map(|v| (v, spread_within(v))) {
            Some((v, Some((mid, least, most)))) if v.iter().any(|x| x.1 > 0.0) => {
                format!("{} ({}…{})", pct(mid), pct(least), pct(most))
            }
            Some((_, Some((mid, ..)))) => pct(mid),
            _ => "—".into(),
        }
    };
    md.push_str(&format!("| spread | | {} | |", spread_cell(&|l| l.limit)));
    for k in 0..2 * speeds.len() {
        md.push_str(&format!(" {} |", spread_cell(&|l| l.values[k])));
    }
    md.push_str(" | | |\n");
    // How far each residual can agree, given the limits (`limit_sensitivity`):
    // per bracketed rung, from its bracket's middle and its fit's exponent
    // (2 without a fitted one, the fit's own default).
    let bracketed: Vec<(String, Real, Real)> = rungs
        .iter()
        .filter_map(|r| {
            let (v_bl, _) = r.study.limit_reading()?.estimate()?;
            Some((r.label(), v_bl, r.study.fit.filter(|f| !f.p_fixed).map_or(2.0, |f| f.p)))
        })
        .collect();
    md.push_str("| v_r's sensitivity to the limit (% per %) | | | |");
    for &v in speeds {
        let mut kappas = Vec::new();
        let mut under = Vec::new();
        for (label, v_bl, p) in &bracketed {
            match limit_sensitivity(v, *p, *v_bl) {
                Some(k) => kappas.push(k),
                None => under.push(label.as_str()),
            }
        }
        let lo = kappas.iter().copied().fold(Real::INFINITY, Real::min);
        let hi = kappas.iter().copied().fold(Real::NEG_INFINITY, Real::max);
        let (lo, hi) = (format!("{lo:.1}"), format!("{hi:.1}"));
        let mut cell = match kappas.len() {
            0 => String::new(),
            _ if lo == hi => lo,
            _ => format!("{lo}–{hi}"),
        };
        if !under.is_empty() {
            let sep = if cell.is_empty() { "" } else { "; " };
            cell.push_str(&format!("{sep}at or under the limit at {}", under.join(", ")));
        }
        md.push_str(&format!(" {} |", if cell.is_empty() { "—".into() } else { cell }));
    }
    // not a residual: no sensitivity to give
    md.push_str(&" — |".repeat(speeds.len()));
    md.push_str(" | | |\n");
    // The two finest resolutions, by rows (the order given need not be).
    let mut by_rows: Vec<&Level> = levels.iter().collect();
    by_rows.sort_by_key(|l| l.rows());
    let signed = |x: Real| format!("{:+.1} %", 100.0 * x);
    let step_cell = |c: Option<(Real, Real)>, f: Option<(Real, Real)>| match (c, f) {
        (Some(c), Some(f)) if c.1 == 0.0 && f.1 == 0.0 => signed(step(c, f).0),
        (Some(c), Some(f)) => {
            let (mid, least, most) = step(c, f);
            format!("{} ({}…{})", signed(mid), signed(least), signed(most))
        }
        _ => "—".into(),
    };
    if let [.., coarse, fine] = by_rows[..] {
        md.push_str(&format!(
            "| step {} → {} rows | | {} | |",
            coarse.rows(),
            fine.rows(),
            step_cell(coarse.limit, fine.limit)
        ));
        for k in 0..2 * speeds.len() {
            md.push_str(&format!(" {} |", step_cell(coarse.values[k], fine.values[k])));
        }
        md.push_str(" | | |\n");
    }
    if let [.., third, second, first] = by_rows[..] {
        let three = [third, second, first];
        let ladder = |value: &dyn Fn(&Level) -> Option<(Real, Real)>| -> Option<Vec<convergence::Rung>> {
            three
                .iter()
                .map(|l| {
                    value(l).map(|(value, half_width)| convergence::Rung { spacing: l.spacing(), value, half_width })
                })
                .collect()
        };
        md.push_str(&format!("| Richardson, {} / {} / {} rows | | ", third.rows(), second.rows(), first.rows()));
        md.push_str(&convergence::describe(ladder(&|l| l.limit).and_then(|l| richardson(&l))));
        md.push_str(" | |");
        for k in 0..2 * speeds.len() {
            let rungs = ladder(&|l| l.values[k]);
            md.push_str(&format!(" {} |", convergence::describe(rungs.and_then(|l| richardson(&l)))));
        }
        md.push_str(" | | |\n");
    }
    (md, csv)
}

/// The resolutions' curves on one plot: each rung's runs as points (held
/// runs at 0) and its Recht–Ipson curve, the experimental points if any.
pub fn ladder_plot(rungs: &[Rung], title: &str, experiments: &[(Real, Real)]) -> LinePlot {
    let mut p = LinePlot {
        title: title.to_string(),
        x_label: "impact velocity v_i (m/s)".into(),
        y_label: "residual velocity v_r (m/s)".into(),
        ..LinePlot::default()
    };
    // One series (one colour) per rung: its points, then its curve after a
    // break.
    for r in rungs {
        let one = plot(&r.study, "", &[]);
        let mut points = Vec::new();
        for s in &one.series {
            points.extend(s.points.iter().copied().chain([(Real::NAN, Real::NAN)]));
        }
        let name = match &r.study.fit {
            Some(f) => format!("{}: Recht-Ipson a = {:.3}, p = {:.2}, v_bl = {:.1} m/s", r.label(), f.a, f.p, f.v_bl),
            None => r.label(),
        };
        p.series.push(Series { name, points });
    }
    if !experiments.is_empty() {
        p.series.push(Series { name: "experiments".into(), points: dots(experiments.iter().copied()) });
    }
    p
}

/// Write `convergence.md`, `convergence.csv` and `convergence.png` into
/// `dir`: the resolutions side by side ([`ladder_table`], [`ladder_plot`]).
pub fn write_ladder_files(
    dir: &Path,
    header: &str,
    title: &str,
    rungs: &[Rung],
    speeds: &[Real],
    experiments: &[(Real, Real)],
) -> Result<Vec<PathBuf>, BallisticError> {
    let (md, csv) = ladder_table(rungs, speeds);
    let mut text = format!("# Ballistic study at {}\n\n{header}\n\n{md}\n", ladder_extent(rungs));
    text.push_str(
        "Spread: (max − min) / mean over the resolutions (for bracketed values, with the least and most it can \
         be within the brackets, relative to the same mean). Sensitivity to the limit: by how many per cent a \
         residual moves when its resolution's limit moves by 1 %, v_bl^p / (v_i^p − v_bl^p) on the Recht–Ipson \
         curve (the bracket's middle; p fitted, else 2), least and largest over the resolutions: residuals at a \
         speed where it is large cannot agree better than that many times the limits' spread. v at the cut: the \
         projectile's speed when the cracks first cut a piece out, compared like the residuals; where it agrees \
         across the resolutions and v_r does not, what parts them comes after the cut. Step: the change \
         from the second-finest resolution to the finest, relative to the former (for a limit, with the least \
         and most it can be within the two brackets). Richardson (three resolutions or more): from the three finest, the observed order of \
         convergence p, the value extrapolated to zero spacing and the grid convergence index of the finest \
         (1.25 |finest − next| / (r^p − 1) relative to the finest, r the spacing ratio; Celik et al. 2008), given \
         only when the two steps have one sign and the last is the smaller (else it says why not); a limit's \
         step within its brackets gives none. Edge − column: where the projectile's edge lies against the \
         target's nearest particle column at that resolution, in spacings (the lattice's phase at the rim; near a \
         limit the rim crack's first steps can depend on it, and a grid's `column_at` holds it at 0). Each \
         resolution's own table, report and plot are in `rows-N/` (its `--set` overrides in its header). With \
         several lattice phases (`--phases K`, each in `phase-±F/`: the target's columns shifted so that the \
         edge lies F of a spacing from one), a line per resolution gives the phases' envelope: the limit from the \
         lowest held bound to the highest perforating one, a residual's mean ± half its range; the spread, step \
         and Richardson compare those.\n\n",
    );
    for r in rungs {
        let set = if r.overrides.is_empty() { "the case as given".to_string() } else { r.overrides.join(" ") };
        text.push_str(&format!("- {}: {set}\n", r.label()));
    }
    text.push_str("\n![v_r against v_i at each resolution](convergence.png)\n");
    write_report(dir, "convergence", csv, text, &ladder_plot(rungs, title, experiments))
}

/// Write `STEM.csv`, `STEM.md` and `STEM.png` (the plot) into `dir`;
/// returns their paths.
fn write_report(
    dir: &Path,
    stem: &str,
    csv: String,
    md: String,
    plot: &LinePlot,
) -> Result<Vec<PathBuf>, BallisticError> {
    let mut files = Vec::new();
    for (ext, text) in [("csv", csv), ("md", md)] {
        let path = dir.join(format!("{stem}.{ext}"));
        std::fs::write(&path, text).map_err(|source| IoError::Write { path: path.clone(), source })?;
        files.push(path);
    }
    let png = dir.join(format!("{stem}.png"));
    crate::io::save_line_plot(&png, plot)?;
    files.push(png);
    Ok(files)
}

/// Write `ballistic.csv`, `ballistic.md` and `ballistic.png` into `dir`.
pub fn write_files(
    dir: &Path,
    header: &str,
    title: &str,
    study: &Study,
    experiments: &[(Real, Real)],
) -> Result<Vec<PathBuf>, BallisticError> {
    let (_, csv) = table(study);
    write_report(dir, "ballistic", csv, report(header, study), &plot(study, title, experiments))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run's jet bound: a rounded nose's, at the depth from the history's
    /// last row before the first contact to the record, for a particle at
    /// least half the contact's radius off the axis; none nearer the axis,
    /// none for a flat nose, and none for a run whose projectile never
    /// touched.
    #[test]
    fn a_rounded_nose_bounds_its_jet_from_the_first_contact() {
        let load = |name: &str| Case::from_str_with(crate::cases::builtin_case(name).unwrap(), name, &[]).unwrap();
        let (hemi, blunt) = (load("borvik-2002-12mm-hemispherical"), load("borvik-2002-12mm-blunt"));
        let dir = crate::io::test_util::scratch_dir("jet-bound");
        let write = |contacts: [Real; 3]| {
            let mut w =
                crate::io::HistoryWriter::create(&dir.join("history.csv"), &["time", "projectile_contacts"]).unwrap();
            for (t, c) in [0.0, 1e-7, 2e-7].into_iter().zip(contacts) {
                w.write_row(&[t, c]).unwrap();
            }
        };
        let touched = || {
            let history = crate::output::read_history(&dir).unwrap();
            crate::output::contact_times(&history, &["projectile".to_string()])[0].first
        };
        write([0.0, 0.0, 3.0]);
        assert_eq!(touched(), Some(1e-7), "the last row before the first contact");
        let nose = hemi.rigid_bodies[0].projectile.as_ref().unwrap().projectile().unwrap();
        // 1.1 us: 0.29 mm deep, touching out to 2.4 mm.
        let depth = 292.1 * 1.0e-6;
        let edge = nose.contact_radius(depth).unwrap();
        let at = |r: Real| crate::step::FastestParticle {
            time: 1.1e-6,
            position: Vec2::new(r, 0.0118),
            ..crate::step::FastestParticle::default()
        };
        let bound = jet_bound(&hemi, Projectile::Rigid(0), 292.1, &at(edge), touched()).unwrap();
        assert_eq!(bound, nose.jet_speed_bound(292.1, depth));
        assert!(bound > 2.0 * 292.1, "a millimetre's tenth deep, the edge outruns the nose: {bound}");
        assert_eq!(jet_bound(&hemi, Projectile::Rigid(0), 292.1, &at(0.6 * edge), touched()), Some(bound));
        assert_eq!(jet_bound(&hemi, Projectile::Rigid(0), 292.1, &at(0.4 * edge), touched()), None, "under the nose");
        assert_eq!(jet_bound(&hemi, Projectile::Rigid(0), 292.1, &at(0.0), touched()), None, "on the axis");
        assert_eq!(jet_bound(&blunt, Projectile::Rigid(0), 184.5, &at(edge), touched()), None);
        write([3.0, 3.0, 3.0]);
        assert_eq!(touched(), Some(0.0), "in contact from the first row");
        write([0.0, 0.0, 0.0]);
        assert_eq!(touched(), None);
        assert_eq!(jet_bound(&hemi, Projectile::Rigid(0), 292.1, &at(edge), touched()), None);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_study_title_marks_the_overrides() {
        let what = "residual against impact velocity";
        assert_eq!(study_title("Case I", &[], what), "Case I: residual against impact velocity");
        let one = vec!["time.end=2e-4".to_string()];
        assert_eq!(study_title("Case I", &one, what), "Case I, with time.end=2e-4: residual against impact velocity");
        let long = vec![format!("bodies.plate.material={}", "x".repeat(60))];
        assert!(study_title("Case I", &long, what).contains(", with 1 --set override (see the report)"));
        let two = vec!["a=1".to_string(), "b=2".to_string()];
        assert!(study_title("Case I", &two, what).starts_with("Case I, with 2 --set overrides (see the report): "));
    }

    /// `--speeds` items: a speed, an inclusive range, and each malformed
    /// item refused naming it.
    #[test]
    fn speeds_are_read_as_values_or_ranges() {
        assert_eq!(parse_speeds("173.7"), Ok(vec![173.7]));
        assert_eq!(parse_speeds("116:120:1"), Ok(vec![116.0, 117.0, 118.0, 119.0, 120.0]));
        // The end is kept when the steps reach it only to rounding, and the
        // speeds are the decimal ones (0.1 is not exact in binary).
        let v = parse_speeds("110:111:0.1").unwrap();
        assert_eq!(v.len(), 11);
        assert_eq!((v[3], v[10]), (110.3, 111.0));
        // A step that passes the end stops below it.
        assert_eq!(parse_speeds("100:110:4"), Ok(vec![100.0, 104.0, 108.0]));
        assert_eq!(parse_speeds("120:120:5"), Ok(vec![120.0]));
        for (bad, says) in [
            ("fast", "'fast' in 'fast' is not a number"),
            ("120:110:1", "needs LO <= HI"),
            ("110:120:0", "STEP > 0"),
            ("110:120", "neither a speed nor a range"),
            ("1:100000:1", "more than 1000 speeds"),
            ("-5", "must be positive"),
            ("0:10:5", "must be positive (got 0 in '0:10:5')"),
            ("inf", "not a number"),
        ] {
            let e = parse_speeds(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    fn synthetic(a: Real, p: Real, v_bl: Real, speeds: &[Real]) -> Vec<(Real, Real)> {
        speeds.iter().map(|&v| (v, recht_ipson(v, a, p, v_bl))).collect()
    }

    #[test]
    fn the_definitions_state_the_default_max_time() {
        assert!(DEFINITIONS.contains(&format!("default {DECIDE_FACTOR} times the case's end time")), "{DEFINITIONS}");
    }

    #[test]
    fn the_fit_recovers_known_parameters() {
        let speeds = [190.0, 200.0, 220.0, 250.0, 280.0, 320.0];
        let f = fit_recht_ipson(&synthetic(0.8, 2.5, 180.0, &speeds), 170.0).unwrap();
        assert!((f.a - 0.8).abs() < 2e-3 && (f.p - 2.5).abs() < 2e-2 && (f.v_bl - 180.0).abs() < 0.2, "{f:?}");
        assert!(f.rms < 0.05 && !f.p_fixed && f.points == 6, "{f:?}");
        // The classic rigid-plug curve, a = 1, p = 2.
        let f = fit_recht_ipson(&synthetic(1.0, 2.0, 150.0, &speeds), 0.0).unwrap();
        assert!((f.a - 1.0).abs() < 1e-3 && (f.p - 2.0).abs() < 1e-2 && (f.v_bl - 150.0).abs() < 0.2, "{f:?}");
        // Noisy points: still close.
        let noisy: Vec<(Real, Real)> = synthetic(0.9, 2.0, 160.0, &speeds)
            .iter()
            .enumerate()
            .map(|(k, p)| (p.0, p.1 + [0.5, -0.5][k % 2]))
            .collect();
        let f = fit_recht_ipson(&noisy, 0.0).unwrap();
        assert!((f.v_bl - 160.0).abs() < 10.0 && (f.a - 0.9).abs() < 0.05 && f.rms < 1.0, "{f:?}");
    }

    #[test]
    fn the_fit_keeps_v_bl_in_the_bracket_and_needs_points() {
        // Held at 185 m/s: v_bl may not be below it, even if the points say 180.
        let pts = synthetic(0.8, 2.5, 180.0, &[190.0, 220.0, 260.0, 300.0]);
        let f = fit_recht_ipson(&pts, 185.0).unwrap();
        assert!(f.v_bl >= 185.0 && f.v_bl <= 190.0, "{f:?}");
        // Two points: p held at 2, the curve through both.
        let f = fit_recht_ipson(&synthetic(0.7, 2.0, 100.0, &[150.0, 250.0]), 0.0).unwrap();
        assert!(f.p_fixed && f.p == 2.0 && (f.v_bl - 100.0).abs() < 0.1 && f.rms < 1e-2, "{f:?}");
        assert_eq!(fit_recht_ipson(&[(200.0, 100.0), (150.0, 0.0)], 0.0), None);
    }

    fn shot(speed: Real, verdict: Verdict) -> Shot {
        Shot {
            speed,
            verdict,
            perforation: None,
            plug_mass: None,
            end_time: 0.0,
            fastest: 0.0,
            tip_damage: None,
            tip_hardening: None,
            steps: 0,
            wall: 0.0,
            added_mass: 0.0,
            floor_eroded: 0,
            axis_energy: 0.0,
            detached: 0,
            detached_particles: vec![],
            fastest_particle: None,
            speed_bound: None,
            cut_speed: None,
            dir: PathBuf::new(),
        }
    }

    /// The report names each run whose fastest particle outran `2 v_i`,
    /// and only those; a run's [`SHOT_FILE`] keeps its fastest particle
    /// across `--resume`, and one written before it was recorded still reads.
    #[test]
    fn runs_past_the_free_surface_doubling_are_named() {
        let held = Verdict::Held { since: 0.0 };
        let thrown = crate::step::FastestParticle {
            speed: 441.2,
            particle: 40608,
            time: 15.85e-6,
            position: Vec2::new(10.01e-3, 10.25e-3),
            reference: Vec2::new(9.7e-3, 12e-3),
            mass: 9.326e-6,
            crack_face: true,
            live_share: Some(0.011),
        };
        let mut fast = shot(180.0, held);
        (fast.fastest, fast.fastest_particle) = (441.2, Some(thrown));
        let mut slow = shot(190.0, Verdict::Perforated { residual: 74.0, since: 0.0 });
        slow.fastest = 313.0;
        assert_eq!(outran_doubling(&[slow.clone()]), None);
        let note = outran_doubling(&[fast.clone(), slow.clone()]).unwrap();
        assert!(
            note.contains("- at 180.00 m/s (2.45 v_i): 441.2 m/s, particle 40608 (a crack-face particle"),
            "{note}"
        );
        assert!(note.contains("plane strain; 1.1 % of its material left) at (10.01, 10.25) mm"), "{note}");
        let ghost = crate::step::FastestParticle { live_share: Some(0.0), ..thrown };
        assert!(ghost.describe().contains("plane strain; none of its material left) at"), "{}", ghost.describe());
        for whole in [Some(1.0), None] {
            let whole = crate::step::FastestParticle { live_share: whole, ..thrown };
            assert!(whole.describe().contains("plane strain) at"), "{}", whole.describe());
        }
        assert!(!note.contains("190.00"), "{note}");
        // a run taken back from a file without the particle: its speed only
        let mut old = fast.clone();
        old.fastest_particle = None;
        assert!(outran_doubling(&[old]).unwrap().contains("- at 180.00 m/s (2.45 v_i): 441.2 m/s\n"));
        let study = Study { shots: vec![fast.clone(), slow], ..Study::default() };
        assert!(report("header", &study).contains(&note));
        // the shot file keeps it, and an older one without it reads
        let text = toml::to_string(&FinishedRun { writer: "w".into(), shot: fast.clone() }).unwrap();
        let back: FinishedRun = toml::from_str(&text).unwrap();
        assert_eq!(back.shot, fast);
        let older = text.lines().take_while(|l| !l.contains("fastest_particle")).collect::<Vec<_>>().join("\n");
        let back: FinishedRun = toml::from_str(&older).unwrap();
        assert_eq!(back.shot.fastest_particle, None);
        assert_eq!(back.shot.fastest, 441.2);
        // Under a rounded nose: a throw within the jet bound is named as
        // the jet, one past it as past it too.
        let mut jet = fast.clone();
        jet.speed_bound = Some(500.0);
        assert_eq!(speed_bound(&jet), 500.0);
        assert!(outran_doubling(&[jet.clone()]).unwrap().contains("(2.45 v_i): 441.2 m/s, particle 40608"));
        assert!(outran_doubling(&[jet.clone()]).unwrap().contains(" (within the nose's jet bound, 500.0 m/s)\n"));
        jet.speed_bound = Some(400.0);
        assert!(outran_doubling(&[jet.clone()]).unwrap().contains(" (past the nose's jet bound too, 400.0 m/s)\n"));
        jet.speed_bound = Some(100.0);
        assert_eq!(speed_bound(&jet), 360.0, "never under the doubling");
        let text = toml::to_string(&FinishedRun { writer: "w".into(), shot: jet.clone() }).unwrap();
        assert_eq!(toml::from_str::<FinishedRun>(&text).unwrap().shot, jet);
    }

    /// Runs a limit search against `truth` (the plate holds below
    /// `v_bl`, else leaves `residual(v)`), two runs a round; the rounds
    /// after the bracket check, and the study.
    fn search_against(
        v_bl: Real,
        residual: impl Fn(Real) -> Real,
        (lo, hi): (Real, Real),
        tol: Real,
    ) -> (usize, Study) {
        let mut study = Study::default();
        let mut rounds = 0;
        let mut round = |_: String, speeds: Vec<Real>, study: &mut Study| {
            rounds += 1;
            for v in speeds {
                let verdict = if v < v_bl {
                    Verdict::Held { since: 0.0 }
                } else {
                    Verdict::Perforated { residual: residual(v), since: 0.0 }
                };
                study.shots.push(shot(v, verdict));
            }
            study.shots.sort_by(|a, b| a.speed.total_cmp(&b.speed));
            Ok(())
        };
        search_limit((lo, hi), tol, 2, &mut study, &mut round).unwrap();
        (rounds - 1, study)
    }

    /// The round after three perforating runs spreads its speeds over
    /// `v_bl ± 0.9 tol` of the Recht–Ipson fit; once per search, not with
    /// `p` held at 2, and otherwise the bracket split evenly.
    #[test]
    fn a_round_spreads_around_the_fit_once_three_runs_perforated() {
        // Case I's plate at 24 rows (docs/validation.md): held at 149,
        // perforated on a curve with v_bl = 181.2, p = 3.84
        let curve = |v| recht_ipson(v, 0.80, 3.84, 181.2);
        let mut study = Study { shots: vec![shot(149.0, Verdict::Held { since: 0.0 })], ..Study::default() };
        for v in [198.67, 248.33, 298.0] {
            study.shots.push(shot(v, Verdict::Perforated { residual: curve(v), since: 0.0 }));
        }
        refit(&mut study);
        let (speeds, guess) = next_round(&study, (149.0, 198.67), 1.0, 2, false);
        let guess = guess.expect("a guided round");
        assert!((guess - 181.2).abs() < 0.3, "{guess}");
        assert_eq!(speeds.len(), 2);
        assert!(speeds[0] < 181.2 && speeds[1] > 181.2 && speeds[1] - speeds[0] <= 2.0, "{speeds:?}");
        // once per search: then the bracket split in three
        assert_eq!(next_round(&study, (149.0, 198.67), 1.0, 2, true), (vec![165.56, 182.11], None));
        // three runs side by side: the fit's v_bl and 0.9 tol either side
        let (three, _) = next_round(&study, (149.0, 198.67), 1.0, 3, false);
        assert!((three[1] - guess).abs() < 0.006 && (three[2] - three[0] - 1.8).abs() < 0.011, "{three:?}");
        // a guess outside the bracket, or within 0.9 tol of its edge: the even split
        assert_eq!(next_round(&study, (120.0, 150.0), 1.0, 2, false), (vec![130.0, 140.0], None));
        assert_eq!(next_round(&study, (180.5, 198.67), 1.0, 2, false).1, None);
        // two perforating runs: p held at 2, no guidance
        study.shots.pop();
        refit(&mut study);
        assert_eq!(next_round(&study, (149.0, 198.67), 1.0, 2, false), (vec![165.56, 182.11], None));
    }

    /// The search ends with the limit inside a bracket at most `2 tol`
    /// wide whatever the curve above it: a Recht–Ipson curve (the fit
    /// right), a step with a linear rise (the fit wrong), at limits across
    /// the range, in at most one round more than the even split (four
    /// here). On Case I's curve it needs two rounds after the bracket
    /// check where the even split needed four (docs/validation.md, first
    /// section).
    #[test]
    fn the_guided_search_brackets_the_limit_whatever_the_curve() {
        let (rounds, study) = search_against(181.2, |v| recht_ipson(v, 0.80, 3.84, 181.2), (149.0, 298.0), 1.0);
        let limit = study.limit.clone().unwrap();
        let (held, perforated) = (limit.held.unwrap(), limit.perforated.unwrap());
        assert!(held < 181.2 && perforated >= 181.2 && perforated - held <= 2.0, "{limit:?}");
        assert_eq!(rounds, 2, "{:?}", study.shots.iter().map(|s| s.speed).collect::<Vec<_>>());
        for v_bl in [150.3, 163.0, 181.2, 211.7, 240.9, 271.4, 296.5] {
            for p in [1.5, 2.0, 3.84, 6.0] {
                let curves: [&dyn Fn(Real) -> Real; 2] =
                    [&|v| recht_ipson(v, 0.8, p, v_bl), &|v| 40.0 + 0.5 * (v - v_bl) * p];
                for residual in curves {
                    let (rounds, study) = search_against(v_bl, residual, (149.0, 298.0), 1.0);
                    let limit = study.limit.clone().unwrap();
                    let (held, perforated) = (limit.held.unwrap(), limit.perforated.unwrap());
                    assert!(held < v_bl && perforated >= v_bl && perforated - held <= 2.0, "{v_bl} {p}: {limit:?}");
                    assert!(rounds <= 5, "{v_bl} {p}: {rounds} rounds");
                }
            }
        }
    }

    #[test]
    fn the_bracket_is_the_highest_hold_below_the_lowest_perforation() {
        let held = Verdict::Held { since: 0.0 };
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let shots = vec![shot(100.0, held), shot(150.0, held), shot(200.0, perf(50.0)), shot(300.0, perf(200.0))];
        assert_eq!(bracket(&shots), (Some(150.0), Some(200.0), None));
        let pushing = Verdict::Undecided { speed: 20.0, plug: true, free: false };
        let shots = vec![shot(150.0, held), shot(170.0, pushing), shot(180.0, held)];
        assert_eq!(bracket(&shots), (Some(150.0), Some(170.0), Some(180.0)));
        let limit = Limit { held: Some(150.0), perforated: Some(170.0), tol: 1.0, non_monotonic: None };
        assert_eq!(limit.estimate(), Some((160.0, 10.0)));
    }

    /// Case II's plate at 24 rows (docs/validation.md): perforated at
    /// 123.33, held at 125.21 and 128.40, perforated at 130 m/s. The report
    /// names the zone of mixed results with both its edges.
    #[test]
    fn the_report_names_a_zone_of_mixed_results() {
        let held = Verdict::Held { since: 0.0 };
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let shots = vec![
            shot(121.85, held),
            shot(123.33, perf(50.5)),
            shot(125.21, held),
            shot(128.4, held),
            shot(130.0, perf(37.2)),
        ];
        let (h, p, above) = bracket(&shots);
        assert_eq!((h, p, above), (Some(121.85), Some(123.33), Some(128.4)));
        let study = Study {
            shots,
            failures: vec![],
            interrupted: false,
            paused: vec![],
            not_started: vec![],
            limit: Some(Limit { held: h, perforated: p, tol: 1.0, non_monotonic: above }),
            fit: None,
        };
        let text = report("header", &study);
        assert!(
            text.contains("Zone of mixed results: the plate held at 128.40 m/s") && text.contains("(123.33 m/s)"),
            "{text}"
        );
        let monotone =
            Study { limit: Some(Limit { non_monotonic: None, ..study.limit.clone().unwrap() }), ..study.clone() };
        assert!(!report("header", &monotone).contains("Zone of mixed results"));
        // A study of speeds alone (no search) reads the same bracket and
        // zone from its runs, without a tolerance.
        let scan = Study { limit: None, ..study.clone() };
        let text = report("header", &scan);
        assert!(text.contains("from the speeds run (no search): **v_bl = 122.59 ± 0.74 m/s**"), "{text}");
        assert!(text.contains("Zone of mixed results: the plate held at 128.40 m/s") && !text.contains("tolerance"));
        // A limit only once both sides are there; with one side the report
        // says which is missing, and a fit with nothing held below it is
        // marked as an extrapolation.
        let shots = vec![study.shots[1].clone(), study.shots[4].clone()];
        let mut perforated = Study { shots, limit: None, ..study.clone() };
        refit(&mut perforated);
        assert!(perforated.fit.is_some());
        assert_eq!(perforated.limit_reading().and_then(|l| l.estimate()), None);
        let text = report("header", &perforated);
        assert!(!text.contains("**v_bl"), "{text}");
        assert!(text.contains("no speed held below") && text.contains("not a ballistic limit"), "{text}");
        assert!(!report("header", &scan).contains("not a ballistic limit"));
        assert_eq!(Study { shots: vec![], limit: None, ..study.clone() }.limit_reading(), None);
    }

    /// An interrupted study's report lists each stopped run where its
    /// checkpoint left it, the force as the plate's push against the
    /// projectile; a finished study's lists none.
    #[test]
    fn an_interrupted_report_says_where_each_stopped_run_stands() {
        let paused = |speed, along, perforation| Paused {
            speed,
            time: 328.5e-6,
            along,
            perforation,
            dir: PathBuf::from("runs/v278.90"),
        };
        let study = Study {
            interrupted: true,
            paused: vec![
                paused(278.9, Some(AlongFlight { speed: 6.716, force: -28_482.2 }), Some(89.004e-6)),
                paused(292.1, None, None),
            ],
            not_started: vec![300.0, 285.5],
            ..Study::default()
        };
        let text = report("header", &study);
        assert!(text.contains("**Interrupted**"), "{text}");
        assert!(text.contains("| 278.90 | 328.5 | 6.72 | 28.5 | 89.00 | runs/v278.90 |"), "{text}");
        assert!(text.contains("| 292.10 | 328.5 | — | — | — | runs/v278.90 |"), "{text}");
        assert!(text.contains("Not started before the interrupt (`--resume` runs them): 300.00, 285.50 m/s."));
        assert_eq!(text.matches("--resume").count(), 2, "{text}");
        let finished = Study { interrupted: false, paused: vec![], not_started: vec![], ..study };
        let text = report("header", &finished);
        assert!(!text.contains("checkpoints") && !text.contains("Not started"), "{text}");
    }

    /// The step's floors, the detached particles and the axis's work are
    /// named in the report, each with its largest run, and only where they
    /// acted.
    #[test]
    fn the_report_names_the_steps_floors_where_they_acted() {
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let mut shots = vec![shot(150.0, perf(80.0)), shot(170.0, perf(110.0)), shot(190.0, perf(140.0))];
        let study = |shots: &[Shot]| Study {
            shots: shots.to_vec(),
            failures: vec![],
            interrupted: false,
            paused: vec![],
            not_started: vec![],
            limit: None,
            fit: None,
        };
        let text = report("header", &study(&shots));
        assert!(
            !text.contains("mass_scaling")
                && !text.contains("erode_failed_below")
                && !text.contains("detach_below")
                && !text.contains("contact.axis"),
            "{text}"
        );
        shots[0].added_mass = 2e-5;
        shots[1].added_mass = 7e-5;
        shots[1].floor_eroded = 3;
        shots[2].floor_eroded = 12;
        shots[0].detached = 2;
        shots[0].detached_particles = [(23040, 48.3e-6, true), (3317, 51.0e-6, false)]
            .map(|(particle, time, crack_face)| crate::run::DetachedParticle {
                particle,
                time,
                reference: Vec2::new(9.917e-3, 11.1e-3),
                mass: 6.9e-6,
                crack_face,
            })
            .to_vec();
        shots[2].axis_energy = 3.7;
        let text = report("header", &study(&shots));
        assert!(
            text.contains("`contact.axis`") && text.contains("at most 3.7000e0 J in one run, at 190.00 m/s"),
            "{text}"
        );
        assert!(
            text.contains("`fracture.detach_below`")
                && text.contains("at most 2 in one run, at 150.00 m/s")
                && text.contains("its `shot.toml` name them"),
            "{text}"
        );
        assert_eq!(
            shots[0].detached_particles[0].describe(),
            "23040 at 48.300 us (a crack-face particle from (9.917, 11.100) mm, 6.900e-6 kg)"
        );
        // The shot file keeps which particles left, and one written with
        // their count alone still reads.
        let kept = FinishedRun { writer: "w".into(), shot: shots[0].clone() };
        let file = toml::to_string(&kept).unwrap();
        assert_eq!(toml::from_str::<FinishedRun>(&file).unwrap().shot, shots[0]);
        let mut older: toml::Table = toml::from_str(&file).unwrap();
        older["shot"].as_table_mut().unwrap().remove("detached_particles").unwrap();
        let back: FinishedRun = toml::from_str(&toml::to_string(&older).unwrap()).unwrap();
        assert_eq!((back.shot.detached, back.shot.detached_particles.len()), (2, 0));
        assert!(text.contains("at most 7.0000e-5 kg") && text.contains("in the run at 170.00 m/s"), "{text}");
        assert!(
            text.contains("`time.erode_failed_below`") && text.contains("at most 12 in one run, at 190.00 m/s"),
            "{text}"
        );
    }

    #[test]
    fn the_plot_draws_held_runs_at_zero_and_skips_plugs_still_pushed() {
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let undecided = |plug| Verdict::Undecided { speed: 5.0, plug, free: false };
        let study = Study {
            shots: vec![
                shot(100.0, Verdict::Held { since: 0.0 }),
                shot(120.0, undecided(false)),
                shot(140.0, undecided(true)),
                shot(200.0, perf(120.0)),
            ],
            ..Study::default()
        };
        let plot = plot(&study, "t", &[]);
        let drawn: Vec<(Real, Real)> = plot.series[0].points.iter().copied().filter(|p| p.0.is_finite()).collect();
        assert_eq!(drawn, vec![(100.0, 0.0), (120.0, 0.0), (200.0, 120.0)]);
    }

    #[test]
    fn experimental_points_need_their_header() {
        let dir = crate::io::test_util::scratch_dir("experiments");
        let path = dir.join("e.csv");
        std::fs::write(&path, "# source\nv_i,v_r\n200.0, 100.5\n150,0 # held\n").unwrap();
        assert_eq!(read_experiments(&path).unwrap(), vec![(200.0, 100.5), (150.0, 0.0)]);
        std::fs::write(&path, "200,100\n").unwrap();
        assert!(read_experiments(&path).unwrap_err().to_string().contains("header"));
        std::fs::write(&path, "v_i,v_r\n200,x\n").unwrap();
        assert!(read_experiments(&path).unwrap_err().to_string().contains("line 2"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn builtin(name: &str, set: &[String]) -> Case {
        Case::from_str_with(crate::cases::builtin_case(name).unwrap(), name, set).unwrap()
    }

    /// Doubling the rows of the coarse Børvik case gives its fine sibling
    /// (an independent case file), and the overrides reported give the same
    /// case again.
    #[test]
    fn twice_the_rows_is_the_fine_case_file() {
        let coarse = builtin("borvik-1-axisymmetric-nonlocal", &[]);
        let (fine, set) = at_rows(&coarse, 48).unwrap();
        assert_eq!(fine.bodies, builtin("borvik-1-axisymmetric-fine-nonlocal", &[]).bodies);
        assert_eq!(fine.bodies, builtin("borvik-1-axisymmetric-nonlocal", &set).bodies);
        assert_eq!(
            (fine.rigid_bodies, fine.fracture, fine.time),
            (coarse.rigid_bodies.clone(), coarse.fracture, coarse.time.clone())
        );
        let (same, none) = at_rows(&coarse, 24).unwrap();
        assert!(none.is_empty() && same.bodies == coarse.bodies);
        let (half, _) = at_rows(&coarse, 12).unwrap();
        assert_eq!(half.bodies[0].rectangle.layers, 12);
        assert_eq!(half.bodies[0].rectangle.coarse_spacing, Some(1.2e-3));
    }

    /// Every body is refined by the same factor: a row count that leaves
    /// another body a fraction of a row is refused, naming it.
    #[test]
    fn a_refinement_must_give_every_body_whole_rows() {
        let two = builtin("two-plates-axisymmetric", &[]);
        let (both, _) = at_rows(&two, 26).unwrap();
        assert_eq!((both.bodies[0].rectangle.layers, both.bodies[1].rectangle.layers), (26, 22));
        let e = at_rows(&two, 20).unwrap_err().to_string();
        assert!(e.contains(&format!("'{}'", two.bodies[1].name)) && e.contains("whole number"), "{e}");
        assert!(at_rows(&two, 1).unwrap_err().to_string().contains("at least 2"));
    }

    /// The lattice's phase at the rim, by hand: the built-in plates' fine
    /// zones start on the axis at the thickness spacing `h = T / (rows −
    /// 1)`, so the projectile's 10 mm radius lies `10/h − round(10/h)`
    /// spacings from the nearest column: Case II's plate at 72 rows −0.39
    /// (the rung whose rim crack takes another path, docs/validation.md),
    /// the 12 mm plate +0.17 at every rung. A column put on the edge
    /// (`column_at`) reads 0.
    #[test]
    fn the_projectile_s_edge_against_the_columns_by_hand() {
        for (name, thickness) in [("borvik-2-axisymmetric-nonlocal", 10.2e-3), ("borvik-2002-12mm-blunt", 12e-3)] {
            let case = builtin(name, &[]);
            let projectile = select_projectile(&case, name, None).unwrap();
            for rows in [24, 48, 72, 96] {
                let (refined, _) = at_rows(&case, rows).unwrap();
                let e = edge_phase(&refined, projectile).unwrap();
                let n = 0.01 / (thickness / (rows - 1) as Real);
                assert!((e.edge - 0.01).abs() < 1e-12, "{name}: edge {}", e.edge);
                assert!(
                    (e.offset - (n - n.round())).abs() < 1e-6,
                    "{name} {rows}: {} against {}",
                    e.offset,
                    n - n.round()
                );
            }
        }
        let case = builtin("borvik-2-axisymmetric-nonlocal", &[]);
        let (mut refined, _) = at_rows(&case, 72).unwrap();
        assert!((edge_phase(&refined, Projectile::Rigid(0)).unwrap().offset + 0.392).abs() < 1e-3);
        refined.bodies[0].rectangle.column_at = Some(0.01);
        assert!(edge_phase(&refined, Projectile::Rigid(0)).unwrap().offset.abs() < 1e-9);
        assert!(edge_phase(&refined, Projectile::Rigid(0)).unwrap().describe().contains("+0.00 of a spacing"));
        // a column on the edge up to round-off, from either side
        for offset in [-1e-15, 1e-15, -0.004] {
            let e = EdgePhase { edge: 0.01, column: 0.01, offset };
            assert!(e.describe().contains(" lies +0.00 of a spacing"), "{}", e.describe());
        }
        assert!(EdgePhase { edge: 0.01, column: 0.01, offset: -0.006 }.describe().contains(" lies -0.01 of"));
        // convergence.csv's four decimals likewise
        let csv = |offset: Real| format!("{:.4}", EdgePhase { edge: 0.01, column: 0.01, offset }.offset_rounding_to(4));
        assert_eq!(
            (csv(-1e-15), csv(-0.00004), csv(-0.00006), csv(-0.392)),
            ("0.0000".into(), "0.0000".into(), "-0.0001".into(), "-0.3920".into())
        );
    }

    /// `--phases`: the phases over one spacing, and the columns they put
    /// next to the edge, by hand. Case II's plate at 24 rows has `h =
    /// 10.2/23 mm` and its fine zone starts on the axis; for phase +0.25
    /// the edge, 10 mm out, is 22.55 spacings away, so `n = round(22.55 −
    /// 0.25) = 22` and the fine spacing becomes `10 / 22.25 = 0.449438`
    /// mm, the column `n` at 9.88764 mm. Every phase is met at 24 and 48
    /// rows, the rows through the thickness unchanged; a phase outside
    /// [−½, ½], or a projectile whose edge lies outside the uniform fine
    /// zone, is refused.
    #[test]
    fn lattice_phases_put_the_edge_where_asked() {
        assert_eq!(phases(4), vec![0.0, 0.25, 0.5, -0.25]);
        assert_eq!(phases(2), vec![0.0, 0.5]);
        assert!((phases(3)[2] + 1.0 / 3.0).abs() < 1e-12);
        let case = builtin("borvik-2-axisymmetric-nonlocal", &[]);
        let projectile = select_projectile(&case, "case II", None).unwrap();
        let (c, set) = at_phase(&case, projectile, 0.25).unwrap();
        let e = edge_phase(&c, projectile).unwrap();
        assert!((e.offset - 0.25).abs() < 1e-9 && (e.column - 9.887640e-3).abs() < 1e-8, "{e:?}");
        assert_eq!(set, vec![format!("bodies.plate.rectangle.fine_spacing={:e}", 0.01 / 22.25)]);
        assert_eq!(c.bodies[0].rectangle.layers, case.bodies[0].rectangle.layers);
        for rows in [24, 48] {
            let (refined, _) = at_rows(&case, rows).unwrap();
            for p in phases(4) {
                let (c, _) = at_phase(&refined, projectile, p).unwrap();
                let got = edge_phase(&c, projectile).unwrap().offset;
                assert!(((got - p + 0.5).rem_euclid(1.0) - 0.5).abs() < 1e-9, "{rows} rows, phase {p}: {got}");
                assert!(c.validate().is_empty());
            }
        }
        // a case's own column_at moves with the columns
        let mut own = case.clone();
        own.bodies[0].rectangle.column_at = Some(0.01);
        let (c, set) = at_phase(&own, projectile, -0.25).unwrap();
        assert!((edge_phase(&c, projectile).unwrap().offset + 0.25).abs() < 1e-9 && set.len() == 2, "{set:?}");
        assert!(at_phase(&case, projectile, 0.6).unwrap_err().to_string().contains("[-0.5, 0.5]"));
        let mut narrow = case.clone();
        narrow.bodies[0].rectangle.fine_half_width = 5e-3;
        let e = at_phase(&narrow, projectile, 0.25).unwrap_err().to_string();
        assert!(e.contains("outside the target's uniform fine zone"), "{e}");
    }

    /// With several phases at a resolution the ladder compares their
    /// envelope, by hand: at 24 rows the limits 119 ± 1 and 125 ± 1 span
    /// 118–126, 122 ± 4, and the residuals at 200 m/s 100 and 110 give
    /// 105 ± 5; at 48 rows 120 ± 1 and 122 ± 1 span 121 ± 2 and 104, 106
    /// give 105 ± 1. The spread of the limits is 1/121.5 = 0.8 %; the step
    /// 122 → 121 is −0.8 %, within (119 − 126)/126 = −5.6 % and (123 −
    /// 118)/118 = +4.2 %; the residual's 105 → 105 is 0.0 %, within
    /// (104 − 110)/110 = −5.5 % and (106 − 100)/100 = +6.0 %.
    #[test]
    fn the_ladder_table_gives_the_envelope_over_phases() {
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let rung = |rows: usize, phase: Real, (lo, hi): (Real, Real), at_200: Real| Rung {
            rows,
            spacing: 0.012 / rows as Real,
            overrides: Vec::new(),
            edge: Some(EdgePhase { edge: 0.01, column: 0.01, offset: phase }),
            phase: Some(phase),
            study: Study {
                shots: vec![shot(200.0, perf(at_200))],
                limit: Some(Limit { held: Some(lo), perforated: Some(hi), tol: 1.0, non_monotonic: None }),
                ..Study::default()
            },
        };
        let mut rungs = [
            rung(24, 0.0, (118.0, 120.0), 100.0),
            rung(24, 0.5, (124.0, 126.0), 110.0),
            rung(48, 0.0, (119.0, 121.0), 104.0),
            rung(48, 0.5, (121.0, 123.0), 106.0),
        ];
        // the speeds at the cut: 150 and 160 at 24 rows, 154 and 156 at 48
        for (r, cut) in rungs.iter_mut().zip([150.0, 160.0, 154.0, 156.0]) {
            r.study.shots[0].cut_speed = Some(cut);
        }
        assert_eq!(ladder_extent(&rungs), "2 resolutions at 2 lattice phases");
        assert_eq!(rungs[1].label(), "24 rows, phase +0.50");
        let (md, csv) = ladder_table(&rungs, &[200.0]);
        assert_eq!(csv.lines().count(), 5, "one CSV line per rung: {csv}");
        let line = |start: &str| md.lines().find(|l| l.starts_with(start)).unwrap_or_else(|| panic!("{start}: {md}"));
        assert!(
            line("| 24 rows, 2 phases |").contains("| 122.00 ± 4.00 | | 105.00 ± 5.00 | 155.00 ± 5.00 | 2 |"),
            "{md}"
        );
        assert!(line("| 48 rows, 2 phases |").contains("| 121.00 ± 2.00 | | 105.00 ± 1.00 | 155.00 ± 1.00 |"), "{md}");
        // the cut's envelopes compare as the residuals' do: 155 ± 5 → 155 ±
        // 1, from (154 − 160)/160 = −3.75 % to (156 − 150)/150 = +4.0 %
        assert!(line("| step 24 → 48 rows").ends_with("| +0.0 % (-3.8 %…+4.0 %) | | | |"), "{md}");
        // within the brackets: 118–126 and 119–123 overlap, so at least 0,
        // and at most (126 − 118)/121.5 = 6.6 %; the residuals 100–110 and
        // 104–106: 0 and 10/105 = 9.5 %
        assert!(line("| spread").starts_with("| spread | | 0.8 % (0.0 %…6.6 %) | | 0.0 % (0.0 %…9.5 %) |"), "{md}");
        let step = line("| step 24 → 48 rows");
        assert!(step.contains("| -0.8 % (-5.6 %…+4.2 %) |") && step.contains("| +0.0 % (-5.5 %…+6.0 %) |"), "{step}");
        // one phase per resolution reads as before: no envelope line
        let (md, _) = ladder_table(&rungs[..1], &[200.0]);
        assert!(!md.contains("phases |"), "{md}");
        // a rung interrupted before its first run ended: 0 runs in 0 s (an
        // empty float sum is −0.0, which printed "-0")
        let mut empty = rungs[0].clone();
        empty.study = Study::default();
        let (md, csv) = ladder_table(&[empty], &[200.0]);
        assert!(md.lines().nth(2).unwrap().contains("| 0 | 0 |") && !md.contains("-0"), "{md}");
        assert!(csv.lines().nth(1).unwrap().contains(",0,0.00,"), "{csv}");
    }

    #[test]
    fn the_residuals_sensitivity_to_the_limit() {
        // The closed form against a central difference of the curve in v_bl.
        for &(v, p, v_bl) in &[(292.1, 2.0, 285.5), (298.0, 1.64, 180.0), (200.0, 3.5, 120.0), (173.7, 1.2, 150.0)] {
            let a = 0.8;
            let d = 1e-4;
            let slope = (recht_ipson(v, a, p, v_bl + d) - recht_ipson(v, a, p, v_bl - d)) / (2.0 * d);
            let fd = -v_bl / recht_ipson(v, a, p, v_bl) * slope;
            let k = limit_sensitivity(v, p, v_bl).unwrap();
            assert!((k - fd).abs() < 1e-6 * k.max(1.0), "{v} {p} {v_bl}: {k} against {fd}");
        }
        // The hemispherical nose at 292.1 m/s on a 285.5 m/s limit: 21.4.
        let k = limit_sensitivity(292.1, 2.0, 285.5).unwrap();
        assert!(
            (k - 285.5f64.powi(2) / (292.1f64.powi(2) - 285.5f64.powi(2))).abs() < 1e-12 && (k - 21.38).abs() < 0.01
        );
        // Near the limit κ → 1 / (p ε).
        for &p in &[1.0, 2.0, 4.0] {
            let eps = 1e-5;
            let k = limit_sensitivity(300.0 * (1.0 + eps), p, 300.0).unwrap();
            assert!((k * p * eps - 1.0).abs() < 1e-4, "{p}: {}", k * p * eps);
        }
        // None at or below the limit.
        assert_eq!(limit_sensitivity(285.5, 2.0, 285.5), None);
        assert_eq!(limit_sensitivity(280.0, 2.0, 285.5), None);
    }

    #[test]
    fn the_ladder_table_gives_the_spread_of_limits_and_residuals() {
        let perf = |v| Verdict::Perforated { residual: v, since: 0.0 };
        let held = Verdict::Held { since: 0.0 };
        let rung = |rows: usize, (lo, hi): (Real, Real), at_200: Verdict, at_300: Real| Rung {
            rows,
            spacing: 0.012 / rows as Real,
            overrides: Vec::new(),
            edge: None,
            phase: None,
            study: Study {
                shots: vec![shot(200.0, at_200), shot(300.0, perf(at_300))],
                limit: Some(Limit { held: Some(lo), perforated: Some(hi), tol: 1.0, non_monotonic: None }),
                ..Study::default()
            },
        };
        let mut rungs = [rung(12, (119.0, 121.0), perf(100.0), 250.0), rung(24, (129.0, 131.0), perf(110.0), 250.0)];
        rungs[0].edge = Some(EdgePhase { edge: 0.01, column: 0.00982, offset: 0.18 });
        // the speed at the cut, at 200 m/s only
        rungs[0].study.shots[0].cut_speed = Some(150.0);
        rungs[1].study.shots[0].cut_speed = Some(156.0);
        let (md, csv) = ladder_table(&rungs, &[200.0, 300.0]);
        // its columns follow the residuals': 150 → 156 m/s is 6/153 = 3.9 %
        // apart and a step of +4.0 %; none at 300 m/s, and no sensitivity
        assert!(md.lines().next().unwrap().contains("| v_r at 300.0 m/s | v at the cut at 200.0 m/s |"), "{md}");
        assert!(md.lines().nth(2).unwrap().contains("| 250.00 | 150.00 | — |"), "{md}");
        let cells = |row: &str| -> Vec<String> { row.split('|').map(|c| c.trim().to_string()).collect() };
        let spread = cells(md.lines().find(|l| l.starts_with("| spread")).unwrap());
        assert_eq!((spread[7].as_str(), spread[8].as_str()), ("3.9 %", "—"), "{md}");
        let step = cells(md.lines().last().unwrap());
        assert_eq!((step[7].as_str(), step[8].as_str()), ("+4.0 %", "—"), "{md}");
        let kappa = cells(md.lines().find(|l| l.starts_with("| v_r's sensitivity")).unwrap());
        assert_eq!((kappa[7].as_str(), kappa[8].as_str()), ("—", "—"), "{md}");
        // the edge's phase: given on the first rung, unknown on the second
        assert!(
            md.lines().nth(2).unwrap().ends_with("| +0.18 |") && md.lines().nth(3).unwrap().ends_with("| — |"),
            "{md}"
        );
        assert!(
            csv.lines().nth(1).unwrap().ends_with(",0.1800") && csv.lines().nth(2).unwrap().ends_with(','),
            "{csv}"
        );
        // limits 120 ± 1 and 130 ± 1: 10/125 = 8.0 %, within the brackets
        // 8/125 = 6.4 % to 12/125 = 9.6 %; at 200 m/s 100 and 110: 10/105 =
        // 9.5 %; at 300 m/s 0 % (residuals have no bracket)
        let spread_row = md.lines().find(|l| l.starts_with("| spread")).unwrap();
        assert!(
            spread_row.contains("| 8.0 % (6.4 %…9.6 %) |")
                && spread_row.contains("| 9.5 % |")
                && spread_row.contains("| 0.0 % |"),
            "{md}"
        );
        // From 12 to 24 rows: the limit 120 ± 1 → 130 ± 1 is +8.3 %, and
        // between +6.6 % (121 → 129) and +10.1 % (119 → 131); 100 → 110 m/s
        // is +10.0 %.
        let step_row = md.lines().last().unwrap();
        assert!(step_row.starts_with("| step 12 → 24 rows |"), "{md}");
        assert!(step_row.contains("| +8.3 % (+6.6 %…+10.1 %) |") && step_row.contains("| +10.0 % |"), "{step_row}");
        assert!(md.contains("| 12 | 1.000 | 120.00 ± 1.00 |"), "{md}");
        // Each residual's sensitivity to the limit, from the brackets'
        // middles at p = 2 (no fits): at 200 m/s 120²/(200² − 120²) = 0.5625
        // and 130²/(200² − 130²) = 0.7316; at 300 m/s 0.1905 and 0.2312.
        let kappa_row = md.lines().find(|l| l.starts_with("| v_r's sensitivity")).unwrap();
        assert!(kappa_row.contains("| 0.6–0.7 | 0.2 |"), "{md}");
        // A speed between the limits: 120²/(125² − 120²) = 11.76 at 12 rows.
        let (md, _) = ladder_table(&rungs, &[125.0]);
        let kappa_row = md.lines().find(|l| l.starts_with("| v_r's sensitivity")).unwrap();
        assert!(kappa_row.contains("| 11.8; at or under the limit at 24 rows |"), "{md}");
        assert_eq!(csv.lines().count(), 3, "{csv}");
        assert!(
            csv.lines().nth(2).unwrap().starts_with("24,0.500000,130.000,1.000,,,,110.000,250.000,156.000,,2,"),
            "{csv}"
        );
        // A held run has no residual to compare: "held", and no spread at that speed.
        let rungs = [rung(12, (119.0, 121.0), held, 250.0), rung(24, (129.0, 131.0), perf(110.0), 250.0)];
        let (md, _) = ladder_table(&rungs, &[200.0]);
        assert!(md.contains("| held |") && md.contains("| 8.0 % (6.4 %…9.6 %) | | — |"), "{md}");
        // The step is between the two finest rungs whatever the order given.
        let rungs = [
            rung(48, (124.0, 126.0), perf(100.0), 250.0),
            rung(12, (119.0, 121.0), perf(100.0), 250.0),
            rung(24, (129.0, 131.0), perf(110.0), 250.0),
        ];
        let (md, _) = ladder_table(&rungs, &[300.0]);
        assert!(md.contains("| step 24 → 48 rows | | -3.8 % ("), "{md}");
        // Three rungs: the limits 120, 130, 125 swing, and the residuals
        // at 300 m/s do not move: no order from either.
        let rich = md.lines().last().unwrap();
        assert!(rich.starts_with("| Richardson, 12 / 24 / 48 rows | | steps change sign: no order |"), "{md}");
        assert!(rich.contains("| a step within the brackets: no order |"), "{rich}");
        // Case I's plate at 24 / 48 / 96 rows (docs/validation.md): limits
        // 123.14 / 115.75 / 113.39 ± 1 m/s fall by 7.39 then 2.36 m/s, a
        // ratio of 3.131 = 2^1.647, so v_bl(0) = 113.39 − 2.36 / 2.131 =
        // 112.28 m/s and GCI = 1.25 × 2.36 / 113.39 / 2.131 = 1.2 %; the
        // residuals at 200 m/s, 153.42 / 155.34 / 156.34, give p = 0.94,
        // 157.43 m/s, GCI 0.9 %.
        let rungs = [
            rung(24, (122.14, 124.14), perf(153.42), 250.0),
            rung(48, (114.75, 116.75), perf(155.34), 250.0),
            rung(96, (112.39, 114.39), perf(156.34), 250.0),
        ];
        let (md, _) = ladder_table(&rungs, &[200.0]);
        let rich = md.lines().last().unwrap();
        assert!(rich.contains("| p = 1.65, 112.28, GCI 1.2 % |"), "{rich}");
        assert!(rich.contains("| p = 0.94, 157.43, GCI 0.9 % |"), "{rich}");
        // A last step within the brackets (±1.5 m/s here) gives none.
        let mut wide = rungs.clone();
        wide[2].study.limit.as_mut().unwrap().held = Some(111.89);
        wide[2].study.limit.as_mut().unwrap().perforated = Some(114.89);
        wide[1].study.limit.as_mut().unwrap().held = Some(114.25);
        wide[1].study.limit.as_mut().unwrap().perforated = Some(117.25);
        let (md, _) = ladder_table(&wide, &[200.0]);
        assert!(md.lines().last().unwrap().contains("| a step within the brackets: no order |"), "{md}");
        // A scan that perforated at every speed (Case II's plate at 48 rows,
        // docs/validation.md) bounds the limit from above only: "< 200.00",
        // its fit marked, and no spread of limits.
        let mut scan = rungs.clone();
        scan[2].study.limit = None;
        scan[2].study.shots[0].verdict = perf(150.0);
        refit(&mut scan[2].study);
        let (md, _) = ladder_table(&scan, &[200.0]);
        let row = md.lines().find(|l| l.starts_with("| 96 |")).unwrap();
        assert!(row.contains("| < 200.00 |") && row.contains("(extrapolated: no run held below)"), "{row}");
        assert!(md.lines().find(|l| l.starts_with("| spread")).unwrap().starts_with("| spread | | — |"), "{md}");
        assert!(!md.lines().find(|l| l.starts_with("| 48 |")).unwrap().contains("extrapolated"), "{md}");
    }
}
