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
