//! `plugsim validate`: run Børvik's plugging cases and compare the
//! projectile's residual velocity with the experiments and with [RL10]'s
//! simulations (shared/reference/ren-li-2010.toml, Tables 1 and 3).
//!
//! Residual velocity is measured as experimenters do: the projectile's speed
//! once contact forces have vanished. A row reports the speed at the end of
//! the run and the time of the last contact; if the projectile is still in
//! contact at the end, the row says so rather than reporting a number.

use crate::case::Case;
use crate::cases::builtin_case;
use crate::io::{HistoryTable, LinePlot, Series};
use crate::math::Real;
use crate::run::{execute, RunConfig, RunError, RunInfo, RunSummary};
use std::path::{Path, PathBuf};

/// One of Børvik's experiments as printed in [RL10] (reference file).
#[derive(Clone, Debug)]
pub struct Experiment {
    pub name: &'static str,
    /// Plate thickness, m.
    pub thickness: Real,
    /// Impact velocity, m/s.
    pub impact_velocity: Real,
    /// Measured residual velocity, m/s.
    pub residual: Real,
    /// Time simulated by [RL10], s.
    pub simulated_time: Real,
    /// [RL10]'s simulated residuals: (particles, criterion, m/s).
    pub paper: &'static [(usize, &'static str, Real)],
}

/// Tables 1 and 3 of [RL10] (`shared/reference/ren-li-2010.toml`).
pub const EXPERIMENTS: &[Experiment] = &[
    Experiment {
        name: "case-1",
        thickness: 0.0111,
        impact_velocity: 298.0,
        residual: 241.4,
        simulated_time: 118.0e-6,
        paper: &[
            (11496, "damage", 238.5),
            (11496, "effective_strain", 246.7),
            (45984, "damage", 239.6),
            (45984, "effective_strain", 246.1),
        ],
    },
    Experiment {
        name: "case-2",
        thickness: 0.0102,
        impact_velocity: 173.7,
        residual: 112.0,
        simulated_time: 216.0e-6,
        paper: &[
            (11496, "damage", 123.0),
            (11496, "effective_strain", 121.8),
            (45984, "damage", 116.1),
            (45984, "effective_strain", 109.4),
        ],
    },
];

/// A validation row: a built-in case, overrides, and its experiment.
#[derive(Clone, Debug)]
pub struct Row {
    pub id: String,
    pub experiment: &'static Experiment,
    pub geometry: &'static str,
    pub discretization: &'static str,
    pub criterion: &'static str,
    pub builtin: &'static str,
    pub overrides: Vec<String>,
}

/// The coarse rows: both cases, plane strain and axisymmetric, both
/// criteria. Case II is Case I's files with the thinner plate, the slower
/// projectile (its nose again 0.05 mm above the plate) and the longer time.
pub fn coarse_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for e in EXPERIMENTS {
        for (geometry, builtin) in
            [("plane_strain", "borvik-1-plane-strain"), ("axisymmetric", "borvik-1-axisymmetric")]
        {
            for criterion in ["effective_strain", "damage"] {
                let t = e.thickness;
                let mut o = vec![
                    format!("time.end={:e}", e.simulated_time),
                    format!("fracture.criterion=\"{criterion}\""),
                    format!("bodies.plate.rectangle.y_max={t}"),
                    format!("bodies.plate.supports.0.region.y_max={t}"),
                    format!("rigid_bodies.projectile.velocity=[0.0, {}]", -e.impact_velocity),
                    format!("rigid_bodies.projectile.rectangle.center=[0.0, {}]", t + 0.04 + 5e-5),
                ];
                if geometry == "plane_strain" {
                    o.push(format!("bodies.plate.supports.1.region.y_max={t}"));
                }
                rows.push(Row {
                    id: format!("{}-{}-coarse-{}", e.name, geometry, criterion),
                    experiment: e,
                    geometry,
                    discretization: "coarse",
                    criterion,
                    builtin,
                    overrides: o,
                });
            }
        }
    }
    rows
}

/// What a row produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub row: Row,
    pub result: Result<RunSummary, String>,
    pub wall: Real,
    /// Projectile speed at the end, m/s.
    pub final_speed: Option<Real>,
    /// Time of its last contact, s.
    pub last_contact: Option<Real>,
    pub out_dir: PathBuf,
}

impl Outcome {
    /// The residual velocity: the final speed if the projectile had left
    /// contact before the end of the run.
    pub fn residual(&self) -> Option<Real> {
        let s = self.result.as_ref().ok()?;
        match (self.final_speed, self.last_contact) {
            (Some(v), Some(t)) if s.time - t > 1e-6 => Some(v),
            (Some(v), None) => Some(v),
            _ => None,
        }
    }
    /// [RL10]'s value for this row (plane strain only; coarse = 11,496 particles).
    pub fn paper(&self) -> Option<Real> {
        if self.row.geometry != "plane_strain" {
            return None;
        }
        let particles = if self.row.discretization == "coarse" { 11496 } else { 45984 };
        self.row.experiment.paper.iter().find(|p| p.0 == particles && p.1 == self.row.criterion).map(|p| p.2)
    }
}

