//! Packaging: every model of every FMU library of this project, rendered and
//! zipped. The model descriptions come from the variable tables only.

use fmi_export::ModelInfo;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The FMU libraries of this project: crate name (the shared library is
/// `lib<crate>.so`, `<crate>.dll`, …: [`PLATFORMS`]), generation tool, and
/// the models it holds.
pub fn libraries() -> Vec<(&'static str, &'static str, Vec<&'static ModelInfo>)> {
    vec![
        (
            "friction_fmu_c",
            friction_fmu::GENERATION_TOOL,
            friction_fmu::models(),
        ),
        ("rig_fmu_c", rig_fmu::GENERATION_TOOL, rig_fmu::models()),
    ]
}

/// Every model we ship, in a stable order.
pub fn all_models() -> Vec<&'static ModelInfo> {
    libraries()
        .into_iter()
        .flat_map(|(_, _, models)| models)
        .collect()
}

/// The list of shipped models, `modelDescription/shipped.txt`: one line per
/// FMU, its name, `law` or `rig`, and its interfaces (`cs`, and `me` for
/// the models offered for Model Exchange too), from the registries. Every
/// test and script that goes over the shipped FMUs reads it.
pub fn shipped_list() -> String {
    let mut s = String::from(
        "# The FMUs this project ships: name, kind (law or rig), interfaces (cs: Co-Simulation,\n\
         # me: Model Exchange). Rendered from the registries by `cargo run -p fmu-packager -- render`;\n\
         # every test and script that goes over the shipped FMUs reads this list.\n",
    );
    let kinds = [
        ("law", friction_fmu::REGISTRY.iter()),
        ("rig", rig_fmu::REGISTRY.iter()),
    ];
    for (kind, factories) in kinds {
        for f in factories {
            let me = if f.create_model_exchange.is_some() {
                " me"
            } else {
                ""
            };
            s.push_str(&format!("{} {kind} cs{me}\n", f.info.model_name));
        }
    }
    s
}

/// Where [`shipped_list`] is checked in, under the model descriptions'
/// directory.
pub fn shipped_list_path(dir: &Path) -> PathBuf {
    dir.join("shipped.txt")
}

/// The library crate that holds `info`.
pub fn library_of(info: &ModelInfo) -> &'static str {
    libraries()
        .into_iter()
        .find(|(_, _, m)| m.iter().any(|i| i.guid == info.guid))
        .map(|(l, _, _)| l)
        .expect("listed")
}

/// The version of the FMI standard an FMU is packaged for: every model is
/// shipped as both, from the same binary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0: `dist/<Name>.fmu`, `modelDescription/<Name>.xml`.
    Fmi2,
    /// FMI 3.0: `dist/fmi3/<Name>.fmu`, `modelDescription/fmi3/<Name>.xml`.
    Fmi3,
}

impl FmiVersion {
    pub const ALL: [FmiVersion; 2] = [FmiVersion::Fmi2, FmiVersion::Fmi3];

    /// The subdirectory of this version's FMUs and descriptions, under
    /// `dist/` and `modelDescription/`.
    pub fn subdirectory(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "",
            FmiVersion::Fmi3 => "fmi3",
        }
    }
}

fn generation_tool(info: &ModelInfo) -> &'static str {
    libraries()
        .into_iter()
        .find(|(_, _, m)| m.iter().any(|i| i.guid == info.guid))
        .map_or("unknown", |(_, t, _)| t)
}

/// The FMI 2.0 model description of `info`, as shipped.
pub fn render(info: &ModelInfo) -> Result<String, String> {
    render_version(info, FmiVersion::Fmi2)
}

/// The model description of `info` for `version`, as shipped.
pub fn render_version(info: &ModelInfo, version: FmiVersion) -> Result<String, String> {
    match version {
        FmiVersion::Fmi2 => fmi_export::model_description::render(info, generation_tool(info)),
        FmiVersion::Fmi3 => {
            fmi_export::fmi3::model_description::render(info, generation_tool(info))
        }
    }
}

/// Path of the checked-in FMI 2.0 description of `info` under `dir`.
pub fn description_path(dir: &Path, info: &ModelInfo) -> PathBuf {
    description_path_version(dir, info, FmiVersion::Fmi2)
}

/// Path of the checked-in description of `info` for `version` under `dir`.
pub fn description_path_version(dir: &Path, info: &ModelInfo, version: FmiVersion) -> PathBuf {
    dir.join(version.subdirectory())
        .join(format!("{}.xml", info.model_name))
}

