//! Checkpoints and resume: a run stopped at a checkpoint and resumed from
//! the file ends in exactly the state, and with exactly the output files, of
//! the run that was never stopped; checkpoints of another format version,
//! damaged or truncated files are refused with a message that says so.

mod common;

use common::plugsim;
use plugsim::case::Case;
use plugsim::checkpoint::{self, RunProgress, FORMAT_VERSION};
use plugsim::run::{build_simulation, execute, resume, Progress, RunConfig, RunError, RunInfo};
use plugsim::step::Simulation;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

const STRIKE: &str = include_str!("../cases/elastic-strike.toml");
const BORVIK: &str = include_str!("../cases/borvik-1-nofracture.toml");
const BORVIK_FRACTURE: &str = include_str!("../cases/borvik-1-plane-strain.toml");

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("checkpoint-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn case(text: &str, overrides: &[&str]) -> Case {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Case::from_str_with(text, "test.toml", &o).unwrap_or_else(|e| panic!("{e}"))
}

fn config(dir: &Path, interrupt: Option<Arc<AtomicBool>>) -> RunConfig {
    RunConfig { interrupt, ..RunConfig::new(dir.to_path_buf(), true, RunInfo::current("test", &[])) }
}

/// Run to the end; the final state.
fn run_through(case: &Case, dir: &Path) -> Simulation {
    let mut last = None;
    execute(case, &config(dir, None), &mut |p| {
        if let Progress::Finished { sim } = p {
            last = Some(sim.clone());
        }
    })
    .unwrap_or_else(|e| panic!("{e}"));
    last.expect("a finished run reports its final state")
}

/// Run until `step`, as if Ctrl-C came then: the run must checkpoint and stop.
fn run_until(case: &Case, dir: &Path, step: u64) -> PathBuf {
    let flag = Arc::new(AtomicBool::new(false));
    let stop = flag.clone();
    let err = execute(case, &config(dir, Some(flag)), &mut |p| {
        if let Progress::Step { sim, .. } = p {
            if sim.step >= step {
                stop.store(true, Ordering::SeqCst);
            }
        }
    })
    .expect_err("an interrupted run returns an error");
    match err {
        RunError::Interrupted { step: s, checkpoint, .. } => {
            assert_eq!(s, step, "the checkpoint is taken at the end of the step during which the interrupt came");
            assert!(err_text(&checkpoint).is_empty());
            checkpoint
        }
        e => panic!("expected Interrupted, got {e}"),
    }
}

fn err_text(p: &Path) -> String {
    if p.exists() {
        String::new()
    } else {
        format!("{} missing", p.display())
    }
}

fn resume_to_end(dir: &Path) -> (Simulation, Vec<String>) {
    let (mut last, mut warnings) = (None, Vec::new());
    resume(&config(dir, None), &mut |p| match p {
        Progress::Finished { sim } => last = Some(sim.clone()),
        Progress::Resumed { warnings: w, .. } => warnings = w.to_vec(),
        _ => {}
    })
    .unwrap_or_else(|e| panic!("{e}"));
    (last.expect("final state"), warnings)
}

/// Byte-for-byte comparison of two final states: the checkpoint encoding of
/// every stored field, and independently the `Debug` text of the stores and
/// the contact (which shows every field, including ones a checkpoint might
/// have forgotten; `Debug` prints each `f64` in its shortest exact form).
fn assert_same_state(a: &Simulation, b: &Simulation, case: &Case) {
    let progress = RunProgress {
        snapshot_times: vec![],
        history_bytes: 0,
        next_snapshot: 0.0,
        next_checkpoint: 0.0,
        max_drift: 0.0,
    };
    assert_eq!((a.step, a.time.to_bits(), a.dt.to_bits()), (b.step, b.time.to_bits(), b.dt.to_bits()));
    assert!(
        checkpoint::state_bytes(a, case, &progress) == checkpoint::state_bytes(b, case, &progress),
        "the encoded states differ"
    );
    assert_eq!(format!("{:?}", a.model.particles), format!("{:?}", b.model.particles));
    assert_eq!(format!("{:?}", a.model.quad), format!("{:?}", b.model.quad));
    assert_eq!(format!("{:?}", a.energies), format!("{:?}", b.energies));
    assert_eq!(format!("{:?}", a.contact), format!("{:?}", b.contact));
    assert_eq!(format!("{:?}", a.f_contact), format!("{:?}", b.f_contact));
    // Everything else the simulation holds (a field added later included),
    // except the wall-clock stage timers.
    let (mut a, mut b) = (a.clone(), b.clone());
    a.timers = Default::default();
    b.timers = Default::default();
    assert!(format!("{a:?}") == format!("{b:?}"), "the simulations differ in a field the checkpoint does not carry");
}

