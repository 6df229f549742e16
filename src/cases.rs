//! Built-in cases, selectable by name from the CLI (`plugsim run --case NAME`).
//! Each is the text of a file under `cases/`, so what runs is what users read.

/// `(name, case text, one-line description)`.
pub const BUILTIN_CASES: &[(&str, &str, &str)] = &[
    (
        "elastic-strike",
        include_str!("../cases/elastic-strike.toml"),
        "elastic steel plate, struck centre patch, plane strain (seconds)",
    ),
    (
        "elastic-disc-axisym",
        include_str!("../cases/elastic-disc-axisym.toml"),
        "elastic steel disc, struck centre, axisymmetric (seconds)",
    ),
    (
        "borvik-1-plane-strain",
        include_str!("../cases/borvik-1-plane-strain.toml"),
        "Borvik Case I (298 m/s, 11.1 mm Weldox), plane strain, coarse, effective-strain cracks",
    ),
    (
        "borvik-1-plane-strain-fine",
        include_str!("../cases/borvik-1-plane-strain-fine.toml"),
        "the same with [RL10]'s fine discretization (48 rows, 46,032 particles)",
    ),
    (
        "borvik-1-axisymmetric",
        include_str!("../cases/borvik-1-axisymmetric.toml"),
        "Borvik Case I (298 m/s, 11.1 mm Weldox), axisymmetric (197 g cylinder), coarse, effective-strain cracks",
    ),
    (
        "borvik-1-nofracture",
        include_str!("../cases/borvik-1-nofracture.toml"),
        "Borvik Case I (298 m/s, 11.1 mm Weldox), plane strain, coarse, no fracture",
    ),
];

/// The text of the built-in case `name`.
pub fn builtin_case(name: &str) -> Option<&'static str> {
    BUILTIN_CASES.iter().find(|c| c.0 == name).map(|c| c.1)
}
