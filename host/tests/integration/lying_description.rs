//! FMUs whose model description lies about the binary (the shipped
//! Dahl.fmu repacked with an edited `modelDescription.xml`): a wrong GUID,
//! a variable the binary does not have, an output declared as an input, a
//! fixed parameter declared tunable, a capability the binary lacks. The
//! host either refuses the FMU when loading it or gets `fmi2Error` from the
//! binary at the first call that meets the lie; the error names the
//! instance, the call and the FMU's own message. Nothing is written outside
//! the host's temporary directory, which is removed when the FMU is dropped.

use crate::common;
use common::assert_message;
use fricsim::fmu::{Fmu, UnpackOptions};
use fricsim::system::System;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// `dist/Dahl.fmu` with `edit` applied to its model description, zipped
/// into `dir/Lying.fmu`.
fn lying_fmu(dir: &Path, edit: impl Fn(&str) -> String) -> PathBuf {
    common::repacked("Dahl", &dir.join("Lying.fmu"), edit)
}

/// Where the host unpacks: must be empty again after each case.
struct Sandbox {
    files: TempDir,
    parent: TempDir,
}

impl Sandbox {
    fn new() -> Sandbox {
        // Make sure the FMU exists before anything is measured.
        common::lugre_fmu();
        Sandbox {
            files: tempfile::tempdir().unwrap(),
            parent: tempfile::tempdir().unwrap(),
        }
    }

    fn open(&self, fmu: &Path) -> Result<Fmu, fricsim::FmuError> {
        Fmu::open_with(
            fmu,
            &UnpackOptions {
                temp_parent: Some(self.parent.path().to_path_buf()),
                ..UnpackOptions::default()
            },
        )
    }

    fn assert_clean(&self) {
        let left: Vec<_> = std::fs::read_dir(self.parent.path())
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert!(left.is_empty(), "left behind: {left:?}");
        let files: Vec<_> = std::fs::read_dir(self.files.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(files, ["Lying.fmu"], "a file appeared next to the archive");
    }
}

#[test]
fn a_wrong_guid_is_refused_by_the_binary_at_instantiation() {
    let s = Sandbox::new();
    let fmu = lying_fmu(s.files.path(), |md| {
        md.replacen("guid=\"{a54e3c99", "guid=\"{00000000", 1)
    });
    {
        let opened = s.open(&fmu).unwrap();
        let e = opened.instantiate("liar").unwrap_err();
        assert_message(
            &e,
            &[
                "fmi2Instantiate failed for instance \"liar\"",
                "unknown fmuGUID {00000000",
            ],
        );
    }
    s.assert_clean();
}

#[test]
fn a_declared_variable_the_binary_does_not_have_fails_at_the_first_call() {
    let s = Sandbox::new();
    // An extra input, value reference 999, that the binary rejects.
    let fmu = lying_fmu(s.files.path(), |md| {
        md.replacen(
            "  </ModelVariables>",
            "    <ScalarVariable name=\"ghost\" valueReference=\"999\" causality=\"input\" variability=\"continuous\"><Real start=\"0\"/></ScalarVariable>\n  </ModelVariables>",
            1,
        )
    });
    {
        // It loads: the lie is only in what the description promises.
        let opened = s.open(&fmu).unwrap();
        let components = [("liar".to_string(), fmu.as_path())];
        let parameters = [("liar.ghost".to_string(), 1.0)];
        drop(opened);
        let e = match System::build(&components, &parameters, &[]) {
            Ok(_) => panic!("the lie must be found"),
            Err(e) => e,
        };
        assert_message(
            &e,
            &[
                "fmi2SetReal failed for instance \"liar\" with fmi2Error",
                "unknown value reference 999",
            ],
        );
    }
    s.assert_clean();
}

#[test]
fn an_output_declared_as_an_input_is_refused_when_set() {
    let s = Sandbox::new();
    // F (value reference 1) is the binary's output; the description says input.
    let fmu = lying_fmu(s.files.path(), |md| {
        let at = md.find("name=\"F\"").unwrap();
        let (head, tail) = md.split_at(at);
        let tail = tail.replacen("causality=\"output\"", "causality=\"input\"", 1);
        // An input has no initial="calculated" and needs a start value.
        let tail = tail.replacen(" initial=\"calculated\"", "", 1);
        let tail = tail.replacen("<Real unit=\"N\"", "<Real unit=\"N\" start=\"0\"", 1);
        // The model structure no longer lists F as an output.
        let text = format!("{head}{tail}");
        let start = text.find("<Outputs>").unwrap();
        let end = text.find("</Outputs>").unwrap();
        let outputs: String = text[start..end]
            .lines()
            .filter(|l| !l.contains(&format!("index=\"{}\"", f_index(&text))))
            .collect::<Vec<_>>()
            .join("\n");
        format!("{}{}{}", &text[..start], outputs, &text[end..])
    });
    {
        let opened = match s.open(&fmu) {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        };
        let f = opened.variable("F").unwrap().value_reference;
        let mut instance = opened.instantiate("liar").unwrap();
        instance.setup_experiment(0.0, None).unwrap();
        instance.enter_initialization_mode().unwrap();
        let e = instance.set_real(&[f], &[1.0]).unwrap_err();
        assert_message(
            &e,
            &[
                "fmi2SetReal failed for instance \"liar\" with fmi2Error",
                "cannot set F",
                "an output",
            ],
        );
    }
    s.assert_clean();
}

/// The 1-based index of variable F in the description.
fn f_index(md: &str) -> usize {
    md.match_indices("<ScalarVariable ")
        .position(|(at, _)| md[at..].starts_with("<ScalarVariable name=\"F\""))
        .unwrap()
        + 1
}

#[test]
fn a_fixed_parameter_declared_tunable_is_refused_after_initialization() {
    let s = Sandbox::new();
    let fmu = lying_fmu(s.files.path(), |md| {
        md.replacen("variability=\"fixed\"", "variability=\"tunable\"", 1)
    });
    {
        let opened = s.open(&fmu).unwrap();
        let p = opened
            .description()
            .variables
            .iter()
            .find(|v| v.variability == fricsim::fmu::Variability::Tunable)
            .unwrap()
            .clone();
        let mut instance = opened.instantiate("liar").unwrap();
        instance.setup_experiment(0.0, None).unwrap();
        instance.enter_initialization_mode().unwrap();
        instance.exit_initialization_mode().unwrap();
        let start = match p.kind {
            fricsim::fmu::VariableKind::Real { start, .. } => start.unwrap(),
            _ => panic!("{p:?}"),
        };
        let e = instance
            .set_real(&[p.value_reference], &[start])
            .unwrap_err();
        assert_message(
            &e,
            &[
                "fmi2SetReal failed for instance \"liar\"",
                &format!("cannot set {}", p.name),
                "StepComplete",
            ],
        );
        // The instance is still usable.
        instance.do_step(0.0, 1e-3).unwrap();
    }
    s.assert_clean();
}

#[test]
fn a_capability_the_binary_lacks_is_refused_when_loading() {
    let s = Sandbox::new();
    // The binary lives under another model identifier: Dahl.so is missing.
    // (Every identifier: the Co-Simulation one follows the Model Exchange
    // one in the description.)
    let fmu = lying_fmu(s.files.path(), |md| {
        md.replace("modelIdentifier=\"Dahl\"", "modelIdentifier=\"Other\"")
    });
    let e = s.open(&fmu).unwrap_err();
    assert_message(&e, &["Lying.fmu", "binaries/linux64/Other.so"]);
    s.assert_clean();
}
