//! modelDescription.xml: a valid FMI 2.0 description is read into typed
//! values; malformed, truncated or rule-breaking ones are refused with a
//! message that says what and where.

use crate::common;
use fricsim::fmu::model_description::Unknown;
use fricsim::fmu::{Causality, Initial, ModelDescription, Variability, VariableKind};
use fricsim::FmuError;

const VALID: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<!-- a comment before the root -->
<fmiModelDescription fmiVersion="2.0" modelName="Spring &amp; damper" guid="{1234-abcd}"
    description="A test model" generationTool="hand" generationDateAndTime="2024-01-01T00:00:00Z"
    variableNamingConvention="structured" numberOfEventIndicators="0">
  <ModelExchange modelIdentifier="Other"/>
  <CoSimulation modelIdentifier="Spring_1" canHandleVariableCommunicationStepSize="true"
      canInterpolateInputs="1" maxOutputDerivativeOrder="2" canGetAndSetFMUstate="true"
      canSerializeFMUstate="true" providesDirectionalDerivative="false"/>
  <UnitDefinitions>
    <Unit name="m"><BaseUnit m="1"/></Unit>
    <Unit name="N"><BaseUnit kg="1" m="1" s="-2"/></Unit>
  </UnitDefinitions>
  <TypeDefinitions>
    <SimpleType name="Mode"><Enumeration><Item name="a" value="1"/><Item name="b" value="2"/></Enumeration></SimpleType>
  </TypeDefinitions>
  <LogCategories>
    <Category name="logError" description="Errors"/>
    <Category name="logCalls"/>
  </LogCategories>
  <DefaultExperiment startTime="0" stopTime="2.5" stepSize="1e-3"/>
  <ModelVariables>
    <!-- index 1 -->
    <ScalarVariable name="x" valueReference="0" causality="input" description="Position">
      <Real start="0.5" unit="m" nominal="0.1" min="-INF" max="10"/>
    </ScalarVariable>
    <ScalarVariable name="F" valueReference="1" causality="output" initial="calculated">
      <Real unit="N"/>
    </ScalarVariable>
    <ScalarVariable name="k" valueReference="2" causality="parameter" variability="fixed" initial="exact">
      <Real start="100"/>
      <Annotations><Tool name="x"/></Annotations>
    </ScalarVariable>
    <ScalarVariable name="n" valueReference="0" causality="parameter" variability="tunable">
      <Integer start="-3" min="-10" max="10"/>
    </ScalarVariable>
    <ScalarVariable name="on" valueReference="0" causality="input" variability="discrete">
      <Boolean start="true"/>
    </ScalarVariable>
    <ScalarVariable name="label" valueReference="0" variability="discrete">
      <String start="hello"/>
    </ScalarVariable>
    <ScalarVariable name="mode" valueReference="3" causality="parameter" variability="fixed">
      <Enumeration declaredType="Mode" start="2"/>
    </ScalarVariable>
    <ScalarVariable name="der(x)" valueReference="4">
      <Real derivative="1"/>
    </ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="2" dependencies="1 5" dependenciesKind="dependent dependent"/>
    </Outputs>
    <InitialUnknowns><Unknown index="2"/></InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"#;

#[test]
fn a_valid_description_is_read() {
    let d = ModelDescription::parse(VALID).unwrap();
    assert_eq!(d.fmi_version, "2.0");
    assert_eq!(d.model_name, "Spring & damper");
    assert_eq!(d.guid, "{1234-abcd}");
    assert_eq!(d.description.as_deref(), Some("A test model"));
    assert_eq!(d.generation_tool.as_deref(), Some("hand"));

    let cs = &d.co_simulation;
    assert_eq!(cs.model_identifier, "Spring_1");
    assert!(cs.can_handle_variable_communication_step_size);
    assert!(cs.can_interpolate_inputs);
    assert_eq!(cs.max_output_derivative_order, 2);
    assert!(cs.can_get_and_set_fmu_state && cs.can_serialize_fmu_state);
    assert!(!cs.provides_directional_derivative);

    assert_eq!(
        d.unit_definitions.as_deref(),
        Some(&["m".to_string(), "N".to_string()][..])
    );
    let categories: Vec<_> = d.log_categories.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(categories, ["logError", "logCalls"]);
    assert_eq!(d.log_categories[0].description.as_deref(), Some("Errors"));
    let e = d.default_experiment.as_ref().unwrap();
    assert_eq!(
        (e.start_time, e.stop_time, e.tolerance, e.step_size),
        (Some(0.0), Some(2.5), None, Some(1e-3))
    );

    assert_eq!(d.variables.len(), 8);
    let x = d.variable("x").unwrap();
    assert_eq!(
        (x.index, x.value_reference, x.causality, x.variability),
        (1, 0, Causality::Input, Variability::Continuous)
    );
    assert_eq!(x.description.as_deref(), Some("Position"));
    assert_eq!(
        x.kind,
        VariableKind::Real {
            start: Some(0.5),
            unit: Some("m".into()),
            nominal: Some(0.1),
            min: Some(f64::NEG_INFINITY),
            max: Some(10.0),
            derivative: None
        }
    );
    let f = d.variable("F").unwrap();
    assert_eq!(
        (f.causality, f.initial),
        (Causality::Output, Some(Initial::Calculated))
    );
    let k = d.variable("k").unwrap();
    assert_eq!(
        (k.variability, k.initial, k.kind.start_text().as_deref()),
        (Variability::Fixed, Some(Initial::Exact), Some("100.0"))
    );
    assert_eq!(
        d.variable("n").unwrap().kind,
        VariableKind::Integer {
            start: Some(-3),
            min: Some(-10),
            max: Some(10)
        }
    );
    assert_eq!(
        d.variable("on").unwrap().kind,
        VariableKind::Boolean { start: Some(true) }
    );
    let label = d.variable("label").unwrap();
    assert_eq!(
        (label.causality, &label.kind),
        (
            Causality::Local,
            &VariableKind::String {
                start: Some("hello".into())
            }
        )
    );
    assert_eq!(d.variable("mode").unwrap().kind.type_name(), "Enumeration");
    assert!(matches!(
        d.variable("der(x)").unwrap().kind,
        VariableKind::Real {
            derivative: Some(1),
            ..
        }
    ));

    assert_eq!(
        d.outputs,
        vec![Unknown {
            index: 2,
            dependencies: Some(vec![1, 5])
        }]
    );

    let e = d.variable("nope").unwrap_err();
    assert!(matches!(&e, FmuError::UnknownVariable { .. }));
    assert!(e.to_string().contains("\"nope\""), "{e}");
}