/// The files a run leaves, except the ones that record how it ran
/// (`run_info.toml`, checkpoints) and the plot.
fn output_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_file())
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n != "run_info.toml" && n != "energy.png")
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect();
    files.sort();
    files
}

fn assert_same_outputs(reference: &Path, resumed: &Path) {
    let (a, b) = (output_files(reference), output_files(resumed));
    let names = |f: &[(String, Vec<u8>)]| f.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "the same files");
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{name} differs between the uninterrupted and the resumed run");
    }
}

/// Kill (no checkpoint at the kill) after a periodic checkpoint, resume:
/// the final state and every output file equal the uninterrupted run's.
/// Returns the state the run was resumed from and the final state.
fn kill_and_resume(name: &str, case: &Case, stop_at: u64) -> (Simulation, Simulation) {
    let reference = scratch(&format!("{name}-reference"));
    let full = run_through(case, &reference);

    let dir = scratch(&format!("{name}-resumed"));
    let at_stop = run_until(case, &dir, stop_at);
    // Pretend the process was killed before that last checkpoint: the run
    // has written history rows and snapshots after the previous one, which
    // the resume must drop and write again.
    std::fs::remove_file(&at_stop).unwrap();
    let ckpts = checkpoint::list(&checkpoint::directory(&dir));
    let (from_step, from) = ckpts.last().cloned().expect("a periodic checkpoint before the stop");
    assert!(from_step < stop_at && from_step > 0, "checkpoint at step {from_step}, stop at {stop_at}");
    std::fs::write(dir.join("particles_00999.vtu"), b"stale").unwrap();
    std::fs::write(dir.join("cracks_00999.vtu"), b"stale").unwrap();
    let rows_before = std::fs::read_to_string(dir.join("history.csv")).unwrap().lines().count();
    let resumed_from = checkpoint::read(&from).unwrap().sim;

    let (resumed, warnings) = resume_to_end(&dir);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_same_state(&full, &resumed, case);
    assert_same_outputs(&reference, &dir);
    assert!(!dir.join("particles_00999.vtu").exists(), "snapshots after the checkpoint are removed");
    assert!(!dir.join("cracks_00999.vtu").exists());
    let history = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    assert!(history.lines().count() > rows_before, "history continued");
    let info = std::fs::read_to_string(dir.join("run_info.toml")).unwrap();
    let info: toml::Table = toml::from_str(&info).expect("run_info.toml stays valid TOML");
    assert_eq!(info["resumed"].as_array().unwrap()[0]["step"].as_integer(), Some(from_step as i64));
    (resumed_from, resumed)
}

#[test]
fn resumed_elastic_run_is_bit_identical_to_an_uninterrupted_one() {
    let case = case(
        STRIKE,
        &[
            "time.end=4e-6",
            "output.interval=5e-7",
            "output.history_every=3",
            "checkpoint.interval=1.2e-6",
            "checkpoint.keep=3",
        ],
    );
    kill_and_resume("strike", &case, 35);
}

