//! Børvik's reference cases (SPEC §10): the built-in `borvik-*` family is
//! complete, its files are the built-ins, every member uses the same
//! numerical parameters and keeps reflected waves out of the impact zone
//! until [RL10]'s perforation time; and one coarse member, run as shipped
//! for its first microseconds, cracks at the projectile's corners and slows
//! the projectile.

use plugsim::case::Case;
use plugsim::cases::{borvik_family, builtin_case, ALIASES, BORVIK_DEFORMABLE_CASES, BORVIK_NOSE_CASES, BUILTIN_CASES};
use plugsim::fracture::{Criterion, EventKind, FractureParameters};
use plugsim::geometry::GeometryMode;
use plugsim::material::Constitutive;
use plugsim::math::Real;
use plugsim::validation::EXPERIMENTS;

fn load(name: &str) -> Case {
    let text = builtin_case(name).unwrap_or_else(|| panic!("{name} is not built in"));
    Case::from_str_with(text, name, &[]).unwrap_or_else(|e| panic!("{e}")).resolved()
}

#[test]
fn the_family_is_complete_and_every_member_parses_and_validates() {
    let family = borvik_family();
    // 2 cases x 2 geometries x 2 discretizations x 2 criteria + 2 x 2 modified
    // + 2 x 2 with the default model (axisymmetric, coarse and fine)
    assert_eq!(family.len(), 16 + 4 + 4);
    let names: Vec<String> = family.iter().map(|m| m.name()).collect();
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "names are distinct");
    for e in 1..=2u8 {
        for g in ["plane_strain", "axisymmetric"] {
            for d in ["coarse", "fine"] {
                for c in ["effective_strain", "damage"] {
                    let n = family
                        .iter()
                        .filter(|m| m.experiment == e && m.geometry == g && m.discretization == d && m.criterion == c)
                        .count();
                    let modified = usize::from(g == "axisymmetric" && d == "fine");
                    assert_eq!(n, 1 + modified, "case {e} {g} {d} {c}");
                }
                let n = family
                    .iter()
                    .filter(|m| m.experiment == e && m.geometry == g && m.discretization == d)
                    .filter(|m| m.criterion == "nonlocal_damage")
                    .count();
                assert_eq!(n, usize::from(g == "axisymmetric"), "case {e} {g} {d}, default model");
            }
        }
    }
    for m in &family {
        let case = load(&m.name());
        let mode = if m.geometry == "plane_strain" { GeometryMode::PlaneStrain } else { GeometryMode::Axisymmetric };
        assert_eq!(case.geometry.mode, mode, "{}", m.name());
        assert_eq!(case.bodies[0].rectangle.layers, if m.discretization == "coarse" { 24 } else { 48 });
        let criterion = match m.criterion {
            "damage" => Criterion::Damage,
            "nonlocal_damage" => Criterion::NonlocalDamage,
            _ => Criterion::EffectiveStrain,
        };
        assert_eq!(case.fracture.criterion, criterion, "{}", m.name());
        assert_eq!(case.bodies[0].material, m.material, "{}", m.name());
    }
    // the names the README and the tests have always used, and the aliases
    for old in ["borvik-1-plane-strain", "borvik-1-plane-strain-fine", "borvik-1-axisymmetric", "borvik-1-nofracture"] {
        assert!(builtin_case(old).is_some(), "{old}");
    }
    assert_eq!(builtin_case("borvik-1"), builtin_case("borvik-1-plane-strain"));
    assert_eq!(ALIASES.len(), 2);
}

#[test]
fn every_case_file_is_a_built_in_and_every_borvik_built_in_is_in_the_family() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases");
    let mut files = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        if path.is_dir() {
            continue; // cases/reference: the experiments' data, not cases
        }
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(builtin_case(&stem), Some(text.as_str()), "{} is not the built-in {stem}", path.display());
        files += 1;
    }
    assert_eq!(files, BUILTIN_CASES.len());
    let family: Vec<String> = borvik_family().iter().map(|m| m.name()).collect();
    for (name, _, _) in BUILTIN_CASES.iter().filter(|c| c.0.starts_with("borvik-")) {
        assert!(
            family.iter().any(|f| f == name)
                || *name == "borvik-1-nofracture"
                || BORVIK_NOSE_CASES.contains(name)
                || BORVIK_DEFORMABLE_CASES.contains(name),
            "{name} outside the family"
        );
    }
}

