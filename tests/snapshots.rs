//! Snapshots: the fused projection of the quadrature fields gives the bits
//! of projecting each field on its own, and a snapshot written beside the
//! time loop joins the series only once its files are complete.

mod common;
use plugsim::case::OUTPUT_FIELDS;
use plugsim::io::{ArrayData, VtuPiece};
use plugsim::math::{mean_stress, von_mises, Real, Tensor3};
use plugsim::output::{particle_piece, OutputWriter};
use plugsim::run::build_simulation;

fn array<'a>(piece: &'a VtuPiece, name: &str) -> &'a [f64] {
    match &piece.point_data.iter().find(|a| a.name == name).unwrap_or_else(|| panic!("no {name}")).data {
        ArrayData::F64(v) => v,
        ArrayData::I32(_) => panic!("{name} is not Float64"),
    }
}

fn bits(v: impl IntoIterator<Item = Real>) -> Vec<u64> {
    v.into_iter().map(f64::to_bits).collect()
}

#[test]
fn fused_projection_has_the_bits_of_one_field_at_a_time() {
    let case = common::small_borvik_nofracture(&[]);
    let mut sim = build_simulation(&case).unwrap();
    for _ in 0..150 {
        sim.step().unwrap();
    }
    let fields: Vec<String> = OUTPUT_FIELDS.iter().map(|s| s.to_string()).collect();
    let piece = particle_piece(&sim.model, &fields);
    let (m, q) = (&sim.model, &sim.model.quad);
    // Each field projected on its own, Cauchy stress as a full tensor.
    let s: Vec<Tensor3> = m.project(|k| q.tau[k].to_tensor() / q.f[k].determinant());
    let six = s.iter().flat_map(|t| [t[(0, 0)], t[(1, 1)], t[(2, 2)], t[(0, 1)], t[(1, 2)], t[(0, 2)]]);
    assert_eq!(bits(array(&piece, "stress").iter().cloned()), bits(six));
    assert_eq!(bits(array(&piece, "effective_stress").iter().cloned()), bits(s.iter().map(von_mises)));
    assert_eq!(bits(array(&piece, "pressure").iter().cloned()), bits(s.iter().map(|t| -mean_stress(t))));
    for (name, col) in [
        ("plastic_strain", &q.eps_p),
        ("plastic_strain_rate", &q.eps_p_rate),
        ("temperature", &q.temperature),
        ("damage", &q.damage),
        ("adiabatic_hardening", &plugsim::output::adiabatic_hardening(m)),
    ] {
        assert_eq!(bits(array(&piece, name).iter().cloned()), bits(m.project(|k| col[k])), "{name}");
    }
    // The state is not trivial: the plate yields and heats under the projectile.
    assert!(array(&piece, "plastic_strain").iter().cloned().fold(0.0, f64::max) > 0.01);
    assert!(array(&piece, "effective_stress").iter().cloned().fold(0.0, f64::max) > 1e8);
    // Hardening everywhere this early (the plate is far from its adiabatic
    // instability): finite and positive at every particle.
    assert!(array(&piece, "adiabatic_hardening").iter().all(|&h| h.is_finite() && h > 0.0));
    // The path's average triaxiality: the ratio of the projections of
    // `∫ η dε̄` and `ε̄`, 0 where nothing has flowed.
    let (num, den) = (m.project(|k| q.triaxiality_strain[k]), m.project(|k| q.eps_p[k]));
    let want = num.iter().zip(&den).map(|(n, d)| if *d > 0.0 { n / d } else { 0.0 });
    let average = array(&piece, "average_triaxiality");
    assert_eq!(bits(average.iter().cloned()), bits(want));
    // Under the projectile the plate has flowed in the impact's compression:
    // the most compressive path averages lie below Bao and Wierzbicki's
    // cut-off, −1/3, and each stays within the bounds a triaxiality of a
    // flowing point can take in this impact (a mean stress of a few GPa
    // over a flow stress of about 1 GPa).
    let least = average.iter().cloned().fold(0.0, f64::min);
    assert!(least < -1.0 / 3.0 && least > -20.0, "{least}");
    assert!(average.iter().all(|a| a.is_finite()));
}

#[test]
fn snapshots_join_the_series_once_written() {
    let case = common::small_borvik_nofracture(&[]);
    let mut sim = build_simulation(&case).unwrap();
    let dir = std::env::temp_dir().join(format!("plugsim-snapshots-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let fields: Vec<String> = OUTPUT_FIELDS.iter().map(|s| s.to_string()).collect();
    let mut out = OutputWriter::create(&dir, &fields, &[]).unwrap();
    let mut paths = Vec::new();
    for _ in 0..3 {
        paths.push(out.snapshot(&sim).unwrap());
        // The series holds the snapshots before the one in flight.
        assert_eq!(out.snapshot_times().len(), paths.len() - 1);
        for _ in 0..5 {
            sim.step().unwrap();
        }
    }
    out.flush().unwrap();
    assert_eq!(out.snapshot_times().len(), 3);
    let pvd = std::fs::read_to_string(dir.join("results.pvd")).unwrap();
    for p in &paths {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        assert!(pvd.contains(&name), "{name} missing from the series");
        let text = std::fs::read(p).unwrap();
        assert!(text.ends_with(b"</VTKFile>\n"), "{name} is incomplete");
    }
    // Dropping the writer with a snapshot in flight finishes and lists it.
    let last = out.snapshot(&sim).unwrap();
    drop(out);
    let pvd = std::fs::read_to_string(dir.join("results.pvd")).unwrap();
    assert!(pvd.contains(&last.file_name().unwrap().to_string_lossy().to_string()));
    assert!(std::fs::read(&last).unwrap().ends_with(b"</VTKFile>\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}
