//! System files (SSP 1.0): a valid system parses, checks and runs; every
//! bad input is refused with a message that names the file, the element
//! and the value, and nothing panics. The systems are written into
//! temporary directories and point at the repository's dist/*.fmu by
//! absolute path.

use crate::common;
use common::{assert_message, repository};
use fricsim::inputs::{interpolate, ExternalInputs, InputTable};
use fricsim::master::{jacobi::Jacobi, simulate, simulate_with};
use fricsim::ssp::{SystemFile, Value};
use std::io::Write;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn dist(name: &str) -> String {
    let p = repository().join("dist").join(name);
    assert!(p.exists(), "{} is missing: run ./build-fmu.sh", p.display());
    p.display().to_string()
}

/// An ssd around `system` (the content of `<ssd:System>`) and `tail`
/// (what follows the system: DefaultExperiment, …).
fn ssd(system: &str, tail: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="test"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="test">
{system}
  </ssd:System>
{tail}
</ssd:SystemStructureDescription>
"#
    )
}

/// The stick-slip components with the given connector lines.
fn components(rig_connectors: &str, friction_connectors: &str, friction_extra: &str) -> String {
    format!(
        r#"    <ssd:Elements>
      <ssd:Component name="rig" source="{rig}">
        <ssd:Connectors>
{rig_connectors}
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="friction" source="{lugre}">
        <ssd:Connectors>
{friction_connectors}
        </ssd:Connectors>
{friction_extra}
      </ssd:Component>
    </ssd:Elements>"#,
        rig = dist("Rig1D.fmu"),
        lugre = dist("LuGre.fmu"),
    )
}

const RIG: &str = r#"          <ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          <ssd:Connector name="v" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="x" kind="output"><ssc:Real unit="m"/></ssd:Connector>"#;
const FRICTION: &str = r#"          <ssd:Connector name="v" kind="input"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real unit="N"/></ssd:Connector>"#;

fn connections(lines: &[(&str, &str, &str, &str)]) -> String {
    let mut s = String::from("    <ssd:Connections>\n");
    for (a, b, c, d) in lines {
        s.push_str(&format!(
            "      <ssd:Connection startElement=\"{a}\" startConnector=\"{b}\" endElement=\"{c}\" endConnector=\"{d}\"/>\n"
        ));
    }
    s.push_str("    </ssd:Connections>");
    s
}

const STICK_SLIP: &[(&str, &str, &str, &str)] =
    &[("rig", "v", "friction", "v"), ("friction", "F", "rig", "F")];

const EXPERIMENT: &str = r#"  <ssd:DefaultExperiment startTime="0" stopTime="0.5">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <f:Simulation xmlns:f="urn:friction-fmu:fricsim:1" stepSize="1e-3" master="gauss-seidel">
          <f:Plot signal="rig.x"/>
          <f:Record signal="friction.v"/>
          <f:Plot signal="friction.F"/>
        </f:Simulation>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>"#;

/// Write `files` (name, text) into a fresh directory; returns it.
fn write(files: &[(&str, &str)]) -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    dir
}

/// `text` as system.ssd beside the parameter files of [`valid_files`].
fn open(text: &str) -> (TempDir, Result<SystemFile, fricsim::ssp::SspError>) {
    let dir = valid_files();
    std::fs::write(dir.path().join("system.ssd"), text).unwrap();
    let file = SystemFile::open(dir.path().join("system.ssd"));
    (dir, file)
}

/// Parse and check `text`; the error message (it must fail).
fn refused(text: &str) -> String {
    let (_dir, file) = open(text);
    match file {
        Err(e) => e.to_string(),
        Ok(f) => match f.check() {
            Err(e) => e.to_string(),
            Ok(_) => panic!("the system was accepted:\n{text}"),
        },
    }
}

