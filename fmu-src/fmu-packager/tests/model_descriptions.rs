//! The checked-in `modelDescription/*.xml` must equal the rendering of the
//! variable tables: nobody edits the XML by hand.

use fmu_packager::{all_models, description_path, render};
use std::path::Path;

#[test]
fn checked_in_model_descriptions_match_the_code() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription");
    for info in all_models() {
        let path = description_path(&dir, info);
        let on_disk =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            on_disk == render(info).unwrap(),
            "{} differs from the variable table of {}: run `cargo run -p fmu-packager -- render`",
            path.display(),
            info.model_name
        );
    }
}

/// The list of shipped models that the tests and scripts read, and no
/// model description beside those of the shipped models.
#[test]
fn the_checked_in_list_of_shipped_models_matches_the_registries() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription");
    let path = fmu_packager::shipped_list_path(&dir);
    let on_disk =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        on_disk == fmu_packager::shipped_list(),
        "{} differs from the registries: run `cargo run -p fmu-packager -- render`",
        path.display()
    );
    let mut described: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            e.ok()?
                .file_name()
                .to_str()?
                .strip_suffix(".xml")
                .map(String::from)
        })
        .collect();
    described.sort();
    let mut shipped: Vec<String> = all_models()
        .iter()
        .map(|i| i.model_name.to_string())
        .collect();
    shipped.sort();
    assert_eq!(
        described, shipped,
        "a model description of a model that is not shipped"
    );
}

#[test]
fn every_model_has_a_distinct_guid_and_identifier() {
    let models = all_models();
    for (i, a) in models.iter().enumerate() {
        for b in &models[i + 1..] {
            assert_ne!(a.guid, b.guid);
            assert_ne!(a.model_identifier, b.model_identifier);
        }
    }
}

#[test]
fn docs_variable_tables_match_the_code() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/fmu-reference.md");
    let page = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        page.contains(&fmu_packager::variables_markdown()),
        "docs/fmu-reference.md's variable tables differ from the code: paste `cargo run -p fmu-packager -- variables-md`"
    );
}