/// The platform folders of FMI 2.0 (FMI 2.0.4 §2.4: `binaries/<platform>/`)
/// with the file name of a Rust `cdylib` built for each: prefix and
/// extension (`libfriction_fmu_c.so`, `friction_fmu_c.dll`,
/// `libfriction_fmu_c.dylib`).
pub const PLATFORMS: &[(&str, &str, &str)] = &[
    ("linux32", "lib", "so"),
    ("linux64", "lib", "so"),
    ("win32", "", "dll"),
    ("win64", "", "dll"),
    ("darwin32", "lib", "dylib"),
    ("darwin64", "lib", "dylib"),
];

/// The FMI 3.0 platform tuple (FMI 3.0 section 2.5.1.1) of an FMI 2.0
/// platform folder, where one is determined: `linux64` is `x86_64-linux`,
/// `win64` `x86_64-windows`; `darwin64` is left out, as it does not say
/// whether the Mac is an Intel or an Arm one.
pub fn fmi3_platform(name: &str) -> Option<&'static str> {
    match name {
        "linux32" => Some("x86-linux"),
        "linux64" => Some("x86_64-linux"),
        "win32" => Some("x86-windows"),
        "win64" => Some("x86_64-windows"),
        _ => None,
    }
}

fn platform(name: &str) -> Result<&'static (&'static str, &'static str, &'static str), String> {
    PLATFORMS
        .iter()
        .find(|(p, _, _)| *p == name)
        .ok_or_else(|| {
            let known: Vec<&str> = PLATFORMS.iter().map(|(p, _, _)| *p).collect();
            format!(
                "unknown platform \"{name}\" (FMI 2.0 platforms: {})",
                known.join(", ")
            )
        })
}

/// The libraries of one platform: `binaries/<platform>/` of every FMU
/// comes from `dir`, where cargo wrote the `cdylib`s for that platform
/// (`target/release`, `target/x86_64-pc-windows-gnu/release`, …).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Platform {
    pub name: &'static str,
    pub dir: PathBuf,
}

impl std::str::FromStr for Platform {
    type Err = String;
    /// `PLATFORM=DIR`, e.g. `win64=target/x86_64-pc-windows-gnu/release`.
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, dir) = s
            .split_once('=')
            .ok_or_else(|| format!("\"{s}\" is not PLATFORM=DIR (e.g. darwin64=target/release)"))?;
        if dir.is_empty() {
            return Err(format!("\"{s}\" names no directory"));
        }
        Ok(Platform {
            name: platform(name)?.0,
            dir: PathBuf::from(dir),
        })
    }
}

impl Platform {
    /// The built library of crate `library` (`lib<crate>.so`,
    /// `<crate>.dll`, `lib<crate>.dylib`) in this platform's directory.
    pub fn built_library(&self, library: &str) -> PathBuf {
        let (_, prefix, extension) = platform(self.name).expect("checked when parsed");
        self.dir.join(format!("{prefix}{library}.{extension}"))
    }
}

/// The archive entry of `model_identifier`'s binary for `platform`:
/// `binaries/win64/LuGre.dll`.
pub fn binary_entry(platform: &str, model_identifier: &str) -> Result<String, String> {
    let (name, _, extension) = self::platform(platform)?;
    Ok(format!("binaries/{name}/{model_identifier}.{extension}"))
}

/// The archive entry of `model_identifier`'s binary for `platform` in an
/// FMU of `version`: `binaries/win64/LuGre.dll` (FMI 2.0),
/// `binaries/x86_64-windows/LuGre.dll` (FMI 3.0).
pub fn binary_entry_version(
    platform: &str,
    model_identifier: &str,
    version: FmiVersion,
) -> Result<String, String> {
    let entry = binary_entry(platform, model_identifier)?;
    match version {
        FmiVersion::Fmi2 => Ok(entry),
        FmiVersion::Fmi3 => {
            let tuple = fmi3_platform(platform).ok_or_else(|| {
                format!("platform {platform} has no FMI 3.0 platform tuple this packager knows")
            })?;
            Ok(entry.replacen(
                &format!("binaries/{platform}/"),
                &format!("binaries/{tuple}/"),
                1,
            ))
        }
    }
}

/// Write `dist/<Name>.fmu`, the FMI 2.0 FMU ([`package_version`]).
pub fn package(
    info: &ModelInfo,
    platforms: &[Platform],
    out_dir: &Path,
) -> Result<PathBuf, String> {
    package_version(info, platforms, out_dir, FmiVersion::Fmi2)
}