fn valid_system() -> String {
    let bindings = r#"        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="p">
                <ssv:Parameters>
                  <ssv:Parameter name="Fs"><ssv:Real value="1.6" unit="N"/></ssv:Parameter>
                  <ssv:Parameter name="n_table"><ssv:Integer value="2"/></ssv:Parameter>
                  <ssv:Parameter name="direction_dependent"><ssv:Boolean value="false"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
          <ssd:ParameterBinding source="more.ssv"/>
        </ssd:ParameterBindings>"#;
    ssd(
        &format!(
            "    <ssd:ParameterBindings>\n      <ssd:ParameterBinding source=\"rig.ssv\" prefix=\"rig.\"/>\n    </ssd:ParameterBindings>\n{}\n{}",
            components(RIG, FRICTION, bindings),
            connections(STICK_SLIP)
        ),
        EXPERIMENT,
    )
}

fn ssv(parameters: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<ssv:ParameterSet version="1.0" name="set" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssv:Parameters>
{parameters}
  </ssv:Parameters>
</ssv:ParameterSet>
"#
    )
}

fn valid_files() -> TempDir {
    write(&[
        ("system.ssd", &valid_system()),
        (
            "more.ssv",
            &ssv(
                r#"    <ssv:Parameter name="Fc"><ssv:Real value="0.9" unit="N"/></ssv:Parameter>"#,
            ),
        ),
        (
            "rig.ssv",
            &ssv(r#"    <ssv:Parameter name="k"><ssv:Real value="3" unit="N/m"/></ssv:Parameter>"#),
        ),
    ])
}

#[test]
fn a_valid_system_is_parsed_checked_and_runs() {
    let dir = valid_files();
    let file = SystemFile::open(dir.path().join("system.ssd")).unwrap();
    assert_eq!(file.name, "test");
    let names: Vec<&str> = file.components.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["rig", "friction"]);
    assert_eq!(file.components[0].connectors.len(), 3);
    assert_eq!(
        file.components[0].connectors[1].unit.as_deref(),
        Some("m/s")
    );
    assert_eq!(file.connections.len(), 2);
    assert_eq!((file.start_time, file.stop_time), (Some(0.0), Some(0.5)));
    assert_eq!(file.settings.step_size, Some(1e-3));
    assert_eq!(file.settings.master.as_deref(), Some("gauss-seidel"));
    assert_eq!(file.settings.plot, ["rig.x", "friction.F"]);
    assert_eq!(file.settings.record, ["friction.v"]);
    // component bindings in order, then the system's (which win)
    let params: Vec<(String, Value)> = file
        .parameters
        .iter()
        .map(|p| (format!("{}.{}", p.component, p.variable), p.value.clone()))
        .collect();
    assert_eq!(
        params,
        [
            ("friction.Fs".to_string(), Value::Real(1.6)),
            ("friction.n_table".to_string(), Value::Integer(2)),
            (
                "friction.direction_dependent".to_string(),
                Value::Boolean(false)
            ),
            ("friction.Fc".to_string(), Value::Real(0.9)),
            ("rig.k".to_string(), Value::Real(3.0)),
        ]
    );
    // the locations name the file and the line
    assert!(file.parameters[0].location.contains("system.ssd:"));
    assert!(file.parameters[3].location.contains("more.ssv:"));

    let mut system = file.build(0.0).unwrap();
    let run = simulate(&mut system, &mut Jacobi::default(), 1e-3, 0.5).unwrap();
    assert!(run.error.is_none());
    assert!(run.columns.contains(&"friction.v".to_string()));
    assert_eq!(run.rows.len(), 501);
}

#[test]
fn the_stick_slip_example_checks() {
    let file = SystemFile::open(repository().join("examples/stick_slip.ssd")).unwrap();
    file.check().unwrap();
    assert_eq!(file.stop_time, Some(20.0));
    assert_eq!(file.settings.step_size, Some(1e-4));
    assert_eq!(file.settings.master.as_deref(), Some("jacobi"));
}

