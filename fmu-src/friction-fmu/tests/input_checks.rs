//! Inputs a model checks (LuGre's normal force must be >= 0) are refused
//! with the model's reason when set alone or in a list, in initialization
//! and step mode, and nothing is set; the inputs it does not check take
//! any finite value (the layer skips the model's check for them).

use fmi_export::instance::Instance;
use fmi_export::logger::Logger;
use fmi_export::VarType;

fn lugre() -> Instance {
    let factory = friction_fmu::REGISTRY
        .iter()
        .find(|f| f.info.model_name == "LuGre")
        .expect("LuGre");
    let logger = Logger::new(
        fmi_export::logger::Callback::Fmi2(None),
        std::ptr::null_mut(),
        "probe",
        false,
    );
    Instance::new(factory.info, (factory.create)(), "probe", logger)
}

fn vr(fmu: &Instance, name: &str) -> u32 {
    fmu.info.by_name(name).expect(name).vr
}

#[test]
fn a_negative_normal_force_is_refused_alone_and_in_a_list() {
    let mut fmu = lugre();
    let (v, x, fn_) = (vr(&fmu, "v"), vr(&fmu, "x"), vr(&fmu, "Fn"));
    fmu.setup_experiment(0.0, None).unwrap();
    fmu.enter_initialization_mode().unwrap();
    for step_mode in [false, true] {
        if step_mode {
            fmu.exit_initialization_mode().unwrap();
        }
        let err = fmu.set(VarType::Real, &[fn_], &[-1.0]).unwrap_err();
        assert!(err.contains("normal force must be >= 0"), "{err}");
        let err = fmu
            .set(VarType::Real, &[v, fn_, x], &[0.5, -2.0, 0.1])
            .unwrap_err();
        assert!(err.contains("Fn"), "{err}");
        // all or nothing: v and x were not set either
        assert_eq!(fmu.values().real(fn_), 1.0);
        assert_eq!(fmu.values().real(v), 0.0);
        assert_eq!(fmu.values().real(x), 0.0);
        // unchecked inputs take any finite value, negative ones too
        fmu.set(VarType::Real, &[v], &[-0.5]).unwrap();
        fmu.set(VarType::Real, &[v, x, fn_], &[-0.25, -3.0, 0.0])
            .unwrap();
        assert_eq!(fmu.values().real(v), -0.25);
        fmu.set(VarType::Real, &[v, x, fn_], &[0.0, 0.0, 1.0])
            .unwrap();
    }
}

/// A parameter is checked against its declared bounds when it is set,
/// whether or not the options in force use it: `Fc_neg` and the
/// `scale_neg` table are read only when `direction_dependent` is on, yet
/// a negative value is refused at once, naming the parameter, the value
/// and the bound, and nothing is set. Values within the bounds are taken.
#[test]
fn unused_parameters_are_checked_against_their_declared_bounds() {
    let mut fmu = lugre();
    let (dd, fc_neg, scale) = (
        vr(&fmu, "direction_dependent"),
        vr(&fmu, "Fc_neg"),
        vr(&fmu, "scale_neg[5]"),
    );
    fmu.setup_experiment(0.0, None).unwrap();
    fmu.enter_initialization_mode().unwrap();
    assert_eq!(fmu.values().real(dd), 0.0, "direction_dependent is off");
    let before = fmu.values().real(fc_neg);

    let err = fmu.set(VarType::Real, &[fc_neg], &[-1.0]).unwrap_err();
    assert_eq!(
        err,
        format!("Fc_neg (value reference {fc_neg}) = -1: below its declared min = 0")
    );
    let err = fmu
        .set(VarType::Real, &[scale, fc_neg], &[0.5, -2.0])
        .unwrap_err();
    assert!(err.starts_with("Fc_neg"), "{err}");
    assert_eq!(fmu.values().real(fc_neg), before);
    assert_eq!(fmu.values().real(scale), 1.0, "all or nothing");
    let err = fmu.set(VarType::Real, &[scale], &[-0.1]).unwrap_err();
    assert!(
        err.contains("scale_neg[5]") && err.contains("min = 0"),
        "{err}"
    );

    fmu.set(VarType::Real, &[fc_neg, scale], &[0.0, 2.0])
        .unwrap();
    assert_eq!(fmu.values().real(fc_neg), 0.0);
    fmu.exit_initialization_mode().unwrap();
}
