//! `plugsim ballistic` end to end on a small plate, and the residual
//! velocity every run reports (`plugsim::residual`).

use plugsim::ballistic::{
    along_flight, at_rows, at_speed, find_limit, flight, run_speeds, select_projectile, write_files, Event, Projectile,
    Setup, Study,
};
use plugsim::case::Case;
use plugsim::residual::Verdict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

mod common;

/// The shared small impact (`tests/common/small_impact.toml`), run until
/// 2 µs after the projectile's release, at most 100 µs.
fn small_plate() -> String {
    assert!(common::SMALL_IMPACT.contains("end = 12.0e-6"), "the shared case's end time moved");
    common::SMALL_IMPACT.replace("end = 12.0e-6", "end = 100.0e-6\nstop_after_release = 2.0e-6")
        + "[output]\ninterval = 1.0e-5\n"
}

/// An empty directory of this process under the system's temporary one.
fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("plugsim-ballistic-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fresh directory holding the small plate as `small.toml`: (the
/// directory, the case file).
fn small_plate_file(name: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = fresh_dir(name);
    let case = dir.join("small.toml");
    std::fs::write(&case, small_plate()).unwrap();
    (dir, case)
}

/// `plugsim --threads 1 ballistic CASE ARGS...`.
fn ballistic_cli(case: &std::path::Path, args: &[&str]) -> std::process::Output {
    common::plugsim(&[&["--threads", "1", "ballistic", case.to_str().unwrap()], args].concat())
}

fn setup(name: &str, jobs: usize) -> Setup {
    let case = Case::from_str_with(&small_plate(), "small", &[]).unwrap();
    let projectile = select_projectile(&case, "small", None).unwrap();
    let out_dir = fresh_dir(name);
    Setup {
        case,
        label: "small".into(),
        overrides: vec![],
        projectile,
        jobs,
        threads_per_run: 1,
        out_dir,
        max_time: 100.0e-6,
        interrupt: None,
        resume: false,
    }
}

/// The history has the axial force; a run that perforates reports its
/// residual velocity along the flight once that force has vanished, even
/// while the hole's wall still touches the projectile's side.
#[test]
fn a_perforating_run_reports_its_residual_velocity() {
    use plugsim::run::{execute, RunConfig, RunInfo};
    let s = setup("single", 1);
    let cfg = RunConfig::new(s.out_dir.join("run"), true, RunInfo::current("test", &[]));
    let summary = execute(&s.case, &cfg, &mut |_| {}).unwrap();
    let history = plugsim::output::read_history(&cfg.out_dir).unwrap();
    let f = history.column("projectile_f_axial").expect("the axial force column");
    let fy = history.column("projectile_fy").unwrap();
    // Flight along -y: the axial force is -fy.
    assert!(f.iter().zip(fy).all(|(a, b)| (a + b).abs() <= 1e-9 * b.abs().max(1.0)));
    assert!(f.iter().any(|&f| f < 0.0), "braked along its flight");
    let (name, verdict) = &summary.flights[0];
    assert_eq!(name, "projectile");
    let Verdict::Perforated { residual, since } = *verdict else { panic!("{verdict:?}") };
    let vy = summary.rigid_velocities[0].1[1];
    assert_eq!(residual, -vy);
    assert!(residual > 0.0 && residual < 400.0, "{residual}");
    assert!(summary.time < 100e-6 && summary.time >= since + 2e-6, "stopped early: {} s", summary.time);
    std::fs::remove_dir_all(&s.out_dir).ok();
}

/// What a run records of its speed and end time are `--set` overrides
/// that rerun it: applied to the case's text they give the case the study
/// ran (its `run_info.toml` reproduces the run with `plugsim run --set`).
#[test]
fn a_runs_recorded_overrides_rerun_it() {
    let case = Case::from_str_with(&small_plate(), "small", &[]).unwrap();
    let p = select_projectile(&case, "small", None).unwrap();
    assert_eq!(p, Projectile::Rigid(0));
    let (fast, set) = at_speed(&case, p, 183.33333333333334, 300e-6);
    assert_eq!(set, ["rigid_bodies.projectile.velocity=[0.0, -183.33333333333334]", "time.end=3e-4"]);
    assert_eq!(Case::from_str_with(&small_plate(), "small", &set).unwrap(), fast);
    assert_ne!(fast, case);
    // a case without its own stop after the release is given the study's, and says so
    let own = small_plate().replace("stop_after_release = 2.0e-6", "");
    let case = Case::from_str_with(&own, "small", &[]).unwrap();
    let (fast, set) = at_speed(&case, p, 400.0, 0.0);
    assert_eq!(set, ["rigid_bodies.projectile.velocity=[0.0, -400.0]", "time.stop_after_release=2e-5"]);
    assert_eq!(Case::from_str_with(&own, "small", &set).unwrap(), fast);
}

#[test]
fn a_case_without_a_moving_rigid_body_is_refused_by_name() {
    let text = small_plate().replace("velocity = [0.0, -400.0]", "velocity = [0.0, 0.0]");
    let case = Case::from_str_with(&text, "still", &[]).unwrap();
    let e = select_projectile(&case, "still.toml", None).unwrap_err().to_string();
    assert!(e.contains("still.toml") && e.contains("no rigid body with an initial velocity"), "{e}");
    let e = select_projectile(&case, "still.toml", Some("bullet")).unwrap_err().to_string();
    assert!(e.contains("no moving body named 'bullet'"), "{e}");
    let plain = Case::from_str_with(include_str!("../cases/elastic-strike.toml"), "elastic-strike", &[]).unwrap();
    let e = select_projectile(&plain, "elastic-strike", None).unwrap_err().to_string();
    assert!(e.contains("elastic-strike") && e.contains("(rigid bodies: none)"), "{e}");
}

#[test]
fn speeds_run_side_by_side_and_the_limit_is_bracketed() {
    let s = setup("limit", 2);
    let mut study = Study::default();
    let mut events = Vec::new();
    let mut writes = 0;
    let mut report = |st: &Study| {
        writes += 1;
        write_files(&s.out_dir, "test", "test", st, &[(300.0, 200.0)]).map(|_| ())
    };
    run_speeds(&s, &[300.0, 500.0], &mut study, &mut report, &mut |e| events.push(e)).unwrap();
    assert_eq!(study.shots.len(), 2, "{:?}", study.failures);
    let (slow, fast) = (&study.shots[0], &study.shots[1]);
    assert!(slow.perforated() && fast.perforated(), "{:?} {:?}", slow.verdict, fast.verdict);
    assert!(fast.residual().unwrap() > slow.residual().unwrap(), "{:?} {:?}", slow.verdict, fast.verdict);
    assert!(slow.plug_mass.unwrap() > 0.0 && slow.perforation.is_some());
    find_limit(&s, (50.0, 300.0), 25.0, &mut study, &mut report, &mut |e| events.push(e)).unwrap();
    let limit = study.limit.clone().unwrap();
    let (v_bl, half) = limit.estimate().expect("bracketed");
    assert!(half <= 25.0 && v_bl > 50.0 && v_bl < 300.0, "{limit:?}");
    let held = study.shots.iter().find(|x| x.speed == limit.held.unwrap()).unwrap();
    // Held, or undecided at the end without a plug cut out (counted held).
    assert!(
        held.residual() == Some(0.0) || matches!(held.verdict, Verdict::Undecided { plug: false, .. }),
        "{:?}",
        held.verdict
    );
    // Each held run is below each perforating one, and v_r rises with v_i.
    let perforating: Vec<_> = study.shots.iter().filter(|x| x.perforated()).collect();
    assert!(perforating.windows(2).all(|w| w[1].residual() >= w[0].residual()), "{:?}", study.shots);
    // A plug was cut out by cracks, so each perforating run reports how far
    // along its locus the material was where they grew.
    assert!(perforating.iter().all(|x| x.tip_damage.is_some_and(|d| d > 0.0 && d.is_finite())), "{:?}", study.shots);
    // Each perforating run's speed at the cut is the projectile's when the
    // plug came out: below the impact speed, and no lower than where it
    // leaves (the plate only brakes it).
    for x in &perforating {
        let cut = x.cut_speed.unwrap_or_else(|| panic!("a cut and no speed at it: {x:?}"));
        assert!(cut < x.speed && cut >= x.residual().unwrap() - 1e-9, "{cut} against {x:?}");
    }
    assert!(study.shots.iter().filter(|x| x.perforation.is_none()).all(|x| x.cut_speed.is_none()));
    // The small plate's cracks run in material that still hardens, as in
    // the full-size plates (docs/validation.md).
    assert!(perforating.iter().all(|x| x.tip_hardening.is_some_and(|h| h > 0.0 && h.is_finite())), "{:?}", study.shots);
    // A run stopped early was stopped because it was decided: the early stop
    // and the verdict read the same states (src/run.rs).
    for x in &study.shots {
        if x.end_time < 99.0e-6 {
            assert!(!matches!(x.verdict, Verdict::Undecided { .. }), "stopped at {} s: {:?}", x.end_time, x.verdict);
        }
    }
    assert_eq!(writes, study.shots.len(), "the table is written after every run");
    let csv = std::fs::read_to_string(s.out_dir.join("ballistic.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + study.shots.len(), "{csv}");
    // Each run's fastest particle beside the bound it is held to: here, with
    // no nose, the free-surface doubling.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let (at_v, at_bound) = (0, header.iter().position(|&c| c == "fastest_bound_m_s").expect("the bound's column"));
    assert_eq!(header[at_bound - 1], "fastest_particle_m_s");
    for row in csv.lines().skip(1) {
        let cells: Vec<f64> = row.split(',').map(|c| c.parse().unwrap_or(f64::NAN)).collect();
        assert_eq!(format!("{:.1}", cells[at_bound]), format!("{:.1}", 2.0 * cells[at_v]), "{row}");
    }
    for f in ["ballistic.md", "ballistic.png"] {
        assert!(s.out_dir.join(f).exists(), "{f}");
    }
    assert!(study.shots.iter().all(|x| x.dir.join("history.csv").exists()));
    // A rectangle is no nose: its runs are held to the free-surface doubling.
    assert!(study.shots.iter().all(|x| x.speed_bound.is_none()), "{:?}", study.shots);
    assert!(events.iter().any(|e| matches!(e, Event::Round { .. })));
    std::fs::remove_dir_all(&s.out_dir).ok();
}

/// A projectile braked below 5 % of its impact speed with no plug cut out
/// is held (`plugsim::residual`, "Held without a plug"): at 60 m/s the
/// small plate slows it through 3 m/s before it stops, and the run ends the
/// study's wait after that, not after the stop; the history shows the
/// speed between 1 % and 5 % of the impact at the verdict's time.
#[test]
fn a_projectile_slowed_with_no_plug_is_held_and_the_run_ends() {
    let s = setup("slow", 1);
    let mut study = Study::default();
    run_speeds(&s, &[60.0], &mut study, &mut |_| Ok(()), &mut |_| {}).unwrap();
    let shot = &study.shots[0];
    let Verdict::Held { since } = shot.verdict else { panic!("{:?}", shot.verdict) };
    assert!(shot.plug_mass.unwrap_or(0.0) == 0.0 && shot.perforation.is_none(), "{shot:?}");
    let history = plugsim::output::read_history(&shot.dir).unwrap();
    let (t, vy) = (history.column("time").unwrap(), history.column("projectile_vy").unwrap());
    let at = t.iter().position(|&x| x == since).expect("the verdict's time is a history row");
    let slowed = -vy[at];
    assert!(slowed > 0.01 * 60.0 && slowed <= 0.05 * 60.0, "{slowed} m/s at {since} s");
    assert!(-vy[at - 1] > 0.05 * 60.0, "the first row at 5 % or below");
    // Ended the wait (2 us) after it, within a history row's steps.
    assert!(shot.end_time >= since + 2.0e-6 && shot.end_time < since + 2.5e-6, "{} {since}", shot.end_time);
    std::fs::remove_dir_all(&s.out_dir).ok();
}

/// A run the plate has neither held nor let go at the case's end time goes
/// on, up to the study's max time, and stops once decided; with the max
/// time at the end time it stops undecided there, as before.
#[test]
fn a_run_undecided_at_the_end_time_goes_on_until_decided() {
    let mut s = setup("decide", 1);
    s.case.time.end = 6.0e-6; // the projectile is still in the plate
    s.max_time = s.case.time.end;
    let mut study = Study::default();
    run_speeds(&s, &[300.0], &mut study, &mut |_| Ok(()), &mut |_| {}).unwrap();
    let cut = &study.shots[0];
    assert!(matches!(cut.verdict, Verdict::Undecided { .. }), "{:?}", cut.verdict);
    assert!((cut.end_time - 6.0e-6).abs() < 0.1e-6, "{}", cut.end_time);
    s.max_time = 100.0e-6;
    let mut study = Study::default();
    run_speeds(&s, &[300.0], &mut study, &mut |_| Ok(()), &mut |_| {}).unwrap();
    let shot = &study.shots[0];
    let Verdict::Perforated { residual, since } = shot.verdict else { panic!("{:?}", shot.verdict) };
    assert!(residual > 0.0 && residual < 300.0, "{residual}");
    // stopped by the early stop (2 us after the release), not at the max time
    assert!(shot.end_time > 6.0e-6 && shot.end_time < 100.0e-6, "{}", shot.end_time);
    assert!(shot.end_time >= since + 2.0e-6, "{} {since}", shot.end_time);
    let info = std::fs::read_to_string(shot.dir.join("run_info.toml")).unwrap();
    assert!(info.contains("time.end=1e-4"), "the run's provenance records the longer end: {info}");
    std::fs::remove_dir_all(&s.out_dir).ok();
}

/// An interrupt after the first run keeps that run in the table and stops
/// the rest.
#[test]
fn an_interrupt_keeps_the_finished_runs() {
    let mut s = setup("interrupt", 1);
    let flag = Arc::new(AtomicBool::new(false));
    s.interrupt = Some(flag.clone());
    let mut study = Study::default();
    let mut report = |st: &Study| write_files(&s.out_dir, "test", "test", st, &[]).map(|_| ());
    let mut progress = |e: Event| {
        if matches!(e, Event::Finished { .. }) {
            flag.store(true, Ordering::SeqCst);
        }
    };
    run_speeds(&s, &[450.0, 350.0, 250.0], &mut study, &mut report, &mut progress).unwrap();
    assert!(study.interrupted);
    assert_eq!(study.shots.len(), 1);
    assert_eq!(study.shots[0].speed, 450.0);
    // the rest: stopped in flight (the next one may have started before
    // the flag was seen) or not started, none lost
    let mut rest: Vec<f64> = study.paused.iter().map(|p| p.speed).chain(study.not_started.iter().copied()).collect();
    rest.sort_by(f64::total_cmp);
    assert_eq!(rest, vec![250.0, 350.0], "{:?} {:?}", study.paused, study.not_started);
    assert!(study.not_started.contains(&250.0), "{:?}", study.not_started);
    let csv = std::fs::read_to_string(s.out_dir.join("ballistic.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().starts_with("450.00,"), "{csv}");
    assert_eq!(csv.lines().count(), 2);
    // A study already interrupted runs nothing more.
    run_speeds(&s, &[250.0], &mut study, &mut report, &mut |_| {}).unwrap();
    assert_eq!(study.shots.len(), 1);
    std::fs::remove_dir_all(&s.out_dir).ok();
}

/// `plugsim ballistic --rows`: the whole study at each resolution, each in
/// its own directory, and the table side by side; a resolution that cannot
/// be made is refused before any run starts.
#[test]
fn the_command_runs_the_study_at_each_resolution() {
    let (dir, case) = small_plate_file("rows");
    let plugsim = |args: &[&str]| ballistic_cli(&case, args);
    let out = dir.join("out");
    // Given out of order and twice: run coarsest first, each once.
    let o = plugsim(&["--rows", "9,5,9", "--speeds", "500", "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for rows in [5, 9] {
        let md = std::fs::read_to_string(out.join(format!("rows-{rows}/ballistic.md"))).unwrap();
        assert!(md.contains("| 500.00 |"), "{md}");
    }
    let md = std::fs::read_to_string(out.join("convergence.md")).unwrap();
    assert!(md.contains("| 5 | 0.800 |") && md.contains("| 9 | 0.444 |") && md.contains("| spread |"), "{md}");
    assert!(
        md.contains("| v_r's sensitivity to the limit (% per %) |") && md.contains("Sensitivity to the limit:"),
        "{md}"
    );
    assert!(md.contains("bodies.plate.rectangle.layers=5"), "{md}");
    assert!(md.find("| 5 | 0.800 |") < md.find("| 9 | 0.444 |") && md.contains("| step 5 → 9 rows |"), "{md}");
    assert_eq!(std::fs::read_to_string(out.join("convergence.csv")).unwrap().lines().count(), 3);
    assert!(out.join("convergence.png").exists());
    // 1 row is no plate: refused, nothing run.
    let bad = dir.join("bad");
    let o = plugsim(&["--rows", "9,1", "--speeds", "500", "--out", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("at least 2"), "{stderr}");
    assert!(!bad.exists(), "refused before any run");
    // The option's help states the default the library uses.
    let o = common::plugsim(&["ballistic", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout);
    let default = format!("default: {} times the case's end time", plugsim::ballistic::DECIDE_FACTOR);
    assert!(help.contains(&default), "{help}");
    // A max time before the case's end time is refused, naming the option.
    let o = plugsim(&["--speeds", "500", "--max-time", "1e-6", "--out", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("--max-time must be at least"), "{stderr}");
    assert!(!bad.exists(), "refused before any run");
    // A range of speeds that runs backwards is refused, naming the option.
    let o = plugsim(&["--speeds", "400,520:500:10", "--out", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("--speeds") && stderr.contains("'520:500:10'"), "{stderr}");
    assert!(!bad.exists(), "refused before any run");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With fewer speeds than `--jobs`, the rungs of a ladder run side by side
/// (each with the jobs its speeds use), their progress lines tagged with
/// the rung; every run gives the same bits as when they run in turn.
#[test]
fn rungs_with_fewer_speeds_than_jobs_run_side_by_side() {
    let (dir, case) = small_plate_file("side-by-side");
    let plugsim = |args: &[&str]| ballistic_cli(&case, args);
    let (alone, together) = (dir.join("in-turn"), dir.join("side-by-side"));
    for (out, jobs) in [(&alone, "1"), (&together, "2")] {
        let o = plugsim(&["--rows", "5,9", "--speeds", "500", "--jobs", jobs, "--out", out.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{stderr}");
        let tagged = stderr.contains("5 rows: 500.00 m/s started") && stderr.contains("9 rows: 500.00 m/s started");
        assert_eq!(tagged, jobs == "2", "{stderr}");
    }
    for rows in [5, 9] {
        let history =
            |out: &std::path::Path| std::fs::read(out.join(format!("rows-{rows}/v500.00/history.csv"))).unwrap();
        assert!(history(&alone) == history(&together), "{rows} rows: the same run whichever way");
    }
    let md = std::fs::read_to_string(together.join("convergence.md")).unwrap();
    assert!(md.find("| 5 | 0.800 |") < md.find("| 9 | 0.444 |"), "the rungs in order: {md}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `plugsim ballistic --phases`: the study at each lattice phase of the
/// rim, each in its own directory with the edge where asked, and the
/// envelope over the phases; a grid whose fine zone cannot hold the
/// shifted column is refused before any run, naming the field.
#[test]
fn the_command_runs_the_study_at_each_lattice_phase() {
    let (dir, case) = small_plate_file("phases");
    let plugsim = |args: &[&str]| ballistic_cli(&case, args);
    let zone = "bodies.plate.rectangle.fine_half_width=0.006";
    let out = dir.join("out");
    let o =
        plugsim(&["--set", zone, "--phases", "2", "--rows", "5,9", "--speeds", "500", "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    for rows in [5, 9] {
        for (phase, says) in [("+0.00", "lies +0.00 of a spacing"), ("+0.50", "0.50 of a spacing")] {
            let md = std::fs::read_to_string(out.join(format!("rows-{rows}/phase-{phase}/ballistic.md"))).unwrap();
            assert!(md.contains("| 500.00 |") && md.contains(says), "{rows} rows, phase {phase}: {md}");
        }
    }
    let md = std::fs::read_to_string(out.join("convergence.md")).unwrap();
    assert!(md.starts_with("# Ballistic study at 2 resolutions at 2 lattice phases"), "{md}");
    assert!(md.contains("| 5 rows, 2 phases |") && md.contains("| 9 rows, 2 phases |"), "{md}");
    assert!(
        md.contains("- 5 rows, phase +0.50: bodies.plate.rectangle.layers=5 bodies.plate.rectangle.fine_spacing="),
        "{md}"
    );
    assert_eq!(std::fs::read_to_string(out.join("convergence.csv")).unwrap().lines().count(), 5);
    // Spacings that grow from the middle with no uniform zone around the
    // edge: no column to shift.
    let bad = dir.join("bad");
    let grown = "bodies.plate.rectangle.growth=1.2";
    let o = plugsim(&["--set", grown, "--phases", "2", "--speeds", "500", "--out", bad.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("outside the target's uniform fine zone"), "{stderr}");
    assert!(!bad.exists(), "refused before any run");
    let o = plugsim(&["--phases", "1", "--speeds", "500", "--out", bad.to_str().unwrap()]);
    assert!(!o.status.success() && !bad.exists());
    // `--phase` runs the phases named, and only those: the 9-row rung's
    // edge midway between two columns, and a quarter spacing inward of a
    // column (the same fitted spacing as `--phases 2`'s and `--phases 4`'s).
    let one = dir.join("one");
    let o = plugsim(&[
        "--set",
        zone,
        "--phase=-0.25,0.5",
        "--rows",
        "9",
        "--speeds",
        "500",
        "--out",
        one.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let phases: Vec<String> =
        std::fs::read_dir(one.join("rows-9")).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    assert_eq!(phases.iter().filter(|p| p.starts_with("phase-")).count(), 2, "{phases:?}");
    for (phase, says) in [("-0.25", "lies -0.25 of a spacing"), ("+0.50", "0.50 of a spacing")] {
        let md = std::fs::read_to_string(one.join(format!("rows-9/phase-{phase}/ballistic.md"))).unwrap();
        assert!(md.contains("| 500.00 |") && md.contains(says), "phase {phase}: {md}");
    }
    let half = |d: &std::path::Path| {
        let csv = std::fs::read_to_string(d.join("rows-9/phase-+0.50/ballistic.csv")).unwrap();
        csv.lines().nth(1).unwrap().split(',').take(3).collect::<Vec<_>>().join(",")
    };
    assert_eq!(half(&one), half(&out), "the same run as --phases 2's");
    let md = std::fs::read_to_string(one.join("convergence.md")).unwrap();
    assert!(md.starts_with("# Ballistic study at 1 resolution at 2 lattice phases") && md.contains("--phase`"), "{md}");
    // Out of range, twice the same directory, or with --phases: refused
    // before any run.
    for (bad_phase, says) in [
        (&["--phase", "0.6"][..], "a lattice phase lies in [-0.5, 0.5] spacings, got 0.6"),
        (&["--phase", "0.25,0.251"], "two phases share the directory phase-+0.25"),
        (&["--phase", "0.25", "--phases", "2"], "cannot be used with '--phases"),
    ] {
        let mut args = vec!["--set", zone, "--speeds", "500", "--out", bad.to_str().unwrap()];
        args.extend_from_slice(bad_phase);
        let o = plugsim(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && !bad.exists(), "{bad_phase:?}: {stderr}");
        assert!(stderr.contains(says), "{bad_phase:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The small impact with the projectile as a deformable body of hard,
/// elastic steel (issue #20): the same 8 mm × 20 mm rectangle at 400 m/s.
fn small_plate_deformable_projectile() -> String {
    let rigid = "[[rigid_bodies]]\nname = \"projectile\"\nrectangle = { center = [0.0, 0.01405], width = 0.008, height = 0.02 }\ndensity = 7850.0\nvelocity = [0.0, -400.0]\n";
    let text = small_plate();
    assert!(text.contains(rigid), "the shared case's projectile moved");
    let deformable =
        "[materials.hard]\nmodel = \"elastic\"\ndensity = 7850.0\nyoungs_modulus = 204.0e9\npoisson_ratio = 0.3\n\
        [[bodies]]\nname = \"projectile\"\nmaterial = \"hard\"\n\
        rectangle = { x_min = -0.004, x_max = 0.004, y_min = 0.00405, y_max = 0.02405, layers = 11 }\n\
        [[bodies.initial_velocity]]\nvelocity = [0.0, -400.0]\n";
    text.replace(rigid, deformable)
}

/// A deformable body flying as a whole is a projectile like a rigid one:
/// chosen when it is the only moving body, its speed set by `at_speed`, and
/// the study's `--rows` refine the target (not the projectile) to the
/// rows asked, and the projectile by the same factor, rounded.
#[test]
fn a_deformable_projectile_is_selected_set_and_refined_with_its_target() {
    let case = Case::from_str_with(&small_plate_deformable_projectile(), "soft", &[]).unwrap();
    assert!(case.rigid_bodies.is_empty());
    let p = select_projectile(&case, "soft", None).unwrap();
    // the plate is body 0, the projectile body 1
    assert_eq!(p, Projectile::Deformable(1));
    assert_eq!(p.name(&case), "projectile");
    let (dir, speed) = flight(&case, p);
    assert_eq!((dir.x, dir.y, speed), (0.0, -1.0, 400.0));
    let (fast, set) = at_speed(&case, p, 550.0, 0.0);
    assert_eq!(fast.bodies[1].initial_velocity[0].velocity, [0.0, -550.0]);
    assert_eq!(set, ["bodies.projectile.initial_velocity.0.velocity=[0.0, -550.0]"]);
    // what a run records reruns it: the same case from the text and `--set`
    let again = Case::from_str_with(&small_plate_deformable_projectile(), "soft", &set).unwrap();
    assert_eq!(again, fast);
    assert_eq!(fast.time.end, case.time.end, "a max time before the end time shortens nothing");
    assert_eq!(fast.bodies[0].initial_velocity.len(), 0, "the plate does not move");
    let (fine, set) = at_rows(&case, 18).unwrap();
    assert_eq!((fine.bodies[0].rectangle.layers, fine.bodies[1].rectangle.layers), (18, 22));
    assert!(set.iter().any(|s| s == "bodies.plate.rectangle.layers=18"), "{set:?}");
    // the target's rows exactly, the projectile's to the nearest whole number (11 x 12/9 = 14.7)
    let (finer, _) = at_rows(&case, 12).unwrap();
    assert_eq!((finer.bodies[0].rectangle.layers, finer.bodies[1].rectangle.layers), (12, 15));
    // Named: the deformable body, or a rigid one beside it.
    assert_eq!(select_projectile(&case, "soft", Some("projectile")).unwrap(), p);
    let two = small_plate_deformable_projectile()
        + "[[rigid_bodies]]\nname = \"bullet\"\nrectangle = { center = [0.0, 0.05], width = 0.004, height = 0.004 }\n\
           density = 7850.0\nvelocity = [0.0, -100.0]\n";
    let two = Case::from_str_with(&two, "two", &[]).unwrap();
    let e = select_projectile(&two, "two", None).unwrap_err().to_string();
    assert!(e.contains("several moving bodies (bullet, projectile)"), "{e}");
    assert_eq!(select_projectile(&two, "two", Some("bullet")).unwrap(), Projectile::Rigid(0));
    assert_eq!(select_projectile(&two, "two", Some("projectile")).unwrap(), Projectile::Deformable(1));
}

/// A study with a deformable projectile runs, and each run's verdict is the
/// deformable projectile's own flight (its mass-averaged velocity).
#[test]
fn a_study_fires_a_deformable_projectile() {
    let case = Case::from_str_with(&small_plate_deformable_projectile(), "soft", &[]).unwrap();
    let projectile = select_projectile(&case, "soft", None).unwrap();
    let out_dir = fresh_dir("deformable");
    let s = Setup {
        case,
        label: "soft".into(),
        overrides: vec![],
        projectile,
        jobs: 1,
        threads_per_run: 1,
        out_dir: out_dir.clone(),
        max_time: 0.0,
        interrupt: None,
        resume: false,
    };
    // what the progress reports give of it: its mass-averaged speed along
    // its flight, the impact speed at the start, slowed by the plate after
    let mut sim = plugsim::run::build_simulation(&s.case).unwrap();
    let (direction, impact) = flight(&s.case, projectile);
    let name = projectile.name(&s.case).to_string();
    let at_start = along_flight(&sim, projectile, &name, &direction).unwrap();
    assert!((at_start.speed - impact).abs() < 1e-9 * impact, "{at_start:?} against {impact}");
    assert_eq!(at_start.force, 0.0, "no contact yet");
    let mut pushed = 0;
    while sim.time < 5e-6 {
        sim.step().unwrap();
        let now = along_flight(&sim, projectile, &name, &direction).unwrap();
        assert!(now.force <= 0.0, "the plate only holds it back: {now:?} at {} s", sim.time);
        pushed += usize::from(now.force < 0.0);
    }
    assert!(pushed > 10, "held back over {pushed} steps");
    let later = along_flight(&sim, projectile, &name, &direction).unwrap();
    assert!(later.speed > 0.5 * impact && later.speed < impact, "{later:?} at 5 us of {impact}");
    let mut study = Study::default();
    run_speeds(&s, &[500.0], &mut study, &mut |_| Ok(()), &mut |_| {}).unwrap();
    assert_eq!(study.shots.len(), 1, "{:?}", study.failures);
    let shot = &study.shots[0];
    let Verdict::Perforated { residual, .. } = shot.verdict else { panic!("{:?}", shot.verdict) };
    // its own history: the deformable projectile's mass-averaged velocity
    let history = plugsim::output::read_history(&shot.dir).unwrap();
    let vy = history.column("projectile_vy").expect("the deformable projectile's velocity column");
    assert!((residual + vy.last().unwrap()).abs() < 1e-9 * residual, "{residual} vs {}", vy.last().unwrap());
    assert!(residual > 0.0 && residual < 500.0, "{residual}");
    let info = std::fs::read_to_string(shot.dir.join("run_info.toml")).unwrap();
    assert!(info.contains("bodies.projectile.initial_velocity"), "{info}");
    std::fs::remove_dir_all(&out_dir).ok();
}

/// `--resume`: a run an interrupt stopped continues from its checkpoint to
/// the result of a run never stopped, to the bit; run again, the finished
/// run is taken back without running; a changed case or a study without
/// `--resume` runs afresh.
#[test]
fn a_resumed_study_continues_the_interrupted_runs_and_takes_back_the_finished() {
    let speed = 300.0;
    let same = |a: &plugsim::ballistic::Shot, b: &plugsim::ballistic::Shot| {
        assert_eq!(
            (a.verdict, a.perforation, a.cut_speed, a.plug_mass, a.end_time, a.fastest, a.steps),
            (b.verdict, b.perforation, b.cut_speed, b.plug_mass, b.end_time, b.fastest, b.steps)
        );
    };
    // Progress reports every 2 us (10 % of the end time), so some come
    // after the plug is cut (at about 9 us of the 11 us the run takes).
    let short = |name: &str| {
        let mut s = setup(name, 1);
        s.case.time.end = 20.0e-6;
        s.max_time = 20.0e-6;
        // a history row at every step, so one at the interrupt's checkpoint
        s.case.output.history_every = 1;
        s
    };
    // The reference: never stopped.
    let whole = short("resume-whole");
    let mut reference = Study::default();
    run_speeds(&whole, &[speed], &mut reference, &mut |_| Ok(()), &mut |_| {}).unwrap();
    let reference = reference.shots[0].clone();
    assert!(matches!(reference.verdict, Verdict::Perforated { .. }), "{:?}", reference.verdict);
    assert!(reference.end_time > 8.0e-6, "long enough to stop it on the way: {}", reference.end_time);

    // Stopped at its first progress report.
    let mut s = short("resume");
    let flag = Arc::new(AtomicBool::new(false));
    s.interrupt = Some(flag.clone());
    let mut study = Study::default();
    let mut reported = None;
    run_speeds(&s, &[speed], &mut study, &mut |_| Ok(()), &mut |e| {
        if let Event::Advanced { along, .. } = e {
            reported.get_or_insert(along);
            flag.store(true, Ordering::SeqCst);
        }
    })
    .unwrap();
    assert!(study.interrupted && study.shots.is_empty() && study.not_started.is_empty());
    // the report carries the projectile's speed along its flight: slowed
    // by the plate at 2 us, still moving on
    let along = reported.flatten().expect("the projectile's speed in the progress report");
    assert!(along > 0.5 * speed && along < speed, "{along} m/s at 2 us of a {speed} m/s impact");
    let dir = plugsim::ballistic::run_dir(&s.out_dir, speed);
    assert!(!dir.join(plugsim::ballistic::SHOT_FILE).exists());
    // the stopped run, where its checkpoint left it: the history's last
    // row, the projectile no faster than at the report
    let [paused] = study.paused.as_slice() else { panic!("one stopped run: {:?}", study.paused) };
    assert_eq!((paused.speed, &paused.dir), (speed, &dir));
    let history = plugsim::output::read_history(&dir).unwrap();
    let column = |name: &str| *history.column(name).and_then(|c| c.last()).unwrap();
    assert_eq!(paused.time, column("time"), "the checkpoint's time is the history's last row");
    let at = paused.along.expect("the projectile's motion at the checkpoint");
    assert!(at.speed <= along && at.speed > 0.5 * speed, "{at:?}");
    assert_eq!(at.force, column("projectile_f_axial"), "the history's sample");
    assert_eq!(at.speed, -column("projectile_vy"), "the history's sample (the flight is along -y)");
    let cut = Some(column("perforation_time")).filter(|&t| t > 0.0);
    assert_eq!(paused.perforation, cut, "the plug's state at the checkpoint is the history's");

    // Resumed: continues from the checkpoint, to the reference's result.
    s.interrupt = None;
    s.resume = true;
    let mut events = Vec::new();
    let mut study = Study::default();
    run_speeds(&s, &[speed], &mut study, &mut |_| Ok(()), &mut |e| events.push(e)).unwrap();
    let resumed_at = events.iter().find_map(|e| match e {
        Event::Resumed { time, .. } => Some(*time),
        _ => None,
    });
    assert!(resumed_at.is_some_and(|t| t >= 2.0e-6 && t < reference.end_time), "{resumed_at:?}");
    assert_eq!(resumed_at, Some(paused.time), "continues where the report said it stopped");
    same(&study.shots[0], &reference);
    // Each progress report carries the plug's cut once it has happened
    // (the threshold of a held run drops from 5 % to 1 % then), none before.
    let cut_at = reference.perforation.expect("the reference cut a plug");
    let mut after = 0;
    for e in &events {
        if let Event::Advanced { time, perforation, .. } = e {
            let expected = (*time >= cut_at).then_some(cut_at);
            assert_eq!(*perforation, expected, "the report at {time:e} s (plug cut at {cut_at:e} s)");
            after += usize::from(perforation.is_some());
        }
    }
    assert!(after > 0, "a report after the cut at {cut_at:e} s: {events:?}");
    assert!(dir.join(plugsim::ballistic::SHOT_FILE).exists());
    let history = std::fs::read(dir.join("history.csv")).unwrap();
    assert_eq!(
        history,
        std::fs::read(reference.dir.join("history.csv")).unwrap(),
        "the same history as a run never stopped"
    );

    // Again: taken back, nothing runs.
    let mut events = Vec::new();
    let mut again = Study::default();
    run_speeds(&s, &[speed], &mut again, &mut |_| Ok(()), &mut |e| events.push(e)).unwrap();
    assert!(matches!(events.as_slice(), [Event::Reused { note: None, .. }]), "{events:?}");
    assert_eq!(again.shots, study.shots, "the whole row, wall time included");
    // A record from a build that did not keep the speed at the cut: read
    // from the run's history, the same.
    let record = dir.join(plugsim::ballistic::SHOT_FILE);
    let text = std::fs::read_to_string(&record).unwrap();
    let older: String = text.lines().filter(|l| !l.starts_with("cut_speed")).map(|l| format!("{l}\n")).collect();
    assert!(older.len() < text.len() && study.shots[0].cut_speed.is_some(), "{text}");
    std::fs::write(&record, older).unwrap();
    let mut older_study = Study::default();
    run_speeds(&s, &[speed], &mut older_study, &mut |_| Ok(()), &mut |_| {}).unwrap();
    assert_eq!(older_study.shots, study.shots, "the speed at the cut read back from the history");

    // Another case (a later max time) or no --resume: runs afresh.
    for (max_time, resume) in [(50.0e-6, true), (20.0e-6, false)] {
        s.max_time = max_time;
        s.resume = resume;
        let mut events = Vec::new();
        let mut fresh = Study::default();
        run_speeds(&s, &[speed], &mut fresh, &mut |_| Ok(()), &mut |e| events.push(e)).unwrap();
        assert!(matches!(events.first(), Some(Event::Started { .. })), "{events:?}");
        assert!(!events.iter().any(|e| matches!(e, Event::Reused { .. } | Event::Resumed { .. })), "{events:?}");
        same(&fresh.shots[0], &reference);
    }
    std::fs::remove_dir_all(&s.out_dir).ok();
    std::fs::remove_dir_all(&whole.out_dir).ok();
}

/// `--snapshot-every`: a study's runs write a snapshot at most that often
/// (the case's own interval where coarser, and always the last state); 0,
/// or an explicit `--set output.interval`, keeps the case's.
#[test]
fn a_study_writes_sparse_snapshots_unless_told() {
    let dir = fresh_dir("snapshots");
    let case = dir.join("small.toml");
    // The case asks for a snapshot every µs; its run lasts about 8 µs.
    let text = small_plate();
    assert!(text.contains("interval = 1.0e-5"));
    std::fs::write(&case, text.replace("interval = 1.0e-5", "interval = 1.0e-6")).unwrap();
    // The snapshot times of the run at 500 m/s in `out`, µs.
    let times = |name: &str, args: &[&str]| -> Vec<f64> {
        let out = dir.join(name);
        let head =
            ["--threads", "1", "ballistic", case.to_str().unwrap(), "--speeds", "500", "--out", out.to_str().unwrap()];
        let o = common::plugsim(&[&head[..], args].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let md = std::fs::read_to_string(out.join("ballistic.md")).unwrap();
        let pvd = std::fs::read_to_string(out.join("v500.00/results.pvd")).unwrap();
        let t: Vec<f64> = pvd
            .lines()
            .filter(|l| l.contains("part=\"0\""))
            .map(|l| l.split("timestep=\"").nth(1).unwrap().split('"').next().unwrap().parse::<f64>().unwrap() * 1e6)
            .collect();
        let every = md.split("a snapshot every ").nth(1).unwrap().split(' ').next().unwrap().parse::<f64>().unwrap();
        // Every snapshot but the last on the stated interval, none skipped.
        for (i, ti) in t[..t.len() - 1].iter().enumerate() {
            assert!((ti - i as f64 * every).abs() < 0.1 * every.min(1.0), "{name}: {t:?} every {every}");
        }
        assert!(t.last().unwrap() - t[t.len() - 2] <= every + 1e-3, "{name}: {t:?}");
        t
    };
    let default = times("default", &[]);
    let sparse = times("sparse", &["--snapshot-every", "3e-6"]);
    let own = times("own", &["--snapshot-every", "0"]);
    let told = times("told", &["--set", "output.interval=2e-6"]);
    // The default's 10 µs: the first and the last state; 3 µs: 0, 3, 6
    // and the last; the case's 1 µs (told 2 µs) where it is kept.
    assert!(*default.last().unwrap() > 6.0, "the run lasts {default:?}");
    assert_eq!(default.len(), 2, "{default:?}");
    assert_eq!(sparse.len(), 4, "{sparse:?}");
    assert!(own.len() >= 7 && sparse.len() < told.len() && told.len() < own.len(), "{own:?} {told:?}");
    for t in [&sparse, &own, &told] {
        assert_eq!(t.last(), default.last(), "the last state is written whatever the interval");
    }
    // A negative interval is refused, naming the option, before any run.
    let bad = dir.join("bad");
    let (case, bad) = (case.to_str().unwrap(), bad.to_str().unwrap());
    let o = common::plugsim(&["ballistic", case, "--speeds", "500", "--snapshot-every=-1", "--out", bad]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.contains("--snapshot-every"), "{stderr}");
    assert!(!dir.join("bad").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The step's floors on a cracking run. Mass scaling (`[time]
/// mass_scaling`, here at 0.9 of the spacing step, above the 0.85 the
/// unscaled run falls to, so that it acts even on this coarse plate): the
/// step never falls below the floor;
/// the mass added is a small fraction of the plate's (0.65 %: at so high a
/// floor the compressed material under the projectile gets some too) and
/// is reported; the residual velocity stays within 1 % of the unscaled
/// run's (here equal to the micrometre per second), and the energy
/// balance closes as well. Erosion at the floor (`[time]
/// erode_failed_below`, at 0.95) erodes fractured points (6 here), which
/// the summary counts, and keeps the residual within 1 % and the
/// balance; the step still falls to what the intact crack-face children
/// allow.
#[test]
fn the_steps_floors_on_a_cracking_run_keep_its_residual() {
    use plugsim::run::{execute, RunConfig, RunInfo};
    let run = |floor: Option<&str>| {
        let s = setup(&format!("floor-{}", floor.unwrap_or("off").replace([' ', '='], "")), 1);
        let text = match floor {
            Some(f) => small_plate().replace("stop_after_release", &format!("{f}\nstop_after_release")),
            None => small_plate(),
        };
        let case = Case::from_str_with(&text, "small", &[]).unwrap();
        let cfg = RunConfig::new(s.out_dir.join("run"), true, RunInfo::current("test", &[]));
        let summary = execute(&case, &cfg, &mut |_| {}).unwrap();
        std::fs::remove_dir_all(&s.out_dir).ok();
        summary
    };
    let (off, on) = (run(None), run(Some("mass_scaling = 0.9")));
    let eroding = run(Some("erode_failed_below = 0.95"));
    let residual = |s: &plugsim::run::RunSummary| match s.flights[0].1 {
        Verdict::Perforated { residual, .. } => residual,
        v => panic!("{v:?}"),
    };
    let (base, (smallest_off, _, _)) = off.stable_step.unwrap();
    eprintln!("unscaled smallest step {:.3} of the spacing step", smallest_off / base);
    assert!(smallest_off < 0.9 * base, "the unscaled step stays at the spacing step ({smallest_off:e} of {base:e})");
    assert!(off.mass_scaling.is_none());
    let (_, (smallest, _, _)) = on.stable_step.unwrap();
    assert!(smallest >= 0.9 * base * (1.0 - 1e-9), "the step fell to {smallest:e} below the floor 0.95 x {base:e}");
    let added = on.mass_scaling.unwrap();
    let plate = on.total_mass - added.mass;
    assert!(added.mass > 0.0 && added.mass < 0.01 * plate, "added {:e} kg of {plate:e}", added.mass);
    assert!(on.energies.mass_scaling >= 0.0);
    let (a, b) = (residual(&off), residual(&on));
    assert!((a - b).abs() < 0.01 * a, "residual {b} m/s with mass scaling against {a} m/s");
    assert!(on.max_drift < off.max_drift + 0.01, "energy drift {} against {}", on.max_drift, off.max_drift);
    eprintln!(
        "mass scaling at 0.9 of the spacing step: v_r {b:.6} against {a:.6} m/s (drift {:.4} against {:.4}; input {:.3e} J); {} against {} steps; {:.3e} kg added ({:.3} % of the plate), {:.3e} J out",
        on.max_drift,
        off.max_drift,
        on.energies.initial_kinetic,
        on.steps,
        off.steps,
        added.mass,
        100.0 * added.mass / plate,
        on.energies.mass_scaling
    );
    // Erosion at a floor of 0.95: the fractured points that would take the
    // step lower go (the summary counts them); the step still falls to
    // what the intact crack-face children allow, and the residual and the
    // balance stay.
    let n = eroding.floor_eroded.expect("the summary counts the floor's points");
    assert!(n > 0 && n as usize <= eroding.eroded_points, "{n} of {} eroded", eroding.eroded_points);
    assert!(off.floor_eroded.is_none());
    let c = residual(&eroding);
    assert!((a - c).abs() < 0.01 * a, "residual {c} m/s with erosion at the floor against {a} m/s");
    assert!(eroding.max_drift < off.max_drift + 0.01, "energy drift {} against {}", eroding.max_drift, off.max_drift);
    eprintln!(
        "erosion at 0.95 of the spacing step: {n} points, v_r {c:.6} against {a:.6} m/s, {} against {} steps",
        eroding.steps, off.steps
    );
}

/// `plugsim check` and `plugsim run` state where the projectile's edge lies
/// against the plate's particle columns, as every ballistic study does. The
/// small plate's lattice is uniform, 0.5 mm from x = −12 mm: an 8.6 mm wide
/// projectile's edge, x = 4.3 mm, lies nearest the column at 4.5 mm, −0.4
/// of a spacing from it (by hand); a case with no projectile says nothing,
/// and `run` says it only once its output directory is accepted.
#[test]
fn check_and_run_state_the_projectile_s_edge_against_the_columns() {
    let (dir, case) = small_plate_file("rim");
    let width = "rigid_bodies.projectile.rectangle.width=0.0086";
    let line = "the projectile's edge (x = 4.300 mm) lies -0.40 of a spacing from the target's nearest particle column (x = 4.500 mm)";
    let o = common::plugsim(&["check", case.to_str().unwrap(), "--set", width]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains(&format!("  rim             {line}")), "{stdout}");
    let out = dir.join("run");
    let o = common::plugsim(&[
        "--threads",
        "1",
        "run",
        case.to_str().unwrap(),
        "--set",
        width,
        "--set",
        "time.end=1e-7",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && stderr.contains(&format!("plugsim: {line}")), "{stderr}");
    let header = stderr.find("particles,").expect("the run's header");
    assert!(stderr.find(line).unwrap() < header, "the rim line comes before the run's header: {stderr}");
    // A run refused (its output directory exists, no --force) states nothing of it.
    let args = ["--threads", "1", "run", case.to_str().unwrap(), "--set", width, "--out", out.to_str().unwrap()];
    let o = common::plugsim(&args);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && !stderr.contains("projectile's edge"), "{stderr}");
    // On a column: +0.00 (the shared case's 8 mm projectile, edge at 4 mm).
    let o = common::plugsim(&["check", case.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("lies +0.00 of a spacing from the target's nearest particle column (x = 4.000 mm)"),
        "{stdout}"
    );
    // No projectile, no line.
    let o = common::plugsim(&["check", "--case", "elastic-strike"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && !stdout.contains("rim "), "{stdout}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A built-in case's tests go on its curve while the overrides change the
/// model only (material, resolution, speed); another plate thickness or
/// another projectile is another experiment, and the reason is named.
#[test]
fn a_built_in_cases_tests_belong_to_its_plate_and_projectile_only() {
    use plugsim::ballistic::tests_differ;
    use plugsim::cases::{builtin_case, builtin_experiments};
    let load = |name: &str, set: &[&str]| {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        Case::from_str_with(builtin_case(name).unwrap(), name, &set).unwrap()
    };
    for name in ["borvik-2002-12mm-hemispherical", "borvik-2-axisymmetric-nonlocal", "borvik-1-axisymmetric-deformable"]
    {
        let shipped = load(name, &[]);
        assert!(builtin_experiments(name).is_some(), "{name} has tests");
        assert_eq!(tests_differ(&shipped, &shipped), None, "{name}");
        let model = load(
            name,
            &[
                "bodies.plate.material=weldox_460e_cockcroft_latham",
                "bodies.plate.rectangle.layers=12",
                "time.end=1e-4",
            ],
        );
        assert_eq!(tests_differ(&shipped, &model), None, "{name}: the model changed, not the experiment");
        let thinner = load(name, &["bodies.plate.rectangle.y_min=0.002"]);
        let why = tests_differ(&shipped, &thinner).unwrap_or_else(|| panic!("{name}: a thinner plate"));
        assert!(why.contains("thick"), "{name}: {why}");
    }
    let hemi = "borvik-2002-12mm-hemispherical";
    let heavier = load(hemi, &["rigid_bodies.projectile.mass=0.25"]);
    let why = tests_differ(&load(hemi, &[]), &heavier).expect("a heavier projectile");
    assert!(why.contains("rigid projectile"), "{why}");
    let faster = load(hemi, &["rigid_bodies.projectile.velocity=[0.0, -350.0]"]);
    assert_eq!(tests_differ(&load(hemi, &[]), &faster), None, "a study sets the speed itself");
    let deformable = "borvik-1-axisymmetric-deformable";
    let longer = load(deformable, &["bodies.projectile.rectangle.y_max=0.1"]);
    let why = tests_differ(&load(deformable, &[]), &longer).expect("a longer projectile");
    assert!(why.contains("deformable projectile"), "{why}");
    // the blunt nose's tests are not the hemispherical nose's
    let blunt = load("borvik-2002-12mm-blunt", &[]);
    assert!(tests_differ(&load(hemi, &[]), &blunt).is_some());
}
