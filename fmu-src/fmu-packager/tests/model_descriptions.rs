//! The checked-in `modelDescription/*.xml` (FMI 2.0) and
//! `modelDescription/fmi3/*.xml` (FMI 3.0) must equal the rendering of the
//! variable tables: nobody edits the XML by hand.

use fmu_packager::{all_models, description_path_version, render_version, FmiVersion};
use std::path::Path;

#[test]
fn checked_in_model_descriptions_match_the_code() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../modelDescription");
    for version in FmiVersion::ALL {
        for info in all_models() {
            let path = description_path_version(&dir, info, version);
            let on_disk = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(
                on_disk == render_version(info, version).unwrap(),
                "{} differs from the variable table of {}: run `cargo run -p fmu-packager -- render`",
                path.display(),
                info.model_name
            );
        }
    }
}

/// The two descriptions of a model declare the same variables under the
/// same value references, in FMI 3.0's types (FMI 2.0's numbered scalars
/// as one array from the first element's value reference on), and FMI
/// 3.0's adds `time` and the event indicators after them.
#[test]
fn the_fmi3_description_declares_the_fmi2_variables() {
    for info in all_models() {
        let two = render_version(info, FmiVersion::Fmi2).unwrap();
        let three = render_version(info, FmiVersion::Fmi3).unwrap();
        assert!(three.contains(r#"fmiVersion="3.0""#));
        assert!(three.contains(&format!(r#"instantiationToken="{}""#, info.guid)));
        // every table variable, as itself or as an element of its array
        let layout = fmi_export::fmi3::arrays::Layout::new(info);
        for v in info.variables {
            assert!(two.contains(&format!(r#"name="{}" valueReference="{}""#, v.name, v.vr)));
            let fmi3 = layout.variable_of(v.vr).unwrap();
            let element = match v.var_type {
                fmi_export::VarType::Real => "Float64",
                fmi_export::VarType::Integer => "Int32",
                fmi_export::VarType::Boolean => "Boolean",
            };
            let declared = format!(
                r#"<{element} name="{}" valueReference="{}""#,
                fmi3.name, fmi3.vr
            );
            assert!(three.contains(&declared), "{}: {declared}", info.model_name);
            if fmi3.is_array {
                assert!(v.name.starts_with(&fmi3.name[..fmi3.name.len() - 1]));
                assert!((fmi3.vr..fmi3.vr + fmi3.len).contains(&v.vr));
            } else {
                assert_eq!((fmi3.name.as_str(), fmi3.vr), (v.name, v.vr));
            }
        }
        let arrays = layout.variables.iter().filter(|v| v.is_array).count();
        assert_eq!(three.matches("<Dimension start=").count(), arrays);
        let time = format!(
            r#"<Float64 name="time" valueReference="{}" causality="independent""#,
            info.variables.len()
        );
        assert!(three.contains(&time), "{}", info.model_name);
        let ni = info.model_exchange.map_or(0, |me| me.event_indicators);
        assert_eq!(three.matches("<EventIndicator ").count(), ni);
        assert_eq!(
            three.contains("<ModelExchange "),
            two.contains("<ModelExchange ")
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
