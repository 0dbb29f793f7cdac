//! Loading the binary: missing platform, not a shared library, missing
//! required or declared functions, wrong FMI version.

use crate::common;
use common::assert_message;

use common::{stub_description, stub_fmu_dir};
use fricsim::fmu::Fmu;
use fricsim::FmuError;

#[test]
fn the_stub_loads() {
    let dir = stub_fmu_dir("", &[]);
    let fmu = Fmu::from_dir(dir.path()).unwrap();
    assert_eq!(fmu.library().version(), "2.0");
    assert_eq!(fmu.library().types_platform(), "default");
    assert!(fmu.library().path().ends_with("binaries/linux64/Stub.so"));
}

#[test]
fn a_missing_linux64_binary_is_refused_listing_the_platforms() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("modelDescription.xml"),
        stub_description(""),
    )
    .unwrap();
    for platform in ["win64", "darwin64"] {
        std::fs::create_dir_all(dir.path().join("binaries").join(platform)).unwrap();
    }
    std::fs::write(dir.path().join("binaries/win64/Stub.dll"), b"MZ").unwrap();
    let e = Fmu::from_dir(dir.path()).unwrap_err();
    assert!(matches!(&e, FmuError::MissingBinary { .. }), "{e}");
    assert_message(&e, &["FMU has no binary for linux64: expected binaries/linux64/Stub.so; it has: darwin64, win64"]);

    // No binaries at all.
    std::fs::remove_dir_all(dir.path().join("binaries")).unwrap();
    let e = Fmu::from_dir(dir.path()).unwrap_err();
    assert_message(
        &e,
        &["expected binaries/linux64/Stub.so", "it has: no binaries"],
    );
}

#[test]
fn a_file_that_is_not_a_shared_library_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("modelDescription.xml"),
        stub_description(""),
    )
    .unwrap();
    std::fs::create_dir_all(dir.path().join("binaries/linux64")).unwrap();
    // Pseudo-random bytes (a fixed LCG, so the test is reproducible).
    let mut x: u32 = 12345;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
            (x >> 16) as u8
        })
        .collect();
    let path = dir.path().join("binaries/linux64/Stub.so");
    std::fs::write(&path, bytes).unwrap();
    let e = Fmu::from_dir(dir.path()).unwrap_err();
    assert!(matches!(&e, FmuError::LoadLibrary { .. }), "{e}");
    // The path, and dlopen's reason (e.g. "invalid ELF header").
    assert_message(&e, &[path.to_str().unwrap(), "as a shared library", "ELF"]);
}

#[test]
fn missing_required_functions_are_all_named() {
    let dir = stub_fmu_dir("", &["-DSTUB_ONLY_GET_VERSION"]);
    let e = Fmu::from_dir(dir.path()).unwrap_err();
    let FmuError::MissingFunctions { symbols, .. } = &e else {
        panic!("{e}")
    };
    let expected = [
        "fmi2GetTypesPlatform",
        "fmi2SetDebugLogging",
        "fmi2Instantiate",
        "fmi2FreeInstance",
        "fmi2SetupExperiment",
        "fmi2EnterInitializationMode",
        "fmi2ExitInitializationMode",
        "fmi2Terminate",
        "fmi2Reset",
        "fmi2GetReal",
        "fmi2GetInteger",
        "fmi2GetBoolean",
        "fmi2GetString",
        "fmi2SetReal",
        "fmi2SetInteger",
        "fmi2SetBoolean",
        "fmi2SetString",
        "fmi2DoStep",
        "fmi2CancelStep",
        "fmi2GetStatus",
        "fmi2GetRealStatus",
        "fmi2GetIntegerStatus",
        "fmi2GetBooleanStatus",
        "fmi2GetStringStatus",
    ];
    assert_eq!(symbols, &expected);
    assert_message(&e, &["Stub.so does not export the required FMI functions: fmi2GetTypesPlatform, fmi2SetDebugLogging"]);
    assert!(
        !e.to_string().contains("fmi2GetVersion"),
        "fmi2GetVersion is exported: {e}"
    );
}

#[test]
fn declared_but_missing_optional_functions_are_named() {
    let cases = [
        (
            r#"canGetAndSetFMUstate="true""#,
            "fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate",
        ),
        (
            r#"canGetAndSetFMUstate="true" canSerializeFMUstate="true""#,
            "fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate",
        ),
        (
            r#"providesDirectionalDerivative="true""#,
            "fmi2GetDirectionalDerivative",
        ),
        (
            r#"canInterpolateInputs="true""#,
            "fmi2SetRealInputDerivatives",
        ),
        (
            r#"maxOutputDerivativeOrder="1""#,
            "fmi2GetRealOutputDerivatives",
        ),
    ];
    for (capability, missing) in cases {
        let dir = stub_fmu_dir(capability, &[]);
        let e = Fmu::from_dir(dir.path()).unwrap_err();
        assert!(
            matches!(&e, FmuError::MissingCapabilityFunctions { .. }),
            "{e}"
        );
        let first = capability
            .split(' ')
            .next()
            .unwrap()
            .split('=')
            .next()
            .unwrap();
        assert_message(&e, &[first, &format!("does not export {missing}")]);
    }
}

#[test]
fn a_wrong_fmi_version_is_refused() {
    let dir = stub_fmu_dir("", &["-DSTUB_VERSION=\"3.0\""]);
    let e = Fmu::from_dir(dir.path()).unwrap_err();
    assert!(matches!(&e, FmuError::WrongFmiVersion { .. }), "{e}");
    assert_message(&e, &["fmi2GetVersion() returned \"3.0\", expected \"2.0\""]);
}

#[test]
fn an_archive_is_opened_and_its_directory_removed_with_the_last_user() {
    let dir = stub_fmu_dir("", &[]);
    let archive = tempfile::tempdir().unwrap();
    let path = archive.path().join("Stub.fmu");
    common::zip_dir(dir.path(), &path);
    let fmu = Fmu::open(&path).unwrap();
    let unpacked = fmu.dir().to_path_buf();
    assert!(unpacked.join("binaries/linux64/Stub.so").is_file());
    let instance = fmu.instantiate("a").unwrap();
    drop(fmu);
    assert!(unpacked.is_dir(), "the instance still needs the FMU");
    drop(instance);
    assert!(!unpacked.exists(), "the unpacked FMU must be removed");
}