/// `fricsim pack` writes an archive that reads back to the same system,
/// and the run from the archive equals the run from the ssd.
#[test]
fn a_packed_archive_runs_like_its_ssd() {
    let dir = valid_files();
    let ssp = dir.path().join("packed.ssp");
    fricsim::ssp::pack(&dir.path().join("system.ssd"), &ssp).unwrap();
    let run = |path: &Path| {
        let file = SystemFile::open(path).unwrap();
        let mut system = file.build(0.0).unwrap();
        simulate(&mut system, &mut Jacobi::default(), 1e-3, 0.2).unwrap()
    };
    let (a, b) = (run(&dir.path().join("system.ssd")), run(&ssp));
    assert_eq!(a.columns, b.columns);
    assert_eq!(a.rows, b.rows);
}

#[test]
fn a_missing_fmu_file_is_named() {
    let text = valid_system().replace(&dist("LuGre.fmu"), "../nowhere/Missing.fmu");
    let message = refused(&text);
    assert_message(
        &message,
        &[
            "system.ssd:",
            "<Component name=\"friction\"",
            "Missing.fmu",
            "does not exist",
        ],
    );
}

#[test]
fn a_connector_for_an_unknown_variable_lists_the_known_ones() {
    let rig = RIG.replace("name=\"v\"", "name=\"vv\"");
    let text = ssd(
        &format!(
            "{}\n{}",
            components(&rig, FRICTION, ""),
            connections(&[("rig", "vv", "friction", "v")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "system.ssd:",
            "<Connector name=\"vv\" kind=\"output\">",
            "has no variable `vv`",
            "outputs: x, v, a",
        ],
    );
}

#[test]
fn a_connection_to_an_unknown_variable_is_refused() {
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("rig", "speed", "friction", "v")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "<Connection startElement=\"rig\" startConnector=\"speed\"",
            "no connector `speed`",
            "its connectors: F, v, x",
            "no variable `speed`",
        ],
    );
}

#[test]
fn a_connection_to_an_undeclared_connector_says_to_declare_it() {
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("rig", "a", "friction", "v")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &["no connector `a`", "has a variable `a`: declare it"],
    );
}

#[test]
fn an_unknown_component_is_refused_with_the_known_ones() {
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("rigg", "v", "friction", "v")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "system.ssd:",
            "no component `rigg`",
            "components: rig, friction",
        ],
    );
}

#[test]
fn an_output_to_output_connection_is_refused() {
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("rig", "v", "friction", "F")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "startConnector=\"v\"",
            "connects output `rig.v` to output `friction.F`",
            "from an output to an input",
        ],
    );
}

/// Start and end do not give the direction: input-to-output is read
/// output-to-input, as the standard says.
#[test]
fn a_connection_written_end_first_is_accepted() {
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("friction", "v", "rig", "v")])
        ),
        "",
    );
    let (_dir, file) = open(&text);
    let checked = file.unwrap().check().unwrap();
    assert_eq!(checked.connections[0].from, "rig.v");
    assert_eq!(checked.connections[0].to, "friction.v");
}

#[test]
fn a_connector_unit_that_differs_from_the_fmu_is_refused() {
    let rig = RIG.replace("<ssc:Real unit=\"m/s\"/>", "<ssc:Real unit=\"km/h\"/>");
    let text = ssd(
        &format!(
            "{}\n{}",
            components(&rig, FRICTION, ""),
            connections(STICK_SLIP)
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &["<Connector name=\"v\"", "unit mismatch", "`km/h`", "`m/s`"],
    );
}

#[test]
fn a_connection_between_different_units_is_refused() {
    // rig.x (m) into friction.v (m/s): both connectors agree with their FMUs
    let text = ssd(
        &format!(
            "{}\n{}",
            components(RIG, FRICTION, ""),
            connections(&[("rig", "x", "friction", "v")])
        ),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "<Connection startElement=\"rig\" startConnector=\"x\"",
            "unit mismatch",
            "`rig.x` has unit `m`",
            "`friction.v` has unit `m/s`",
        ],
    );
}

