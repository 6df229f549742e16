//! Case files: the shipped cases parse and validate; bad input is rejected
//! before the run with a message naming the key and the file.

use plugsim::case::{Case, CaseError};
use plugsim::cases::BUILTIN_CASES;

const GOOD: &str = include_str!("../cases/elastic-strike.toml");

fn err_of(text: &str) -> String {
    match Case::from_str_with(text, "bad.toml", &[]) {
        Ok(_) => panic!("case should have been rejected:\n{text}"),
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with("bad.toml"), "message must name the file: {s}");
            s
        }
    }
}

fn with(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "fixture lacks {from}");
    GOOD.replacen(from, to, 1)
}

#[test]
fn every_builtin_case_parses_and_validates() {
    for (name, text, _) in BUILTIN_CASES {
        let case = Case::from_str_with(text, name, &[]).unwrap_or_else(|e| panic!("{e}"));
        // the resolved case round-trips through TOML
        let again: Case = toml::from_str(&case.resolved_toml()).unwrap();
        assert_eq!(again, case.resolved(), "{name}");
    }
}

#[test]
fn unknown_key_is_named() {
    let s = err_of(&with("poisson_ratio = 0.3", "poisson_ratio = 0.3\npoisons_ratio = 0.3"));
    assert!(s.contains("poisons_ratio"), "{s}");
}

#[test]
fn missing_key_is_named() {
    let s = err_of(&with("youngs_modulus = 200.0e9  # Pa\n", ""));
    assert!(s.contains("youngs_modulus"), "{s}");
}

#[test]
fn wrong_type_is_named() {
    let s = err_of(&with("layers = 12", "layers = \"twelve\""));
    assert!(s.contains("layers") || s.contains("twelve"), "{s}");
}

#[test]
fn negative_density_rejected() {
    let s = err_of(&with("density = 7850.0", "density = -7850.0"));
    assert!(s.contains("materials.steel.density"), "{s}");
}

#[test]
fn incompressible_poisson_rejected() {
    let s = err_of(&with("poisson_ratio = 0.3", "poisson_ratio = 0.5"));
    assert!(s.contains("materials.steel.poisson_ratio"), "{s}");
}

#[test]
fn zero_thickness_rejected() {
    let s = err_of(&with("y_max = 0.0111\n", "y_max = 0.0\n"));
    assert!(s.contains("bodies[0].rectangle.y_max") && s.contains("thickness"), "{s}");
}

#[test]
fn non_positive_end_time_rejected() {
    let s = err_of(&with("end = 30.0e-6", "end = 0.0"));
    assert!(s.contains("time.end"), "{s}");
    let s = err_of(&with("end = 30.0e-6", "end = -1.0"));
    assert!(s.contains("time.end"), "{s}");
}

#[test]
fn unknown_material_rejected() {
    let s = err_of(&with("material = \"steel\"", "material = \"unobtainium\""));
    assert!(s.contains("bodies[0].material") && s.contains("unobtainium"), "{s}");
}

/// The damage locus's cut-off triaxiality: a built-in material carries it,
/// a case file may give it, and a positive one is refused by its key.
#[test]
fn damage_cut_off_is_read_and_checked() {
    let text = include_str!("../cases/borvik-1-axisymmetric-deformable.toml");
    let line = "damage = { d1 = 100.0, d2 = 0.0, d3 = 0.0, d4 = 0.0, d5 = 0.0 }";
    assert!(text.contains(line));
    let cut = |v: &str| text.replace(line, &line.replace(" }", &format!(", cutoff_triaxiality = {v} }}")));
    let case = Case::from_str_with(&cut("-0.3333"), "cut.toml", &[]).unwrap();
    let Some(plugsim::material::Material::JohnsonCook(m)) = case.material("arne_tool_steel") else { panic!() };
    assert_eq!(m.damage.cutoff_triaxiality, Some(-0.3333));
    let s = match Case::from_str_with(&cut("0.2"), "bad.toml", &[]) {
        Ok(_) => panic!("a positive cut-off must be refused"),
        Err(e) => e.to_string(),
    };
    assert!(s.contains("materials.arne_tool_steel.damage.cutoff_triaxiality"), "{s}");
    let plate = Case::from_str_with(text, "plate.toml", &["bodies.plate.material=weldox_460e_cutoff".into()]).unwrap();
    let Some(plugsim::material::Material::JohnsonCook(w)) = plate.material(&plate.bodies[1].material) else { panic!() };
    assert_eq!(w.damage.cutoff_triaxiality, Some(-1.0 / 3.0));
}

