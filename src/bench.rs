//! Fixed benchmark workloads (`plugsim bench`): each returns measured
//! figures; the CLI prints them. Throughput is reported as quadrature-point
//! updates per second (velocity gradient + stress update + force assembly,
//! i.e. whole steps) and particle-steps per second, always beside a
//! baseline measured in the same run (one thread; the alternative force
//! assembly).
//!
//! Deliberately not covered: neighbour search alone (it is part of the
//! shape-function build), the contact search alone (below 1 % of a step in
//! the plugging case), output writing (timed in every run's summary).

use crate::case::Case;
use crate::material::{Constitutive, Material, PointState, StepKinematics};
use crate::math::{Real, Tensor3, Vec2};
use crate::model::Gather;
use crate::run::{build_simulation, RunError};
use crate::shape::{build_table, rebuild_rows, AllVisible, ShapeTable};
use crate::step::Simulation;
use rayon::prelude::*;
use std::time::Instant;

/// One measured figure.
#[derive(Clone, Debug)]
pub struct Figure {
    pub name: String,
    pub value: Real,
    pub unit: &'static str,
}

fn fig(name: impl Into<String>, value: Real, unit: &'static str) -> Figure {
    Figure { name: name.into(), value, unit }
}

/// What a whole run of the built-in case `name` to `end` s that took
/// `wall` s says against \[RL10\]'s published run of the same case
/// ([`crate::validation::published_run`]): the speed-up where the run
/// covers the paper's simulated time, else how to make it comparable;
/// `None` for a case the paper did not time.
pub fn against_paper(name: &str, end: Real, wall: Real) -> Option<String> {
    let (paper, simulated) = crate::validation::published_run(name)?;
    Some(if (end - simulated).abs() <= 1e-6 * simulated {
        format!(
            "speed-up over [RL10]'s published run of this case ({paper:.0} s on a 2-core Core 2 Duo): {:.0}x",
            paper / wall
        )
    } else {
        format!(
            "[RL10] published {paper:.0} s for {:.0} us of this case: --whole {:e} compares with it",
            simulated * 1e6,
            simulated
        )
    })
}

/// Run `f` inside a pool of `threads` threads.
pub fn with_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool").install(f)
}

/// Shape-function table build at the quadrature points of a case: rows/s.
pub fn shape_build(case: &Case, threads: usize) -> Result<Figure, RunError> {
    let sim = build_simulation(case)?;
    let m = &sim.model;
    let t = Instant::now();
    let table = with_threads(threads, || {
        build_table(&m.quad.x0, &m.particles.x0, &m.particles.support, &m.particles.volume, &AllVisible)
    })
    .map_err(|source| crate::model::ModelError::Shape { body: "bench".into(), source })?;
    let s = t.elapsed().as_secs_f64();
    Ok(fig(
        format!("shape-function build, {threads} thread(s), {} entries", table.nnz()),
        m.quad.len() as Real / s,
        "rows/s",
    ))
}

/// Single-point material updates per second (one thread), in the elastic
/// regime and in plastic flow, for `material`.
pub fn material_kernel(material: &Material, n: usize) -> Vec<Figure> {
    let mut out = Vec::new();
    for (label, rate) in [("elastic", 1e-3), ("plastic", 1e4)] {
        let mut d = Tensor3::zeros();
        d[(0, 1)] = 0.5 * rate;
        d[(1, 0)] = 0.5 * rate;
        let k = StepKinematics { d, w: Tensor3::zeros(), dt: 4e-8 };
        let mut s = PointState::at_rest(material.initial_temperature());
        // bring the point into the regime first
        for _ in 0..2000 {
            s = material.update(&s, &k);
        }
        let t = Instant::now();
        let mut acc = 0.0;
        for _ in 0..n {
            let next = material.update(&s, &k);
            acc += next.tau[(0, 1)];
            s = if label == "elastic" { PointState { tau: s.tau, ..next } } else { next };
        }
        std::hint::black_box(acc);
        out.push(fig(
            format!("material update ({label}), 1 thread"),
            n as Real / t.elapsed().as_secs_f64(),
            "updates/s",
        ));
    }
    out
}

