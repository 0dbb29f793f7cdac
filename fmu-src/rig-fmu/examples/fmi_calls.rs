//! The FMI calls of the stick-slip benchmark (`examples/stick_slip.ssd`:
//! Rig1D pulled at 0.1 m/s, LuGre friction with Canudas de Wit's 1995
//! parameters, h = 1e-4) through the FMU side of the C edge
//! (`fmi_export::exports`), linked statically: a profiler sees the FMI layer
//! line by line, which it cannot in an FMU library loaded from a temporary
//! directory. The call sequence per macro step is the host's:
//!
//! - `jacobi`: fmi2SetReal of each connected input, fmi2DoStep of both,
//!   fmi2GetReal of every Real output of both;
//! - `newton`: as the strong-coupling master, two iterations and one
//!   Jacobian per step: fmi2GetFMUstate, set, step, get the coupled outputs,
//!   fmi2GetDirectionalDerivative; fmi2SetFMUstate, set, step, get; then
//!   every output. As the host, the first iteration after the first step
//!   sets no input (they hold the last accepted values).
//!
//! ```text
//! CARGO_PROFILE_RELEASE_DEBUG=line-tables-only cargo build --release -p rig-fmu --example fmi_calls
//! valgrind --tool=callgrind target/release/examples/fmi_calls jacobi 20000
//! ```
//! It prints the final friction force, which must not change with the FMI
//! layer's implementation.

use fmi_export::exports as x;
use fmi_export::ffi::*;
use fmi_export::{Causality, ModelFactory, ModelInfo, VarType};
use std::ffi::CString;

fn real_outputs(info: &ModelInfo) -> Vec<u32> {
    info.variables
        .iter()
        .filter(|v| v.causality == Causality::Output && v.var_type == VarType::Real)
        .map(|v| v.vr)
        .collect()
}

fn vr_of(info: &ModelInfo, name: &str) -> u32 {
    info.variables
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("{} has no variable {name}", info.model_name))
        .vr
}

fn ok(status: fmi2Status, what: &str) {
    assert_eq!(status, fmi2Status::fmi2OK, "{what}");
}