/// One set of numerical parameters for every member: what is not the
/// experiment (thickness, speed, span, times), the geometry, the
/// discretization level, the criterion or the material must be equal.
#[test]
fn every_member_uses_the_same_numerical_parameters() {
    let family = borvik_family();
    let reference = load(&family[0].name());
    let r0 = &reference.bodies[0].rectangle;
    for m in &family {
        let case = load(&m.name());
        let name = m.name();
        assert_eq!(case.contact, reference.contact, "{name}: contact");
        assert_eq!(case.heat, reference.heat, "{name}: heat");
        // the criterion, and the tip's rule that goes with it (its defaults)
        let own = FractureParameters::for_criterion(case.fracture.criterion);
        let expected = FractureParameters {
            criterion: own.criterion,
            tip_direction: own.tip_direction,
            nonlocal_tip_triaxiality: own.nonlocal_tip_triaxiality,
            detach_below: own.detach_below,
            ..reference.fracture
        };
        assert_eq!(case.fracture, expected, "{name}: fracture");
        assert_eq!(case.time.safety_factor, reference.time.safety_factor, "{name}");
        assert_eq!(case.time.fixed_dt, reference.time.fixed_dt, "{name}");
        assert_eq!(case.output.interval, reference.output.interval, "{name}");
        assert_eq!(case.output.history_every, reference.output.history_every, "{name}");
        let r = &case.bodies[0].rectangle;
        assert_eq!(
            (r.support_factor, r.gauss, r.growth, r.fine_half_width),
            (r0.support_factor, r0.gauss, r0.growth, r0.fine_half_width),
            "{name}: grid"
        );
        // the coarsest spacing scales with the rows: 0.6 mm coarse, 0.3 mm fine
        let ratio = r.coarse_spacing.unwrap() * r.layers as Real / (r0.coarse_spacing.unwrap() * r0.layers as Real);
        assert!((ratio - 1.0).abs() < 1e-12, "{name}: coarse spacing");
        for s in &case.bodies[0].supports {
            assert!(s.region.x_max - s.region.x_min >= 2.0 * r.support_factor * r.coarse_spacing.unwrap(), "{name}");
        }
    }
}

/// SPEC §4: the span must keep waves reflected at the clamps out of the
/// impact zone until perforation. A longitudinal wave leaving the
/// projectile's edge at impact is back there after `2 d / c_L`, with `d`
/// the distance from the edge to the nearest clamp; [RL10]'s perforation
/// times are 28 µs (Case I) and 46 µs (Case II).
#[test]
fn reflected_waves_return_after_the_papers_perforation_time() {
    for m in borvik_family() {
        let case = load(&m.name());
        let e = &EXPERIMENTS[m.experiment as usize - 1];
        let c = case.material(&case.bodies[0].material).unwrap().longitudinal_wave_speed();
        let p = case.rigid_bodies[0].rectangle.as_ref().unwrap();
        let edge = p.center[0] + 0.5 * p.width;
        for s in &case.bodies[0].supports {
            let d = s.region.x_min.abs().min(s.region.x_max.abs()) - edge;
            let back = 2.0 * d / c;
            assert!(back > e.perforation_time * 1.05, "{}: reflection back after {:.1} us", m.name(), back * 1e6);
        }
        assert_eq!(case.time.end, e.simulated_time, "{}", m.name());
        assert_eq!(case.output.plot_times, vec![e.perforation_time], "{}", m.name());
    }
}

