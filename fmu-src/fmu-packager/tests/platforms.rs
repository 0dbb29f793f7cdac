//! `fmu-package build --platform PLATFORM=DIR`: a library for any FMI 2.0
//! platform folder, several in one FMU, each under its own name.

use fmu_packager::{all_models, library_of, package, Platform};
use std::io::Read;
use std::path::{Path, PathBuf};

/// A fresh directory under cargo's scratch space for integration tests.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("platforms-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The entries of the zip archive at `path`, in order, with their bytes.
fn entries(path: &Path) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut entry = zip.by_index(i).unwrap();
            let mut data = Vec::new();
            entry.read_to_end(&mut data).unwrap();
            (entry.name().unwrap().to_string(), data)
        })
        .collect()
}

#[test]
fn platform_arguments_are_checked() {
    let p: Platform = "darwin64=build/mac".parse().unwrap();
    assert_eq!(p.name, "darwin64");
    assert_eq!(
        p.built_library("friction_fmu_c"),
        Path::new("build/mac/libfriction_fmu_c.dylib")
    );
    let p: Platform = "win64=target/x86_64-pc-windows-gnu/release"
        .parse()
        .unwrap();
    assert_eq!(
        p.built_library("rig_fmu_c"),
        Path::new("target/x86_64-pc-windows-gnu/release/rig_fmu_c.dll")
    );
    for (arg, message) in [
        ("win65=dir", "unknown platform \"win65\" (FMI 2.0 platforms: linux32, linux64, win32, win64, darwin32, darwin64)"),
        ("win64", "\"win64\" is not PLATFORM=DIR"),
        ("win64=", "\"win64=\" names no directory"),
        ("=dir", "unknown platform \"\""),
    ] {
        let e = arg.parse::<Platform>().unwrap_err();
        assert!(e.starts_with(message), "{arg}: {e}");
    }
}

#[test]
fn one_fmu_holds_every_platform_given() {
    let root = scratch("three");
    let lugre = all_models()
        .into_iter()
        .find(|m| m.model_name == "LuGre")
        .unwrap();
    let crate_name = library_of(lugre);
    let mut platforms = Vec::new();
    for (name, file) in [
        ("linux64", format!("lib{crate_name}.so")),
        ("win64", format!("{crate_name}.dll")),
        ("darwin64", format!("lib{crate_name}.dylib")),
    ] {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(file), format!("the {name} library")).unwrap();
        platforms.push(Platform { name, dir });
    }
    let out = root.join("dist");
    let fmu = package(lugre, &platforms, &out).unwrap();
    assert_eq!(fmu, out.join("LuGre.fmu"));
    let names: Vec<(String, Vec<u8>)> = entries(&fmu);
    let listed: Vec<&str> = names.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        listed,
        [
            "modelDescription.xml",
            "binaries/linux64/LuGre.so",
            "binaries/win64/LuGre.dll",
            "binaries/darwin64/LuGre.dylib"
        ]
    );
    assert_eq!(names[1].1, b"the linux64 library");
    assert_eq!(names[2].1, b"the win64 library");
    assert_eq!(names[3].1, b"the darwin64 library");
    assert_eq!(
        String::from_utf8(names[0].1.clone()).unwrap(),
        fmu_packager::render(lugre).unwrap()
    );
    // the model description deflated, every binary stored as it is (an
    // importer unpacks it at every load: nothing to inflate)
    let mut zip = zip::ZipArchive::new(std::fs::File::open(&fmu).unwrap()).unwrap();
    for i in 0..zip.len() {
        let entry = zip.by_index(i).unwrap();
        let expected = if i == 0 {
            zip::CompressionMethod::Deflated
        } else {
            zip::CompressionMethod::Stored
        };
        assert_eq!(entry.compression(), expected, "{}", entry.name().unwrap());
    }
}

#[test]
fn a_missing_library_or_a_platform_given_twice_is_refused() {
    let root = scratch("refused");
    let dahl = all_models()
        .into_iter()
        .find(|m| m.model_name == "Dahl")
        .unwrap();
    let linux = root.join("linux");
    std::fs::create_dir_all(&linux).unwrap();
    std::fs::write(linux.join(format!("lib{}.so", library_of(dahl))), b"so").unwrap();
    let out = root.join("dist");

    let e = package(
        dahl,
        &[
            Platform {
                name: "linux64",
                dir: linux.clone(),
            },
            "win64=nowhere".parse().unwrap(),
        ],
        &out,
    )
    .unwrap_err();
    assert!(
        e.starts_with("cannot read nowhere/friction_fmu_c.dll (win64): "),
        "{e}"
    );
    assert!(!out.join("Dahl.fmu").exists(), "no archive is written");

    let twice = Platform {
        name: "linux64",
        dir: linux.clone(),
    };
    let e = package(dahl, &[twice.clone(), twice], &out).unwrap_err();
    assert_eq!(e, "platform linux64 given twice");
    assert_eq!(
        package(dahl, &[], &out).unwrap_err(),
        "no platform to package"
    );
}

/// The FMI 3.0 FMU of a model: `<out>/fmi3/<Name>.fmu`, the same libraries
/// under FMI 3.0's platform tuples, its FMI 3.0 description; a platform
/// without a tuple this packager can name (darwin64: Intel or Arm?) is
/// refused, naming it.
#[test]
fn the_fmi3_fmu_holds_the_same_libraries_under_platform_tuples() {
    use fmu_packager::{package_version, render_version, FmiVersion};
    let root = scratch("fmi3");
    let lugre = all_models()
        .into_iter()
        .find(|m| m.model_name == "LuGre")
        .unwrap();
    let crate_name = library_of(lugre);
    let mut platforms = Vec::new();
    for (name, file) in [
        ("linux64", format!("lib{crate_name}.so")),
        ("win64", format!("{crate_name}.dll")),
        ("darwin64", format!("lib{crate_name}.dylib")),
    ] {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(file), format!("the {name} library")).unwrap();
        platforms.push(Platform { name, dir });
    }
    let out = root.join("dist");
    let fmu = package_version(lugre, &platforms[..2], &out, FmiVersion::Fmi3).unwrap();
    assert_eq!(fmu, out.join("fmi3").join("LuGre.fmu"));
    let names = entries(&fmu);
    let listed: Vec<&str> = names.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        listed,
        [
            "modelDescription.xml",
            "binaries/x86_64-linux/LuGre.so",
            "binaries/x86_64-windows/LuGre.dll",
        ]
    );
    assert_eq!(names[1].1, b"the linux64 library");
    assert_eq!(
        String::from_utf8(names[0].1.clone()).unwrap(),
        render_version(lugre, FmiVersion::Fmi3).unwrap()
    );
    let e = package_version(lugre, &platforms, &out, FmiVersion::Fmi3).unwrap_err();
    assert_eq!(
        e,
        "platform darwin64 has no FMI 3.0 platform tuple this packager knows"
    );
}
