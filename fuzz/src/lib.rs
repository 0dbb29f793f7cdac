//! Shared by the fuzz targets: all seven shipped models behind one set of
//! FMI exports linked into the fuzzer (so the FMU code is instrumented for
//! coverage), the raw FMI access of `host/tests/fmi` over them, and the
//! models as their checked-in model descriptions describe them.
#![allow(clippy::missing_safety_doc)]

#[path = "../../host/tests/fmi/mod.rs"]
pub mod fmi;

use fmi_export::ModelFactory;
use std::ffi::c_void;
use std::sync::LazyLock;

/// The friction and rig registries together (GUIDs are distinct).
pub static ALL: LazyLock<Vec<ModelFactory>> = LazyLock::new(|| {
    friction_fmu::REGISTRY
        .iter()
        .chain(rig_fmu::REGISTRY.iter())
        .map(|f| ModelFactory {
            info: f.info,
            create: f.create,
            create_model_exchange: f.create_model_exchange,
        })
        .collect()
});

fmi_export::export_fmi2!(&ALL[..]);

macro_rules! lookup {
    ($name:expr; $($symbol:ident),*) => {
        match $name {
            $(stringify!($symbol) => fmi2_exports::$symbol as *const c_void,)*
            _ => std::ptr::null(),
        }
    };
}

/// The exports above as an [`fmi::Api`], the importer's raw FMI 2.0 table
/// (`fricsim_fmi::fmi2::Functions`) filled from the exports linked in.
pub fn api() -> fmi::Api {
    // SAFETY: each name maps to the export of that name, linked into this
    // program for as long as it runs.
    let api = unsafe {
        fmi::Api::from_lookup(|name| {
            lookup!(name;
                fmi2GetTypesPlatform, fmi2GetVersion, fmi2SetDebugLogging, fmi2Instantiate,
                fmi2FreeInstance, fmi2SetupExperiment, fmi2EnterInitializationMode,
                fmi2ExitInitializationMode, fmi2Terminate, fmi2Reset, fmi2GetReal,
                fmi2GetInteger, fmi2GetBoolean, fmi2GetString, fmi2SetReal, fmi2SetInteger,
                fmi2SetBoolean, fmi2SetString, fmi2GetFMUstate, fmi2SetFMUstate,
                fmi2FreeFMUstate, fmi2SerializedFMUstateSize, fmi2SerializeFMUstate,
                fmi2DeSerializeFMUstate, fmi2GetDirectionalDerivative,
                fmi2SetRealInputDerivatives, fmi2GetRealOutputDerivatives, fmi2DoStep,
                fmi2CancelStep, fmi2GetStatus, fmi2GetRealStatus, fmi2GetIntegerStatus,
                fmi2GetBooleanStatus, fmi2GetStringStatus)
        })
    };
    api.unwrap_or_else(|missing| panic!("not linked: {missing:?}"))
}

/// The seven models, from `modelDescription/<Name>.xml`.
pub static MODELS: LazyLock<Vec<fmi::Model>> = LazyLock::new(|| {
    fmi::SHIPPED
        .iter()
        .map(|name| {
            let path = fmi::repository()
                .join("modelDescription")
                .join(format!("{name}.xml"));
            let md = fricsim_fmi::ModelDescription::from_file(&path).unwrap();
            fmi::Model::from_description(&md)
        })
        .collect()
});