/// Cockcroft–Latham's critical work (Deviation 15 of `johnson_cook`): a
/// case file may give it, a non-positive one is refused by its key, and the
/// built-in material carries the tension test's value.
#[test]
fn cockcroft_latham_work_is_read_and_checked() {
    let text = include_str!("../cases/borvik-1-axisymmetric-deformable.toml");
    let line = "damage = { d1 = 100.0, d2 = 0.0, d3 = 0.0, d4 = 0.0, d5 = 0.0 }";
    let with_w = |v: &str| text.replace(line, &line.replace(" }", &format!(", cockcroft_latham = {v} }}")));
    let case = Case::from_str_with(&with_w("2.0e9"), "cl.toml", &[]).unwrap();
    let Some(plugsim::material::Material::JohnsonCook(m)) = case.material("arne_tool_steel") else { panic!() };
    assert_eq!(m.damage.cockcroft_latham, Some(2.0e9));
    let s = match Case::from_str_with(&with_w("-1.0"), "bad.toml", &[]) {
        Ok(_) => panic!("a negative W_c must be refused"),
        Err(e) => e.to_string(),
    };
    assert!(s.contains("materials.arne_tool_steel.damage.cockcroft_latham"), "{s}");
    let plate = Case::from_str_with(text, "plate.toml", &["bodies.plate.material=weldox_460e_cockcroft_latham".into()])
        .unwrap();
    let Some(plugsim::material::Material::JohnsonCook(w)) = plate.material(&plate.bodies[1].material) else { panic!() };
    assert_eq!(w.damage.cockcroft_latham, Some(w.tension_fracture_work()));
}

#[test]
fn all_problems_reported_at_once() {
    let t = with("density = 7850.0", "density = -1.0").replace("end = 30.0e-6", "end = -1.0");
    let e = Case::from_str_with(&t, "bad.toml", &[]).unwrap_err();
    let CaseError::Invalid { problems, .. } = e else { panic!("expected Invalid") };
    let keys: Vec<&str> = problems.iter().map(|p| p.key.as_str()).collect();
    assert!(keys.contains(&"materials.steel.density") && keys.contains(&"time.end"), "{keys:?}");
}

#[test]
fn malformed_toml_rejected() {
    let s = err_of("[geometry\nmode = ");
    assert!(s.to_lowercase().contains("line") || s.contains("expected"), "{s}");
}

#[test]
fn overrides_apply_and_are_validated() {
    let c = Case::from_str_with(GOOD, "good.toml", &["time.end=2e-5".into(), "bodies.plate.rectangle.layers=8".into()])
        .unwrap();
    assert_eq!(c.time.end, 2e-5);
    assert_eq!(c.bodies[0].rectangle.layers, 8);
    let c = Case::from_str_with(GOOD, "good.toml", &["bodies.0.material=steel".into()]).unwrap();
    assert_eq!(c.bodies[0].material, "steel");
    let e = Case::from_str_with(GOOD, "good.toml", &["time.end=-3".into()]).unwrap_err().to_string();
    assert!(e.contains("time.end"), "{e}");
    let e = Case::from_str_with(GOOD, "good.toml", &["bodies.nosuch.layers=3".into()]).unwrap_err().to_string();
    assert!(e.contains("nosuch"), "{e}");
    let e = Case::from_str_with(GOOD, "good.toml", &["time.ned=1".into()]).unwrap_err().to_string();
    assert!(e.contains("ned"), "{e}");
}

#[test]
fn missing_file_is_a_clear_error() {
    let e = Case::load(std::path::Path::new("/nonexistent/case.toml"), &[]).unwrap_err().to_string();
    assert!(e.contains("/nonexistent/case.toml") && e.contains("cannot read"), "{e}");
}

