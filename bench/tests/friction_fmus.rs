//! The per-step table of the speed benchmarks drives every shipped
//! friction law (`modelDescription/shipped.txt`, the one list of them).

use fricsim_bench::FRICTION_FMUS;

#[test]
fn every_shipped_law_is_timed() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription/shipped.txt");
    let list = std::fs::read_to_string(&path).unwrap();
    let laws: Vec<&str> = list
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f.get(1) == Some(&"law")).then(|| f[0])
        })
        .collect();
    assert!(!laws.is_empty());
    let timed: Vec<&str> = FRICTION_FMUS.iter().map(|d| d.model).collect();
    let missing: Vec<&&str> = laws.iter().filter(|l| !timed.contains(l)).collect();
    assert!(
        missing.is_empty(),
        "FRICTION_FMUS has no row for {missing:?}"
    );
}