/// The shipped model descriptions with both interfaces are read for
/// Co-Simulation, the Model Exchange element and the state derivatives
/// noted; the ones without it have none.
#[test]
fn the_shipped_descriptions_with_model_exchange_are_read() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    for (name, states, indicators) in [
        ("Dahl", &["F_dahl"][..], 1),
        ("LuGre", &["z"][..], 1),
        ("ResetIntegrator", &["z"][..], 2),
        ("Bristle2D", &["z1", "z2"][..], 1),
        ("Bristle", &[][..], 0),
        ("Rig1D", &[][..], 0),
    ] {
        let d = ModelDescription::from_file(&dir.join(format!("{name}.xml"))).unwrap();
        assert_eq!(d.co_simulation.model_identifier, name);
        let me = d.model_exchange.as_deref();
        assert_eq!(me, (!states.is_empty()).then_some(name), "{name}");
        assert_eq!(d.number_of_event_indicators, indicators, "{name}");
        for state in states {
            let index = d.variable(state).unwrap().index;
            let der = d.variable(&format!("der({state})")).unwrap();
            assert_eq!(der.causality, Causality::Local, "{name}");
            assert!(
                matches!(der.kind, VariableKind::Real { derivative: Some(i), .. } if i == index),
                "{name}: {:?}",
                der.kind
            );
        }
    }
}

#[test]
fn a_minimal_description_uses_the_defaults() {
    let d = ModelDescription::parse(
        r#"<fmiModelDescription fmiVersion="2.0" modelName="M" guid="g">
             <CoSimulation modelIdentifier="M"/>
             <ModelVariables><ScalarVariable name="y" valueReference="7"><Real/></ScalarVariable></ModelVariables>
           </fmiModelDescription>"#,
    )
    .unwrap();
    let y = d.variable("y").unwrap();
    assert_eq!(
        (y.causality, y.variability, y.initial),
        (Causality::Local, Variability::Continuous, None)
    );
    assert!(!d.co_simulation.can_get_and_set_fmu_state);
    assert_eq!(d.co_simulation.max_output_derivative_order, 0);
    assert!(d.unit_definitions.is_none() && d.default_experiment.is_none() && d.outputs.is_empty());
}

/// Parse `xml`, expecting an error whose message holds every part.
fn refused(xml: &str, parts: &[&str]) -> FmuError {
    let e = ModelDescription::parse(xml).expect_err("must be refused");
    common::assert_message(&e, parts);
    e
}

