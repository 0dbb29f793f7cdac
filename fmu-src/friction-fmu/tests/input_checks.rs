//! Inputs a model checks (LuGre's normal force must be >= 0) are refused
//! with the model's reason when set alone or in a list, in initialization
//! and step mode, and nothing is set; the inputs it does not check take
//! any finite value (the layer skips the model's check for them).

use fmi2_cs::instance::Instance;
use fmi2_cs::logger::Logger;
use fmi2_cs::VarType;

fn lugre() -> Instance {
    let factory = friction_fmu::REGISTRY
        .iter()
        .find(|f| f.info.model_name == "LuGre")
        .expect("LuGre");
    let logger = Logger::new(None, std::ptr::null_mut(), "probe", false);
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