#[test]
fn resumed_contact_run_is_bit_identical_to_an_uninterrupted_one() {
    let case = case(
        BORVIK,
        &[
            "bodies.plate.rectangle.layers=6",
            "bodies.plate.rectangle.x_min=-0.04",
            "bodies.plate.rectangle.x_max=0.04",
            "bodies.plate.supports.0.region.x_min=-0.04",
            "bodies.plate.supports.0.region.x_max=-0.037",
            "bodies.plate.supports.1.region.x_min=0.037",
            "bodies.plate.supports.1.region.x_max=0.04",
            "time.end=5e-6",
            "output.interval=5e-7",
            "output.history_every=2",
            "checkpoint.interval=1.5e-6",
            // `trace.csv` is cut back to the checkpoint's step on resume
            "output.trace_particles=[57, 3]",
            // set from the case on resume, not stored: a resume without it
            // would differ from the uninterrupted run
            "time.bulk_viscosity.linear=0.1",
            "time.bulk_viscosity.quadratic=1.5",
        ],
    );
    assert!(case.bulk_viscosity().is_active());
    let (from, _) = kill_and_resume("contact", &case, 20);
    // The contact must be active across the checkpoint for the test to mean anything.
    let c = from.contact.as_ref().unwrap();
    assert!(c.bodies[0].velocity.y > -298.0 + 1.0, "the projectile was slowed by contact");
    assert!(c.sample(0).unwrap().active_contacts > 0, "contacts at the checkpoint");
    assert!((0..c.slaves.len()).any(|k| c.slaves.pairing(k).is_some()), "slaves are paired");
}

