//! Single-material-point driver: one point driven through a prescribed
//! deformation-rate history, for checking a material model against analytic
//! answers and experiments without the discretization.
//!
//! # API (the `plugsim material-point` subcommand is a thin wrapper of it)
//!
//! - [`DriverConfig`] `{ path, rate, final_strain, dt, initial_temperature }`
//!   says how to drive the point; [`run`] returns one [`Record`] at `t = 0`
//!   and one after every step.
//! - [`write_csv`] / [`save_csv`] write the records as CSV ([`CSV_HEADER`]);
//!   [`line_plots`] builds the stress–strain, temperature and damage plots and
//!   [`save_plots`] renders them as PNG files.
//!
//! ```
//! use plugsim::material_point::{run, DriverConfig, LoadPath};
//! use plugsim::material::library::builtin;
//!
//! let steel = builtin("weldox_460e").unwrap();
//! let config = DriverConfig {
//!     path: LoadPath::SimpleShear,
//!     rate: 1.0e4,       // shear rate γ̇, 1/s
//!     final_strain: 0.5, // γ
//!     dt: 1.0e-7,        // s
//!     initial_temperature: None,
//! };
//! let records = run(&steel, &config).unwrap();
//! let last = records.last().unwrap();
//! assert!(last.eps_p > 0.2 && last.temperature > 293.0);
//! ```
//!
//! Stresses are Kirchhoff (`τ = J σ`, SPEC §2); divide by
//! [`Record::jacobian`] for Cauchy.

use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::io::plot::{save_line_plot, LinePlot, PlotError, Series};
use crate::material::{Constitutive, Material, PointState, StepKinematics};
use crate::math::{mean_stress, von_mises, Real, Tensor3};

/// The most steps one run may take (each step keeps a [`Record`], ~170 bytes).
pub const MAX_STEPS: usize = 5_000_000;

/// Which homogeneous deformation drives the point. The axes are x (0),
/// y (1), z (2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadPath {
    /// `d = diag(ε̇, 0, 0)`, `w = 0`. Strain measure: axial logarithmic
    /// strain `∫ d_xx dt`.
    UniaxialStrain,
    /// `d = diag(ε̇, d_l, d_l)`, `w = 0`, with the lateral rate `d_l` solved
    /// each step (secant iteration) so that `τ_yy = τ_zz ≈ 0` (to 1e-10 of
    /// the axial stress). Strain measure: axial logarithmic strain.
    UniaxialStress,
    /// `ℓ = γ̇ e_x ⊗ e_y`: `d = sym ℓ` and the spin `w = skw ℓ` of simple
    /// shear. Strain measure: the shear `γ = ∫ γ̇ dt`.
    SimpleShear,
}

impl LoadPath {
    /// Label of the strain measure, for plots and CSV users.
    pub fn strain_label(self) -> &'static str {
        match self {
            LoadPath::UniaxialStrain | LoadPath::UniaxialStress => "axial log strain",
            LoadPath::SimpleShear => "shear strain gamma",
        }
    }
}

/// How to drive the point.
#[derive(Clone, Debug, PartialEq)]
pub struct DriverConfig {
    /// The deformation path.
    pub path: LoadPath,
    /// Magnitude of the driving rate, 1/s (> 0): `ε̇` for the uniaxial paths,
    /// `γ̇` for simple shear.
    pub rate: Real,
    /// Strain at the end (nonzero; its sign gives the direction: negative is
    /// compression for the uniaxial paths).
    pub final_strain: Real,
    /// Largest time step, s (> 0). The run takes `N = ceil(t_end/dt)` equal
    /// steps of `t_end/N` with `t_end = |final_strain|/rate`, so it ends
    /// exactly at `final_strain`.
    pub dt: Real,
    /// Initial temperature, K; `None` means the material's
    /// [`Constitutive::initial_temperature`].
    pub initial_temperature: Option<Real>,
}

/// The state of the point at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// Time, s.
    pub time: Real,
    /// Strain measure of the path ([`LoadPath`]), signed.
    pub strain: Real,
    /// Equivalent (von Mises) Kirchhoff stress `τ̄`, Pa.
    pub equivalent_stress: Real,
    /// Kirchhoff pressure `−tr τ / 3`, Pa.
    pub pressure: Real,
    /// Equivalent plastic strain `ε̄`.
    pub eps_p: Real,
    /// Equivalent plastic strain rate of the last step, 1/s.
    pub eps_p_rate: Real,
    /// Temperature, K.
    pub temperature: Real,
    /// Johnson–Cook damage `D`.
    pub damage: Real,
    /// Kirchhoff stress tensor, Pa.
    pub tau: Tensor3,
    /// Volume ratio `J = exp ∫ tr d dt`.
    pub jacobian: Real,
}