/// Write `<out_dir>/<Name>.fmu` (FMI 2.0) or `<out_dir>/fmi3/<Name>.fmu`
/// (FMI 3.0): `modelDescription.xml` of `version` and, for every platform
/// of `platforms` (in that order, no platform twice), the library of
/// `info`'s crate built for it, as
/// `binaries/<platform>/<modelIdentifier>.<so|dll|dylib>` (the platform
/// folder of the version: `linux64` or `x86_64-linux`).
pub fn package_version(
    info: &ModelInfo,
    platforms: &[Platform],
    out_dir: &Path,
    version: FmiVersion,
) -> Result<PathBuf, String> {
    let out_dir = &out_dir.join(version.subdirectory());
    if platforms.is_empty() {
        return Err("no platform to package".into());
    }
    let mut binaries = Vec::with_capacity(platforms.len());
    for (i, p) in platforms.iter().enumerate() {
        if platforms[..i].iter().any(|q| q.name == p.name) {
            return Err(format!("platform {} given twice", p.name));
        }
        let library = p.built_library(library_of(info));
        let binary = std::fs::read(&library)
            .map_err(|e| format!("cannot read {} ({}): {e}", library.display(), p.name))?;
        binaries.push((
            binary_entry_version(p.name, info.model_identifier, version)?,
            binary,
        ));
    }
    let xml = render_version(info, version)?;
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let path = out_dir.join(format!("{}.fmu", info.model_name));
    let file = std::fs::File::create(&path)
        .map_err(|e| format!("cannot create {}: {e}", path.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    // The text is deflated (a tenth of its size). The binaries are stored
    // as they are: an importer unpacks the binary of its platform every
    // time it loads the FMU (FMPy, fricsim and most tools unpack into a
    // fresh directory), and inflating it costs more than the
    // few hundred kilobytes saved are worth (BENCHMARKS.md, "What
    // starting a run costs").
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .unix_permissions(0o644);
    let stored = deflated.compression_method(zip::CompressionMethod::Stored);
    let mut add = |name: &str, data: &[u8], options| -> Result<(), String> {
        zip.start_file(name, options)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        zip.write_all(data)
            .map_err(|e| format!("{}: {e}", path.display()))
    };
    add("modelDescription.xml", xml.as_bytes(), deflated)?;
    for (entry, binary) in &binaries {
        add(entry, binary, stored)?;
    }
    zip.finish()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// Markdown tables of every model's variables, for `docs/fmu-reference.md`
/// (arrays such as `x_table[1]`…`x_table[32]` collapse into one row
/// `x_table[i]`).
pub fn variables_markdown() -> String {
    use fmi_export::{Causality, VarType};
    let mut md = String::new();
    for info in all_models() {
        md.push_str(&format!("### {} — {}\n\n", info.model_name, info.source));
        md.push_str("| variable | causality | type | start | unit | description |\n|---|---|---|---|---|---|\n");
        let mut seen_arrays: Vec<&str> = Vec::new();
        for v in info.variables {
            let (name, start) = match v.name.split_once('[') {
                Some((base, rest)) => {
                    // what follows the index: `)` of `der(F_element[1])`
                    let after = rest.split_once(']').map_or("", |(_, after)| after);
                    if seen_arrays.contains(&base) {
                        continue;
                    }
                    seen_arrays.push(base);
                    let n = info
                        .variables
                        .iter()
                        .filter(|w| w.name.starts_with(&format!("{base}[")))
                        .count();
                    (
                        format!("{base}[i]{after}, i = 1..{n}"),
                        "see XML".to_string(),
                    )
                }
                None => (
                    v.name.to_string(),
                    match (v.start, v.var_type) {
                        (None, _) => String::new(),
                        (Some(s), VarType::Boolean) => (s != 0.0).to_string(),
                        (Some(s), VarType::Integer) => format!("{}", s as i64),
                        (Some(s), VarType::Real) => format!("{s}"),
                    },
                ),
            };
            let causality = match v.causality {
                Causality::Parameter => "parameter",
                Causality::Input => "input",
                Causality::Output => "output",
                Causality::Local => "local",
            };
            let ty = match v.var_type {
                VarType::Real => "Real",
                VarType::Integer => "Integer",
                VarType::Boolean => "Boolean",
            };
            md.push_str(&format!(
                "| `{name}` | {causality} | {ty} | {start} | {} | {} |\n",
                v.unit.unwrap_or(""),
                v.description.replace('|', "\\|")
            ));
        }
        md.push('\n');
    }
    md
}
