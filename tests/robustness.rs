//! Bad input never becomes a panic or NaNs: each kind of hostile input gets
//! one clear line naming the problem, leaves no output directory behind and
//! exits non-zero; an unstable run stops with a message naming step, time,
//! place and likely cause, keeping its earlier output and checkpoints; and a
//! fuzzer over mutated case files finds no panic in the path of
//! `plugsim check`.

mod common;

use common::plugsim;
use plugsim::case::Case;
use plugsim::cases::BUILTIN_CASES;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("robustness-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The run failed, without a panic, with exactly one line on stderr; returns it.
fn one_error_line(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "must fail: {stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let lines: Vec<&str> = stderr.trim().lines().collect();
    assert_eq!(lines.len(), 1, "one line: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    lines[0].to_string()
}

/// `check` and `run` both refuse the case with one line; `run` leaves no
/// output directory. Returns the line of `check`.
fn refused(case_file: &Path, extra: &[&str], name: &str) -> String {
    let case = case_file.display().to_string();
    let check = one_error_line(&plugsim(&[&["check", &case], extra].concat()));
    let out_dir = scratch(&format!("{name}-run")).join("out");
    let out = out_dir.display().to_string();
    let run = one_error_line(&plugsim(&[&["run", &case, "--out", &out], extra].concat()));
    assert!(!out_dir.exists(), "a refused run leaves no output directory: {run}");
    check
}

fn write_case(name: &str, text: &str) -> PathBuf {
    let path = scratch(name).join("case.toml");
    std::fs::write(&path, text).unwrap();
    path
}

const STRIKE: &str = include_str!("../cases/elastic-strike.toml");

#[test]
fn malformed_toml_names_file_and_line() {
    let path = write_case("malformed", "title = \"x\"\n[geometry\nmode = ");
    let line = refused(&path, &[], "malformed");
    assert!(line.contains(&path.display().to_string()) && line.contains("line 2"), "{line}");
}

#[test]
fn wrong_type_names_the_key() {
    let path = write_case("wrong-type", &STRIKE.replace("layers = 12 ", "layers = \"twelve\" "));
    let line = refused(&path, &[], "wrong-type");
    assert!(line.contains("layers") && line.contains("twelve"), "{line}");
    let line = refused(&write_case("wrong-type-2", STRIKE), &["--set", "time.end=soon"], "wrong-type-2");
    assert!(line.contains("time.end") && line.contains("soon"), "{line}");
}

#[test]
fn absurd_discretization_is_refused_up_front_with_the_estimate() {
    let path = write_case("absurd", STRIKE);
    for set in ["bodies.plate.rectangle.layers=2000000", "bodies.plate.rectangle.fine_spacing=1e-300"] {
        let t = std::time::Instant::now();
        let line = refused(&path, &["--set", set], "absurd");
        assert!(t.elapsed().as_secs_f64() < 10.0, "refused fast");
        assert!(line.contains("memory") && line.contains("particles") && line.contains("available"), "{line}");
    }
}

#[test]
fn absurd_step_count_and_snapshot_count_are_refused() {
    let path = write_case("steps", STRIKE);
    let line = refused(&path, &["--set", "time.fixed_dt=1e-20"], "steps");
    assert!(line.contains("time step") && line.contains("steps"), "{line}");
    let line = refused(&path, &["--set", "output.interval=1e-15"], "snapshots");
    assert!(line.contains("output.interval") && line.contains("snapshots"), "{line}");
    // moduli so large that the wave speed overflows: the step would be zero
    let line = refused(
        &path,
        &["--set", "materials.steel.youngs_modulus=1e308", "--set", "materials.steel.density=1e-300"],
        "zero-dt",
    );
    assert!(line.contains("time step") && line.contains("positive"), "{line}");
}

#[test]
fn unreadable_case_path_is_named() {
    let line = one_error_line(&plugsim(&["check", "/nonexistent/case.toml"]));
    assert!(line.contains("/nonexistent/case.toml") && line.contains("cannot read"), "{line}");
    let dir = scratch("case-is-dir");
    let line = one_error_line(&plugsim(&["check", &dir.display().to_string()]));
    assert!(line.contains("cannot read"), "{line}");
}

#[test]
fn unwritable_output_path_is_named_and_nothing_is_left() {
    let dir = scratch("unwritable");
    let blocker = dir.join("a-file");
    std::fs::write(&blocker, b"not a directory").unwrap();
    for out in [blocker.join("run"), blocker.clone()] {
        let line = one_error_line(&plugsim(&["run", "--case", "elastic-strike", "--out", &out.display().to_string()]));
        assert!(line.contains("output directory") && line.contains(&out.display().to_string()), "{line}");
    }
    assert_eq!(std::fs::read(&blocker).unwrap(), b"not a directory");
}

#[test]
fn a_limit_search_that_cannot_run_is_refused_before_any_run() {
    // `--speeds` runs before the search: the bounds must be checked first,
    // or a bad `--tol` is found only after the listed runs have been spent.
    for (extra, named) in [
        (&["--speeds", "300", "--limit", "--tol", "0"][..], "tol = 0 m/s"),
        (&["--limit", "--lo", "300", "--hi", "100"][..], "lo = 300, hi = 100"),
    ] {
        let out_dir = scratch("bad-search").join("out");
        let out = out_dir.display().to_string();
        let args = [&["ballistic", "--case", "borvik-1-axisymmetric-nonlocal", "--out", &out][..], extra].concat();
        let line = one_error_line(&plugsim(&args));
        assert!(line.contains("the limit search needs") && line.contains(named), "{line}");
        assert!(!out_dir.exists(), "nothing ran: {line}");
    }
}

/// `--jobs 0` (no run could start) is refused by the parser before any
/// run, naming the option; it used to run as `--jobs 1`.
#[test]
fn no_runs_side_by_side_is_refused() {
    let out_dir = scratch("no-jobs").join("out");
    let out = out_dir.display().to_string();
    let args =
        ["ballistic", "--case", "borvik-1-axisymmetric-nonlocal", "--speeds", "300", "--jobs", "0", "--out", &out];
    let run = plugsim(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "a usage error: {stderr}");
    assert!(stderr.contains("'0'") && stderr.contains("--jobs") && stderr.contains("at least 1"), "{stderr}");
    assert!(!out_dir.exists(), "nothing ran: {stderr}");
}

/// An impact at or above a body's elastic wave speed (a speed in mm/s, say)
/// is refused before any run, in a case file and as `plugsim ballistic`'s
/// speeds, naming the field or option and the body whose wave it outruns.
#[test]
fn a_speed_past_the_elastic_wave_is_refused() {
    // steel: c_L = sqrt((K + 4G/3)/rho) about 5.9 km/s; 50 m/s runs
    let path = write_case("hypervelocity", STRIKE);
    let line = refused(&path, &["--set", "bodies.plate.initial_velocity.0.velocity=[0.0, -5.0e4]"], "hypervelocity");
    assert!(
        line.contains("bodies[0].initial_velocity[0].velocity") && line.contains("'plate'") && line.contains("m/s"),
        "{line}"
    );
    for (extra, option) in [
        (&["--speeds", "300,1e9"][..], "--speeds: 1000000000 m/s"),
        (&["--limit", "--hi", "6000"][..], "--hi: 6000 m/s"),
        (
            &["--set", "rigid_bodies.projectile.velocity=[0.0, -3.0e5]", "--speeds", "300"][..],
            "rigid_bodies[0].velocity",
        ),
    ] {
        let out_dir = scratch("hypervelocity-ballistic").join("out");
        let out = out_dir.display().to_string();
        let args = [&["ballistic", "--case", "borvik-1-axisymmetric-nonlocal", "--out", &out][..], extra].concat();
        let line = one_error_line(&plugsim(&args));
        assert!(line.contains(option) && line.contains("elastic wave speed of body 'plate'"), "{line}");
        assert!(!out_dir.exists(), "nothing ran: {line}");
    }
}

#[test]
fn unknown_material_and_body_are_named() {
    let path = write_case("unknown-material", &STRIKE.replace("material = \"steel\"", "material = \"unobtainium\""));
    let line = refused(&path, &[], "unknown-material");
    assert!(
        line.contains("bodies[0].material") && line.contains("unobtainium") && line.contains("weldox_460e"),
        "{line}"
    );
    let path = write_case("unknown-body", STRIKE);
    let line = refused(&path, &["--set", "bodies.anvil.material=steel"], "unknown-body");
    assert!(line.contains("bodies.anvil.material") && line.contains("no element named 'anvil'"), "{line}");
}

/// A fixed step about twice the stable one: the run must stop with the
/// step, time, place and likely cause, exit 1, and keep the snapshots,
/// history and checkpoints written before.
#[test]
fn unstable_fixed_dt_stops_with_a_message() {
    let dir = scratch("unstable").join("out");
    let out = plugsim(&[
        "run",
        "--case",
        "elastic-strike",
        "--set",
        "time.fixed_dt=3e-7",
        "--set",
        "checkpoint.interval=6e-7",
        "--set",
        "output.interval=6e-7",
        "--set",
        "output.history_every=1",
        "--out",
        &dir.display().to_string(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("energy blow-up in step") && stderr.contains("(t = "), "{stderr}");
    assert!(stderr.contains("likely cause") && stderr.contains("fixed_dt") && stderr.contains("particle"), "{stderr}");
    // earlier output intact: every snapshot the series names exists and parses
    let pvd = std::fs::read_to_string(dir.join("results.pvd")).unwrap();
    let files: Vec<&str> = pvd.split("file=\"").skip(1).map(|s| &s[..s.find('"').unwrap()]).collect();
    assert!(files.len() >= 3, "{pvd}");
    for f in &files {
        let text = std::fs::read(dir.join(f)).unwrap();
        assert!(text.starts_with(b"<?xml") || text.starts_with(b"<VTKFile"), "{f}");
    }
    assert!(stderr.contains(files.last().unwrap()), "the message names the last snapshot: {stderr}");
    let history = plugsim::io::HistoryTable::read(&dir.join("history.csv")).unwrap();
    let steps = history.column("step").unwrap();
    assert!(steps.windows(2).all(|w| w[1] == w[0] + 1.0), "{steps:?}");
    let ckpts = plugsim::checkpoint::list(&plugsim::checkpoint::directory(&dir));
    assert!(!ckpts.is_empty());
    for (_, path) in ckpts {
        let r = plugsim::checkpoint::read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(r.sim.energies.total() < 2.0 * r.sim.energies.initial_kinetic);
    }
}

/// A rigid punch driven at a prescribed velocity puts energy in as it goes:
/// the blow-up check must count the driver's work as input, not stop the run.
#[test]
fn a_driven_punch_is_not_an_energy_blow_up() {
    use plugsim::run::{execute, Progress, RunConfig, RunInfo};
    let overrides: Vec<String> = [
        "bodies.plate.rectangle.layers=6",
        "bodies.plate.rectangle.x_min=-0.04",
        "bodies.plate.rectangle.x_max=0.04",
        "bodies.plate.supports.0.region.x_min=-0.04",
        "bodies.plate.supports.0.region.x_max=-0.037",
        "bodies.plate.supports.1.region.x_min=0.037",
        "bodies.plate.supports.1.region.x_max=0.04",
        "rigid_bodies.projectile.prescribed=true",
        "rigid_bodies.projectile.density=100.0",
        "time.end=3e-6",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let case =
        Case::from_str_with(include_str!("../cases/borvik-1-nofracture.toml"), "punch.toml", &overrides).unwrap();
    let dir = scratch("punch").join("out");
    let mut last = None;
    execute(&case, &RunConfig::new(dir, true, RunInfo::current("punch", &[])), &mut |p| {
        if let Progress::Finished { sim } = p {
            last = Some(sim.clone());
        }
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let sim = last.unwrap();
    let e = sim.energies;
    assert!(e.total() > 2.0 * e.initial_kinetic, "the driver put in more than the punch's kinetic energy: {e:?}");
    let input = sim.input_energy();
    assert!((e.total() - input).abs() < 0.05 * input, "balance {} J against input {input} J", e.total());
}

// ------------------------------------------------------------------ fuzz

#[derive(Clone, Debug)]
enum Seg {
    Key(String),
    Index(usize),
}

/// Every path into the document (tables, arrays and leaves).
fn paths(v: &toml::Value, prefix: &mut Vec<Seg>, out: &mut Vec<Vec<Seg>>) {
    match v {
        toml::Value::Table(t) => {
            for (k, child) in t {
                prefix.push(Seg::Key(k.clone()));
                out.push(prefix.clone());
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        toml::Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                prefix.push(Seg::Index(i));
                out.push(prefix.clone());
                paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(v: &'a mut toml::Value, path: &[Seg]) -> Option<&'a mut toml::Value> {
    path.iter().try_fold(v, |cur, seg| match (seg, cur) {
        (Seg::Key(k), toml::Value::Table(t)) => t.get_mut(k),
        (Seg::Index(i), toml::Value::Array(a)) => a.get_mut(*i),
        _ => None,
    })
}

#[derive(Clone, Debug)]
enum Edit {
    /// Keep the type, change the value: a float scaled or replaced by an
    /// extreme, an integer likewise, a string replaced.
    Tweak(f64, i64, String),
    Delete,
    Set(toml::Value),
    AddKey(String, toml::Value),
    /// The same change as a `--set` override.
    Override(toml::Value),
}

#[derive(Clone, Debug)]
enum TextEdit {
    None,
    Truncate(prop::sample::Index),
    Insert(prop::sample::Index, String),
}

fn value() -> impl Strategy<Value = toml::Value> {
    use toml::Value as V;
    let special = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 0.0, -0.0, 1e-300, -1.0, 1e9, 0.5];
    prop_oneof![
        prop::sample::select(special.clone()).prop_map(V::Float),
        any::<f64>().prop_map(V::Float),
        prop::sample::select(vec![0i64, -1, 1, 2, 5, 1_000_000_000, i64::MAX, i64::MIN]).prop_map(V::Integer),
        any::<i64>().prop_map(V::Integer),
        "\\PC{0,12}".prop_map(V::String),
        prop::sample::select(vec![
            "plate",
            "steel",
            "weldox_460e",
            "all",
            "x",
            "plane_strain",
            "axisymmetric",
            "log",
            "elastic",
            "johnson_cook"
        ])
        .prop_map(|s| V::String(s.into())),
        any::<bool>().prop_map(V::Boolean),
        Just(V::Array(vec![])),
        Just(V::Table(toml::Table::new())),
        prop::collection::vec(prop::sample::select(special), 0..4)
            .prop_map(|v| V::Array(v.into_iter().map(V::Float).collect())),
    ]
}

fn edit() -> impl Strategy<Value = Edit> {
    let factors = vec![0.0, -1.0, 1e-300, 1e300, 1e-6, 1e6, 10.0, 0.1, 0.999, 1.001, f64::NAN, f64::INFINITY, -0.0];
    let ints = vec![0i64, 1, 2, 3, -1, 1000, 1_000_000_000, i64::MAX, i64::MIN];
    let names = "(plate|steel|weldox_460e|disc|projectile|all|x|y|log|power|\\PC{0,8})";
    prop_oneof![
        6 => (prop_oneof![prop::sample::select(factors), -10.0..10.0f64], prop::sample::select(ints), names)
            .prop_map(|(f, i, s)| Edit::Tweak(f, i, s)),
        2 => Just(Edit::Delete),
        4 => value().prop_map(Edit::Set),
        1 => ("[a-z_]{1,10}", value()).prop_map(|(k, v)| Edit::AddKey(k, v)),
        1 => value().prop_map(Edit::Override),
    ]
}

fn text_edit() -> impl Strategy<Value = TextEdit> {
    prop_oneof![
        6 => Just(TextEdit::None),
        1 => any::<prop::sample::Index>().prop_map(TextEdit::Truncate),
        1 => (any::<prop::sample::Index>(), "\\PC{1,6}").prop_map(|(i, s)| TextEdit::Insert(i, s)),
    ]
}

/// The shipped cases, and the same shrunk to a few hundred particles so
/// that mutations which stay valid reach the model builder quickly.
fn base_cases() -> Vec<toml::Value> {
    let mut cases = Vec::new();
    for (_, text, _) in BUILTIN_CASES.iter().map(|c| (c.0, c.1, c.2)).chain([(
        "borvik",
        include_str!("../cases/borvik-1-nofracture.toml"),
        "",
    )]) {
        let v: toml::Value = toml::from_str(text).unwrap();
        let mut small = v.clone();
        if let Some(toml::Value::Array(bodies)) = get_mut(&mut small, &[Seg::Key("bodies".into())]) {
            for b in bodies {
                if let Some(layers) = get_mut(b, &[Seg::Key("rectangle".into()), Seg::Key("layers".into())]) {
                    *layers = toml::Value::Integer(4);
                }
            }
        }
        cases.push(v);
        cases.push(small);
    }
    cases
}

fn dotted(path: &[Seg]) -> String {
    path.iter()
        .map(|s| match s {
            Seg::Key(k) => k.clone(),
            Seg::Index(i) => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// What `plugsim check` does with a case text: parse with overrides,
/// validate, the memory guard, then build the model (only for small
/// models, to keep the fuzz fast: the guard must refuse the big ones
/// without building anything).
fn check_like_the_cli(text: &str, overrides: &[String]) {
    let case = match Case::from_str_with(text, "fuzz.toml", overrides) {
        Ok(c) => c,
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("fuzz.toml"), "{msg}");
            return;
        }
    };
    let _ = case.resolved_toml();
    let resolved = case.resolved();
    let footprint = match plugsim::run::preflight(&resolved) {
        Ok(f) => f,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    if footprint.particles <= 3000.0 && footprint.quadrature_entries <= 2e5 {
        match plugsim::run::build_simulation(&resolved) {
            Ok(sim) => {
                assert!(sim.dt.is_finite() && sim.dt > 0.0);
                assert!(sim.model.particles.mass.iter().all(|m| m.is_finite() && *m > 0.0));
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 1500,
        rng_seed: RngSeed::Fixed(0x9106_5113),
        max_shrink_iters: 2000,
        ..ProptestConfig::default()
    })]

    /// Mutated shipped cases (deleted keys, swapped types, NaN, inf, 1e300,
    /// negative, zero, random strings, unknown keys, overrides, truncated or
    /// garbled text) never panic in the path of `plugsim check`.
    #[test]
    fn fuzz_case_files_never_panic(
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), edit()), 1..4),
        text in text_edit(),
    ) {
        let bases = base_cases();
        let mut doc = which.get(&bases).clone();
        let mut overrides = Vec::new();
        for (at, e) in edits {
            let mut all = Vec::new();
            paths(&doc, &mut Vec::new(), &mut all);
            if all.is_empty() {
                break;
            }
            let path = at.get(&all).clone();
            let (parent, last) = path.split_at(path.len() - 1);
            match e {
                Edit::Tweak(f, i, text) => {
                    if let Some(slot) = get_mut(&mut doc, &path) {
                        let new = match slot {
                            toml::Value::Float(x) => Some(toml::Value::Float(*x * f)),
                            toml::Value::Integer(_) => Some(toml::Value::Integer(i)),
                            toml::Value::String(_) => Some(toml::Value::String(text)),
                            toml::Value::Boolean(b) => Some(toml::Value::Boolean(!*b)),
                            _ => None,
                        };
                        if let Some(v) = new {
                            *slot = v;
                        }
                    }
                }
                Edit::Delete => match (get_mut(&mut doc, parent), &last[0]) {
                    (Some(toml::Value::Table(t)), Seg::Key(k)) => {
                        t.remove(k);
                    }
                    (Some(toml::Value::Array(a)), Seg::Index(i)) if *i < a.len() => {
                        a.remove(*i);
                    }
                    _ => {}
                },
                Edit::Set(v) => {
                    if let Some(slot) = get_mut(&mut doc, &path) {
                        *slot = v;
                    }
                }
                Edit::AddKey(k, v) => {
                    if let Some(toml::Value::Table(t)) = get_mut(&mut doc, parent) {
                        t.insert(k, v);
                    }
                }
                Edit::Override(v) => overrides.push(format!("{}={}", dotted(&path), v)),
            }
        }
        let Ok(mut text_out) = toml::to_string(&doc) else { return Ok(()) };
        match text {
            TextEdit::None => {}
            TextEdit::Truncate(at) => {
                let mut cut = at.index(text_out.len() + 1);
                while !text_out.is_char_boundary(cut) {
                    cut -= 1;
                }
                text_out.truncate(cut);
            }
            TextEdit::Insert(at, s) => {
                let mut pos = at.index(text_out.len() + 1);
                while !text_out.is_char_boundary(pos) {
                    pos -= 1;
                }
                text_out.insert_str(pos, &s);
            }
        }
        check_like_the_cli(&text_out, &overrides);
    }
}

/// `plugsim cases` lists every built-in case and alias, and a reader that
/// closes the pipe before the listing is written (`plugsim cases | head -0`)
/// ends it quietly: exit 0, no panic on the closed pipe.
#[test]
fn case_listing_survives_a_closed_pipe() {
    let out = plugsim(&["cases"]);
    assert!(out.status.success());
    let listed = String::from_utf8_lossy(&out.stdout).lines().count();
    assert_eq!(listed, BUILTIN_CASES.len() + plugsim::cases::ALIASES.len());
    for _ in 0..5 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_plugsim"))
            .arg("cases")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader is gone before the child starts writing
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "exit {:?}: {stderr}", out.status);
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