#[test]
fn a_connector_of_the_wrong_kind_or_type_is_refused() {
    let rig = RIG.replace("name=\"F\" kind=\"input\"", "name=\"F\" kind=\"output\"");
    let text = ssd(
        &format!("{}\n{}", components(&rig, FRICTION, ""), connections(&[])),
        "",
    );
    assert_message(
        &refused(&text),
        &[
            "<Connector name=\"F\" kind=\"output\">",
            "causality \"input\"",
        ],
    );
    let rig = RIG.replace("<ssc:Real unit=\"m\"/>", "<ssc:Integer/>");
    let text = ssd(
        &format!("{}\n{}", components(&rig, FRICTION, ""), connections(&[])),
        "",
    );
    assert_message(
        &refused(&text),
        &["<Connector name=\"x\"", "ssc:Integer", "is Real"],
    );
}

#[test]
fn malformed_xml_is_located() {
    let text = valid_system().replace("<ssd:Connections>", "<ssd:Connections");
    assert_message(&refused(&text), &["system.ssd:"]);
    let text = valid_system().replace("</ssd:Elements>", "</ssd:Element>");
    let message = refused(&text);
    assert_message(&message, &["system.ssd:", "Element"]);
    // line of the offending end tag
    let line = valid_system()
        .lines()
        .position(|l| l.contains("</ssd:Elements>"))
        .unwrap()
        + 1;
    assert!(
        message.contains(&format!("system.ssd:{line}:")),
        "{message}"
    );
}

#[test]
fn two_hyphens_inside_a_comment_are_refused_with_their_line() {
    // XML 1.0 §2.5: other tools' parsers (expat, libxml2) refuse the file,
    // so fricsim must not accept it either; examples/ once had such comments.
    // the line and column of the `--`, in a comment of several lines with
    // single hyphens before it
    let text = valid_system().replace(
        "<ssd:Connections>",
        "<!-- run it, re-plotted,\n     with the option --plot -->\n    <ssd:Connections>",
    );
    let line = text.lines().position(|l| l.contains("--plot")).unwrap() + 1;
    let message = refused(&text);
    assert_message(
        &message,
        &[&format!("system.ssd:{line}:22:"), "`--` inside a comment"],
    );
    // and in a parameter file (more.ssv, bound to the friction component)
    let dir = valid_files();
    let more = dir.path().join("more.ssv");
    let good = std::fs::read_to_string(&more).unwrap();
    let bad = good.replacen("<ssv:Parameters>", "<!-- a -- b --><ssv:Parameters>", 1);
    assert_ne!(bad, good);
    std::fs::write(&more, bad).unwrap();
    let message = match SystemFile::open(dir.path().join("system.ssd")) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a parameter file with -- in a comment was accepted"),
    };
    assert_message(&message, &["more.ssv:3:", "`--` inside a comment"]);
}

#[test]
fn a_truncated_file_says_so() {
    let text = valid_system();
    for cut in [text.len() / 3, text.len() / 2, text.len() - 40] {
        let message = refused(&text[..cut]);
        assert_message(&message, &["system.ssd:"]);
    }
    // wherever the cut falls: between elements, inside a tag or inside an
    // attribute value
    for cut in (text.len() / 4..text.len() - 20).step_by(37) {
        if text.is_char_boundary(cut) {
            assert_message(&refused(&text[..cut]), &["truncated"]);
        }
    }
    assert_message(&refused(""), &["system.ssd:", "no root element"]);
}

#[test]
fn text_outside_the_root_element_is_refused_with_its_line() {
    let text = valid_system();
    let end = text.rfind('>').unwrap() + 1;
    let (head, tail) = text.split_at(end);
    // white space (and comments) around the root stay allowed: the valid
    // system ends with a line break
    assert!(tail.chars().all(char::is_whitespace), "{tail:?}");
    let last_line = head.lines().count();
    for (extra, where_) in [
        ("stray words", "after"),
        ("&amp;", "after"),
        ("<![CDATA[x]]>", "after"),
    ] {
        let message = refused(&format!("{head}\n{extra}\n"));
        assert_message(
            &message,
            &[
                &format!("system.ssd:{}:", last_line + 1),
                &format!("text {where_} the root element <SystemStructureDescription>"),
            ],
        );
    }
    let declaration_end = text.find("?>").unwrap() + 2;
    let (declaration, rest) = text.split_at(declaration_end);
    let message = refused(&format!("{declaration}\nstray{rest}"));
    assert_message(
        &message,
        &[
            "system.ssd:2:",
            "text before the root element <SystemStructureDescription>",
        ],
    );
}