/// The CI run of a reference case: Case I, plane strain, coarse, as
/// shipped (11,496 particles), for its first 5 µs of 118. In that time
/// [RL10]'s model starts one crack at each corner of the projectile on the
/// impact face (here at 1.3 µs), both run several particles into the
/// thickness, and the projectile slows down. About 120 steps.
#[test]
fn coarse_case_one_cracks_at_both_corners_and_slows_the_projectile() {
    let case = load("borvik-1");
    let r = &case.bodies[0].rectangle;
    assert_eq!((r.layers, r.x_max, r.y_max), (24, 0.138, 0.0111), "the case as shipped, not shrunk");
    let h = r.layer_spacing();
    let mut sim = plugsim::run::build_simulation(&case).unwrap();
    assert_eq!(sim.model.particles.len(), 11496);
    while sim.time < 5e-6 {
        sim.step().unwrap();
    }
    let g = sim.cracks.as_ref().unwrap();
    assert!(g.cracks.len() >= 2, "two cracks: {:?}", g.events);
    let mut sides = Vec::new();
    for c in &g.cracks {
        let p0 = c.vertices[0].x0;
        assert!((p0.y - 0.0111).abs() < 1e-9, "crack {} nucleated on the impact face: {p0:?}", c.id);
        assert!((p0.x.abs() - 0.01).abs() < 1.5 * h, "crack {} at a corner (|x| = 10 mm): {p0:?}", c.id);
        sides.push(p0.x.signum());
        let grown = g.events.iter().filter(|e| e.crack == c.id && e.kind == EventKind::Propagate).count();
        assert!(grown >= 3, "crack {} propagated {grown} times", c.id);
        let deepest = c.vertices.iter().map(|v| v.x0.y).fold(Real::INFINITY, Real::min);
        assert!(deepest < 0.0111 - 2.0 * h, "crack {} runs into the thickness: {:?}", c.id, c.vertices);
    }
    assert!(sides.contains(&1.0) && sides.contains(&-1.0), "one crack at each corner: {sides:?}");
    let v = sim.contact.as_ref().unwrap().bodies[0].velocity;
    assert!(v.y > -298.0 + 10.0, "the projectile decelerated: {v:?}");
    assert!(sim.model.particles.mass.iter().all(|&m| m > 0.0));
}

/// Børvik et al.'s nose-shape cases (2002) use the numerical parameters of
/// the coarse axisymmetric family member, a 12 mm plate, the 197 g, 20 mm
/// projectile by its nose, and a span that keeps reflected waves out of the
/// impact zone until the nose has passed through the plate at the impact
/// speed (the plate thickness plus the nose length: a lower bound on the
/// perforation time, [RL10] giving none for these experiments).
#[test]
fn nose_shape_cases_share_the_family_parameters_and_keep_reflections_out() {
    let reference = load("borvik-1-axisymmetric-nonlocal");
    let r0 = &reference.bodies[0].rectangle;
    let mut noses = Vec::new();
    for name in BORVIK_NOSE_CASES {
        assert!(builtin_case(name).is_some(), "{name} is not built in");
        let case = load(name);
        assert_eq!(case.geometry.mode, GeometryMode::Axisymmetric, "{name}");
        assert_eq!(case.bodies[0].material, reference.bodies[0].material, "{name}");
        assert_eq!(case.contact, reference.contact, "{name}: contact");
        assert_eq!(case.heat, reference.heat, "{name}: heat");
        assert_eq!(case.fracture, reference.fracture, "{name}: fracture");
        assert_eq!(
            (case.time.safety_factor, case.time.fixed_dt, case.output.interval, case.output.history_every),
            (
                reference.time.safety_factor,
                reference.time.fixed_dt,
                reference.output.interval,
                reference.output.history_every
            ),
            "{name}: time and output"
        );
        let r = &case.bodies[0].rectangle;
        assert_eq!(
            (r.layers, r.support_factor, r.gauss, r.growth, r.fine_half_width, r.coarse_spacing),
            (r0.layers, r0.support_factor, r0.gauss, r0.growth, r0.fine_half_width, r0.coarse_spacing),
            "{name}: grid"
        );
        assert_eq!((r.y_min, r.y_max), (0.0, 0.012), "{name}: the 12 mm plate");
        let rb = &case.rigid_bodies[0];
        let p = rb.projectile.as_ref().unwrap_or_else(|| panic!("{name}: the projectile is given by its nose"));
        assert_eq!((p.diameter, rb.mass), (0.02, Some(0.197)), "{name}: the 20 mm, 197 g projectile");
        assert!((p.tip[1] - 0.01205).abs() < 1e-12, "{name}: tip 0.05 mm above the plate");
        let geometry = p.projectile().unwrap();
        let speed = (rb.velocity[0].powi(2) + rb.velocity[1].powi(2)).sqrt();
        let passage = (0.012 + geometry.nose_length()) / speed;
        let c = case.material(&case.bodies[0].material).unwrap().longitudinal_wave_speed();
        for s in &case.bodies[0].supports {
            assert!(s.region.x_max - s.region.x_min >= 2.0 * r.support_factor * r.coarse_spacing.unwrap(), "{name}");
            let back = 2.0 * (s.region.x_min - geometry.radius()) / c;
            assert!(
                back > passage * 1.05,
                "{name}: reflection back after {:.1} us, nose through at {:.1} us",
                back * 1e6,
                passage * 1e6
            );
        }
        noses.push(p.nose);
    }
    noses.dedup();
    assert_eq!(noses.len(), BORVIK_NOSE_CASES.len(), "one case per nose");
}