/// Whole steps on a case's model: quadrature-point updates/s and
/// particle-steps/s with `threads` threads.
pub fn steps(case: &Case, threads: usize, n: usize) -> Result<Vec<Figure>, RunError> {
    with_threads(threads, || {
        let mut sim = build_simulation(case)?;
        warm_up(&mut sim)?;
        let s = timed_steps(&mut sim, n)?;
        let (nq, np) = (sim.model.quad.len() as Real, sim.model.particles.len() as Real);
        Ok(vec![
            fig(format!("whole steps, {threads} thread(s)"), nq * n as Real / s, "qp-updates/s"),
            fig(format!("whole steps, {threads} thread(s)"), np * n as Real / s, "particle-steps/s"),
        ])
    })
}

/// What the material stage costs without plasticity: `n` steps timed on
/// the case's model after stepping to `warm_until` s of response (so that
/// the impact zone flows and heats), first as the case is, then with
/// every Johnson–Cook body made hypoelastic with the same density, moduli
/// and thermal constants ([`Material::elastic_twin`]). The second figure is the sweep's cost
/// without the plasticity: reading the shape table, the kinematics, the
/// elastic trial and the state's loads and stores — the part that no
/// faster Johnson–Cook update can remove. Both as nanoseconds of the
/// stage per point update, with `threads` threads (times `threads`: core
/// time per update).
pub fn material_floor(case: &Case, threads: usize, warm_until: Real, n: usize) -> Result<Vec<Figure>, RunError> {
    with_threads(threads, || {
        let mut sim = build_simulation(case)?;
        while sim.time < warm_until {
            sim.step().map_err(unstable)?;
        }
        let per_update = |sim: &mut Simulation| -> Result<Real, RunError> {
            let before = sim.timers.material;
            (0..n).try_for_each(|_| sim.step().map_err(unstable))?;
            let stage = (sim.timers.material - before).as_secs_f64();
            Ok(stage * threads as Real * 1e9 / (sim.model.quad.len() * n) as Real)
        };
        let plastic = per_update(&mut sim)?;
        for m in sim.model.materials.iter_mut() {
            *m = m.elastic_twin();
        }
        let elastic = per_update(&mut sim)?;
        Ok(vec![
            fig(format!("material stage as the case is, {threads} thread(s)"), plastic, "core-ns/qp-update"),
            fig(
                format!("material stage, plate made elastic (the floor), {threads} thread(s)"),
                elastic,
                "core-ns/qp-update",
            ),
        ])
    })
}

/// The machine's own ceiling for the thread speed-up of [`steps`]:
/// `copies` independent one-thread runs of the same steps at once (each
/// its own simulation in its own pool, nothing shared), as aggregate
/// quadrature-point updates/s. Against the one-thread figure of [`steps`]
/// the ratio is what the cores give to code that loses nothing to serial
/// work or imbalance; below `copies`, memory bandwidth, the shared cache
/// or the clock speed caps the scaling, and no change to the solver's
/// threading can win that back. The timed windows start together (after
/// five warm-up steps each).
pub fn independent_copies(case: &Case, copies: usize, n: usize) -> Result<Figure, RunError> {
    let sims = (0..copies.max(1)).map(|_| build_simulation(case)).collect::<Result<Vec<_>, _>>()?;
    let nq = sims[0].model.quad.len() as Real;
    let start = std::sync::Barrier::new(sims.len());
    let seconds: Vec<Result<Real, RunError>> = std::thread::scope(|scope| {
        let runs: Vec<_> = sims
            .into_iter()
            .map(|mut sim| {
                let start = &start;
                scope.spawn(move || {
                    with_threads(1, || {
                        let warm = warm_up(&mut sim);
                        // Every copy reaches the barrier, also one that failed.
                        start.wait();
                        warm?;
                        timed_steps(&mut sim, n)
                    })
                })
            })
            .collect();
        runs.into_iter().map(|r| r.join().expect("a benchmark copy panicked")).collect()
    });
    let mut rate = 0.0;
    for s in seconds {
        rate += nq * n as Real / s?;
    }
    Ok(fig(format!("whole steps, {copies} independent one-thread copies at once (sum)"), rate, "qp-updates/s"))
}