/// Run one row into `out/ROW_ID`.
pub fn run_row(row: &Row, out: &Path, progress: &mut dyn FnMut(&str)) -> Outcome {
    let dir = out.join(&row.id);
    let t = std::time::Instant::now();
    let text = builtin_case(row.builtin).expect("validation rows name built-in cases");
    let result = Case::from_str_with(text, row.builtin, &row.overrides).map_err(|e| e.to_string()).and_then(|case| {
        let cfg = RunConfig::new(dir.clone(), true, RunInfo::current(row.builtin, &row.overrides));
        execute(&case, &cfg, &mut |_| {}).map_err(|e: RunError| e.to_string())
    });
    let wall = t.elapsed().as_secs_f64();
    let (final_speed, last_contact) = match &result {
        Ok(s) => (
            s.rigid_velocities.first().map(|(_, v)| (v[0] * v[0] + v[1] * v[1]).sqrt()),
            s.last_contacts.first().and_then(|(_, t)| *t),
        ),
        Err(_) => (None, None),
    };
    progress(&row.id);
    Outcome { row: row.clone(), result, wall, final_speed, last_contact, out_dir: dir }
}

fn fmt_opt(v: Option<Real>, digits: usize) -> String {
    v.map_or_else(|| "—".to_string(), |v| format!("{v:.digits$}"))
}

/// The table as Markdown and CSV.
pub fn table(outcomes: &[Outcome]) -> (String, String) {
    let mut md = String::from(
        "| case | geometry | discretization | criterion | particles | steps | wall (s) | residual (m/s) | experiment (m/s) | error % | [RL10] (m/s) | perforation (µs) | last contact (µs) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "case,geometry,discretization,criterion,particles,steps,wall_s,residual_m_s,experiment_m_s,error_percent,paper_m_s,perforation_us,last_contact_us,status\n",
    );
    for o in outcomes {
        let r = &o.row;
        let residual = o.residual();
        let err = residual.map(|v| 100.0 * (v - r.experiment.residual) / r.experiment.residual);
        let (particles, steps, perforation, status) = match &o.result {
            Ok(s) => (s.particles.to_string(), s.steps.to_string(), s.separation.map(|t| t * 1e6), "ok".to_string()),
            Err(e) => ("—".into(), "—".into(), None, format!("failed: {}", e.lines().next().unwrap_or(""))),
        };
        let residual_md = match (&o.result, residual) {
            (Err(_), _) => format!("failed ({})", status.trim_start_matches("failed: ")),
            (Ok(_), None) => format!("in contact at the end ({} m/s)", fmt_opt(o.final_speed, 1)),
            (Ok(_), Some(v)) => format!("{v:.1}"),
        };
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.1} | {} | {:.1} | {} | {} | {} | {} |\n",
            r.experiment.name,
            r.geometry,
            r.discretization,
            r.criterion,
            particles,
            steps,
            o.wall,
            residual_md,
            r.experiment.residual,
            fmt_opt(err, 1),
            fmt_opt(o.paper(), 1),
            fmt_opt(perforation, 1),
            fmt_opt(o.last_contact.map(|t| t * 1e6), 1),
        ));
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{}\n",
            r.experiment.name,
            r.geometry,
            r.discretization,
            r.criterion,
            particles,
            steps,
            o.wall,
            fmt_opt(residual, 3),
            r.experiment.residual,
            fmt_opt(err, 3),
            fmt_opt(o.paper(), 1),
            fmt_opt(perforation, 3),
            fmt_opt(o.last_contact.map(|t| t * 1e6), 3),
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
            Some(Series {
                name: format!("{} {} {}", o.row.geometry, o.row.discretization, o.row.criterion),
                points: t.iter().zip(vx.iter().zip(vy)).map(|(t, (x, y))| (t * 1e6, (x * x + y * y).sqrt())).collect(),
            })
        })
        .collect();
    LinePlot {
        title: format!(
            "{}: {} mm plate, {} m/s impact",
            experiment.name,
            experiment.thickness * 1e3,
            experiment.impact_velocity
        ),
        x_label: "time (us)".into(),
        y_label: "projectile speed (m/s)".into(),
        series,
        hlines: vec![(format!("experiment {} m/s", experiment.residual), experiment.residual)],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_coarse_row_is_a_valid_case_of_its_experiment() {
        let rows = coarse_rows();
        assert_eq!(rows.len(), 8);
        for r in &rows {
            let text = builtin_case(r.builtin).unwrap();
            let case = Case::from_str_with(text, &r.id, &r.overrides).unwrap_or_else(|e| panic!("{}: {e}", r.id));
            let plate = &case.bodies[0].rectangle;
            assert_eq!(plate.y_max - plate.y_min, r.experiment.thickness, "{}", r.id);
            let p = &case.rigid_bodies[0];
            assert_eq!(p.velocity[1], -r.experiment.impact_velocity);
            let nose = p.rectangle.as_ref().unwrap().center[1] - 0.04;
            assert!(nose > plate.y_max && nose - plate.y_max < 1e-4, "{}: nose {nose}", r.id);
            assert_eq!(case.time.end, r.experiment.simulated_time);
            let fracture = toml::to_string(&case.fracture).unwrap();
            assert!(fracture.contains(&format!("criterion = \"{}\"", r.criterion)), "{}: {fracture}", r.id);
            for s in &case.bodies[0].supports {
                assert_eq!(s.region.y_max, r.experiment.thickness, "{}: support spans the thickness", r.id);
            }
        }
    }
}