/// Why a driver run or an output failed.
#[derive(Debug, thiserror::Error)]
pub enum DriverError {
    /// A configuration value out of range.
    #[error("driver setting `{field}` = {value}: {reason}")]
    InvalidConfig { field: &'static str, value: Real, reason: &'static str },
    /// The material's parameters are invalid (all problems listed).
    #[error("invalid material: {}", .0.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("; "))]
    InvalidMaterial(Vec<crate::material::johnson_cook::ParameterError>),
    /// Uniaxial stress: the lateral-rate iteration did not bring `τ_yy` to zero.
    #[error("uniaxial stress: lateral stress {residual} Pa did not converge at step {step}")]
    LateralStressNotConverged { step: usize, residual: Real },
    /// The material returned a NaN or infinite state.
    #[error("non-finite {field} at step {step} (t = {time} s)")]
    NonFinite { step: usize, time: Real, field: &'static str },
    /// Writing output failed.
    #[error("cannot write {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// Rendering a plot failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// Drive one point of `material` as `config` says. Returns the records at
/// `t = 0` and after every step.
pub fn run(material: &Material, config: &DriverConfig) -> Result<Vec<Record>, DriverError> {
    if let Material::JohnsonCook(m) = material {
        m.validate().map_err(DriverError::InvalidMaterial)?;
    }
    let steps = check_config(config)?;
    let t_end = config.final_strain.abs() / config.rate;
    let h = t_end / steps as Real;
    let signed_rate = config.rate * config.final_strain.signum();
    let t0 = config.initial_temperature.unwrap_or_else(|| material.initial_temperature());

    let mut state = PointState::at_rest(t0);
    let mut jacobian = 1.0;
    let mut lateral = -poisson_ratio(material) * signed_rate;
    let mut records = Vec::with_capacity(steps + 1);
    records.push(record(0.0, 0.0, &state, jacobian));
    for step in 1..=steps {
        let (next, d) = match config.path {
            LoadPath::UniaxialStrain => {
                let d = Tensor3::from_diagonal(&nalgebra::Vector3::new(signed_rate, 0.0, 0.0));
                let k = StepKinematics { d, w: Tensor3::zeros(), dt: h };
                (material.update(&state, &k), d)
            }
            LoadPath::UniaxialStress => {
                let (next, d_l) = solve_lateral(material, &state, signed_rate, lateral, h, step)?;
                lateral = d_l;
                (next, Tensor3::from_diagonal(&nalgebra::Vector3::new(signed_rate, d_l, d_l)))
            }
            LoadPath::SimpleShear => {
                let mut l = Tensor3::zeros();
                l[(0, 1)] = signed_rate;
                let d = crate::math::sym(&l);
                let k = StepKinematics { d, w: crate::math::skew(&l), dt: h };
                (material.update(&state, &k), d)
            }
        };
        let time = step as Real * h;
        check_finite(&next, step, time)?;
        state = next;
        jacobian *= (h * d.trace()).exp();
        records.push(record(time, signed_rate * time, &state, jacobian));
    }
    Ok(records)
}

fn check_config(c: &DriverConfig) -> Result<usize, DriverError> {
    let bad = |field, value, reason| Err(DriverError::InvalidConfig { field, value, reason });
    if !(c.rate > 0.0 && c.rate.is_finite()) {
        return bad("rate", c.rate, "must be positive and finite");
    }
    if !(c.final_strain != 0.0 && c.final_strain.is_finite()) {
        return bad("final_strain", c.final_strain, "must be nonzero and finite");
    }
    if !(c.dt > 0.0 && c.dt.is_finite()) {
        return bad("dt", c.dt, "must be positive and finite");
    }
    if let Some(t) = c.initial_temperature {
        if !(t >= 0.0 && t.is_finite()) {
            return bad("initial_temperature", t, "must be a finite absolute temperature");
        }
    }
    let steps = (c.final_strain.abs() / c.rate / c.dt).ceil();
    if steps > MAX_STEPS as Real {
        return bad("dt", c.dt, "needs more than MAX_STEPS steps to reach final_strain");
    }
    Ok((steps as usize).max(1))
}

fn poisson_ratio(m: &Material) -> Real {
    let (k, g) = (m.bulk_modulus(), m.shear_modulus());
    (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g))
}

/// Uniaxial stress: the lateral rate `d_l` that makes `τ_yy` vanish after the
/// step, by secant iteration started from the last step's `d_l` with the
/// elastic slope `∂τ_yy/∂d_l = Δt (2λ + 2G)`.
fn solve_lateral(
    material: &Material,
    state: &PointState,
    axial: Real,
    guess: Real,
    dt: Real,
    step: usize,
) -> Result<(PointState, Real), DriverError> {
    const MAX_ITERATIONS: usize = 60;
    let trial = |d_l: Real| {
        let d = Tensor3::from_diagonal(&nalgebra::Vector3::new(axial, d_l, d_l));
        let next = material.update(state, &StepKinematics { d, w: Tensor3::zeros(), dt });
        (next, next.tau[(1, 1)])
    };
    let converged = |s: &PointState, r: Real| {
        let scale = s.tau[(0, 0)].abs().max(1e-6 * material.shear_modulus());
        r.abs() <= 1e-10 * scale
    };
    let lambda = material.bulk_modulus() - 2.0 * material.shear_modulus() / 3.0;
    let mut x0 = guess;
    let (s0, mut r0) = trial(x0);
    if converged(&s0, r0) {
        return Ok((s0, x0));
    }
    let mut x1 = x0 - r0 / (dt * 2.0 * (lambda + material.shear_modulus()));
    let (mut s1, mut r1) = trial(x1);
    for _ in 0..MAX_ITERATIONS {
        if converged(&s1, r1) {
            return Ok((s1, x1));
        }
        if r1 == r0 || !r1.is_finite() {
            break;
        }
        let x2 = x1 - r1 * (x1 - x0) / (r1 - r0);
        (x0, r0) = (x1, r1);
        x1 = x2;
        (s1, r1) = trial(x1);
    }
    Err(DriverError::LateralStressNotConverged { step, residual: r1 })
}

fn check_finite(s: &PointState, step: usize, time: Real) -> Result<(), DriverError> {
    let fields = [
        ("stress", s.tau.iter().all(|v| v.is_finite())),
        ("eps_p", s.eps_p.is_finite()),
        ("eps_p_rate", s.eps_p_rate.is_finite()),
        ("temperature", s.temperature.is_finite()),
        ("damage", s.damage.is_finite()),
    ];
    match fields.iter().find(|(_, ok)| !ok) {
        Some((field, _)) => Err(DriverError::NonFinite { step, time, field }),
        None => Ok(()),
    }
}

fn record(time: Real, strain: Real, s: &PointState, jacobian: Real) -> Record {
    Record {
        time,
        strain,
        equivalent_stress: von_mises(&s.tau),
        pressure: -mean_stress(&s.tau),
        eps_p: s.eps_p,
        eps_p_rate: s.eps_p_rate,
        temperature: s.temperature,
        damage: s.damage,
        tau: s.tau,
        jacobian,
    }
}

/// CSV header written by [`write_csv`]; units: s, Pa, K, 1/s.
pub const CSV_HEADER: &str = "time,strain,equivalent_stress,pressure,eps_p,eps_p_rate,temperature,damage,\
tau_xx,tau_yy,tau_zz,tau_xy,tau_yz,tau_xz,jacobian";

/// Write `records` as CSV ([`CSV_HEADER`], one row per record, numbers in
/// shortest round-trip form).
pub fn write_csv<W: Write>(records: &[Record], mut out: W) -> std::io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    for r in records {
        let t = &r.tau;
        let row = [
            r.time,
            r.strain,
            r.equivalent_stress,
            r.pressure,
            r.eps_p,
            r.eps_p_rate,
            r.temperature,
            r.damage,
            t[(0, 0)],
            t[(1, 1)],
            t[(2, 2)],
            t[(0, 1)],
            t[(1, 2)],
            t[(0, 2)],
            r.jacobian,
        ];
        let line: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
        writeln!(out, "{}", line.join(","))?;
    }
    Ok(())
}

