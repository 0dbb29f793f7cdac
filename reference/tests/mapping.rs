//! Systems the reference cannot map are refused with a message naming the
//! component or connection and the reason.

use fricsim_reference::{ComponentSpec, MapError, ReferenceModel, SystemSpec, Value};

fn rig() -> ComponentSpec {
    ComponentSpec::new("rig", "Rig1D")
}

fn coupled(law: ComponentSpec) -> SystemSpec {
    SystemSpec {
        components: vec![rig(), law],
        connections: Vec::new(),
    }
    .connect("rig.v", "friction.v")
    .connect("friction.F", "rig.F")
}

fn refused(spec: &SystemSpec) -> String {
    match ReferenceModel::from_spec(spec) {
        Err(MapError(m)) => m,
        Ok(m) => panic!("mapped: {}", m.description()),
    }
}

fn assert_mentions(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "`{p}` not in: {message}");
    }
}

#[test]
fn supported_couplings_map() {
    let m = ReferenceModel::from_spec(&coupled(ComponentSpec::new("friction", "LuGre"))).unwrap();
    assert!(
        m.description().contains("LuGre `friction`"),
        "{}",
        m.description()
    );
    let m = ReferenceModel::from_spec(&coupled(ComponentSpec::new("friction", "Dahl"))).unwrap();
    assert!(m.description().contains("Dahl"));
    // LuGre's position input from the rig, body velocity, GUID given.
    let mut lugre = ComponentSpec::new("friction", "LuGre").boolean("position_dependent", true);
    lugre.guid = Some("{cc09ec7b-20f5-4798-9c84-4aa863242977}".into());
    let spec = SystemSpec {
        components: vec![rig(), lugre],
        connections: Vec::new(),
    }
    .connect("rig.v_body", "friction.v")
    .connect("rig.x_rel", "friction.x")
    .connect("friction.F", "rig.F");
    assert!(ReferenceModel::from_spec(&spec).is_ok());
}

#[test]
fn unsupported_models_and_counts_are_named() {
    let m = refused(&coupled(ComponentSpec::new("friction", "ResetIntegrator")));
    assert_mentions(
        &m,
        &["`friction`", "ResetIntegrator", "no monolithic reference"],
    );
    let mut three = coupled(ComponentSpec::new("friction", "LuGre"));
    three.components.push(ComponentSpec::new("other", "Dahl"));
    assert_mentions(&refused(&three), &["3", "rig, friction, other"]);
    let two_laws = SystemSpec {
        components: vec![
            ComponentSpec::new("a", "LuGre"),
            ComponentSpec::new("b", "Dahl"),
        ],
        connections: Vec::new(),
    };
    assert_mentions(
        &refused(&two_laws),
        &["one rig (Rig1D or Rig2D)", "LuGre", "Dahl"],
    );
    // A known rig with a law it has no reference with.
    let mismatched = SystemSpec {
        components: vec![
            ComponentSpec::new("rig", "Rig2D"),
            ComponentSpec::new("friction", "LuGre"),
        ],
        connections: Vec::new(),
    };
    assert_mentions(
        &refused(&mismatched),
        &[
            "`friction` (LuGre) with Rig2D `rig`",
            "Rig2D with Bristle2D",
        ],
    );
    // A foreign FMU that calls itself LuGre.
    let mut foreign = ComponentSpec::new("friction", "LuGre");
    foreign.guid = Some("{00000000-0000-0000-0000-000000000000}".into());
    assert_mentions(
        &refused(&coupled(foreign)),
        &["`friction`", "GUID {00000000", "not the GUID"],
    );
}

#[test]
fn parameters_are_checked_as_the_fmu_checks_them() {
    let bad = ComponentSpec::new("friction", "LuGre").real("sigma0", -1.0);
    assert_mentions(&refused(&coupled(bad)), &["`friction`", "sigma0 = -1"]);
    let bad = ComponentSpec::new("friction", "LuGre").real("Fs", 0.5);
    assert_mentions(&refused(&coupled(bad)), &["`friction`", "Fs = 0.5", "Fc"]);
    let unknown = ComponentSpec::new("friction", "LuGre").real("sigma9", 1.0);
    assert_mentions(
        &refused(&coupled(unknown)),
        &["`friction`", "no variable `sigma9`"],
    );
    let output = ComponentSpec::new("friction", "LuGre").real("F", 1.0);
    assert_mentions(
        &refused(&coupled(output)),
        &["`F` is not a parameter or input"],
    );
    let mut typed = ComponentSpec::new("friction", "LuGre");
    typed
        .parameters
        .push(("position_dependent".into(), Value::Real(1.0)));
    assert_mentions(
        &refused(&coupled(typed)),
        &["`position_dependent`", "Boolean", "Real 1"],
    );
    let mut spec = coupled(ComponentSpec::new("friction", "LuGre"));
    spec.components[0] = rig().real("k", f64::NAN);
    assert_mentions(&refused(&spec), &["`rig`", "k = NaN"]);
}

#[test]
fn couplings_the_reference_does_not_know_are_refused() {
    let wrong = SystemSpec {
        components: vec![rig(), ComponentSpec::new("friction", "LuGre")],
        connections: Vec::new(),
    }
    .connect("rig.x", "friction.v")
    .connect("friction.F", "rig.F");
    assert_mentions(
        &refused(&wrong),
        &["rig.x → friction.v", "rig.v (or v_body) → friction.v"],
    );
    let missing = SystemSpec {
        components: vec![rig(), ComponentSpec::new("friction", "Dahl")],
        connections: Vec::new(),
    }
    .connect("friction.F", "rig.F");
    assert_mentions(
        &refused(&missing),
        &["not coupled", "rig.v (or v_body) → friction.v"],
    );
    let twice =
        coupled(ComponentSpec::new("friction", "LuGre")).connect("rig.v_body", "friction.v");
    assert_mentions(&refused(&twice), &["friction.v is connected twice"]);
    let dahl_x = coupled(ComponentSpec::new("friction", "Dahl")).connect("rig.x", "friction.x");
    assert_mentions(&refused(&dahl_x), &["rig.x → friction.x"]);
    // Modes: LuGre on the quasi-static rig, Bristle on a rig with mass.
    let mut qs = coupled(ComponentSpec::new("friction", "LuGre"));
    qs.components[0] = rig().real("m", 0.0);
    assert_mentions(&refused(&qs), &["`rig`", "m = 0", "needs m > 0"]);
    let bristle = SystemSpec {
        components: vec![rig(), ComponentSpec::new("friction", "Bristle")],
        connections: Vec::new(),
    }
    .connect("rig.x", "friction.x")
    .connect("friction.F", "rig.F");
    assert_mentions(
        &refused(&bristle),
        &["`friction` (Bristle)", "m = 0, c = 0", "m = 1"],
    );
}