fn main() {
    let mut args = std::env::args().skip(1);
    let master = args.next().unwrap_or_else(|| "jacobi".into());
    let steps: usize = args.next().map_or(20_000, |s| s.parse().expect("steps"));
    let newton = match master.as_str() {
        "jacobi" => false,
        "newton" => true,
        other => panic!("unknown master {other} (jacobi or newton)"),
    };

    let lugre = friction_fmu::REGISTRY
        .iter()
        .find(|f| f.info.model_name == "LuGre")
        .expect("LuGre");
    let rig = rig_fmu::REGISTRY
        .iter()
        .find(|f| f.info.model_name == "Rig1D")
        .expect("Rig1D");
    let registry: &'static [ModelFactory] = Box::leak(Box::new([
        ModelFactory {
            info: rig.info,
            create: rig.create,
            create_model_exchange: rig.create_model_exchange,
        },
        ModelFactory {
            info: lugre.info,
            create: lugre.create,
            create_model_exchange: lugre.create_model_exchange,
        },
    ]));
    let functions = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let instantiate = |info: &ModelInfo, name: &str| {
        let name = CString::new(name).unwrap();
        let guid = CString::new(info.guid).unwrap();
        // SAFETY: valid C strings and callback struct for the call.
        let c = unsafe {
            x::instantiate(
                registry,
                name.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                &functions,
                fmi2False,
                fmi2False,
            )
        };
        assert!(!c.is_null(), "instantiate {}", info.model_name);
        c
    };
    let (rig_info, lugre_info) = (rig.info, lugre.info);
    let r = instantiate(rig_info, "rig");
    let f = instantiate(lugre_info, "friction");
    let rig_f = vr_of(rig_info, "F");
    let rig_v = vr_of(rig_info, "v");
    let lugre_v = vr_of(lugre_info, "v");
    let lugre_f = vr_of(lugre_info, "F");
    let rig_outputs = real_outputs(rig_info);
    let lugre_outputs = real_outputs(lugre_info);
    let h = 1e-4;

    // SAFETY (every call below): live instances, arrays of the lengths given.
    unsafe {
        for c in [r, f] {
            ok(x::setup_experiment(c, 0, 0.0, 0.0, 0, 0.0), "setup");
            ok(x::enter_initialization_mode(c), "enter init");
        }
        for (name, value) in [
            ("sigma0", 1e5),
            ("sigma1", 316.22776601683796),
            ("sigma2", 0.4),
            ("Fc", 1.0),
            ("Fs", 1.5),
            ("vs", 0.001),
        ] {
            ok(
                x::set_real(f, &vr_of(lugre_info, name), 1, &value),
                "parameter",
            );
        }
        for c in [r, f] {
            ok(x::exit_initialization_mode(c), "exit init");
        }
        let mut y_rig = vec![0.0; rig_outputs.len()];
        let mut y_lugre = vec![0.0; lugre_outputs.len()];
        let mut v = 0.0;
        let mut force = 0.0;
        ok(x::get_real(r, &rig_v, 1, &mut v), "get v");
        ok(x::get_real(f, &lugre_f, 1, &mut force), "get F");
        let mut states: [fmi2FMUstate; 2] = [std::ptr::null_mut(); 2];
        for i in 0..steps {
            let t = i as f64 * h;
            if newton {
                ok(x::get_fmu_state(r, &mut states[0]), "get state");
                ok(x::get_fmu_state(f, &mut states[1]), "get state");
                for iteration in 0..2 {
                    if iteration > 0 {
                        ok(x::set_fmu_state(r, states[0]), "set state");
                        ok(x::set_fmu_state(f, states[1]), "set state");
                    }
                    // The host leaves out the sets of the first iteration
                    // after the first step (the FMUs still hold the last
                    // accepted inputs). Here that iteration's result is not
                    // used: the second one, from the restored state with
                    // the new inputs, decides the step either way.
                    if iteration > 0 || i == 0 {
                        ok(x::set_real(f, &lugre_v, 1, &v), "set v");
                        ok(x::set_real(r, &rig_f, 1, &force), "set F");
                    }
                    ok(x::do_step(r, t, h, fmi2True), "step rig");
                    ok(x::do_step(f, t, h, fmi2True), "step friction");
                    let (mut v_new, mut f_new) = (0.0, 0.0);
                    ok(x::get_real(r, &rig_v, 1, &mut v_new), "get v");
                    ok(x::get_real(f, &lugre_f, 1, &mut f_new), "get F");
                    if iteration == 0 {
                        let (mut dv, mut df) = (0.0, 0.0);
                        let one = 1.0;
                        ok(
                            x::get_directional_derivative(r, &rig_v, 1, &rig_f, 1, &one, &mut dv),
                            "dv/dF",
                        );
                        ok(
                            x::get_directional_derivative(
                                f, &lugre_f, 1, &lugre_v, 1, &one, &mut df,
                            ),
                            "dF/dv",
                        );
                    }
                }
            } else {
                ok(x::set_real(f, &lugre_v, 1, &v), "set v");
                ok(x::set_real(r, &rig_f, 1, &force), "set F");
                ok(x::do_step(r, t, h, fmi2True), "step rig");
                ok(x::do_step(f, t, h, fmi2True), "step friction");
            }
            ok(
                x::get_real(r, rig_outputs.as_ptr(), y_rig.len(), y_rig.as_mut_ptr()),
                "get rig",
            );
            ok(
                x::get_real(
                    f,
                    lugre_outputs.as_ptr(),
                    y_lugre.len(),
                    y_lugre.as_mut_ptr(),
                ),
                "get friction",
            );
            v = y_rig[rig_outputs.iter().position(|&k| k == rig_v).unwrap()];
            force = y_lugre[lugre_outputs.iter().position(|&k| k == lugre_f).unwrap()];
        }
        println!("{master}, {steps} steps: final friction F = {force:?}, rig v = {v:?}, rig outputs {y_rig:?}");
        for (c, s) in [r, f].into_iter().zip(states.iter_mut()) {
            if !s.is_null() {
                ok(x::free_fmu_state(c, s), "free state");
            }
            x::free_instance(c);
        }
    }
}