/// The steps every workload takes before it measures: past the first
/// contact and the scratch's first sizing.
fn warm_up(sim: &mut Simulation) -> Result<(), RunError> {
    (0..5).try_for_each(|_| sim.step().map_err(unstable))
}

/// Seconds taken by `n` steps.
fn timed_steps(sim: &mut Simulation, n: usize) -> Result<Real, RunError> {
    let t = Instant::now();
    for _ in 0..n {
        sim.step().map_err(unstable)?;
    }
    Ok(t.elapsed().as_secs_f64())
}

fn unstable(error: crate::step::SolverError) -> RunError {
    RunError::Unstable {
        error: Box::new(error),
        last_snapshot: "(none: benchmark)".into(),
        at_failure: true,
        dir: "(none)".into(),
    }
}

/// What the per-step and per-history-row diagnostics cost against a
/// whole step, on the state after a few steps: the fastest particle
/// ([`crate::step::fastest_particle`], every step: one interpolation of
/// the velocity field at each particle) and the gap between the
/// coefficients and the field ([`crate::step::coefficient_gap`], once per
/// `history.csv` row: one interpolation of the displacement field). As
/// passes/s, and each pass as a fraction of one step with `threads`
/// threads.
pub fn diagnostics(case: &Case, threads: usize, n: usize) -> Result<Vec<Figure>, RunError> {
    with_threads(threads, || {
        let mut sim = build_simulation(case)?;
        warm_up(&mut sim)?;
        let step = timed_steps(&mut sim, n)? / n as Real;
        let mut out = Vec::new();
        type Pass = fn(&crate::model::Model) -> (Real, usize);
        let passes: [(&str, Pass); 2] = [
            ("fastest particle (every step)", crate::step::fastest_particle),
            ("coefficient gap (every history row)", crate::step::coefficient_gap),
        ];
        for (name, pass) in passes {
            let t = Instant::now();
            for _ in 0..n {
                std::hint::black_box(pass(&sim.model));
            }
            let each = t.elapsed().as_secs_f64() / n as Real;
            out.push(fig(format!("{name}, {threads} thread(s)"), 1.0 / each, "passes/s"));
            out.push(fig(format!("{name}: one pass, {threads} thread(s)"), each / step, "whole steps"));
        }
        Ok(out)
    })
}

/// Internal-force assembly: the production gather (each particle sums its
/// own entries in fixed order) against a scatter into per-thread force
/// buffers reduced at the end (the usual alternative; not bit-identical
/// across thread counts). Assemblies/s on the state after a few steps.
pub fn force_assembly(case: &Case, threads: usize, n: usize) -> Result<Vec<Figure>, RunError> {
    with_threads(threads, || {
        let mut sim = build_simulation(case)?;
        warm_up(&mut sim)?;
        let m = &sim.model;
        let np = m.particles.len();
        let t = Instant::now();
        let mut f = vec![Vec2::zeros(); np];
        for _ in 0..n {
            crate::step::gather_internal_force(&sim.model, &mut f);
        }
        let gather_rate = n as Real / t.elapsed().as_secs_f64();
        std::hint::black_box(&f);
        let t = Instant::now();
        for _ in 0..n {
            f = scatter(&sim);
        }
        let scatter_rate = n as Real / t.elapsed().as_secs_f64();
        std::hint::black_box(&f);
        Ok(vec![
            fig(format!("force assembly: gather (production), {threads} thread(s)"), gather_rate, "assemblies/s"),
            fig(
                format!("force assembly: per-thread scatter (alternative), {threads} thread(s)"),
                scatter_rate,
                "assemblies/s",
            ),
        ])
    })
}