#[test]
fn the_root_element_and_version_are_checked() {
    let text = valid_system().replace(
        "http://ssp-standard.org/SSP1/SystemStructureDescription",
        "http://example.org/other",
    );
    assert_message(
        &refused(&text),
        &["root element", "SystemStructureDescription", "SSP 1.0"],
    );
    let text = valid_system().replace(
        "version=\"1.0\" name=\"test\"",
        "version=\"2.0\" name=\"test\"",
    );
    assert_message(&refused(&text), &["version=\"2.0\"", "only SSP 1.0"]);
}

#[test]
fn a_parameter_for_an_unknown_variable_is_refused() {
    let dir = valid_files();
    std::fs::write(
        dir.path().join("more.ssv"),
        ssv(r#"    <ssv:Parameter name="Fcc"><ssv:Real value="0.9"/></ssv:Parameter>"#),
    )
    .unwrap();
    let err = SystemFile::open(dir.path().join("system.ssd"))
        .unwrap()
        .check()
        .err()
        .unwrap();
    assert_message(
        &err,
        &[
            "more.ssv:4: <Parameter name=\"Fcc\">",
            "component `friction`",
            "no variable `Fcc`",
            "sigma0",
            "x_table[1..32]",
        ],
    );
    // a system-level name must start with a component
    let text = valid_system();
    let dir = write(&[
        ("system.ssd", &text),
        ("more.ssv", &ssv("")),
        (
            "rig.ssv",
            &ssv(r#"    <ssv:Parameter name="k"><ssv:Real value="3"/></ssv:Parameter>"#),
        ),
    ]);
    std::fs::write(
        dir.path().join("system.ssd"),
        text.replace("prefix=\"rig.\"", "prefix=\"table.\""),
    )
    .unwrap();
    let err = SystemFile::open(dir.path().join("system.ssd"))
        .err()
        .unwrap();
    assert_message(
        &err,
        &[
            "rig.ssv",
            "`table.k`",
            "names no component",
            "components: rig, friction",
        ],
    );
}

#[test]
fn a_parameter_of_the_wrong_type_unit_or_causality_is_refused() {
    let cases = [
        (
            r#"<ssv:Parameter name="n_table"><ssv:Real value="2"/></ssv:Parameter>"#,
            vec!["ssv:Real", "is Integer", "<ssv:Integer>"],
        ),
        (
            r#"<ssv:Parameter name="Fc"><ssv:Real value="1" unit="kN"/></ssv:Parameter>"#,
            vec!["unit mismatch", "`kN`", "`N`"],
        ),
        (
            r#"<ssv:Parameter name="F"><ssv:Real value="1"/></ssv:Parameter>"#,
            vec!["`friction.F`", "causality \"output\""],
        ),
        (
            r#"<ssv:Parameter name="Fc"><ssv:Real value="fast"/></ssv:Parameter>"#,
            vec!["value=\"fast\"", "not a finite number"],
        ),
        (
            r#"<ssv:Parameter name="direction_dependent"><ssv:Boolean value="yes"/></ssv:Parameter>"#,
            vec!["value=\"yes\""],
        ),
    ];
    for (parameter, parts) in cases {
        let dir = valid_files();
        std::fs::write(dir.path().join("more.ssv"), ssv(parameter)).unwrap();
        let message = match SystemFile::open(dir.path().join("system.ssd")) {
            Err(e) => e.to_string(),
            Ok(f) => f.check().err().expect(parameter).to_string(),
        };
        let mut parts = parts;
        parts.push("more.ssv:4:");
        assert_message(&message, &parts);
    }
}

#[test]
fn a_missing_parameter_file_is_named() {
    let dir = valid_files();
    std::fs::remove_file(dir.path().join("more.ssv")).unwrap();
    let err = SystemFile::open(dir.path().join("system.ssd"))
        .err()
        .unwrap();
    assert_message(
        &err,
        &[
            "system.ssd:",
            "<ParameterBinding source=\"more.ssv\">",
            "more.ssv",
            "does not exist",
        ],
    );
}

#[test]
fn unsupported_constructs_are_refused_by_name() {
    let system_connector = ssd(
        &format!(
            "    <ssd:Connectors><ssd:Connector name=\"u\" kind=\"input\"/></ssd:Connectors>\n{}",
            components(RIG, FRICTION, "")
        ),
        "",
    );
    assert_message(
        &refused(&system_connector),
        &[
            "<Connector name=\"u\"",
            "connectors of the system",
            "--input",
        ],
    );
    let to_system = ssd(
        &format!(
            "{}\n    <ssd:Connections><ssd:Connection startConnector=\"u\" endElement=\"rig\" endConnector=\"F\"/></ssd:Connections>",
            components(RIG, FRICTION, "")
        ),
        "",
    );
    assert_message(
        &refused(&to_system),
        &["connector `u` of the system itself"],
    );
    let nested = valid_system().replace(
        "    </ssd:Elements>",
        "      <ssd:System name=\"inner\"/>\n    </ssd:Elements>",
    );
    assert_message(
        &refused(&nested),
        &["<System name=\"inner\">", "nested systems"],
    );
    let not_fmu = valid_system().replacen(
        "<ssd:Component name=\"rig\"",
        "<ssd:Component type=\"application/x-ssp-package\" name=\"rig\"",
        1,
    );
    assert_message(
        &refused(&not_fmu),
        &["type=\"application/x-ssp-package\"", "only FMUs"],
    );
    let transform = valid_system().replace(
        "endElement=\"friction\" endConnector=\"v\"/>",
        "endElement=\"friction\" endConnector=\"v\"><ssc:LinearTransformation factor=\"2\"/></ssd:Connection>",
    );
    assert_message(
        &refused(&transform),
        &["LinearTransformation", "not supported"],
    );
    let bad_step = valid_system().replace("stepSize=\"1e-3\"", "stepSize=\"-1\"");
    assert_message(
        &refused(&bad_step),
        &["stepSize=\"-1\"", "not a positive number"],
    );
    let bad_master = valid_system().replace("master=\"gauss-seidel\"", "master=\"euler\"");
    assert_message(&refused(&bad_master), &["master=\"euler\"", "jacobi"]);
    let bad_signal = valid_system().replace("signal=\"rig.x\"", "signal=\"rig.y\"");
    assert_message(
        &refused(&bad_signal),
        &["signal `rig.y`", "no variable `y`"],
    );
    let twice = valid_system().replace(
        "</ssd:Connections>",
        "  <ssd:Connection startElement=\"rig\" startConnector=\"v\" endElement=\"friction\" endConnector=\"v\"/>\n    </ssd:Connections>",
    );
    assert_message(
        &refused(&twice),
        &["input `friction.v` is already connected"],
    );
}

/// A zip with the given entries (stored).
fn archive(path: &Path, entries: &[(&str, &[u8])]) {
    let mut zip = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    for (name, bytes) in entries {
        zip.start_file(*name, zip::write::SimpleFileOptions::default())
            .unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap();
}

#[test]
fn an_ssp_with_a_path_traversal_entry_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let ssp = dir.path().join("evil.ssp");
    archive(
        &ssp,
        &[
            ("SystemStructure.ssd", valid_system().as_bytes()),
            ("../escaped.txt", b"gotcha"),
        ],
    );
    let err = SystemFile::open(&ssp).err().unwrap();
    assert_message(&err, &["evil.ssp", "../escaped.txt", "path traversal"]);
    assert!(!dir.path().join("escaped.txt").exists());
    assert!(!dir.path().parent().unwrap().join("escaped.txt").exists());
}

#[test]
fn an_ssp_without_a_system_structure_or_with_escaping_sources_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let ssp = dir.path().join("empty.ssp");
    archive(&ssp, &[("readme.txt", b"nothing")]);
    assert_message(
        &SystemFile::open(&ssp).err().unwrap(),
        &["empty.ssp", "no SystemStructure.ssd"],
    );

    let ssp = dir.path().join("outside.ssp");
    let text = valid_system().replace(&dist("Rig1D.fmu"), "../Rig1D.fmu");
    archive(&ssp, &[("SystemStructure.ssd", text.as_bytes())]);
    assert_message(
        &SystemFile::open(&ssp).err().unwrap(),
        &[
            "outside.ssp!/SystemStructure.ssd:",
            "source=\"../Rig1D.fmu\"",
            "inside the archive",
        ],
    );

    let ssp = dir.path().join("missing.ssp");
    let text = valid_system()
        .replace(&dist("Rig1D.fmu"), "resources/Rig1D.fmu")
        .replace(&dist("LuGre.fmu"), "resources/LuGre.fmu");
    let more = ssv("");
    let rig = ssv("");
    archive(
        &ssp,
        &[
            ("SystemStructure.ssd", text.as_bytes()),
            ("more.ssv", more.as_bytes()),
            ("rig.ssv", rig.as_bytes()),
        ],
    );
    let err = SystemFile::open(&ssp).unwrap().check().err().unwrap();
    assert_message(
        &err,
        &["missing.ssp!/resources/Rig1D.fmu", "does not exist"],
    );

    let ssp = dir.path().join("broken.ssp");
    std::fs::write(&ssp, b"PK\x03\x04 not really a zip").unwrap();
    assert_message(
        &SystemFile::open(&ssp).err().unwrap(),
        &["broken.ssp", "cannot unpack"],
    );
}

/// An input CSV: columns bound to unconnected inputs, errors named.
#[test]
fn input_tables_are_checked_and_bound() {
    let dir = tempfile::tempdir().unwrap();
    let csv = |name: &str, text: &str| -> PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let read_err = |p: PathBuf| InputTable::read(&p).err().unwrap();
    assert_message(
        &read_err(csv("a.csv", "t,v\n0,1\n")),
        &["a.csv", "first column must be `time`", "`t`"],
    );
    assert_message(
        &read_err(csv("b.csv", "time,v\n0,1\n1,x\n")),
        &["b.csv: line 3", "`x` is not a finite number"],
    );
    assert_message(
        &read_err(csv("c.csv", "time,v\n1,1\n0,2\n")),
        &["c.csv: line 3", "must not decrease"],
    );
    assert_message(&read_err(csv("d.csv", "time,v\n")), &["d.csv", "no rows"]);
    assert_message(
        &read_err(csv("e.csv", "time,v,v\n0,1,2\n")),
        &["e.csv", "`v` occurs twice"],
    );
    assert_message(
        &read_err(csv("f.csv", "time,v\n0,1,2\n")),
        &["f.csv: line 2", "3 values"],
    );

    let system_dir = valid_files();
    let file = SystemFile::open(system_dir.path().join("system.ssd")).unwrap();
    let bind = |text: &str| {
        let table = InputTable::read(&csv("in.csv", text)).unwrap();
        ExternalInputs::bind(table, &file.build(0.0).unwrap())
            .err()
            .unwrap()
    };
    assert_message(
        &bind("time,friction.v\n0,1\n"),
        &[
            "in.csv",
            "`friction.v` is driven by the connection rig.v -> friction.v",
        ],
    );
    assert_message(
        &bind("time,rig.nothing\n0,1\n"),
        &[
            "column `rig.nothing`",
            "no variable `nothing`",
            "unconnected inputs: rig.F_ext",
        ],
    );
    assert_message(
        &bind("time,rig.x\n0,1\n"),
        &["`rig.x` has causality \"output\""],
    );

    // a bound input drives the run: F_ext = 2 N from t = 0 moves the rig
    let table = InputTable::read(&csv("ok.csv", "time,rig.F_ext\n0,2\n1,2\n")).unwrap();
    let mut system = file.build(0.0).unwrap();
    let mut inputs = ExternalInputs::bind(table, &system).unwrap();
    let run = simulate_with(
        &mut system,
        &mut Jacobi::default(),
        0.0,
        1e-3,
        0.5,
        &mut inputs,
    )
    .unwrap();
    let k = run
        .columns
        .iter()
        .position(|c| c == "rig.F_spring")
        .unwrap();
    assert!(run.rows.last().unwrap()[k].abs() > 0.0);
    assert_eq!(interpolate(0.25, &[0.0, 1.0], &[0.0, 4.0], false), 1.0);
}

/// Non-UTF-8 bytes and binary junk are refused, never a panic.
#[test]
fn junk_is_refused_without_a_panic() {
    for junk in [
        &b"\xff\xfe\x00<"[..],
        b"<<<>>>",
        b"<?xml version=\"1.0\"?><a",
        b"\x00\x01\x02",
    ] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("junk.ssd");
        std::fs::write(&path, junk).unwrap();
        let err = SystemFile::open(&path).expect_err("junk must be refused");
        assert_message(&err, &["junk.ssd"]);
    }
    let dir = tempfile::tempdir().unwrap();
    assert_message(
        &SystemFile::open(dir.path().join("none.ssd")).err().unwrap(),
        &["none.ssd", "no such file"],
    );
}