/// A projectile is through its target ([`plugsim::residual`]) once its
/// nose lies one target depth beyond the target's far face: for Børvik's
/// plates, hit from above, when the nose is one plate thickness below the
/// back face (y = 0). From the case files: the blunt face starts 0.05 mm
/// above the 10.2 mm plate, the hemispherical tip at y = 12.05 mm above
/// the 12 mm plate; the body frame's origin must then have moved down by
/// the face's travel, `face + thickness`.
#[test]
fn a_projectile_is_through_one_plate_thickness_past_the_back_face() {
    for (name, thickness, nose) in [
        ("borvik-2-axisymmetric-nonlocal", 0.0102, 0.0102 + 0.05e-3),
        ("borvik-2002-12mm-hemispherical", 0.012, 0.01205),
    ] {
        let case = load(name);
        let sim = plugsim::run::build_simulation(&case).unwrap();
        let (names, v0): (Vec<String>, Vec<_>) = case.flights().into_iter().unzip();
        let through = plugsim::output::through_positions(&sim, &names, &v0);
        let origin = sim.contact.as_ref().unwrap().bodies[0].position;
        // along the flight (−y): the origin's position when through
        let expected = -(origin.y - (nose + thickness));
        assert_eq!(through.len(), 1, "{name}");
        let got = through[0].unwrap_or_else(|| panic!("{name}: no target"));
        assert!((got - expected).abs() < 1e-9, "{name}: through at {got} m along the flight, expected {expected}");
    }
}

/// The experiments CSVs shipped for `plugsim ballistic --experiments`
/// (`cases/reference/*.csv`) read with the command's own reader and carry
/// what the data file `borvik-experiments.toml` and the SPEC's table say:
/// each nose's held shots and its published limit as points with `v_r = 0`
/// (no more, no less), and Case I's and II's tests as
/// [`EXPERIMENTS`] has them; and each is the one a built-in case carries
/// (`cases::BUILTIN_EXPERIMENTS`). A CSV edited without its source, or a
/// source edited without its CSV, fails here.
#[test]
fn reference_experiment_files_agree_with_the_data_file() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/reference");
    let data: toml::Table = std::fs::read_to_string(dir.join("borvik-experiments.toml")).unwrap().parse().unwrap();
    let noses = data["nose_shapes"].as_table().unwrap();
    let number = |v: &toml::Value| v.as_float().unwrap_or_else(|| panic!("{v} is not a number"));
    let mut csvs: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    csvs.sort();
    let mut checked = Vec::new();
    for path in &csvs {
        let name = path.file_stem().unwrap().to_str().unwrap();
        let points = plugsim::ballistic::read_experiments(path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!points.is_empty(), "{name}: no points");
        // the built-in cases carry this file as it is (`plugsim ballistic` plots it)
        let file = format!("cases/reference/{name}.csv");
        let carried = plugsim::cases::BUILTIN_EXPERIMENTS.iter().find(|e| e.1 == file);
        let carried = carried.unwrap_or_else(|| panic!("{name}: no built-in case carries it"));
        assert_eq!(carried.2, std::fs::read_to_string(path).unwrap(), "{name}");
        assert!(
            plugsim::cases::BUILTIN_CASES.iter().any(|c| c.0.starts_with(carried.0)),
            "{name}: `{}` names no built-in case",
            carried.0
        );
        let case = EXPERIMENTS.iter().find(|e| name == format!("borvik-{}", e.name));
        let mut expected: Vec<(Real, Real)> = match case {
            Some(e) => vec![(e.impact_velocity, e.residual)],
            None => {
                let nose =
                    name.strip_prefix("borvik-2002-12mm-").unwrap_or_else(|| panic!("{name}: which experiment?"));
                let held = noses[&format!("{nose}_held_shots")].as_array().unwrap();
                let limit = number(&noses[&format!("{nose}_ballistic_limit")]);
                held.iter().map(|v| (number(v), 0.0)).chain([(limit, 0.0)]).collect()
            }
        };
        let mut got = points;
        let by_speed = |a: &(Real, Real), b: &(Real, Real)| a.0.total_cmp(&b.0);
        expected.sort_by(by_speed);
        got.sort_by(by_speed);
        assert_eq!(got, expected, "{name}");
        checked.push(name.to_string());
    }
    assert_eq!(
        checked,
        ["borvik-2002-12mm-blunt", "borvik-2002-12mm-hemispherical", "borvik-case-1", "borvik-case-2"],
        "every shipped experiments file is checked"
    );
}