/// The transpose after a crack split: patching the gather where the rows
/// of a split's neighbourhood changed (production, [`Gather::patch_into`])
/// against building it afresh (what every split did before). The rows
/// within three particle supports of the plate's centre are rebuilt (with
/// unchanged visibility: the work of a patch does not depend on what
/// changed). Updates/s.
pub fn gather_update(case: &Case, threads: usize, n: usize) -> Result<Vec<Figure>, RunError> {
    with_threads(threads, || {
        let sim = build_simulation(case)?;
        let m = &sim.model;
        let (np, p) = (m.particles.len(), &m.particles);
        let (lo, hi) = p.x0.iter().fold((p.x0[0], p.x0[0]), |(lo, hi), x| (lo.inf(x), hi.sup(x)));
        let centre = (lo + hi) * 0.5;
        let reach = 3.0 * p.support.iter().cloned().fold(0.0, Real::max);
        let rows: Vec<usize> = (0..m.quad.len()).filter(|&q| (m.quad.x0[q] - centre).amax() <= reach).collect();
        let mut table = m.qp_shape.clone();
        let mut before = ShapeTable::default();
        rebuild_rows(&mut table, &mut before, &rows, &m.quad.x0, &p.x0, &p.support, &p.volume, &AllVisible, &|_| None)
            .map_err(|source| crate::model::ModelError::Shape { body: "bench".into(), source })?;
        let touched = Gather::touched(&before, &table, &rows, np);
        let mut out = Gather::default();
        let t = Instant::now();
        for _ in 0..n {
            m.gather.patch_into(&before.offsets, &table, &rows, &touched, np, &mut out);
        }
        let patch_rate = n as Real / t.elapsed().as_secs_f64();
        let t = Instant::now();
        for _ in 0..n {
            std::hint::black_box(Gather::new(&table, np));
        }
        let fresh_rate = n as Real / t.elapsed().as_secs_f64();
        Ok(vec![
            fig(
                format!("gather after a split ({} rows): patched (production), {threads} thread(s)", rows.len()),
                patch_rate,
                "updates/s",
            ),
            fig(format!("gather after a split: rebuilt (before), {threads} thread(s)"), fresh_rate, "updates/s"),
        ])
    })
}

fn scatter(sim: &Simulation) -> Vec<Vec2> {
    let m = &sim.model;
    let np = m.particles.len();
    let (tab, pw, pw_zz, xq, mode) = (&m.qp_shape, &m.quad.pw, &m.quad.pw_zz, &m.quad.x0, m.mode);
    (0..m.quad.len())
        .into_par_iter()
        .fold(
            || vec![Vec2::zeros(); np],
            |mut acc, q| {
                for k in tab.range(q) {
                    acc[tab.index[k] as usize] +=
                        mode.internal_force(&pw[q], pw_zz[q], tab.value[k], &tab.grad[k], &xq[q]);
                }
                acc
            },
        )
        .reduce(
            || vec![Vec2::zeros(); np],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
                a
            },
        )
}

#[cfg(test)]
mod tests {
    use super::against_paper;

    /// The comparison `plugsim bench --whole` prints: the speed-up over the
    /// paper's timed run where the end time matches it, else how to compare.
    #[test]
    fn against_paper_compares_only_with_the_papers_timed_runs() {
        let line = against_paper("borvik-1", 118e-6, 20.0).unwrap();
        assert!(line.contains("3312 s") && line.ends_with(": 166x"), "{line}");
        let line = against_paper("borvik-1-plane-strain-fine", 30e-6, 20.0).unwrap();
        assert!(line.contains("13680 s for 118 us") && line.contains("--whole 1.18e-4"), "{line}");
        assert_eq!(against_paper("borvik-1-axisymmetric", 118e-6, 20.0), None);
    }
}