/// [`write_csv`] to the file `path`.
pub fn save_csv(path: &Path, records: &[Record]) -> Result<(), DriverError> {
    let io_err = |source| DriverError::Io { path: path.display().to_string(), source };
    let file = std::fs::File::create(path).map_err(io_err)?;
    let mut out = std::io::BufWriter::new(file);
    write_csv(records, &mut out).map_err(io_err)?;
    out.flush().map_err(io_err)
}

/// The plots of a run, each with a file-name suffix: `"stress"` (equivalent
/// stress and the driven component vs strain, MPa), `"temperature"` (K vs
/// strain) and `"damage"` (`D` and `ε̄` vs strain, with the line `D = 1`).
pub fn line_plots(records: &[Record], path: LoadPath) -> Vec<(&'static str, LinePlot)> {
    let x_label = path.strain_label().to_string();
    let curve = |name: &str, f: &dyn Fn(&Record) -> Real| Series {
        name: name.to_string(),
        points: records.iter().map(|r| (r.strain, f(r))).collect(),
    };
    let (component, index) = match path {
        LoadPath::SimpleShear => ("tau_xy", (0, 1)),
        LoadPath::UniaxialStrain | LoadPath::UniaxialStress => ("tau_xx", (0, 0)),
    };
    vec![
        (
            "stress",
            LinePlot {
                title: "Stress-strain (Kirchhoff)".into(),
                x_label: x_label.clone(),
                y_label: "stress [MPa]".into(),
                series: vec![
                    curve("equivalent stress", &|r| r.equivalent_stress * 1e-6),
                    curve(component, &|r| r.tau[index] * 1e-6),
                ],
                hlines: Vec::new(),
            },
        ),
        (
            "temperature",
            LinePlot {
                title: "Temperature".into(),
                x_label: x_label.clone(),
                y_label: "temperature [K]".into(),
                series: vec![curve("temperature", &|r| r.temperature)],
                hlines: Vec::new(),
            },
        ),
        (
            "damage",
            LinePlot {
                title: "Damage and plastic strain".into(),
                x_label,
                y_label: "[-]".into(),
                series: vec![curve("damage D", &|r| r.damage), curve("plastic strain", &|r| r.eps_p)],
                hlines: vec![("failure D = 1".into(), 1.0)],
            },
        ),
    ]
}

