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

/// The top-level modules of `src/` and the modules each one names in code
/// (`crate::NAME`, comment lines left out: a doc link is no dependency).
fn module_imports() -> Vec<(String, Vec<String>)> {
    fn rust_files(path: &Path, out: &mut Vec<std::path::PathBuf>) {
        if path.is_dir() {
            for e in std::fs::read_dir(path).unwrap() {
                rust_files(&e.unwrap().path(), out);
            }
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path.to_path_buf());
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut modules = Vec::new();
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if name == "lib" || name == "main" {
            continue;
        }
        let mut files = Vec::new();
        rust_files(&path, &mut files);
        let mut uses = Vec::new();
        for f in files {
            for line in std::fs::read_to_string(&f).unwrap().lines() {
                if line.trim_start().starts_with("//") {
                    continue;
                }
                for part in line.split("crate::").skip(1) {
                    assert!(!part.starts_with('{'), "{}: write `crate::NAME::...` paths, not groups", f.display());
                    let used: String = part.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                    if used != name && !uses.contains(&used) {
                        uses.push(used);
                    }
                }
            }
        }
        modules.push((name, uses));
    }
    modules
}

/// No two modules import each other, directly or through others: the
/// layers of `ARCHITECTURE.md` are a true order (issue #21: `output` once
/// imported `run::RunError` while `run` drives `output`).
#[test]
fn modules_import_each_other_in_no_circle() {
    let modules = module_imports();
    assert!(modules.len() > 20);
    let index = |name: &str| modules.iter().position(|(m, _)| m == name);
    // Depth-first search with colours: 1 = on the current path, 2 = done.
    fn visit(
        k: usize,
        modules: &[(String, Vec<String>)],
        index: &dyn Fn(&str) -> Option<usize>,
        colour: &mut [u8],
        path: &mut Vec<usize>,
    ) {
        colour[k] = 1;
        path.push(k);
        for used in &modules[k].1 {
            let Some(j) = index(used) else { continue };
            if colour[j] == 1 {
                let start = path.iter().position(|&p| p == j).unwrap();
                let circle: Vec<&str> = path[start..].iter().chain([&j]).map(|&p| modules[p].0.as_str()).collect();
                panic!("modules import each other in a circle: {}", circle.join(" -> "));
            }
            if colour[j] == 0 {
                visit(j, modules, index, colour, path);
            }
        }
        path.pop();
        colour[k] = 2;
    }
    let mut colour = vec![0u8; modules.len()];
    for k in 0..modules.len() {
        if colour[k] == 0 {
            visit(k, &modules, &index, &mut colour, &mut Vec::new());
        }
    }
}
