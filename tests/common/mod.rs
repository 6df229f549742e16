//! Helpers shared by the integration tests.

use plugsim::case::Case;

/// Borvik Case I without fracture on a narrower (60 mm), coarser (10-row)
/// plate, clamped at both ends as the real case: the same physics, fast
/// enough for a test. `extra` overrides are applied after these.
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