/// Crack growth across the checkpoint: a crack nucleated before it grows
/// after it; the crack state, the crack files of the series and
/// `cracks.csv` continue exactly (the plane-strain Borvik case on a narrow,
/// thin plate, with a low critical strain so that cracks start early).
#[test]
fn resumed_fracture_run_is_bit_identical_to_an_uninterrupted_one() {
    let case = case(BORVIK_FRACTURE, FRACTURE_SETS);
    let (from, end) = kill_and_resume("fracture", &case, FRACTURE_STOP);
    assert!(case.heat_conduction(), "conduction is on across the checkpoint");
    assert!(from.heat_pending > 0.0, "heat is pending at the checkpoint");
    let at = from.cracks.as_ref().expect("fracture is on");
    let final_events = &end.cracks.as_ref().unwrap().events;
    assert!(!at.cracks.is_empty(), "a crack nucleated before the checkpoint");
    assert!(!from.model.quad.f_carry.is_empty(), "deformation-gradient jumps are carried across the checkpoint");
    assert!(
        final_events.len() > at.events.len()
            && final_events[at.events.len()..].iter().any(|e| e.crack < at.cracks.len()),
        "a crack of the checkpoint grew after it"
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("checkpoint-fracture-resumed");
    let log = std::fs::read_to_string(dir.join("cracks.csv")).unwrap();
    assert_eq!(log.lines().count(), 1 + final_events.len(), "one row per event");
    let pvd = std::fs::read_to_string(dir.join("results.pvd")).unwrap();
    assert_eq!(
        pvd.matches("part=\"1\"").count(),
        pvd.matches("part=\"0\"").count(),
        "every snapshot has its crack file"
    );
}

/// Overrides of the fracture resume test; the checkpoint it resumes from is
/// the periodic one at `checkpoint.interval`, the (discarded) stop at
/// [`FRACTURE_STOP`].
const FRACTURE_SETS: &[&str] = &[
    "bodies.plate.rectangle.layers=6",
    "bodies.plate.rectangle.x_min=-0.03",
    "bodies.plate.rectangle.x_max=0.03",
    "bodies.plate.rectangle.fine_half_width=0.015",
    "bodies.plate.supports.0.region.x_min=-0.03",
    "bodies.plate.supports.0.region.x_max=-0.028",
    "bodies.plate.supports.1.region.x_min=0.028",
    "bodies.plate.supports.1.region.x_max=0.03",
    "fracture.critical_effective_strain=0.1",
    "heat.every=4",
    "time.end=8e-6",
    "output.interval=1e-6",
    "output.history_every=5",
    "checkpoint.interval=4.7e-6",
];
const FRACTURE_STOP: u64 = 30;

/// Detached particles across the checkpoint (`fracture.detach_below`):
/// in the fracture test's plate run on to 40 µs, one particle is detached
/// before the checkpoint and one after it; the resumed run equals the
/// uninterrupted one, the detached particles and when included.
#[test]
fn resumed_run_with_detached_particles_is_bit_identical() {
    let mut sets: Vec<&str> =
        FRACTURE_SETS.iter().copied().filter(|s| !s.starts_with("time.end") && !s.starts_with("checkpoint")).collect();
    sets.extend(["time.end=4e-5", "checkpoint.interval=2.5e-5", "fracture.detach_below=0.5"]);
    let case = case(BORVIK_FRACTURE, &sets);
    let (from, end) = kill_and_resume("detach", &case, 190);
    let (before, after) = (&from.cracks.as_ref().unwrap().detached, &end.cracks.as_ref().unwrap().detached);
    assert!(
        !before.is_empty() && after.len() > before.len(),
        "detached {before:?} by the checkpoint, {after:?} at the end"
    );
    assert_eq!(&after[..before.len()], &before[..]);
    assert!(after.iter().all(|&(i, _)| end.model.particles.flags[i].has(plugsim::particles::ParticleFlags::DETACHED)));
}

/// The crack log round-trips bit for bit, NaN payloads and −0.0 included.
#[test]
fn crack_state_round_trips_bit_for_bit() {
    let case = case(BORVIK_FRACTURE, FRACTURE_SETS);
    let dir = scratch("crack-round-trip");
    let path = run_until(&case, &dir, 2);
    let mut restored = checkpoint::read(&path).unwrap();
    let cracks = restored.sim.cracks.as_mut().expect("fracture is on");
    assert!(cracks.cracks.is_empty(), "no crack yet at step 2");
    let odd = [f64::from_bits(0x7ff8_dead_beef_0001), -0.0, f64::NEG_INFINITY];
    for (k, value) in odd.into_iter().enumerate() {
        cracks.events.push(plugsim::fracture::CrackEvent {
            time: -0.0,
            step: k as u64,
            crack: 0,
            kind: plugsim::fracture::EventKind::Nucleate,
            particles: vec![k, 2 * k],
            value,
            damage: -value,
            hardening: value,
        });
    }
    // Events must name an existing crack.
    cracks.cracks.push(plugsim::fracture::Crack {
        id: 0,
        vertices: vec![
            plugsim::fracture::CrackVertex { x0: restored.sim.model.particles.x0[0], faces: None },
            plugsim::fracture::CrackVertex { x0: restored.sim.model.particles.x0[1], faces: Some((0, 1)) },
        ],
        tip: Some(1),
        offset: 1e-6,
        nucleated: (-0.0, 1),
        arrested: Some((2e-9, 2)),
        allowance: 3.5e-5,
    });
    let again = dir.join("odd.ckpt");
    checkpoint::write(&again, &restored.sim, &restored.case, &restored.progress).unwrap();
    let back = checkpoint::read(&again).unwrap();
    let bytes = |s: &Simulation| checkpoint::state_bytes(s, &restored.case, &restored.progress);
    assert!(bytes(&back.sim) == bytes(&restored.sim), "state bytes differ after a round trip");
    let bits = |s: &Simulation| {
        s.cracks.as_ref().unwrap().events.iter().map(|e| (e.time.to_bits(), e.value.to_bits())).collect::<Vec<_>>()
    };
    assert_eq!(bits(&back.sim), bits(&restored.sim));
}

/// What catches a field forgotten by the checkpoint: a simulation with
/// contact, a crack, carried deformation-gradient jumps and heat pending,
/// written and read back. The model (stores, tables, gather, bodies,
/// materials) reads back printing (`Debug`) exactly as it was written, the
/// encoded states are equal, and the two copies, stepped on, stay equal in
/// every field of the `Simulation`: a field marked `#[serde(skip)]` and not
/// rebuilt on reading (one that holds other than its default here, as
/// `heat_pending` does: tried) fails here.
#[test]
fn checkpoint_round_trip_restores_every_field() {
    let case = case(BORVIK_FRACTURE, FRACTURE_SETS);
    let mut sim = build_simulation(&case).unwrap();
    while sim.cracks.as_ref().unwrap().cracks.is_empty() || sim.model.quad.f_carry.is_empty() || sim.heat_pending == 0.0
    {
        sim.step().unwrap();
        assert!(sim.step < 200, "no crack by step 200");
    }
    assert!(sim.contact.as_ref().unwrap().sample(0).unwrap().active_contacts > 0, "contacts at the checkpoint");
    let progress = RunProgress {
        snapshot_times: vec![0.0, 1e-6, -0.0],
        history_bytes: 1234,
        next_snapshot: 2e-6,
        next_checkpoint: f64::INFINITY,
        max_drift: 1e-3,
    };
    let path = scratch("every-field").join("state.ckpt");
    checkpoint::write(&path, &sim, &case, &progress).unwrap();
    let back = checkpoint::read(&path).unwrap();
    assert_eq!(back.progress, progress);
    assert_eq!(format!("{:?}", back.sim.model), format!("{:?}", sim.model), "the model reads back as written");
    let c = (sim.contact.as_ref().unwrap(), back.sim.contact.as_ref().unwrap());
    assert_eq!(format!("{:?}", (&c.0.bodies, &c.0.slaves)), format!("{:?}", (&c.1.bodies, &c.1.slaves)));
    let g = (sim.cracks.as_ref().unwrap(), back.sim.cracks.as_ref().unwrap());
    assert_eq!(format!("{:?}", g.0.segments()), format!("{:?}", g.1.segments()), "crack segments rebuilt");
    let bytes = |s: &Simulation| checkpoint::state_bytes(s, &case, &progress);
    assert!(bytes(&sim) == bytes(&back.sim), "the encoded states differ");
    let (mut a, mut b) = (sim, back.sim);
    for _ in 0..3 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_same_state(&a, &b, &case);
}

#[test]
fn checkpoint_round_trips_the_state_exactly() {
    let case = case(STRIKE, &["time.end=1e-6"]);
    let dir = scratch("round-trip");
    let path = run_until(&case, &dir, 5);
    let restored = checkpoint::read(&path).unwrap();
    let again = dir.join("again.ckpt");
    let progress = restored.progress.clone();
    checkpoint::write(&again, &restored.sim, &restored.case, &progress).unwrap();
    assert!(std::fs::read(&path).unwrap() == std::fs::read(&again).unwrap(), "write(read(file)) == file");
    assert_eq!(restored.sim.step, 5);
    assert_eq!(restored.writer, checkpoint::this_writer());
}

fn corrupt(path: &Path, at: usize, bytes: &[u8]) {
    let mut b = std::fs::read(path).unwrap();
    b[at..at + bytes.len()].copy_from_slice(bytes);
    std::fs::write(path, b).unwrap();
}

#[test]
fn checkpoint_of_another_format_version_is_refused_naming_both() {
    let case = case(STRIKE, &["time.end=1e-6"]);
    let dir = scratch("version");
    let path = run_until(&case, &dir, 3);
    for old in [0u32, FORMAT_VERSION + 1] {
        corrupt(&path, 8, &old.to_le_bytes());
        let e = resume(&config(&dir, None), &mut |_| {}).unwrap_err().to_string();
        assert!(
            e.contains(&format!("format version {old}")) && e.contains(&format!("format version {FORMAT_VERSION}")),
            "{e}"
        );
        assert!(e.contains(&path.display().to_string()) && e.contains("plugsim 0."), "{e}");
    }
}

/// Format 17 (before the history's `max_coefficient_gap`) is refused,
/// naming both versions, rather than resumed into a history without the
/// column.
#[test]
fn older_format_version_checkpoint_is_refused_naming_both_versions() {
    assert_eq!(FORMAT_VERSION, 18);
    let case = case(STRIKE, &["time.end=1e-6"]);
    let dir = scratch("version-17");
    let path = run_until(&case, &dir, 2);
    corrupt(&path, 8, &17u32.to_le_bytes());
    let e = checkpoint::read(&path).unwrap_err().to_string();
    assert!(e.contains("format version 17 ") && e.contains("reads format version 18"), "{e}");
    let e = resume(&config(&dir, None), &mut |_| {}).unwrap_err().to_string();
    assert!(e.contains("format version 17 ") && e.contains("format version 18"), "{e}");
}

#[test]
fn damaged_checkpoints_are_refused_or_skipped_for_an_older_one() {
    let case = case(STRIKE, &["time.end=2e-6", "checkpoint.interval=4e-7"]);
    let dir = scratch("damaged");
    let newest = run_until(&case, &dir, 8);
    let all = checkpoint::list(&checkpoint::directory(&dir));
    assert_eq!(all.len(), 2, "keep = 2 by default: {all:?}");
    let len = std::fs::metadata(&newest).unwrap().len() as usize;
    // a flipped byte in the payload
    corrupt(&newest, len / 2, &[0xAB, 0xCD]);
    let e = checkpoint::read(&newest).unwrap_err().to_string();
    assert!(e.contains("damaged") && e.contains("checksum"), "{e}");
    // resume falls back to the older checkpoint and says so
    let (_, warnings) = resume_to_end(&dir);
    assert!(warnings.iter().any(|w| w.contains("damaged")), "{warnings:?}");

    // truncated, and not a checkpoint at all
    let dir = scratch("truncated");
    let path = run_until(&case, &dir, 2);
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 100]).unwrap();
    let e = checkpoint::read(&path).unwrap_err().to_string();
    assert!(e.contains("damaged") && e.contains("truncated"), "{e}");
    std::fs::write(&path, b"hello").unwrap();
    let e = checkpoint::read(&path).unwrap_err().to_string();
    assert!(e.contains("not a plugsim checkpoint"), "{e}");
    let e = resume(&config(&scratch("none"), None), &mut |_| {}).unwrap_err().to_string();
    assert!(e.contains("no checkpoint"), "{e}");
}

