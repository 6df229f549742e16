//! ARCHITECTURE.md stays true: every path it names exists, every module in
//! `src/` is named, and physics modules do not reach up into the driver layer.

use std::path::Path;

#[test]
fn architecture_map_names_existing_paths_and_all_modules() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).unwrap();
    let named: Vec<&str> = text.split('`').filter(|s| s.starts_with("src/")).collect();
    assert!(named.len() > 10);
    for p in &named {
        assert!(root.join(p).exists(), "ARCHITECTURE.md names {p}, which does not exist");
    }
    for entry in std::fs::read_dir(root.join("src")).unwrap() {
        let e = entry.unwrap();
        let name = e.file_name().to_string_lossy().to_string();
        if name == "lib.rs" {
            continue;
        }
        let key = if e.path().is_dir() { format!("src/{name}/") } else { format!("src/{name}") };
        assert!(named.contains(&key.as_str()), "{key} is missing from ARCHITECTURE.md");
    }
}

#[test]
fn physics_modules_do_not_import_the_driver_layer() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let physics = [
        "math.rs",
        "particles.rs",
        "quadrature.rs",
        "geometry.rs",
        "neighbors.rs",
        "kernel.rs",
        "shape",
        "material",
        "discretize.rs",
        "thermal.rs",
    ];
    let upper = ["crate::step", "crate::case", "crate::run", "crate::output", "crate::cases"];
    let mut files = Vec::new();
    for p in physics {
        let path = root.join(p);
        if path.is_dir() {
            for e in std::fs::read_dir(&path).unwrap() {
                files.push(e.unwrap().path());
            }
        } else {
            files.push(path);
        }
    }
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for u in upper {
            assert!(!text.contains(u), "{} imports {u}", f.display());
        }
    }
}
