//! Built-in cases, selectable by name from the CLI (`plugsim run --case NAME`).
//! Each is the text of a file under `cases/`, so what runs is what users read.
//!
//! Børvik's reference cases (\[RL10\] §5, SPEC §10) form one family named
//! `borvik-<1|2>-<plane-strain|axisymmetric>[-fine][-damage][-modified]`:
//! Case I or II; the paper's plane-strain model or the true axisymmetric
//! geometry; the coarse (24 rows) or fine (48 rows) discretization; the
//! effective-strain (default) or damage crack criterion; \[RL10\]'s material
//! (default) or Børvik's modified one (axisymmetric fine only). All share one
//! set of numerical parameters ([`borvik_family`] lists them; the
//! `tests/reference_cases.rs` suite checks the family is complete and
//! consistent). [`ALIASES`] name the paper's own models briefly.

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
        "two-plates-axisymmetric",
        include_str!("../cases/two-plates-axisymmetric.toml"),
        "two spaced plates of different steels, rigid projectile at 350 m/s, axisymmetric, to 60 us (a minute)",
    ),
    (
        "borvik-1-plane-strain",
        include_str!("../cases/borvik-1-plane-strain.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), plane strain, coarse, effective-strain cracks",
    ),
    (
        "borvik-1-plane-strain-damage",
        include_str!("../cases/borvik-1-plane-strain-damage.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), plane strain, coarse, damage cracks",
    ),
    (
        "borvik-1-plane-strain-fine",
        include_str!("../cases/borvik-1-plane-strain-fine.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), plane strain, fine, effective-strain cracks",
    ),
    (
        "borvik-1-plane-strain-fine-damage",
        include_str!("../cases/borvik-1-plane-strain-fine-damage.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), plane strain, fine, damage cracks",
    ),
    (
        "borvik-1-axisymmetric",
        include_str!("../cases/borvik-1-axisymmetric.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, coarse, effective-strain cracks",
    ),
    (
        "borvik-1-axisymmetric-deformable",
        include_str!("../cases/borvik-1-axisymmetric-deformable.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, coarse, deformable tool-steel projectile",
    ),
    (
        "borvik-1-axisymmetric-damage",
        include_str!("../cases/borvik-1-axisymmetric-damage.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, coarse, damage cracks",
    ),
    (
        "borvik-1-axisymmetric-fine",
        include_str!("../cases/borvik-1-axisymmetric-fine.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, fine, effective-strain cracks",
    ),
    (
        "borvik-1-axisymmetric-fine-damage",
        include_str!("../cases/borvik-1-axisymmetric-fine-damage.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, fine, damage cracks",
    ),
    (
        "borvik-1-axisymmetric-fine-modified",
        include_str!("../cases/borvik-1-axisymmetric-fine-modified.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, fine, effective-strain cracks, Borvik's modified material",
    ),
    (
        "borvik-1-axisymmetric-fine-damage-modified",
        include_str!("../cases/borvik-1-axisymmetric-fine-damage-modified.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, fine, damage cracks, Borvik's modified material",
    ),
    (
        "borvik-2-plane-strain",
        include_str!("../cases/borvik-2-plane-strain.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), plane strain, coarse, effective-strain cracks",
    ),
    (
        "borvik-2-plane-strain-damage",
        include_str!("../cases/borvik-2-plane-strain-damage.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), plane strain, coarse, damage cracks",
    ),
    (
        "borvik-2-plane-strain-fine",
        include_str!("../cases/borvik-2-plane-strain-fine.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), plane strain, fine, effective-strain cracks",
    ),
    (
        "borvik-2-plane-strain-fine-damage",
        include_str!("../cases/borvik-2-plane-strain-fine-damage.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), plane strain, fine, damage cracks",
    ),
    (
        "borvik-2-axisymmetric",
        include_str!("../cases/borvik-2-axisymmetric.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, coarse, effective-strain cracks",
    ),
    (
        "borvik-2-axisymmetric-deformable",
        include_str!("../cases/borvik-2-axisymmetric-deformable.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, coarse, deformable tool-steel projectile",
    ),
    (
        "borvik-2-axisymmetric-damage",
        include_str!("../cases/borvik-2-axisymmetric-damage.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, coarse, damage cracks",
    ),
    (
        "borvik-2-axisymmetric-fine",
        include_str!("../cases/borvik-2-axisymmetric-fine.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, fine, effective-strain cracks",
    ),
    (
        "borvik-2-axisymmetric-fine-damage",
        include_str!("../cases/borvik-2-axisymmetric-fine-damage.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, fine, damage cracks",
    ),
    (
        "borvik-2-axisymmetric-fine-modified",
        include_str!("../cases/borvik-2-axisymmetric-fine-modified.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, fine, effective-strain cracks, Borvik's modified material",
    ),
    (
        "borvik-2-axisymmetric-fine-damage-modified",
        include_str!("../cases/borvik-2-axisymmetric-fine-damage-modified.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, fine, damage cracks, Borvik's modified material",
    ),
    (
        "borvik-1-axisymmetric-nonlocal",
        include_str!("../cases/borvik-1-axisymmetric-nonlocal.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, coarse, the default fracture model (damage over a length)",
    ),
    (
        "borvik-1-axisymmetric-fine-nonlocal",
        include_str!("../cases/borvik-1-axisymmetric-fine-nonlocal.toml"),
        "Borvik Case I (298 m/s, 11.1 mm), axisymmetric, fine, the default fracture model (damage over a length)",
    ),
    (
        "borvik-2-axisymmetric-nonlocal",
        include_str!("../cases/borvik-2-axisymmetric-nonlocal.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, coarse, the default fracture model (damage over a length)",
    ),
    (
        "borvik-2-axisymmetric-fine-nonlocal",
        include_str!("../cases/borvik-2-axisymmetric-fine-nonlocal.toml"),
        "Borvik Case II (173.7 m/s, 10.2 mm), axisymmetric, fine, the default fracture model (damage over a length)",
    ),
    (
        "borvik-2002-12mm-blunt",
        include_str!("../cases/borvik-2002-12mm-blunt.toml"),
        "Borvik et al. 2002 nose shapes: blunt nose, 12 mm Weldox 460 E, 300 m/s (not a test speed), axisymmetric, coarse",
    ),
    (
        "borvik-2002-12mm-hemispherical",
        include_str!("../cases/borvik-2002-12mm-hemispherical.toml"),
        "Borvik et al. 2002 nose shapes: hemispherical nose, 12 mm Weldox 460 E, 300 m/s (not a test speed), axisymmetric, coarse",
    ),
    (
        "borvik-1-nofracture",
        include_str!("../cases/borvik-1-nofracture.toml"),
        "Borvik Case I (298 m/s, 11.1 mm Weldox), plane strain, coarse, no fracture",
    ),
    (
        "taylor-cu-130",
        include_str!("../cases/taylor-cu-130.toml"),
        "Taylor anvil test: OFHC copper, 130 m/s, axisymmetric, rigid wall",
    ),
    (
        "taylor-cu-146",
        include_str!("../cases/taylor-cu-146.toml"),
        "Taylor anvil test: OFHC copper, 146 m/s, axisymmetric, rigid wall",
    ),
    (
        "taylor-cu-190",
        include_str!("../cases/taylor-cu-190.toml"),
        "Taylor anvil test: OFHC copper, 190 m/s, axisymmetric, rigid wall",
    ),
    (
        "taylor-cu-190-rod-on-rod",
        include_str!("../cases/taylor-cu-190-rod-on-rod.toml"),
        "Rod on rod: two OFHC copper bars head on, 190 m/s each (= taylor-cu-190 onto its anvil), axisymmetric",
    ),
    (
        "taylor-4340-208",
        include_str!("../cases/taylor-4340-208.toml"),
        "Taylor anvil test: 4340 steel, 208 m/s, L0 = 25.4 mm, axisymmetric, rigid wall",
    ),
    (
        "taylor-4340-282",
        include_str!("../cases/taylor-4340-282.toml"),
        "Taylor anvil test: 4340 steel, 282 m/s, L0 = 12.7 mm, axisymmetric, rigid wall",
    ),
    (
        "taylor-4340-343",
        include_str!("../cases/taylor-4340-343.toml"),
        "Taylor anvil test: 4340 steel, 343 m/s, L0 = 8.1 mm, axisymmetric, rigid wall",
    ),
    (
        "taylor-42crmo4-287",
        include_str!("../cases/taylor-42crmo4-287.toml"),
        "Taylor anvil test: 42CrMo4 steel, 287 m/s (DynELA/Abaqus benchmark), axisymmetric, face held on the wall as in the references",
    ),
];

/// Børvik et al.'s nose-shape experiments (IJIE 27, 2002; the reference
/// data found is in `cases/reference/borvik-experiments.toml`): the
/// projectile given by its nose ([`crate::case::ProjectileSpec`]) on a 12 mm
/// plate, with the numerical parameters of the coarse axisymmetric member of
/// [`borvik_family`] (checked by `tests/reference_cases.rs`). The conical
/// nose is missing: its apex angle was not found.
pub const BORVIK_NOSE_CASES: &[&str] = &["borvik-2002-12mm-blunt", "borvik-2002-12mm-hemispherical"];

/// Børvik's Cases I and II with the projectile as a deformable body of
/// hardened Arne tool steel (issue #20), beside the rigid one; the
/// numerical parameters of the coarse axisymmetric members of
/// [`borvik_family`].
pub const BORVIK_DEFORMABLE_CASES: &[&str] = &["borvik-1-axisymmetric-deformable", "borvik-2-axisymmetric-deformable"];

/// The tests a built-in case stands for, plotted by `plugsim ballistic` on
/// its curve: `(case name or name prefix, file, CSV text)`, the file being
/// the one the text is read from (`cases/reference/`, header `v_i,v_r`).
/// Every member of Børvik's Case I or II family (any geometry, resolution or
/// criterion: the same test) carries its test, each nose case its tests.
/// `tests/reference_cases.rs` checks that every experiments file belongs to
/// a built-in case and every prefix names one.
pub const BUILTIN_EXPERIMENTS: &[(&str, &str, &str)] = &[
    ("borvik-1-", "cases/reference/borvik-case-1.csv", include_str!("../cases/reference/borvik-case-1.csv")),
    ("borvik-2-", "cases/reference/borvik-case-2.csv", include_str!("../cases/reference/borvik-case-2.csv")),
    (
        "borvik-2002-12mm-blunt",
        "cases/reference/borvik-2002-12mm-blunt.csv",
        include_str!("../cases/reference/borvik-2002-12mm-blunt.csv"),
    ),
    (
        "borvik-2002-12mm-hemispherical",
        "cases/reference/borvik-2002-12mm-hemispherical.csv",
        include_str!("../cases/reference/borvik-2002-12mm-hemispherical.csv"),
    ),
];

/// The tests of built-in case `name` (or its alias), `(file, CSV text)`,
/// where [`BUILTIN_EXPERIMENTS`] has them.
pub fn builtin_experiments(name: &str) -> Option<(&'static str, &'static str)> {
    builtin_case(name)?;
    let name = resolve_alias(name);
    BUILTIN_EXPERIMENTS.iter().find(|e| name.starts_with(e.0)).map(|e| (e.1, e.2))
}

/// Short names for the paper's models: `(alias, built-in case)`.
pub const ALIASES: &[(&str, &str)] = &[("borvik-1", "borvik-1-plane-strain"), ("borvik-2", "borvik-2-plane-strain")];

/// The built-in material of \[RL10\] (Table 2).
pub const MATERIAL_RL10: &str = "weldox_460e";
/// Børvik et al.'s modified fit of the same steel (power rate law).
pub const MATERIAL_MODIFIED: &str = "weldox_460e_borvik";
/// The default model's material: \[RL10\]'s steel with Cockcroft–Latham
/// damage (`crate::fracture`, "The default model's tip and damage").
pub const MATERIAL_DEFAULT_MODEL: &str = "weldox_460e_cockcroft_latham";

/// One member of Børvik's reference family: which experiment, geometry,
/// discretization, criterion and material a built-in case stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BorvikCase {
    /// 1 or 2: Børvik's Case I (11.1 mm, 298.0 m/s) or II (10.2 mm, 173.7 m/s).
    pub experiment: u8,
    /// `"plane_strain"` or `"axisymmetric"`.
    pub geometry: &'static str,
    /// `"coarse"` (24 rows) or `"fine"` (48 rows).
    pub discretization: &'static str,
    /// `"effective_strain"` or `"damage"` (\[RL10\]'s, the paper's mode), or
    /// `"nonlocal_damage"` (the default model, axisymmetric with its own
    /// material only).
    pub criterion: &'static str,
    /// The built-in material: [`MATERIAL_RL10`] or [`MATERIAL_MODIFIED`]
    /// with \[RL10\]'s criteria, [`MATERIAL_DEFAULT_MODEL`] with the
    /// default model.
    pub material: &'static str,
}

impl BorvikCase {
    /// The built-in case's name,
    /// `borvik-<1|2>-<plane-strain|axisymmetric>[-fine][-damage|-nonlocal][-modified]`.
    pub fn name(&self) -> String {
        let mut n = format!("borvik-{}-{}", self.experiment, self.geometry.replace('_', "-"));
        if self.discretization == "fine" {
            n.push_str("-fine");
        }
        if self.criterion == "damage" {
            n.push_str("-damage");
        }
        if self.criterion == "nonlocal_damage" {
            n.push_str("-nonlocal");
        }
        if self.material == MATERIAL_MODIFIED {
            n.push_str("-modified");
        }
        n
    }

    /// The particle count \[RL10\] gives for this discretization (its
    /// tables key its results and run times by it): coarse 11,496, fine
    /// 45,984.
    pub fn paper_particles(&self) -> usize {
        if self.discretization == "coarse" {
            11496
        } else {
            45984
        }
    }

    /// Whether this is one of \[RL10\]'s own models (plane strain, its material).
    pub fn is_papers_model(&self) -> bool {
        self.geometry == "plane_strain" && self.material == MATERIAL_RL10
    }
}

/// The whole reference family, in the order `plugsim validate` reports it:
/// per case, both geometries × both discretizations × both of \[RL10\]'s
/// criteria with its material, the axisymmetric fine cases with Børvik's
/// modified material (both criteria), then the axisymmetric cases with the
/// default fracture model and its material (coarse and fine): 24 cases.
pub fn borvik_family() -> Vec<BorvikCase> {
    let mut v = Vec::new();
    for experiment in [1, 2] {
        for geometry in ["plane_strain", "axisymmetric"] {
            for discretization in ["coarse", "fine"] {
                for criterion in ["effective_strain", "damage"] {
                    v.push(BorvikCase { experiment, geometry, discretization, criterion, material: MATERIAL_RL10 });
                }
            }
        }
        for criterion in ["effective_strain", "damage"] {
            v.push(BorvikCase {
                experiment,
                geometry: "axisymmetric",
                discretization: "fine",
                criterion,
                material: MATERIAL_MODIFIED,
            });
        }
        for discretization in ["coarse", "fine"] {
            v.push(BorvikCase {
                experiment,
                geometry: "axisymmetric",
                discretization,
                criterion: "nonlocal_damage",
                material: MATERIAL_DEFAULT_MODEL,
            });
        }
    }
    v
}

/// The case an alias names, else `name` itself.
pub fn resolve_alias(name: &str) -> &str {
    ALIASES.iter().find(|a| a.0 == name).map_or(name, |a| a.1)
}

/// The text of the built-in case `name` (or of the case an alias names).
pub fn builtin_case(name: &str) -> Option<&'static str> {
    let name = resolve_alias(name);
    BUILTIN_CASES.iter().find(|c| c.0 == name).map(|c| c.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_member_and_alias_is_built_in() {
        let family = borvik_family();
        assert_eq!(family.len(), 24);
        for m in &family {
            assert!(builtin_case(&m.name()).is_some(), "{} is not built in", m.name());
        }
        for (alias, name) in ALIASES {
            assert_eq!(builtin_case(alias), builtin_case(name));
            assert!(builtin_case(name).is_some());
        }
        assert_eq!(family[0].name(), "borvik-1-plane-strain");
        assert_eq!(family[9].name(), "borvik-1-axisymmetric-fine-damage-modified");
        assert_eq!(family[11].name(), "borvik-1-axisymmetric-fine-nonlocal");
        assert_eq!(family[23].name(), "borvik-2-axisymmetric-fine-nonlocal");
    }

    /// Every member of Børvik's family carries its own experiment's test
    /// (Case I's or II's, whatever the model), each nose case its nose's,
    /// and the aliases their cases'; the other built-ins carry none.
    #[test]
    fn every_borvik_case_carries_its_tests() {
        for m in borvik_family() {
            let (file, _) = builtin_experiments(&m.name()).unwrap_or_else(|| panic!("{}", m.name()));
            assert_eq!(file, format!("cases/reference/borvik-case-{}.csv", m.experiment), "{}", m.name());
        }
        for name in BORVIK_NOSE_CASES.iter().chain(BORVIK_DEFORMABLE_CASES) {
            assert!(builtin_experiments(name).is_some(), "{name}");
        }
        let (file, _) = builtin_experiments("borvik-2002-12mm-hemispherical").unwrap();
        assert_eq!(file, "cases/reference/borvik-2002-12mm-hemispherical.csv");
        assert_eq!(builtin_experiments("borvik-2"), builtin_experiments("borvik-2-plane-strain"));
        for name in ["elastic-strike", "two-plates-axisymmetric", "taylor-cu-130", "no-such-case"] {
            assert_eq!(builtin_experiments(name), None, "{name}");
        }
    }
}
