//! Helpers shared by the integration tests.

use plugsim::case::Case;
use plugsim::discretize::RectangleGrid;
use plugsim::math::Real;

/// `[materials.steel]`, elastic steel (ρ = 7850 kg/m³, E = 200 GPa,
/// ν = 0.3) of the small elastic cases; a string literal, for `concat!`
/// (or `format!`) with the rest of a case.
#[allow(unused_macros)] // not every test binary uses every helper
macro_rules! elastic_steel {
    () => {
        "
[materials.steel]
model = \"elastic\"
density = 7850.0
youngs_modulus = 200.0e9
poisson_ratio = 0.3
"
    };
}

/// The head of the small elastic cases: `[geometry]` in plane strain and
/// [`elastic_steel`]'s `[materials.steel]`.
#[allow(unused_macros)] // not every test binary uses every helper
macro_rules! elastic_steel_plane_strain {
    () => {
        concat!(
            "
[geometry]
mode = \"plane_strain\"",
            elastic_steel!()
        )
    };
}

/// Run the built `plugsim` command line with `args`: its exit status and
/// output (the command-line tests).
#[allow(dead_code)] // not every test binary uses every helper
pub fn plugsim(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_plugsim")).args(args).output().unwrap()
}

/// A 4 mm plate and a blunt 8 mm projectile at 400 m/s with cracks
/// (`small_impact.toml`), 12 µs: the fracture and ballistic tests' impact.
#[allow(dead_code)] // not every test binary uses every helper
pub const SMALL_IMPACT: &str = include_str!("small_impact.toml");

/// A uniform lattice of `nx × ny` particles of spacing `h` on
/// `[0, (nx−1)h] × [0, (ny−1)h]`, finest (uniform) from x = 0, support
/// factor 2, 2×2 Gauss points.
#[allow(dead_code)] // not every test binary uses every helper
pub fn uniform_lattice(nx: usize, ny: usize, h: Real) -> RectangleGrid {
    let (w, t) = ((nx - 1) as Real * h, (ny - 1) as Real * h);
    RectangleGrid { refine_at: Some(0.0), fine_spacing: None, ..RectangleGrid::uniform((0.0, w), (0.0, t), h) }
}

/// Borvik Case I without fracture on a narrower (60 mm), coarser (10-row)
/// plate, clamped at both ends as the real case: the same physics, fast
/// enough for a test. `extra` overrides are applied after these.
#[allow(dead_code)] // not every test binary uses every helper
pub fn small_borvik_nofracture(extra: &[&str]) -> Case {
    let text = include_str!("../../cases/borvik-1-nofracture.toml");
    let set: Vec<String> = [
        "bodies.plate.rectangle.x_min=-0.03",
        "bodies.plate.rectangle.x_max=0.03",
        "bodies.plate.rectangle.layers=10",
        "bodies.plate.rectangle.fine_half_width=0.015",
        "bodies.plate.supports.0.region.x_min=-0.03",
        "bodies.plate.supports.0.region.x_max=-0.028",
        "bodies.plate.supports.1.region.x_min=0.028",
        "bodies.plate.supports.1.region.x_max=0.03",
    ]
    .iter()
    .chain(extra)
    .map(|s| s.to_string())
    .collect();
    Case::from_str_with(text, "borvik", &set).unwrap().resolved()
}