/// A document of 240 000 elements (120 000 inline parameters of the
/// friction component, `Fs` again and again: the last one counts) is read
/// in one pass, every element's line counted as the parser goes; a
/// connection to an unknown component after them is refused naming its
/// line. (Asking for each element's line from the start of the file made
/// the pass quadratic: 77 s for 120 000 elements; BENCHMARKS.md times it.)
#[test]
fn a_document_of_many_elements_is_read_in_one_pass_and_located() {
    let one = r#"                  <ssv:Parameter name="Fs"><ssv:Real value="1.6" unit="N"/></ssv:Parameter>
"#;
    let system = valid_system().replacen(one, &one.repeat(120_000), 1);
    let (_dir, file) = open(&system);
    file.expect("accepted").check().expect("checks");

    let bad = system.replacen(
        r#"startElement="rig" startConnector="v""#,
        r#"startElement="rigg" startConnector="v""#,
        1,
    );
    let line = bad.lines().position(|l| l.contains("rigg")).unwrap() + 1;
    assert!(line > 120_000, "{line}");
    assert_message(
        &refused(&bad),
        &[&format!("system.ssd:{line}"), "no component `rigg`"],
    );
}

/// Elements nested deeper than the XML reader supports (65 535 levels)
/// are refused at once, naming the line where the limit is passed, not
/// the start of the file.
#[test]
fn a_nesting_too_deep_is_refused_where_it_passes_the_limit() {
    let depth = 70_000;
    let nested = format!("{}{}", "<x>\n".repeat(depth), "</x>\n".repeat(depth));
    let system = valid_system().replacen("</ssd:System>", &format!("{nested}</ssd:System>"), 1);
    let first = system.lines().position(|l| l == "<x>").unwrap() + 1;
    let message = refused(&system);
    let line: usize = message
        .split("system.ssd:")
        .nth(1)
        .and_then(|rest| rest.split(':').next())
        .and_then(|l| l.parse().ok())
        .unwrap_or_else(|| panic!("no line in: {message}"));
    // the root, the system and its elements are open around the <x>s
    assert!(
        line > first + 65_000 && line < first + depth,
        "line {line}: {message}"
    );
    assert!(message.contains("65535"), "{message}");
}