#[test]
fn a_fresh_run_removes_the_checkpoints_of_an_earlier_run_in_its_directory() {
    let case1 = case(STRIKE, &["time.end=1e-6"]);
    let dir = scratch("fresh");
    run_until(&case1, &dir, 4);
    run_through(&case1, &dir);
    assert!(checkpoint::list(&checkpoint::directory(&dir)).is_empty());
}

fn history_rows(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("history.csv")).map_or(0, |t| t.lines().count().saturating_sub(1))
}

/// The real thing: the binary, stopped by SIGTERM (checkpoint, exit 130,
/// a message saying how to resume) and by SIGKILL after a periodic
/// checkpoint, resumed with `plugsim resume`; both directories end equal to
/// an uninterrupted run's.
#[cfg(unix)]
#[test]
fn binary_survives_sigterm_and_sigkill() {
    let args = |dir: &Path| -> Vec<String> {
        [
            "--threads",
            "1",
            "run",
            "--case",
            "elastic-strike",
            "--set",
            "time.end=8e-5",
            "--set",
            "checkpoint.interval=2e-6",
            "--force",
            "--out",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([dir.display().to_string()])
        .collect()
    };
    let reference = scratch("binary-reference");
    let a = args(&reference);
    let out = plugsim(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    for signal in ["TERM", "KILL"] {
        let dir = scratch(&format!("binary-{signal}"));
        let child = Command::new(env!("CARGO_BIN_EXE_plugsim"))
            .args(args(&dir))
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let pid = child.id();
        let started = std::time::Instant::now();
        while checkpoint::list(&checkpoint::directory(&dir)).is_empty() || history_rows(&dir) < 30 {
            assert!(started.elapsed().as_secs() < 60, "the run wrote no checkpoint");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let status = Command::new("kill").args([&format!("-{signal}"), &child.id().to_string()]).status().unwrap();
        assert!(status.success());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "a stopped run must not exit 0 ({signal}): {stderr}");
        if signal == "TERM" {
            assert_eq!(out.status.code(), Some(130), "{stderr}");
            assert!(stderr.contains("plugsim resume") && stderr.contains("interrupted at step"), "{stderr}");
        }
        // A kill inside an atomic write leaves its temporary file (a race
        // CI once lost); leave one on purpose so the resume always meets it.
        std::fs::write(dir.join(format!(".results.pvd.tmp{pid}-7")), b"<VTKFile").unwrap();
        let out = plugsim(&["resume", &dir.display().to_string()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        assert!(stderr.contains("resuming from"), "{stderr}");
        assert_same_outputs(&reference, &dir);
    }
}

/// A valid checkpoint with random bytes changed and its checksum made to
/// match again (so the damage reaches the decoder): reading it, and taking
/// a step from what was read, gives an error or a state, never a panic.
#[test]
fn altered_checkpoints_never_panic_the_reader() {
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
    let dir = scratch("fuzz");
    let path = run_until(&case(STRIKE, &["time.end=1e-6", "bodies.plate.rectangle.layers=4"]), &dir, 2);
    let original = std::fs::read(&path).unwrap();
    let writer_len = u32::from_le_bytes(original[12..16].try_into().unwrap()) as usize;
    let payload_at = 16 + writer_len + 12;
    let config = Config { cases: 200, failure_persistence: None, ..Config::default() };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let edits = prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6);
    let target = dir.join("altered.ckpt");
    runner
        .run(&edits, |edits| {
            let mut bytes = original.clone();
            for (at, value) in edits {
                let k = payload_at + at.index(bytes.len() - payload_at);
                bytes[k] = value;
            }
            let crc = crc32fast::hash(&bytes[payload_at..]);
            bytes[payload_at - 4..payload_at].copy_from_slice(&crc.to_le_bytes());
            std::fs::write(&target, &bytes).unwrap();
            if let Ok(mut r) = checkpoint::read(&target) {
                let _ = r.sim.step();
            }
            Ok(())
        })
        .unwrap();
}

/// A checkpoint that is not there gets one line naming it, with the
/// system's reason said once (the error's own text already ends with it).
#[test]
fn a_missing_checkpoint_is_named_with_its_cause_once() {
    for command in ["time-step", "crack-tips"] {
        let out = plugsim(&[command, "/nonexistent/plugsim-test.ckpt"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: checkpoint /nonexistent/plugsim-test.ckpt: "), "{stderr}");
        assert_eq!(stderr.matches("os error").count(), 1, "{stderr}");
    }
}

/// `plugsim crack-tips` reads the growing tips of a checkpoint (the fracture
/// resume test's periodic one, where a crack grows on after it): each
/// growing tip with its candidate table, its own faces among them as
/// "taken"; with `--set fracture.tip_gate="tension"` the same state under
/// the other gate; a key outside `fracture.*` refused naming it. And
/// `plugsim time-step` reads the same checkpoint: the particles that allow
/// the smallest steps, as many as asked, the first the one
/// `stability::step_setters` puts first.
#[test]
fn crack_tips_and_time_step_read_a_checkpoint() {
    let case = case(BORVIK_FRACTURE, FRACTURE_SETS);
    let dir = scratch("crack-tips");
    let _ = run_until(&case, &dir, FRACTURE_STOP);
    let ckpts = checkpoint::list(&checkpoint::directory(&dir));
    let (_, periodic) = ckpts.first().cloned().expect("the periodic checkpoint");
    let growing = checkpoint::read(&periodic).unwrap().sim.cracks.unwrap();
    let growing = growing.cracks.iter().filter(|c| c.growing()).count();
    assert!(growing > 0, "a crack grows at the checkpoint");
    let text = |args: &[&str]| {
        let out = plugsim(args);
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let file = periodic.to_str().unwrap();
    let (ok, stdout, stderr) = text(&["crack-tips", file]);
    assert!(ok, "{stderr}");
    assert_eq!(stdout.matches(": tip particle ").count(), growing, "{stdout}");
    assert!(stdout.contains("tip gate Triaxiality"), "{stdout}");
    assert!(stdout.lines().any(|l| l.trim_end().ends_with(" taken")), "the crack's own faces: {stdout}");
    let (ok, stdout, stderr) = text(&["crack-tips", file, "--set", "fracture.tip_gate=\"tension\""]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("tip gate Tension") && stdout.contains("read with fracture.tip_gate"), "{stdout}");
    let (ok, _, stderr) = text(&["crack-tips", file, "--set", "time.end=1e-6"]);
    assert!(!ok && stderr.contains("time.end") && stderr.contains("fracture.*"), "{stderr}");
    let (ok, stdout, stderr) = text(&["time-step", file, "--top", "3"]);
    assert!(ok, "{stderr}");
    let sim = checkpoint::read(&periodic).unwrap().sim;
    let first = plugsim::stability::step_setters(&sim.model, sim.stable.as_ref().unwrap(), sim.fractures_points(), 1);
    let rows: Vec<&str> = stdout.lines().skip_while(|l| !l.trim_start().starts_with("particle")).skip(1).collect();
    assert_eq!(rows.len(), 3, "{stdout}");
    assert_eq!(rows[0].split_whitespace().next(), Some(first[0].particle.to_string().as_str()), "{stdout}");
    assert!(stdout.contains("of the spacing step"), "{stdout}");
}
