//! The memory estimate against measured peak memory (issue #21): `plugsim
//! run` prints the peak resident memory of its process (`VmHWM`) beside the
//! estimate that `plugsim check` and the guard use; on bodies of several
//! shapes the two agree within 30 % (and a few MiB of the process's own,
//! below). Each run is a process of its own, so
//! the tests running beside it do not count in its peak.

use std::path::Path;
use std::process::Command;

/// `12.3 MiB` (as `memory::human_bytes` writes it) in bytes.
fn parse_size(text: &str) -> f64 {
    let (number, unit) = text.trim().split_once(' ').expect("NUMBER UNIT");
    let scale = match unit {
        "B" => 1.0,
        "KiB" => 1024.0,
        "MiB" => 1024.0 * 1024.0,
        "GiB" => 1024.0 * 1024.0 * 1024.0,
        other => panic!("unit {other}"),
    };
    number.parse::<f64>().unwrap() * scale
}

/// Run `args` (a case and its overrides) and return (peak resident, estimate), bytes.
fn peak_and_estimate(name: &str, args: &[&str]) -> (f64, f64) {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("memory-{name}"));
    let output = Command::new(env!("CARGO_BIN_EXE_plugsim"))
        .args(["run", "--force", "--threads", "2", "--out"])
        .arg(&out)
        .args(args)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{name}: {}\n{stdout}", String::from_utf8_lossy(&output.stderr));
    let line = stdout.lines().find(|l| l.contains("memory: peak resident")).expect("the summary's memory line");
    let rest = line.split("peak resident").nth(1).unwrap();
    let (peak, estimate) = rest.split_once("(estimated").unwrap();
    (parse_size(peak), parse_size(estimate.trim_end_matches(')')))
}

/// A Taylor bar: a tall, narrow axisymmetric body (20 x 128 particles) on a
/// rigid anvil, the shape whose estimate was once 24 times its peak.
const BAR: &str = r#"
title = "Taylor bar (memory test)"
[geometry]
mode = "axisymmetric"
[materials.steel]
model = "elastic"
density = 7850.0
youngs_modulus = 200.0e9
poisson_ratio = 0.3
[[bodies]]
name = "bar"
material = "steel"
[bodies.rectangle]
x_min = 0.0
x_max = 0.0038
y_min = 0.0001
y_max = 0.0255
layers = 128
fine_half_width = 0.01
fine_spacing = 0.0002
[[bodies.initial_velocity]]
velocity = [0.0, -150.0]
region = { x_min = 0.0, x_max = 0.0038, y_min = 0.0, y_max = 0.0256 }
[[rigid_bodies]]
name = "anvil"
rectangle = { center = [0.0, -0.005], width = 0.02, height = 0.01 }
prescribed = true
mass = 1.0
velocity = [0.0, 0.0]
[time]
end = 1.0e-6
[output]
interval = 0.5e-6
"#;

#[test]
fn estimate_is_within_30_percent_of_the_peak_on_several_shapes() {
    let bar = Path::new(env!("CARGO_TARGET_TMPDIR")).join("memory-bar.toml");
    std::fs::write(&bar, BAR).unwrap();
    let cases: [(&str, Vec<&str>); 4] = [
        ("bar", vec![bar.to_str().unwrap()]),
        ("strike", vec!["--case", "elastic-strike", "--set", "time.end=1e-6"]),
        ("disc", vec!["--case", "elastic-disc-axisym", "--set", "time.end=1e-6"]),
        // A wide graded plate with contact, heat and cracks (they nucleate
        // at about 2 us, and crack growth keeps its spare tables from then).
        ("borvik-axisymmetric", vec!["--case", "borvik-1-axisymmetric", "--set", "time.end=3e-6"]),
    ];
    // Within 30 %, plus a few MiB the process's own memory moves by from
    // run to run: the smallest shapes are mostly that (the 468-particle
    // disc peaked at 13.5-14.0 MiB in five runs beside a test run, and at
    // 16.6 MiB once within one, against an estimate of 11.5 MiB;
    // presumably the threads' first allocations meeting the allocator's
    // arenas in another order). The large shapes are held to
    // the 30 % alone in effect (4 MiB is 6 % of the axisymmetric plate's).
    const SLACK: f64 = 4.0 * 1024.0 * 1024.0;
    for (name, args) in cases {
        let (peak, estimate) = peak_and_estimate(name, &args);
        let error = estimate / peak - 1.0;
        assert!(
            (estimate - peak).abs() < 0.3 * peak + SLACK,
            "{name}: estimate {estimate:.3e} B against a peak of {peak:.3e} B ({:+.0} %)",
            100.0 * error
        );
    }
}