#[test]
fn malformed_xml_is_refused_with_a_position() {
    // Mismatched end tag on line 3.
    let xml = "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"M\" guid=\"g\">\n  <CoSimulation modelIdentifier=\"M\">\n  </Cosimulation>\n</fmiModelDescription>";
    let e = refused(xml, &["modelDescription.xml:3:"]);
    assert!(matches!(e, FmuError::XmlSyntax { line: 3, .. }), "{e}");
    // Not XML at all.
    refused("just text", &["modelDescription.xml:1:"]);
    refused("", &["no root element"]);
    // Another root element.
    refused(
        "<fmiModelDescriptions fmiVersion=\"2.0\"/>",
        &["<fmiModelDescriptions>"],
    );
    // An attribute with a value of the wrong type.
    let bad_number = VALID.replace(r#"stopTime="2.5""#, r#"stopTime="later""#);
    let e = refused(&bad_number, &["modelDescription.xml:"]);
    assert!(matches!(e, FmuError::XmlSyntax { line: 21, .. }), "{e}");
}

/// `--` inside a comment is not well-formed XML (XML 1.0 §2.5); FMPy
/// (lxml) refuses such a description, so fricsim does too, naming where
/// the `--` is, in the prolog and inside the document alike.
#[test]
fn a_double_hyphen_in_a_comment_is_refused_where_it_is() {
    let inside = VALID.replacen(
        "<CoSimulation",
        "<!-- a - comment -- with a double hyphen -->\n  <CoSimulation",
        1,
    );
    let line = inside
        .lines()
        .position(|l| l.contains("double hyphen"))
        .unwrap()
        + 1;
    let e = refused(&inside, &["`--` inside a comment"]);
    assert!(
        matches!(e, FmuError::XmlSyntax { line: l, .. } if l == line),
        "{e}"
    );
    let prolog = VALID.replacen("a comment before", "a comment -- before", 1);
    let e = refused(&prolog, &["`--` inside a comment"]);
    assert!(
        matches!(
            e,
            FmuError::XmlSyntax {
                line: 2,
                column: 16,
                ..
            }
        ),
        "{e}"
    );
    // a comment with single hyphens only is fine
    let fine = VALID.replacen("<CoSimulation", "<!-- a - b -->\n  <CoSimulation", 1);
    ModelDescription::parse(&fine).expect("single hyphens are allowed");
}

#[test]
fn truncated_xml_is_refused() {
    for cut in [10, 100, VALID.len() / 2, VALID.len() - 30] {
        let mut end = cut;
        while !VALID.is_char_boundary(end) {
            end -= 1;
        }
        let e = ModelDescription::parse(&VALID[..end])
            .expect_err("a truncated description must be refused");
        assert!(matches!(e, FmuError::XmlSyntax { .. }), "cut at {cut}: {e}");
    }
}

#[test]
fn other_fmi_versions_are_refused() {
    for version in ["1.0", "2.1", "4.0"] {
        let xml = VALID.replace(r#"fmiVersion="2.0""#, &format!(r#"fmiVersion="{version}""#));
        let e = refused(
            &xml,
            &[&format!("fmiVersion is \"{version}\""), "only FMI 2.0"],
        );
        assert!(matches!(e, FmuError::UnsupportedFmiVersion { .. }));
    }
    // An FMI 2.0 body under "3.0" is read as FMI 3.0, which has no guid.
    let xml = VALID.replace(r#"fmiVersion="2.0""#, r#"fmiVersion="3.0""#);
    refused(&xml, &["no instantiationToken attribute"]);
    refused(
        r#"<fmiModelDescription modelName="M" guid="g"/>"#,
        &["no fmiVersion"],
    );
}

#[test]
fn duplicated_variable_names_are_refused() {
    let xml = VALID.replace(r#"name="label""#, r#"name="x""#);
    let e = refused(
        &xml,
        &["variable \"x\" (index 6)", "already used", "index 1"],
    );
    assert!(matches!(e, FmuError::InvalidModelDescription { .. }));
}

#[test]
fn an_undefined_unit_is_refused() {
    let xml = VALID.replace(r#"<Real unit="N"/>"#, r#"<Real unit="lbf"/>"#);
    refused(
        &xml,
        &[
            "variable \"F\" (index 2)",
            "unit \"lbf\"",
            "UnitDefinitions",
        ],
    );
    // Without UnitDefinitions units are not checked.
    let start = VALID.find("<UnitDefinitions>").unwrap();
    let end = VALID.find("</UnitDefinitions>").unwrap() + "</UnitDefinitions>".len();
    let without =
        format!("{}{}", &VALID[..start], &VALID[end..]).replace(r#"unit="N""#, r#"unit="lbf""#);
    ModelDescription::parse(&without).unwrap();
}

/// The unit of a variable is its own `unit`, else that of its declared
/// type (FMI 2.0 §2.2.7: a `SimpleType`'s `Real`; FMI 3.0 §2.4.7: a
/// `Float64Type`), as Modelica tools write it; a declared type that is
/// not defined is refused, and so is the type's unit where the
/// description's units do not define it.
#[test]
fn a_unit_comes_from_the_declared_type_unless_the_variable_gives_one() {
    let unit_of = |d: &ModelDescription, name: &str| match &d.variable(name).unwrap().kind {
        VariableKind::Real { unit, .. } => unit.clone(),
        other => panic!("{name}: {other:?}"),
    };
    // FMI 2.0
    let types = r#"<SimpleType name="Force"><Real quantity="Force" unit="N"/></SimpleType>
    <SimpleType name="Mode">"#;
    let fmi2 = VALID
        .replace(r#"<SimpleType name="Mode">"#, types)
        .replace(r#"<Real unit="N"/>"#, r#"<Real declaredType="Force"/>"#)
        .replace(
            r#"<Real start="100"/>"#,
            r#"<Real declaredType="Force" unit="m" start="100"/>"#,
        );
    let d = ModelDescription::parse(&fmi2).unwrap();
    assert_eq!(unit_of(&d, "F").as_deref(), Some("N"));
    assert_eq!(unit_of(&d, "k").as_deref(), Some("m"), "its own unit wins");
    refused(
        &fmi2.replace(
            r#"<Real declaredType="Force"/>"#,
            r#"<Real declaredType="Torque"/>"#,
        ),
        &[
            "variable \"F\" (index 2)",
            "declaredType=\"Torque\"",
            "TypeDefinitions",
        ],
    );
    refused(
        &fmi2.replace(r#"quantity="Force" unit="N""#, r#"unit="lbf""#),
        &[
            "variable \"F\" (index 2)",
            "unit \"lbf\"",
            "UnitDefinitions",
        ],
    );
    refused(
        &fmi2.replace(r#"declaredType="Mode""#, r#"declaredType="Gear""#),
        &[
            "variable \"mode\"",
            "declaredType=\"Gear\"",
            "TypeDefinitions",
        ],
    );

    // FMI 3.0
    let fmi3 = VALID_FMI3
        .replace(
            r#"<EnumerationType name="Mode">"#,
            r#"<Float64Type name="Time" quantity="Time" unit="s"/>
    <EnumerationType name="Mode">"#,
        )
        .replace(
            r#"<Float64 name="x1" valueReference="3" causality="output""#,
            r#"<Float64 name="x1" valueReference="3" causality="output" declaredType="Time""#,
        );
    let d = ModelDescription::parse(&fmi3).unwrap();
    assert_eq!(unit_of(&d, "x1").as_deref(), Some("s"));
    assert_eq!(unit_of(&d, "x0"), None);
    refused(
        &fmi3.replace(r#"declaredType="Time""#, r#"declaredType="Angle""#),
        &[
            "variable \"x1\"",
            "declaredType=\"Angle\"",
            "TypeDefinitions",
        ],
    );
    refused(
        &fmi3.replace(r#"quantity="Time" unit="s""#, r#"unit="min""#),
        &["variable \"x1\"", "unit \"min\"", "UnitDefinitions"],
    );
}

#[test]
fn a_missing_co_simulation_element_is_refused() {
    let start = VALID.find("<CoSimulation").unwrap();
    let end = start + VALID[start..].find("/>").unwrap() + 2;
    let xml = format!("{}{}", &VALID[..start], &VALID[end..]);
    let e = refused(&xml, &["not a co-simulation FMU"]);
    assert!(matches!(e, FmuError::NotCoSimulation));
}

#[test]
fn variables_breaking_the_rules_are_refused() {
    let cases: &[(&str, &str, &[&str])] = &[
        (
            r#"name="F" valueReference="1" "#,
            r#"name="F" "#,
            &["variable \"F\" (index 2)", "valueReference"],
        ),
        (
            r#"causality="input" description"#,
            r#"causality="in" description"#,
            &["\"x\" (index 1)", "causality \"in\""],
        ),
        (
            r#"variability="tunable""#,
            r#"variability="sometimes""#,
            &["\"n\" (index 4)", "variability \"sometimes\""],
        ),
        (
            r#"initial="exact""#,
            r#"initial="maybe""#,
            &["\"k\" (index 3)", "initial \"maybe\""],
        ),
        (
            r#"causality="input" variability="discrete""#,
            r#"causality="input" variability="fixed""#,
            &[
                "\"on\" (index 5)",
                "causality \"input\" with variability \"fixed\"",
            ],
        ),
        (
            r#"<Real start="100"/>"#,
            r#"<Real start="100"/><Integer/>"#,
            &["\"k\" (index 3)", "exactly one", "found 2"],
        ),
        (r#"<Real unit="N"/>"#, "", &["\"F\" (index 2)", "found 0"]),
        (
            r#"<Enumeration declaredType="Mode" start="2"/>"#,
            r#"<Enumeration start="2"/>"#,
            &["\"mode\"", "declaredType"],
        ),
        (
            r#"name="label""#,
            r#"name="""#,
            &["variable at index 6", "name"],
        ),
        (
            r#"<Unknown index="2" dependencies"#,
            r#"<Unknown index="3" dependencies"#,
            &["Outputs", "\"k\"", "expected \"output\""],
        ),
        (
            r#"<Unknown index="2" dependencies"#,
            r#"<Unknown index="99" dependencies"#,
            &["index 99", "1..=8"],
        ),
        (
            r#"dependencies="1 5""#,
            r#"dependencies="1 x""#,
            &["dependency \"x\""],
        ),
        (
            r#"<Real derivative="1"/>"#,
            r#"<Real derivative="42"/>"#,
            &["\"der(x)\"", "derivative=\"42\""],
        ),
        (
            r#"modelIdentifier="Spring_1""#,
            r#"modelIdentifier="../../evil""#,
            &["modelIdentifier \"../../evil\"", "C identifier"],
        ),
    ];
    for (from, to, parts) in cases {
        assert!(VALID.contains(from), "test case does not apply: {from}");
        let e = refused(&VALID.replacen(from, to, 1), parts);
        assert!(
            matches!(e, FmuError::InvalidModelDescription { .. }),
            "{from} -> {to}: {e}"
        );
    }
}

#[test]
fn invalid_utf8_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("modelDescription.xml");
    let mut bytes = VALID.as_bytes().to_vec();
    let at = VALID.find("A test model").unwrap();
    bytes[at] = 0xFF;
    std::fs::write(&path, &bytes).unwrap();
    let e = ModelDescription::from_file(&path).unwrap_err();
    assert!(matches!(e, FmuError::XmlSyntax { line: 4, .. }), "{e}");
    assert!(e.to_string().contains("UTF-8"), "{e}");
}

/// What the single-pass reader refuses beyond well-formedness: a missing
/// required attribute, an attribute of the wrong type, an element that
/// may appear once appearing twice, a second root, and a file cut short
/// (named as truncated, with the element left open).
#[test]
fn structural_errors_are_refused_with_the_element() {
    let cases: &[(&str, &str, &[&str])] = &[
        (
            r#" guid="{1234-abcd}""#,
            "",
            &["<fmiModelDescription>", "no guid"],
        ),
        (
            r#" modelName="Spring &amp; damper""#,
            "",
            &["<fmiModelDescription>", "no modelName"],
        ),
        (
            r#"<CoSimulation modelIdentifier="Spring_1""#,
            "<CoSimulation",
            &["<CoSimulation>", "no modelIdentifier"],
        ),
        (
            r#"canInterpolateInputs="1""#,
            r#"canInterpolateInputs="yes""#,
            &["canInterpolateInputs=\"yes\"", "not a boolean"],
        ),
        (
            r#"maxOutputDerivativeOrder="2""#,
            r#"maxOutputDerivativeOrder="-2""#,
            &[
                "maxOutputDerivativeOrder=\"-2\"",
                "not a valid non-negative integer",
            ],
        ),
        (
            r#"<Boolean start="true"/>"#,
            r#"<Boolean start="on"/>"#,
            &["<Boolean> start=\"on\""],
        ),
        (
            r#"<Real start="0.5""#,
            r#"<Real start="half""#,
            &["<Real> start=\"half\"", "not a valid number"],
        ),
        (
            r#"<Unknown index="2" "#,
            r#"<Unknown "#,
            &["<Unknown>", "no index"],
        ),
        (
            r#"<Category name="logCalls"/>"#,
            r#"<Category/>"#,
            &["<Category>", "no name"],
        ),
        (
            "<DefaultExperiment ",
            "<DefaultExperiment/><DefaultExperiment ",
            &["a second <DefaultExperiment>"],
        ),
        (
            "</fmiModelDescription>",
            "</fmiModelDescription><fmiModelDescription/>",
            &["second root element"],
        ),
        (
            "</fmiModelDescription>",
            "</fmiModelDescription>\n  trailing words\n",
            &["text outside the root element"],
        ),
        (
            r#"<Real unit="N"/>"#,
            r#"<Real unit="N" unit="m"/>"#,
            &["<Real>", "duplicated attribute"],
        ),
    ];
    for (from, to, parts) in cases {
        assert!(VALID.contains(from), "test case does not apply: {from}");
        let e = refused(&VALID.replacen(from, to, 1), parts);
        assert!(
            matches!(e, FmuError::XmlSyntax { .. }),
            "{from} -> {to}: {e}"
        );
    }
    // A root element written as an empty element ends the document too.
    refused(
        r#"<fmiModelDescription fmiVersion="2.0" modelName="M" guid="g"/>
<fmiModelDescription fmiVersion="2.0" modelName="N" guid="h"/>"#,
        &["modelDescription.xml:2:", "second root element"],
    );
    refused("just text", &["text outside the root element"]);
    refused(
        &VALID.replace("</fmiModelDescription>", "</fmiModelDescription>&amp;"),
        &["text outside the root element"],
    );
    refused(
        &VALID.replace(
            "</fmiModelDescription>",
            "</fmiModelDescription><![CDATA[x]]>",
        ),
        &["text outside the root element"],
    );
    // Cut inside <ModelVariables>, between elements and inside a tag: the
    // message names the element left open.
    let end = VALID.find("</ModelVariables>").unwrap();
    let opened = VALID[..VALID.find("<ModelVariables>").unwrap()]
        .lines()
        .count();
    refused(
        &VALID[..end],
        &["truncated", "<ModelVariables>", &format!("line {opened}")],
    );
    let end = VALID.find("<ScalarVariable name=\"k\"").unwrap() + 10;
    refused(&VALID[..end], &["truncated", "<ModelVariables>"]);
}

/// An FMI 3.0 description in the style of the Modelica Reference-FMUs
/// (a Van der Pol oscillator with a counter and a mode), written for the
/// test against FMI 3.0.1 §2.4.
const VALID_FMI3: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="VanDerPol" instantiationToken="{8c4e810f-3da3-4a00-8276-176fa3c9f000}"
    description="Van der Pol oscillator" generationTool="hand">
  <ModelExchange modelIdentifier="VanDerPol"/>
  <CoSimulation modelIdentifier="VanDerPol" canHandleVariableCommunicationStepSize="true"
      canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="true"
      hasEventMode="true" providesIntermediateUpdate="true"/>
  <UnitDefinitions><Unit name="s"><BaseUnit s="1"/></Unit></UnitDefinitions>
  <TypeDefinitions>
    <EnumerationType name="Mode"><Item name="a" value="1"/><Item name="b" value="2"/></EnumerationType>
  </TypeDefinitions>
  <LogCategories><Category name="logEvents" description="Log events"/></LogCategories>
  <DefaultExperiment startTime="0" stopTime="20" stepSize="1e-2"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous" unit="s"/>
    <Float64 name="x0" valueReference="1" causality="output" initial="exact" start="2"/>
    <Float64 name="der(x0)" valueReference="2" causality="local" derivative="1"/>
    <Float64 name="x1" valueReference="3" causality="output" initial="exact" start="0"/>
    <Float64 name="der(x1)" valueReference="4" causality="local" derivative="3"/>
    <Float64 name="mu" valueReference="5" causality="parameter" variability="fixed" initial="exact" start="1" min="0"/>
    <Int32 name="counter" valueReference="10" causality="output" initial="exact" start="-3"/>
    <Boolean name="on" valueReference="11" causality="input" start="true"/>
    <String name="label" valueReference="12" causality="parameter" variability="fixed">
      <Start value="van der Pol"/>
    </String>
    <Enumeration name="mode" valueReference="13" causality="parameter" variability="tunable" declaredType="Mode" start="2"/>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="1"/>
    <Output valueReference="3"/>
    <Output valueReference="10" dependencies="11 5"/>
    <ContinuousStateDerivative valueReference="2"/>
    <ContinuousStateDerivative valueReference="4" dependencies="1 3 5"/>
    <InitialUnknown valueReference="2"/>
    <EventIndicator valueReference="1"/>
  </ModelStructure>
</fmiModelDescription>
"#;

#[test]
fn an_fmi3_description_is_read_into_the_same_types() {
    let d = ModelDescription::parse(VALID_FMI3).unwrap();
    assert_eq!(d.fmi_version, "3.0");
    assert_eq!(d.model_name, "VanDerPol");
    // instantiationToken is FMI 2.0's guid
    assert_eq!(d.guid, "{8c4e810f-3da3-4a00-8276-176fa3c9f000}");
    assert_eq!(d.model_exchange.as_deref(), Some("VanDerPol"));
    let cs = &d.co_simulation;
    assert_eq!(cs.model_identifier, "VanDerPol");
    assert!(cs.can_get_and_set_fmu_state && cs.can_serialize_fmu_state);
    assert!(cs.provides_directional_derivative);
    assert!(cs.can_handle_variable_communication_step_size);
    assert!(!cs.can_interpolate_inputs && !cs.can_run_asynchronuously);
    assert_eq!(d.number_of_event_indicators, 1);
    assert_eq!(d.unit_definitions.as_deref(), Some(&["s".to_string()][..]));
    assert_eq!(d.log_categories[0].name, "logEvents");
    let e = d.default_experiment.as_ref().unwrap();
    assert_eq!((e.stop_time, e.step_size), (Some(20.0), Some(1e-2)));
    assert_eq!(d.variables.len(), 10);

    let x0 = d.variable("x0").unwrap();
    assert_eq!((x0.index, x0.value_reference), (2, 1));
    assert_eq!(x0.causality, Causality::Output);
    assert_eq!(x0.variability, Variability::Continuous);
    assert_eq!(x0.initial, Some(Initial::Exact));
    assert!(matches!(x0.kind, VariableKind::Real { start: Some(s), .. } if s == 2.0));
    // derivative names a value reference in FMI 3.0: 1 is x0, index 2
    let der = d.variable("der(x1)").unwrap();
    assert!(matches!(
        der.kind,
        VariableKind::Real {
            derivative: Some(4),
            ..
        }
    ));
    let mu = d.variable("mu").unwrap();
    assert!(matches!(mu.kind, VariableKind::Real { min: Some(m), .. } if m == 0.0));
    // a non-float defaults to discrete
    let counter = d.variable("counter").unwrap();
    assert_eq!(counter.variability, Variability::Discrete);
    assert!(matches!(
        counter.kind,
        VariableKind::Integer {
            start: Some(-3),
            ..
        }
    ));
    assert_eq!(counter.kind.type_name_in("3.0"), "Int32");
    assert_eq!(x0.kind.type_name_in("3.0"), "Float64");
    assert_eq!(x0.kind.type_name_in("2.0"), "Real");
    assert!(matches!(
        d.variable("on").unwrap().kind,
        VariableKind::Boolean { start: Some(true) }
    ));
    assert!(matches!(&d.variable("label").unwrap().kind,
        VariableKind::String { start: Some(s) } if s == "van der Pol"));
    assert!(matches!(&d.variable("mode").unwrap().kind,
        VariableKind::Enumeration { declared_type, start: Some(2), .. } if declared_type == "Mode"));

    // outputs by index, their dependencies from value references
    assert_eq!(
        d.outputs,
        vec![
            Unknown {
                index: 2,
                dependencies: None
            },
            Unknown {
                index: 4,
                dependencies: None
            },
            Unknown {
                index: 7,
                dependencies: Some(vec![8, 6])
            },
        ]
    );
}

#[test]
fn what_fmi3_has_and_fricsim_does_not_read_yet_is_refused_by_name() {
    let with = |old: &str, new: &str| {
        assert!(VALID_FMI3.contains(old), "{old}");
        VALID_FMI3.replace(old, new)
    };
    let mu = r#"<Float64 name="mu" valueReference="5" causality="parameter" variability="fixed" initial="exact" start="1" min="0"/>"#;
    let array = |start: &str, dimensions: &str| {
        with(
            mu,
            &format!(
                r#"<Float64 name="mu" valueReference="5" causality="parameter" variability="fixed" start="{start}">{dimensions}</Float64>"#
            ),
        )
    };
    // an array sized by a structural parameter, an array of String
    refused(
        &array("1 2", r#"<Dimension valueReference="10"/>"#),
        &[
            "variable \"mu\" (index 6)",
            "size is the structural parameter with valueReference 10",
            "not read yet",
        ],
    );
    refused(
        &with(
            r#"<Start value="van der Pol"/>"#,
            r#"<Dimension start="2"/><Start value="a"/><Start value="b"/>"#,
        ),
        &["variable \"label\"", "String array", "not read yet"],
    );
    // what no array can be
    refused(
        &array("1 2 3", r#"<Dimension start="2"/>"#),
        &[
            "variable \"mu\"",
            "start has 3 values for the 2 elements of the array (dimensions 2)",
        ],
    );
    refused(
        &array("1 2", r#"<Dimension start="2"/><Dimension/>"#),
        &["<Dimension> has either a start or a valueReference attribute"],
    );
    refused(
        &array("1", r#"<Dimension start="1000"/><Dimension start="1000"/>"#),
        &[
            "1000000 elements (dimensions 1000 × 1000)",
            "at most 100000 array elements",
        ],
    );
    // the types fricsim does not read
    for t in ["Binary", "Clock"] {
        refused(
            &with(
                mu,
                &format!(
                    r#"<{t} name="mu" valueReference="5" causality="parameter" variability="fixed"/>"#
                ),
            ),
            &[
                "variable \"mu\"",
                &format!("<{t}> is not read yet"),
                "Float32, Float64, Int8, UInt8",
            ],
        );
    }
    refused(
        &with(mu, r#"<Float65 name="mu" valueReference="5"/>"#),
        &["<Float65> is not a variable type of FMI 3.0"],
    );
    // a value outside its type, or one an f64 cannot hold exactly
    for (t, start, parts) in [
        ("UInt8", "256", "start=\"256\" is not a value of type UInt8 (whole numbers from 0 to 255)"),
        ("Int8", "1.5", "start=\"1.5\" is not a value of type Int8 (whole numbers from -128 to 127)"),
        (
            "Int64",
            "9007199254740993",
            "start=\"9007199254740993\": fricsim holds Int64 values as 64-bit floats, which cannot hold this one exactly",
        ),
    ] {
        refused(
            &with(
                mu,
                &format!(
                    r#"<{t} name="mu" valueReference="5" causality="parameter" variability="fixed" start="{start}"/>"#
                ),
            ),
            &["variable \"mu\"", parts],
        );
    }
    refused(
        &with(
            mu,
            r#"<UInt32 name="n" valueReference="5" causality="structuralParameter" variability="fixed" start="2"/>"#,
        ),
        &["variable \"n\"", "structural parameters"],
    );
    refused(
        &with(
            mu,
            r#"<Int32 name="n" valueReference="5" causality="structuralParameter" variability="fixed" start="2"/>"#,
        ),
        &["variable \"n\"", "structural parameters"],
    );
    // the rules of the standard
    refused(
        &with(
            r#"<Int32 name="counter" valueReference="10" causality="output""#,
            r#"<Int32 name="counter" valueReference="10" variability="continuous" causality="output""#,
        ),
        &["variable \"counter\"", "cannot be continuous"],
    );
    refused(
        &with(r#"valueReference="13""#, r#"valueReference="12""#),
        &["valueReference 12 is already the variable at index 9"],
    );
    refused(
        &with(r#"derivative="3""#, r#"derivative="99""#),
        &[
            "variable \"der(x1)\"",
            "derivative=\"99\" is not the value reference of a variable",
        ],
    );
    refused(
        &with(
            r#"<Output valueReference="3"/>"#,
            r#"<Output valueReference="98"/>"#,
        ),
        &[
            "ModelStructure/Output[2] (valueReference 98)",
            "not the value reference of a variable",
        ],
    );
    refused(
        &with(
            r#"<Output valueReference="3"/>"#,
            r#"<Output valueReference="5"/>"#,
        ),
        &["variable \"mu\" has causality \"parameter\", expected \"output\""],
    );
    refused(
        &with(r#"dependencies="11 5""#, r#"dependencies="11 x""#),
        &["dependency \"x\" is not a value reference"],
    );
    refused(
        &with(r#"unit="s"/>"#, r#"unit="ms"/>"#),
        &["unit \"ms\" is not defined in <UnitDefinitions>"],
    );
    refused(
        &with(
            r#"canSerializeFMUState="true""#,
            r#"canGetAndSetFMUState="false" canSerializeFMUState="true""#,
        )
        .replacen(r#"canGetAndSetFMUState="true""#, "", 1),
        &["canSerializeFMUState=\"true\" requires canGetAndSetFMUState=\"true\""],
    );
    refused(
        &with(r#"start="-3""#, r#"start="3000000000""#),
        &["start=\"3000000000\" is not a value of type Int32"],
    );
    refused(
        &with(
            r#"instantiationToken="{8c4e810f-3da3-4a00-8276-176fa3c9f000}""#,
            "",
        ),
        &["no instantiationToken attribute"],
    );
    let e = ModelDescription::parse(&with(
        r#"<CoSimulation modelIdentifier="VanDerPol""#,
        r#"<ScheduledExecution modelIdentifier="VanDerPol""#,
    ))
    .unwrap_err();
    assert!(matches!(e, FmuError::NotCoSimulation), "{e}");
}

/// Cut anywhere, or with any one byte changed, the FMI 3.0 description is
/// read or refused with a message, never a panic.
#[test]
fn an_fmi3_description_cut_or_changed_anywhere_never_panics() {
    let bytes = VALID_FMI3.as_bytes();
    // cut before the root's end tag is complete
    let complete = VALID_FMI3.find("</fmiModelDescription>").unwrap() + 21;
    for cut in 0..complete {
        if let Ok(text) = std::str::from_utf8(&bytes[..cut]) {
            let e = ModelDescription::parse(text).expect_err("a cut description is refused");
            assert!(!e.to_string().is_empty());
        }
    }
    for (i, replacement) in (0..bytes.len())
        .step_by(7)
        .zip([b'"', b'<', b'0', b' ', b'x'].iter().cycle())
    {
        let mut changed = bytes.to_vec();
        changed[i] = *replacement;
        if let Ok(text) = std::str::from_utf8(&changed) {
            // read or refused: both are fine, a panic is not
            let _ = ModelDescription::parse(text).map_err(|e| e.to_string());
        }
    }
}

/// FMI 3.0 arrays of fixed size, and the types without an FMI 2.0
/// counterpart: the value reference 4000000000 is the FMU's largest, so
/// the elements are numbered above it.
const ARRAYS_FMI3: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Arrays" instantiationToken="{a}">
  <CoSimulation modelIdentifier="Arrays"/>
  <ModelVariables>
    <Float64 name="x" valueReference="3" causality="output" initial="exact" start="1 2"><Dimension start="2"/></Float64>
    <Float64 name="der(x)" valueReference="7" causality="local" derivative="3"><Dimension start="2"/></Float64>
    <Float64 name="u" valueReference="1" causality="input" start="0"/>
    <Int16 name="M" valueReference="4000000000" causality="parameter" variability="fixed" start="1 2 3&#10;4 5 6" min="-5">
      <Dimension start="2"/><Dimension start="3"/>
    </Int16>
    <Boolean name="on" valueReference="9" causality="parameter" variability="fixed" start="true false 1"><Dimension start="3"/></Boolean>
    <Float32 name="f" valueReference="10" causality="parameter" variability="fixed" start="0.5"/>
    <UInt64 name="big" valueReference="11" causality="parameter" variability="fixed" start="9007199254740992"/>
    <UInt8 name="bytes" valueReference="12" causality="parameter" variability="tunable" start="255 0"><Dimension start="2"/></UInt8>
    <Float64 name="none" valueReference="13" causality="parameter" variability="fixed"><Dimension start="0"/></Float64>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="3" dependencies="1 4000000000"/>
    <ContinuousStateDerivative valueReference="7"/>
  </ModelStructure>
</fmiModelDescription>
"#;

#[test]
fn fmi3_arrays_are_read_per_element_and_every_type_as_the_kind_that_holds_it() {
    use fricsim::fmu::model_description::Fmi3Type;
    let d = ModelDescription::parse(ARRAYS_FMI3).unwrap();
    let names: Vec<&str> = d.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "x[1]",
            "x[2]",
            // the elements of der(x) as FMI 2.0 names them
            "der(x[1])",
            "der(x[2])",
            "u",
            // row-major: the last index runs fastest
            "M[1,1]",
            "M[1,2]",
            "M[1,3]",
            "M[2,1]",
            "M[2,2]",
            "M[2,3]",
            "on[1]",
            "on[2]",
            "on[3]",
            "f",
            "big",
            "bytes[1]",
            "bytes[2]",
        ]
    );
    for (i, v) in d.variables.iter().enumerate() {
        assert_eq!(v.index, i + 1, "{}", v.name);
    }
    // each element its own start value, the array's attributes
    let m21 = d.variable("M[2,1]").unwrap();
    assert_eq!(
        m21.kind,
        VariableKind::Integer {
            start: Some(4),
            min: Some(-5),
            max: None
        }
    );
    assert_eq!(m21.causality, Causality::Parameter);
    assert_eq!(m21.type_name(), "Int16");
    let on: Vec<_> = (1..=3)
        .map(|i| d.variable(&format!("on[{i}]")).unwrap().kind.clone())
        .collect();
    assert_eq!(
        on,
        [true, false, true].map(|b| VariableKind::Boolean { start: Some(b) })
    );
    // the other types as the kind that holds their values
    let f = d.variable("f").unwrap();
    assert!(matches!(f.kind, VariableKind::Real { start: Some(s), .. } if s == 0.5));
    assert_eq!(
        (f.fmi3_type, f.type_name(), f.element.is_none()),
        (Some(Fmi3Type::Float32), "Float32", true)
    );
    let big = d.variable("big").unwrap();
    assert!(
        matches!(big.kind, VariableKind::Real { start: Some(s), .. } if s == 9007199254740992.0)
    );
    assert_eq!(big.type_name(), "UInt64");
    assert!(matches!(
        d.variable("bytes[1]").unwrap().kind,
        VariableKind::Integer {
            start: Some(255),
            ..
        }
    ));

    // the elements' value references are above the FMU's largest, in
    // order; the FMU's own scalars keep theirs
    let vrs: Vec<u32> = d.variables.iter().map(|v| v.value_reference).collect();
    assert_eq!(&vrs[..4], [4000000001, 4000000002, 4000000003, 4000000004]);
    assert_eq!(vrs[4], 1);
    assert_eq!(vrs[5..14], (4000000005..4000000014).collect::<Vec<_>>()[..]);
    assert_eq!(&vrs[14..], [10, 11, 4000000014, 4000000015]);
    assert_eq!(
        d.variable_by_value_reference(4000000009).unwrap().name,
        "M[2,2]"
    );

    // the arrays, the empty one too
    let shapes: Vec<(&str, u32, Vec<usize>, u32, usize)> = d
        .arrays
        .iter()
        .map(|a| {
            (
                a.name.as_str(),
                a.value_reference,
                a.dimensions.clone(),
                a.first_element,
                a.first_index,
            )
        })
        .collect();
    assert_eq!(
        shapes,
        [
            ("x", 3, vec![2], 4000000001, 1),
            ("der(x)", 7, vec![2], 4000000003, 3),
            ("M", 4000000000, vec![2, 3], 4000000005, 6),
            ("on", 9, vec![3], 4000000011, 12),
            ("bytes", 12, vec![2], 4000000014, 17),
            ("none", 13, vec![0], 4000000016, 19),
        ]
    );
    let m = &d.arrays[2];
    assert_eq!((m.len(), m.value_type), (6, Fmi3Type::Int16));
    assert_eq!(m.element_position(4000000010), Some(5));
    assert_eq!(m.element_position(4000000011), None);
    assert_eq!(
        d.variable("M[1,3]")
            .unwrap()
            .element
            .as_ref()
            .map(|e| (e.array, e.position)),
        Some((2, 2))
    );
    // the array's name is no variable; the message can say what to name
    assert!(d.variable("M").is_err());
    assert_eq!(
        d.array_hint("M"),
        "; `M` is an FMI 3.0 array of 6 elements, which are variables one by one: `M[1,1]` … `M[2,3]`"
    );
    assert_eq!(d.array_hint("u"), "");

    // der(x[i]) is the derivative of x[i]
    for i in 1..=2 {
        assert!(matches!(
            d.variable(&format!("der(x[{i}])")).unwrap().kind,
            VariableKind::Real { derivative: Some(k), .. } if k == i
        ));
    }
    // each element of an output is one, depending on every element of
    // the arrays its array depends on
    let m_indices: Vec<usize> = (6..=11).collect();
    let dependencies: Vec<usize> = std::iter::once(5).chain(m_indices).collect();
    assert_eq!(
        d.outputs,
        [1, 2].map(|index| Unknown {
            index,
            dependencies: Some(dependencies.clone())
        })
    );

    // a derivative must be what its state is, an array or a scalar
    refused(
        &ARRAYS_FMI3.replace(
            r#"<Float64 name="der(x)" valueReference="7" causality="local" derivative="3"><Dimension start="2"/></Float64>"#,
            r#"<Float64 name="der(x)" valueReference="7" causality="local" derivative="3"/>"#,
        ),
        &[
            "variable \"der(x)\" (index 2)",
            "derivative=\"3\" names an array of 2 elements, but this variable is a scalar",
        ],
    );
}

/// The element value references start at 2³¹ when the FMU's own are
/// below it, and where the FMU's reach the top, nothing is left for them.
#[test]
fn fmi3_element_value_references_never_meet_the_fmus() {
    let low = ARRAYS_FMI3.replace("4000000000", "40");
    let d = ModelDescription::parse(&low).unwrap();
    assert_eq!(d.arrays[0].first_element, 1 << 31);
    assert_eq!(d.variable("x[1]").unwrap().value_reference, 1 << 31);
    assert_eq!(d.variable("M[1,1]").unwrap().value_reference, (1 << 31) + 4);
    refused(
        &ARRAYS_FMI3.replace("4000000000", "4294967290"),
        &[
            "the FMU's value references reach 4294967290",
            "no room for the value references fricsim gives the 15 array elements",
        ],
    );
}

/// An FMI 3.0 description at the limits is read or refused, never runs
/// the reader out of memory or into an overflow: a size 0 next to sizes
/// whose product passes `usize` is an empty array; the element limit
/// counts all arrays together; outputs whose dependencies would be more
/// than the reader keeps (an output of 3000 elements depending on an
/// input of 3000) keep none, which says they may depend on everything.
#[test]
fn fmi3_arrays_at_the_limits_are_read_or_refused_without_running_out() {
    let description = |variables: &str, structure: &str| {
        format!(
            r#"<fmiModelDescription fmiVersion="3.0" modelName="M" instantiationToken="{{t}}">
  <CoSimulation modelIdentifier="M"/>
  <ModelVariables>{variables}</ModelVariables>
  <ModelStructure>{structure}</ModelStructure>
</fmiModelDescription>"#
        )
    };
    let empty = description(
        r#"<Float64 name="e" valueReference="1" causality="parameter" variability="fixed">
             <Dimension start="100000"/><Dimension start="100000"/><Dimension start="100000"/>
             <Dimension start="100000"/><Dimension start="0"/></Float64>
           <Float64 name="after" valueReference="2" causality="parameter" variability="fixed" start="1"/>"#,
        "",
    );
    let d = ModelDescription::parse(&empty).unwrap();
    assert_eq!((d.arrays[0].len(), d.variables.len()), (0, 1));
    assert_eq!(d.variables[0].name, "after");

    let two = description(
        r#"<Float64 name="a" valueReference="1" causality="parameter" variability="fixed"><Dimension start="60000"/></Float64>
           <Float64 name="b" valueReference="2" causality="parameter" variability="fixed"><Dimension start="60000"/></Float64>"#,
        "",
    );
    refused(
        &two,
        &[
            "variable \"b\" (index 2)",
            "the array has 60000 elements",
            "at most 100000 array elements per FMU",
        ],
    );

    let wide = description(
        r#"<Float64 name="u" valueReference="1" causality="input"><Dimension start="3000"/></Float64>
           <Float64 name="y" valueReference="2" causality="output"><Dimension start="3000"/></Float64>
           <Float64 name="s" valueReference="3" causality="output"/>"#,
        r#"<Output valueReference="2" dependencies="1"/><Output valueReference="3" dependencies="1"/>"#,
    );
    let d = ModelDescription::parse(&wide).unwrap();
    assert_eq!(d.outputs.len(), 3001);
    assert!(d.outputs[..3000].iter().all(|o| o.dependencies.is_none()));
    // what is within the limit is kept
    assert_eq!(
        d.outputs[3000].dependencies.as_deref(),
        Some(&(1..=3000).collect::<Vec<usize>>()[..])
    );
}