/// Render [`line_plots`] to `<stem>_stress.png`, `<stem>_temperature.png` and
/// `<stem>_damage.png`; returns the paths written.
pub fn save_plots(stem: &Path, records: &[Record], path: LoadPath) -> Result<Vec<PathBuf>, DriverError> {
    let mut written = Vec::new();
    for (suffix, plot) in line_plots(records, path) {
        let mut name: OsString = stem.as_os_str().to_os_string();
        name.push(format!("_{suffix}.png"));
        let file = PathBuf::from(name);
        save_line_plot(&file, &plot)?;
        written.push(file);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::library::weldox_460e;
    use crate::material::Elastic;

    fn steel() -> Material {
        Material::Elastic(Elastic {
            density: 7850.0,
            youngs_modulus: 200e9,
            poisson_ratio: 0.3,
            room_temperature: 293.0,
            thermal: None,
        })
    }

    fn config(path: LoadPath, rate: Real, final_strain: Real, dt: Real) -> DriverConfig {
        DriverConfig { path, rate, final_strain, dt, initial_temperature: None }
    }

    #[test]
    fn steps_land_exactly_on_the_final_strain() {
        let r = run(&steel(), &config(LoadPath::UniaxialStrain, 1e3, -0.01, 3e-7)).unwrap();
        // t_end = 1e-5 s, ceil(1e-5 / 3e-7) = 34 steps.
        assert_eq!(r.len(), 35);
        assert!((r.last().unwrap().strain + 0.01).abs() < 1e-15);
        assert!((r.last().unwrap().time - 1e-5).abs() < 1e-18);
        // Compression: J = exp(-0.01), pressure positive.
        assert!((r.last().unwrap().jacobian - (-0.01f64).exp()).abs() < 1e-12);
        assert!(r.last().unwrap().pressure > 0.0);
    }

    #[test]
    fn invalid_settings_are_rejected_with_their_name() {
        let bad = |c: DriverConfig, want: &str| match run(&steel(), &c) {
            Err(DriverError::InvalidConfig { field, .. }) => assert_eq!(field, want),
            other => panic!("{other:?}"),
        };
        bad(config(LoadPath::SimpleShear, 0.0, 0.1, 1e-6), "rate");
        bad(config(LoadPath::SimpleShear, 1.0, 0.0, 1e-6), "final_strain");
        bad(config(LoadPath::SimpleShear, 1.0, 0.1, -1.0), "dt");
        bad(config(LoadPath::SimpleShear, 1.0, 1.0, 1e-12), "dt");
        let mut c = config(LoadPath::SimpleShear, 1.0, 0.1, 1e-3);
        c.initial_temperature = Some(Real::NAN);
        bad(c, "initial_temperature");
        let mut jc = weldox_460e();
        jc.rate_sensitivity = 0.0;
        jc.taylor_quinney = 2.0;
        match run(&Material::JohnsonCook(jc), &config(LoadPath::SimpleShear, 1.0, 0.1, 1e-3)) {
            Err(DriverError::InvalidMaterial(errors)) => assert_eq!(errors.len(), 2),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn non_finite_state_is_reported_with_its_step() {
        let broken = Material::Elastic(Elastic {
            youngs_modulus: Real::INFINITY,
            ..match steel() {
                Material::Elastic(e) => e,
                _ => unreachable!(),
            }
        });
        match run(&broken, &config(LoadPath::SimpleShear, 1.0, 0.01, 1e-3)) {
            Err(DriverError::NonFinite { step, field, .. }) => {
                assert_eq!((step, field), (1, "stress"))
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn uniaxial_stress_keeps_lateral_stress_zero_and_gives_youngs_modulus() {
        let r = run(&steel(), &config(LoadPath::UniaxialStress, 1.0, 1e-3, 1e-5)).unwrap();
        let last = r.last().unwrap();
        // Hypoelastic, small strain: τ_xx = E ε to O(ε).
        assert!((last.tau[(0, 0)] / 1e-3 / 200e9 - 1.0).abs() < 2e-3, "{}", last.tau[(0, 0)]);
        for rec in &r {
            assert!(rec.tau[(1, 1)].abs() <= 1e-9 * rec.tau[(0, 0)].abs().max(1.0));
            assert!(rec.tau[(2, 2)].abs() <= 1e-9 * rec.tau[(0, 0)].abs().max(1.0));
        }
    }

    #[test]
    fn uniaxial_stress_of_johnson_cook_keeps_lateral_stress_zero_through_yield() {
        for m in [weldox_460e(), crate::material::library::weldox_460e_borvik()] {
            let r = run(&Material::JohnsonCook(m), &config(LoadPath::UniaxialStress, 1e3, 0.1, 1e-6)).unwrap();
            let last = r.last().unwrap();
            assert!(last.eps_p > 0.09);
            for rec in &r {
                assert!(rec.tau[(1, 1)].abs() <= 1e-9 * rec.tau[(0, 0)].abs().max(1.0));
            }
            // Uniaxial tension: triaxiality 1/3.
            assert!((-last.pressure / last.equivalent_stress - 1.0 / 3.0).abs() < 1e-9);
        }
    }

    #[test]
    fn csv_round_trips_every_record() {
        let r = run(&Material::JohnsonCook(weldox_460e()), &config(LoadPath::SimpleShear, 1e4, 0.2, 1e-6)).unwrap();
        let mut buf = Vec::new();
        write_csv(&r, &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next().unwrap(), CSV_HEADER);
        let columns = CSV_HEADER.split(',').count();
        let rows: Vec<Vec<Real>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), r.len());
        for (row, rec) in rows.iter().zip(&r) {
            assert_eq!(row.len(), columns);
            assert_eq!(row[0], rec.time);
            assert_eq!(row[1], rec.strain);
            assert_eq!(row[2], rec.equivalent_stress);
            assert_eq!(row[4], rec.eps_p);
            assert_eq!(row[6], rec.temperature);
            assert_eq!(row[7], rec.damage);
            assert_eq!(row[11], rec.tau[(0, 1)]);
            assert_eq!(row[14], rec.jacobian);
        }
    }

    #[test]
    fn save_csv_writes_a_file() {
        let r = run(&steel(), &config(LoadPath::SimpleShear, 1.0, 0.01, 1e-3)).unwrap();
        let path = std::env::temp_dir().join(format!("plugsim-driver-{}.csv", std::process::id()));
        save_csv(&path, &r).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(text.lines().count(), r.len() + 1);
    }

    #[test]
    fn plots_carry_the_records() {
        let r = run(&Material::JohnsonCook(weldox_460e()), &config(LoadPath::SimpleShear, 1e4, 0.2, 1e-6)).unwrap();
        let plots = line_plots(&r, LoadPath::SimpleShear);
        let names: Vec<&str> = plots.iter().map(|(n, _)| *n).collect();
        assert_eq!(names, ["stress", "temperature", "damage"]);
        let stress = &plots[0].1.series[0].points;
        assert_eq!(stress.len(), r.len());
        let last = r.last().unwrap();
        assert_eq!(*stress.last().unwrap(), (last.strain, last.equivalent_stress * 1e-6));
        assert_eq!(plots[2].1.series[0].points.last().unwrap().1, last.damage);
    }
}