/// Bodies placed inside each other at t = 0 are refused before the run,
/// naming both: a projectile sunk 1 mm into the plate, a rounded nose whose
/// tip is below the surface, two plates that overlap; a projectile resting
/// on the plate and two plates in contact are accepted (issue #20).
#[test]
fn bodies_overlapping_at_the_start_are_refused_naming_both() {
    let borvik = include_str!("../cases/borvik-1-axisymmetric.toml");
    let err =
        Case::from_str_with(borvik, "bad.toml", &["rigid_bodies.projectile.rectangle.center=[0.0,0.0501]".into()])
            .unwrap_err()
            .to_string();
    assert!(err.contains("rigid_bodies[0]") && err.contains("'projectile'") && err.contains("'plate'"), "{err}");
    // Nose resting on the surface (the plate's top is y = 11.1 mm).
    Case::from_str_with(borvik, "ok.toml", &["rigid_bodies.projectile.rectangle.center=[0.0,0.0511]".into()]).unwrap();
    let nose = include_str!("../cases/borvik-2002-12mm-hemispherical.toml");
    let err = Case::from_str_with(nose, "bad.toml", &["rigid_bodies.0.projectile.tip=[0.0,0.0115]".into()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("overlaps body 'plate'"), "{err}");
    let two_plates = |lower_top: f64| {
        format!(
            "{GOOD}\n[[bodies]]\nname = \"backing\"\nmaterial = \"steel\"\n[bodies.rectangle]\n\
             x_min = -0.06\nx_max = 0.06\ny_min = -0.005\ny_max = {lower_top}\nlayers = 6\n"
        )
    };
    let err = err_of(&two_plates(0.001));
    assert!(err.contains("bodies[1].rectangle") && err.contains("'backing' overlaps body 'plate'"), "{err}");
    Case::from_str_with(&two_plates(0.0), "ok.toml", &[]).unwrap();
}

#[test]
fn bulk_viscosity_is_off_unless_asked_and_its_coefficients_are_checked() {
    use plugsim::bulk_viscosity::BulkViscosity;
    let case = Case::from_str_with(GOOD, "good.toml", &[]).unwrap();
    assert_eq!(case.bulk_viscosity(), BulkViscosity::NONE);
    // either coefficient may be left out for the common codes' value
    let on = with("end = 30.0e-6", "end = 30.0e-6\nbulk_viscosity = { quadratic = 1.5 }");
    let case = Case::from_str_with(&on, "on.toml", &[]).unwrap();
    assert_eq!(case.bulk_viscosity(), BulkViscosity { linear: 0.06, quadratic: 1.5 });
    let s = err_of(&with("end = 30.0e-6", "end = 30.0e-6\nbulk_viscosity = { linear = 1.2 }"));
    assert!(s.contains("time.bulk_viscosity.linear"), "{s}");
    let s = err_of(&with("end = 30.0e-6", "end = 30.0e-6\nbulk_viscosity = { linaer = 0.1 }"));
    assert!(s.contains("linaer"), "{s}");
}

/// The step's floors, mass scaling and erosion at the floor: off unless
/// asked; a value outside (0, 1], or with a fixed step, is refused naming
/// the key; erosion also with a criterion that fractures no point.
#[test]
fn the_steps_floors_are_off_unless_asked_and_checked() {
    let text = BUILTIN_CASES.iter().find(|(n, _, _)| *n == "borvik-2-axisymmetric-nonlocal").unwrap().1;
    let parse = |sets: &[String]| Case::from_str_with(text, "c2.toml", sets);
    let time = parse(&[]).unwrap().time;
    assert_eq!((time.mass_scaling, time.erode_failed_below), (None, None));
    for key in ["mass_scaling", "erode_failed_below"] {
        let time = parse(&[format!("time.{key}=0.5")]).unwrap().time;
        assert_eq!(if key == "mass_scaling" { time.mass_scaling } else { time.erode_failed_below }, Some(0.5));
        for bad in ["0.0", "1.5", "-0.2"] {
            let e = parse(&[format!("time.{key}={bad}")]).unwrap_err().to_string();
            assert!(e.contains(&format!("time.{key}")) && e.contains("(0, 1]"), "{e}");
        }
        let e = parse(&[format!("time.{key}=0.5"), "time.fixed_dt=1e-9".into()]).unwrap_err().to_string();
        assert!(e.contains(&format!("time.{key}")) && e.contains("fixed_dt"), "{e}");
    }
    for set in ["fracture.criterion=\"none\"", "fracture.nonlocal_point_fracture=false"] {
        let e = parse(&["time.erode_failed_below=0.5".into(), set.into()]).unwrap_err().to_string();
        assert!(e.contains("time.erode_failed_below") && e.contains("fractures none"), "{set}: {e}");
    }
}

/// `column_at`: off unless asked; inside the fine zone it fits the fine
/// spacing to a column on it (in the resolved case); outside the zone, at
/// `refine_at` or outside the body it is refused, naming the key.
#[test]
fn a_column_at_the_projectiles_edge_is_checked() {
    let text = BUILTIN_CASES.iter().find(|(n, _, _)| *n == "borvik-2-axisymmetric-nonlocal").unwrap().1;
    let case = Case::from_str_with(text, "c2.toml", &[]).unwrap();
    assert_eq!(case.bodies[0].rectangle.column_at, None);
    let on = Case::from_str_with(text, "c2.toml", &["bodies.plate.rectangle.column_at=0.01".into()]).unwrap();
    let r = &on.resolved().bodies[0].rectangle;
    let h = r.fine_spacing.unwrap();
    assert!((0.01 / h - (0.01 / h).round()).abs() < 1e-9 && (h / r.layer_spacing() - 1.0).abs() < 0.03, "{h}");
    for bad in ["0.0", "0.03", "-0.01", "0.2"] {
        let e = Case::from_str_with(text, "bad.toml", &[format!("bodies.plate.rectangle.column_at={bad}")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("rectangle.column_at") && e.contains("fine zone"), "{bad}: {e}");
    }
}

/// The crack tip's fields follow the criterion where a case leaves them
/// out (`FractureParameters::for_criterion`): the default model's tip
/// (the velocity jump, the gate over `ℓ`) under `"nonlocal_damage"`,
/// SPEC §9's under [RL10]'s criteria, also when `--set` changes the
/// criterion; a value the case gives is kept. So does `detach_below`: 0.1
/// under the default model, 0 (never) in the paper's mode.
#[test]
fn a_case_without_the_tip_fields_gets_its_criterions() {
    use plugsim::fracture::{Criterion, TipDirection, DETACH_BELOW};
    let text = BUILTIN_CASES.iter().find(|(n, _, _)| *n == "borvik-1-axisymmetric-nonlocal").unwrap().1;
    let sets_tip = |l: &str| {
        l.starts_with("tip_direction") || l.starts_with("nonlocal_tip_triaxiality") || l.starts_with("detach_below")
    };
    assert!(!text.lines().any(sets_tip), "the case relies on the defaults");
    let tip = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let f = Case::from_str_with(text, "c1.toml", &sets).unwrap().fracture;
        (f.criterion, f.tip_direction, f.nonlocal_tip_triaxiality, f.detach_below)
    };
    assert_eq!(tip(&[]), (Criterion::NonlocalDamage, TipDirection::VelocityJump, true, DETACH_BELOW));
    for (set, c) in [
        ("fracture.criterion=\"damage\"", Criterion::Damage),
        ("fracture.criterion=\"effective_strain\"", Criterion::EffectiveStrain),
    ] {
        assert_eq!(tip(&[set]), (c, TipDirection::MostDamaged, false, 0.0), "{set}");
    }
    let kept = tip(&["fracture.criterion=\"damage\"", "fracture.tip_direction=\"velocity_jump\""]);
    assert_eq!(kept, (Criterion::Damage, TipDirection::VelocityJump, false, 0.0));
    let earlier = tip(&["fracture.tip_direction=\"most_damaged\"", "fracture.nonlocal_tip_triaxiality=false"]);
    assert_eq!(earlier, (Criterion::NonlocalDamage, TipDirection::MostDamaged, false, DETACH_BELOW));
    // the default model without detaching, as before 2026-12-02
    let never = tip(&["fracture.detach_below=0"]);
    assert_eq!(never, (Criterion::NonlocalDamage, TipDirection::VelocityJump, true, 0.0));
    // the paper's cases get SPEC §9's tip and never detach
    let paper = BUILTIN_CASES.iter().find(|(n, _, _)| *n == "borvik-1-plane-strain").unwrap().1;
    let f = Case::from_str_with(paper, "b1.toml", &[]).unwrap().fracture;
    assert_eq!((f.tip_direction, f.nonlocal_tip_triaxiality, f.detach_below), (TipDirection::MostDamaged, false, 0.0));
    // a bad criterion is still named by the parse
    let e = Case::from_str_with(text, "c1.toml", &["fracture.criterion=\"nosuch\"".into()]).unwrap_err().to_string();
    assert!(e.contains("nosuch"), "{e}");
}
