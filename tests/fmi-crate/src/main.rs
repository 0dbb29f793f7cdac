//! Drives one of our FMUs through the `fmi` crate's Co-Simulation import
//! API (fmi-rs), as an importer that is not ours would: FMI 2.0 or FMI 3.0,
//! whichever the FMU's model description declares.
//!
//! ```text
//! fmi-crate-drive FMU INPUT.csv OUT.csv [NAME=VALUE ...]
//! ```
//!
//! INPUT.csv has a header `time,<input>,...` and one row per communication
//! point. The FMU is unpacked and loaded by the crate, the parameters are
//! set after instantiation (FMI 2.0 Real, Integer or Boolean, FMI 3.0
//! Float64, Int32 or Boolean, by the type the crate read from the model
//! description), the experiment is set up from the first to the last time
//! of INPUT.csv (a defined stop time), and at each row but the last the
//! inputs are set and the FMU steps to the next row's time. OUT.csv gets
//! `time` and every Real/Float64, Integer/Int32 and Boolean (as 0/1)
//! output the crate finds in the model description, in its order, after
//! initialization and after each step; reals are printed with Rust's
//! shortest round-trip formatting, so they are read back bit for bit. The
//! same input gives the same OUT.csv layout for both versions, so that the
//! two exports of one FMU can be compared column by column.
//!
//! Afterwards one step past the stop time is attempted; its outcome is
//! printed on stdout as `step past stop: <result>` (FMI 2.0 §2.1.6, and
//! FMI 3.0 at `stopTime` of fmi3EnterInitializationMode: it must fail).

use std::rc::Rc;
use std::{
    error::Error,
    fmt::{Debug, Write as _},
    fs,
    io::{Cursor, Read as _, Write as _},
    process::ExitCode,
};

use fmi::{
    fmi2::{
        self,
        import::Fmi2Import,
        schema::{Causality as Causality2, ScalarVariableElement},
    },
    fmi3::{
        self,
        import::Fmi3Import,
        schema::{
            Causality as Causality3, Fmi3ModelDescription, Variability, Variable, VariableType,
        },
        Fmi3Model, GetSet,
    },
    import,
    schema::{traits::FmiModelDescription, MajorVersion},
    traits::{FmiImport, FmiInstance, FmiStatus},
};
use zip::write::SimpleFileOptions;

type Res<T> = Result<T, Box<dyn Error>>;

/// The value types the driver sets and reads: FMI 2.0's Real, Integer and
/// Boolean, which FMI 3.0 calls Float64, Int32 and Boolean (our FMUs
/// declare the same variables with these types in both exports).
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
}

/// What the driver does with a variable.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    /// A continuous Real (Float64) input: the columns of INPUT.csv.
    Input,
    /// An output: the columns of OUT.csv.
    Output,
    /// Anything else; only parameters are set, by name.
    Other,
}

/// A model variable as the crate parsed it, reduced to what the driver
/// needs, so that everything after loading is the same code for both
/// versions. `kind` is `None` for the types the driver does not handle.
struct Var {
    name: String,
    vr: u32,
    kind: Option<Kind>,
    role: Role,
    /// An element of an FMI 3.0 Float64 array parameter, named `base[i]`
    /// as FMI 2.0 names it: its index from 0 and the array's start values.
    /// `vr` is the array's: the array is set as a whole.
    element: Option<(usize, Rc<Vec<f64>>)>,
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: fmi-crate-drive FMU INPUT.csv OUT.csv [NAME=VALUE ...]");
        return ExitCode::from(2);
    }
    match run(&args[0], &args[1], &args[2], &args[3..]) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmi-crate-drive: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The input table: column names after `time`, and the rows.
fn read_input(path: &str) -> Res<(Vec<String>, Vec<Vec<f64>>)> {
    let text = fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or("empty input file")?
        .split(',')
        .map(str::to_owned)
        .collect();
    if header.first().map(String::as_str) != Some("time") {
        return Err("the input's first column must be `time`".into());
    }
    let mut rows = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let row = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<Vec<_>, _>>()?;
        if row.len() != header.len() {
            return Err(format!("row `{line}` has {} columns", row.len()).into());
        }
        rows.push(row);
    }
    if rows.len() < 2 {
        return Err("the input needs at least two rows".into());
    }
    Ok((header[1..].to_vec(), rows))
}

/// Loads the FMU with the crate's importer for the FMI version its model
/// description declares (read first with `import::peek_descr_path`, since
/// the importer's type has to be chosen before the crate parses the full
/// description), instantiates it for Co-Simulation and drives it.
fn run(fmu: &str, input: &str, out: &str, assignments: &[String]) -> Res<()> {
    let (input_names, rows) = read_input(input)?;
    match import::peek_descr_path(fmu)?.major_version()? {
        MajorVersion::FMI2 => {
            let import: Fmi2Import = import::from_path(fmu)?;
            let plan = Plan::new(fmi2_variables(&import), &input_names)?;
            let inst = import.instantiate_cs("fmi-crate", false, false)?;
            drive(inst, &plan, &rows, assignments, out)
        }
        MajorVersion::FMI3 => {
            let import = load_fmi3(fmu)?;
            let plan = Plan::new(fmi3_variables(import.model_description())?, &input_names)?;
            // No event mode (our FMUs have none in Co-Simulation and refuse
            // it), no early return, no intermediate update: plain steps,
            // as FMI 2.0 Co-Simulation.
            let inst = import.instantiate_cs("fmi-crate", false, false, false, false, &[])?;
            drive(inst, &plan, &rows, assignments, out)
        }
        v => Err(format!("FMI {v} FMUs are not handled").into()),
    }
}

/// The crate's FMI 3.0 import of `fmu`.
///
/// fmi-schema 0.8.0, with which the crate parses the model description,
/// refuses attributes that FMI 3.0 defines (its element structs are
/// strict about unknown attributes): on `<Float64>` variables the real
/// type's `quantity`, `unit`, `displayUnit`, `relativeQuantity`,
/// `unbounded` and `nominal` (it knows them on `<Float64Type>` only), and
/// on `<BaseUnit>` the exponents `A` and `K`, which it spells `a` and `k`.
/// Every FMI 3.0 FMU with a unit on a variable is refused, ours included
/// (`unknown field "unit" in element "FmiFloat64"`). So the FMU is first
/// given to the crate as it is, and only if the crate refuses its model
/// description, it is given once more as an in-memory copy in which those
/// attributes are removed or respelled; nothing the driver reads (names,
/// value references, types, causalities, variabilities) changes, and the
/// crate still unpacks the archive, parses the description and loads the
/// binary. The refusal is printed on stdout as `fmi-schema refuses the
/// model description: <error>`, so that a test notices when a newer crate
/// reads the FMU as it is.
fn load_fmi3(fmu: &str) -> Res<Fmi3Import> {
    match import::from_path(fmu) {
        Ok(import) => Ok(import),
        Err(fmi::Error::Schema(refusal)) => {
            println!("fmi-schema refuses the model description: {refusal}");
            Ok(import::new(Cursor::new(readable_by_fmi_schema(fmu)?))?)
        }
        Err(e) => Err(e.into()),
    }
}

/// The FMU archive `fmu` with its modelDescription.xml rewritten for
/// fmi-schema 0.8.0 (see [`load_fmi3`]); every other entry is copied as it
/// is, still compressed.
fn readable_by_fmi_schema(fmu: &str) -> Res<Vec<u8>> {
    const MODEL_DESCRIPTION: &str = "modelDescription.xml";
    let mut archive = zip::ZipArchive::new(fs::File::open(fmu)?)?;
    let mut xml = String::new();
    archive
        .by_name(MODEL_DESCRIPTION)?
        .read_to_string(&mut xml)?;
    let xml = edit_start_tags(&xml, "Float64", |attribute| {
        let unknown = [
            "quantity",
            "unit",
            "displayUnit",
            "relativeQuantity",
            "unbounded",
            "nominal",
        ];
        (!unknown.contains(&attribute)).then_some(attribute)
    })?;
    let xml = edit_start_tags(&xml, "BaseUnit", |attribute| match attribute {
        "A" => Some("a"),
        "K" => Some("k"),
        other => Some(other),
    })?;

    let mut copy = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..archive.len() {
        let entry = archive.by_index_raw(i)?;
        if entry.name() != MODEL_DESCRIPTION {
            copy.raw_copy_file(entry)?;
        }
    }
    copy.start_file(MODEL_DESCRIPTION, SimpleFileOptions::default())?;
    copy.write_all(xml.as_bytes())?;
    Ok(copy.finish()?.into_inner())
}

/// `xml` with the attributes of every `<tag …>` start tag passed through
/// `edit`: `None` drops the attribute, `Some(name)` keeps its value under
/// `name`. A plain scan, enough for a generated model description: it
/// does not skip comments or CDATA.
fn edit_start_tags<'a>(
    xml: &'a str,
    tag: &str,
    edit: impl Fn(&'a str) -> Option<&'a str>,
) -> Res<String> {
    let open = format!("<{tag}");
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(at) = rest.find(&open) {
        out.push_str(&rest[..at + open.len()]);
        rest = &rest[at + open.len()..];
        // `<Float64` also starts `<Float64Type`: only the element itself
        if !rest.starts_with(|c: char| c.is_ascii_whitespace()) {
            continue;
        }
        loop {
            let attributes = rest.trim_start();
            if attributes.starts_with(['/', '>']) {
                break;
            }
            let bad = || {
                format!(
                    "malformed <{tag}> start tag near `{}`",
                    &attributes[..attributes.len().min(40)]
                )
            };
            let (name, after) = attributes.split_once('=').ok_or_else(bad)?;
            let after = after.trim_start();
            let quote = after
                .chars()
                .next()
                .filter(|q| ['"', '\''].contains(q))
                .ok_or_else(bad)?;
            let end = after[1..].find(quote).ok_or_else(bad)? + 2;
            if let Some(name) = edit(name.trim()) {
                write!(out, " {name}={}", &after[..end])?;
            }
            rest = &after[end..];
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// The FMI 2.0 model description's variables, in its order.
fn fmi2_variables(import: &Fmi2Import) -> Vec<Var> {
    import
        .model_description()
        .get_model_variables()
        .map(|v| Var {
            name: v.name.clone(),
            vr: v.value_reference,
            kind: match v.elem {
                ScalarVariableElement::Real(_) => Some(Kind::Real),
                ScalarVariableElement::Integer(_) => Some(Kind::Integer),
                ScalarVariableElement::Boolean(_) => Some(Kind::Boolean),
                _ => None,
            },
            role: match v.causality {
                Causality2::Input if v.is_continuous_input() => Role::Input,
                Causality2::Output => Role::Output,
                _ => Role::Other,
            },
            element: None,
        })
        .collect()
}

/// The FMI 3.0 model description's variables, in its order. FMI 3.0
/// variables may be arrays (`<Dimension>`), which take one value per
/// element in every get and set. A one-dimensional Float64 parameter array
/// (our FMUs' position tables and element parameters) becomes one `Var`
/// per element, named `base[i]` as the FMI 2.0 description names its
/// scalars, so that the same NAME=VALUE arguments set both; an array that
/// is read as the run goes (an input or output) is refused rather than
/// read as one value; other arrays (local states) are never touched.
fn fmi3_variables(md: &Fmi3ModelDescription) -> Res<Vec<Var>> {
    let mut out = Vec::new();
    // the variables twice, in the same order: as the crate's enum of
    // element types, for the dimensions and starts, and as its common view
    for (var, v) in md
        .model_variables
        .variables
        .iter()
        .zip(md.model_variables.iter_abstract())
    {
        let dimensions = match var {
            Variable::Float64(f) => f.dimensions.clone(),
            Variable::Int32(i) => i.dimensions.clone(),
            Variable::Boolean(b) => b.dimensions.clone(),
            _ => Vec::new(),
        };
        if !dimensions.is_empty() {
            let starts = match var {
                Variable::Float64(f) if v.causality() == Causality3::Parameter => {
                    f.start.as_ref().map(|s| s.0.clone())
                }
                _ => None,
            };
            let sizes: Option<Vec<u64>> = dimensions.iter().map(|d| d.as_fixed()).collect();
            match (starts, sizes.as_deref()) {
                (Some(starts), Some(&[n])) if starts.len() as u64 == n => {
                    let starts = Rc::new(starts);
                    for i in 0..starts.len() {
                        out.push(Var {
                            name: format!("{}[{}]", v.name(), i + 1),
                            vr: v.value_reference(),
                            kind: Some(Kind::Real),
                            role: Role::Other,
                            element: Some((i, starts.clone())),
                        });
                    }
                }
                _ if matches!(v.causality(), Causality3::Input | Causality3::Output) => {
                    return Err(format!(
                        "`{}` is an array input or output; only parameter arrays are handled",
                        v.name()
                    )
                    .into())
                }
                _ => out.push(Var {
                    name: v.name().to_owned(),
                    vr: v.value_reference(),
                    kind: None,
                    role: Role::Other,
                    element: None,
                }),
            }
            continue;
        }
        out.push({
            let kind = match v.data_type() {
                VariableType::FmiFloat64 => Some(Kind::Real),
                VariableType::FmiInt32 => Some(Kind::Integer),
                VariableType::FmiBoolean => Some(Kind::Boolean),
                _ => None,
            };
            let role = match v.causality() {
                Causality3::Input
                    if kind == Some(Kind::Real) && v.variability() == Variability::Continuous =>
                {
                    Role::Input
                }
                Causality3::Output => Role::Output,
                _ => Role::Other,
            };
            Var {
                name: v.name().to_owned(),
                vr: v.value_reference(),
                kind,
                role,
                element: None,
            }
        });
    }
    Ok(out)
}

/// What the run sets and reads, worked out from the model description
/// before the FMU is instantiated.
struct Plan {
    variables: Vec<Var>,
    /// The value references of INPUT.csv's columns after `time`.
    input_vrs: Vec<u32>,
    /// Every Real, Integer and Boolean output, in the model description's
    /// order: (name, value reference, kind).
    outputs: Vec<(String, u32, Kind)>,
}

impl Plan {
    fn new(variables: Vec<Var>, input_names: &[String]) -> Res<Self> {
        let mut plan = Plan {
            variables,
            input_vrs: Vec::new(),
            outputs: Vec::new(),
        };
        for name in input_names {
            let var = plan.variable(name)?;
            if var.role != Role::Input {
                return Err(format!("`{name}` is not a continuous Real input").into());
            }
            plan.input_vrs.push(var.vr);
        }
        plan.outputs = plan
            .variables
            .iter()
            .filter(|v| v.role == Role::Output)
            .filter_map(|v| Some((v.name.clone(), v.vr, v.kind?)))
            .collect();
        if !plan.outputs.iter().any(|o| o.2 == Kind::Real) {
            return Err("the model description declares no Real output".into());
        }
        Ok(plan)
    }

    fn variable(&self, name: &str) -> Res<&Var> {
        self.variables
            .iter()
            .find(|v| v.name == name)
            .ok_or_else(|| format!("the model description has no variable `{name}`").into())
    }

    /// The value references of the outputs of one kind, in their order.
    fn output_vrs(&self, kind: Kind) -> Vec<u32> {
        self.outputs
            .iter()
            .filter(|o| o.2 == kind)
            .map(|o| o.1)
            .collect()
    }
}

/// The calls the driver makes on a Co-Simulation instance beyond the
/// version-independent life cycle of the crate's `FmiInstance` (enter and
/// exit initialization mode, terminate, reset): the typed gets and sets,
/// whose names and Boolean type differ between the versions, and the step,
/// whose arguments differ.
trait Slave: FmiInstance {
    /// The FMI functions behind `FmiInstance::enter_initialization_mode`,
    /// `exit_initialization_mode` and `step`, named in error messages.
    const ENTER_INITIALIZATION: &'static str;
    const EXIT_INITIALIZATION: &'static str;
    const DO_STEP: &'static str;
    /// The crate's status of a successful step (`Fmi2Res`, `Fmi3Res`).
    type StepStatus: Debug;

    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Res<()>;
    fn set_integers(&mut self, vrs: &[u32], values: &[i32]) -> Res<()>;
    fn set_booleans(&mut self, vrs: &[u32], values: &[bool]) -> Res<()>;
    fn get_reals(&mut self, vrs: &[u32], values: &mut [f64]) -> Res<()>;
    fn get_integers(&mut self, vrs: &[u32], values: &mut [i32]) -> Res<()>;
    fn get_booleans(&mut self, vrs: &[u32], values: &mut [bool]) -> Res<()>;

    /// One step from `t` by `h`, telling the FMU that its state will not be
    /// set back before `t`; the crate's status (`Fmi2Res`, `Fmi3Res`) or
    /// error.
    fn step(&mut self, t: f64, h: f64) -> Res<Self::StepStatus>;
}

impl Slave for fmi2::instance::InstanceCS {
    const ENTER_INITIALIZATION: &'static str = "fmi2SetupExperiment/fmi2EnterInitializationMode";
    const EXIT_INITIALIZATION: &'static str = "fmi2ExitInitializationMode";
    const DO_STEP: &'static str = "fmi2DoStep";
    type StepStatus = fmi2::Fmi2Res;

    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Res<()> {
        fmi2::instance::Common::set_real(self, vrs, values)?;
        Ok(())
    }
    fn set_integers(&mut self, vrs: &[u32], values: &[i32]) -> Res<()> {
        fmi2::instance::Common::set_integer(self, vrs, values)?;
        Ok(())
    }
    /// FMI 2.0's Boolean is a C int.
    fn set_booleans(&mut self, vrs: &[u32], values: &[bool]) -> Res<()> {
        let ints: Vec<i32> = values.iter().map(|&b| i32::from(b)).collect();
        fmi2::instance::Common::set_boolean(self, vrs, &ints)?;
        Ok(())
    }
    fn get_reals(&mut self, vrs: &[u32], values: &mut [f64]) -> Res<()> {
        fmi2::instance::Common::get_real(self, vrs, values)?;
        Ok(())
    }
    fn get_integers(&mut self, vrs: &[u32], values: &mut [i32]) -> Res<()> {
        fmi2::instance::Common::get_integer(self, vrs, values)?;
        Ok(())
    }
    fn get_booleans(&mut self, vrs: &[u32], values: &mut [bool]) -> Res<()> {
        let mut ints = vec![0; values.len()];
        fmi2::instance::Common::get_boolean(self, vrs, &mut ints)?;
        for (b, i) in values.iter_mut().zip(ints) {
            *b = i != 0;
        }
        Ok(())
    }

    /// `newStep = true`: the step is not a retry of the previous one.
    fn step(&mut self, t: f64, h: f64) -> Res<Self::StepStatus> {
        Ok(fmi2::instance::CoSimulation::do_step(self, t, h, true)?)
    }
}

impl Slave for fmi3::instance::InstanceCS {
    const ENTER_INITIALIZATION: &'static str = "fmi3EnterInitializationMode";
    const EXIT_INITIALIZATION: &'static str = "fmi3ExitInitializationMode";
    const DO_STEP: &'static str = "fmi3DoStep";
    type StepStatus = fmi3::Fmi3Res;

    fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Res<()> {
        self.set_float64(vrs, values)?;
        Ok(())
    }
    fn set_integers(&mut self, vrs: &[u32], values: &[i32]) -> Res<()> {
        self.set_int32(vrs, values)?;
        Ok(())
    }
    fn set_booleans(&mut self, vrs: &[u32], values: &[bool]) -> Res<()> {
        self.set_boolean(vrs, values)?;
        Ok(())
    }
    fn get_reals(&mut self, vrs: &[u32], values: &mut [f64]) -> Res<()> {
        self.get_float64(vrs, values)?;
        Ok(())
    }
    fn get_integers(&mut self, vrs: &[u32], values: &mut [i32]) -> Res<()> {
        self.get_int32(vrs, values)?;
        Ok(())
    }
    fn get_booleans(&mut self, vrs: &[u32], values: &mut [bool]) -> Res<()> {
        self.get_boolean(vrs, values)?;
        Ok(())
    }

    /// `noSetFMUStatePriorToCurrentPoint = true`, FMI 3.0's counterpart of
    /// `newStep`. fmi3DoStep also reports whether the FMU needs event
    /// handling, asks to terminate, returned early, and the time it
    /// reached: with event mode and early return not allowed, a completed
    /// step must report none of the first three and `t + h` (the FMI 2.0
    /// run, which has no such flags, is compared with this one), so a
    /// successful step that reports anything else is an error here.
    fn step(&mut self, t: f64, h: f64) -> Res<Self::StepStatus> {
        let (mut event, mut terminate, mut early) = (false, false, false);
        let mut last = f64::NAN;
        let status = fmi3::CoSimulation::do_step(
            self,
            t,
            h,
            true,
            &mut event,
            &mut terminate,
            &mut early,
            &mut last,
        )?;
        if event || terminate || early || last != t + h {
            return Err(format!(
                "{status:?} with eventHandlingNeeded = {event}, terminateSimulation = \
                 {terminate}, earlyReturn = {early}, lastSuccessfulTime = {last:?} \
                 (t + h = {:?})",
                t + h
            )
            .into());
        }
        Ok(status)
    }
}

/// The crate's error from an `FmiInstance` call, as the crate displays it.
fn fmi_error<S: FmiInstance>(e: <S::Status as FmiStatus>::Err) -> fmi::Error {
    e.into()
}

/// The run, the same for both versions: parameters, initialization with a
/// stop time, the steps with the outputs recorded, and the step past the
/// stop time.
fn drive<S: Slave>(
    mut inst: S,
    plan: &Plan,
    rows: &[Vec<f64>],
    assignments: &[String],
    out: &str,
) -> Res<()> {
    // the arrays whose elements are assigned, from their start values,
    // set as a whole after the scalars (by value reference, in order)
    let mut arrays: Vec<(u32, Vec<f64>)> = Vec::new();
    for assignment in assignments {
        let (name, value) = assignment
            .split_once('=')
            .ok_or_else(|| format!("`{assignment}` is not NAME=VALUE"))?;
        let var = plan.variable(name)?;
        if let Some((index, starts)) = &var.element {
            let at = match arrays.iter().position(|(vr, _)| *vr == var.vr) {
                Some(at) => at,
                None => {
                    arrays.push((var.vr, starts.to_vec()));
                    arrays.len() - 1
                }
            };
            arrays[at].1[*index] = value.parse()?;
            continue;
        }
        let vr = [var.vr];
        match var.kind {
            Some(Kind::Real) => inst.set_reals(&vr, &[value.parse()?]),
            Some(Kind::Integer) => inst.set_integers(&vr, &[value.parse()?]),
            Some(Kind::Boolean) => {
                let b = match value {
                    "true" | "1" => true,
                    "false" | "0" => false,
                    _ => return Err(format!("`{value}` is not a Boolean").into()),
                };
                inst.set_booleans(&vr, &[b])
            }
            None => return Err(format!("`{name}` is neither Real, Integer nor Boolean").into()),
        }
        .map_err(|e| format!("setting {name}={value}: {e}"))?;
    }
    for (vr, values) in &arrays {
        inst.set_reals(&[*vr], values)
            .map_err(|e| format!("setting the array of value reference {vr}: {e}"))?;
    }

    let start = rows[0][0];
    let stop = rows[rows.len() - 1][0];
    inst.enter_initialization_mode(None, start, Some(stop))
        .map_err(|e| format!("{}: {}", S::ENTER_INITIALIZATION, fmi_error::<S>(e)))?;
    inst.exit_initialization_mode()
        .map_err(|e| format!("{}: {}", S::EXIT_INITIALIZATION, fmi_error::<S>(e)))?;

    let (real_vrs, int_vrs, bool_vrs) = (
        plan.output_vrs(Kind::Real),
        plan.output_vrs(Kind::Integer),
        plan.output_vrs(Kind::Boolean),
    );
    let mut csv = String::from("time");
    for (name, _, _) in &plan.outputs {
        write!(csv, ",{name}")?;
    }
    csv.push('\n');
    let mut reals = vec![0.0; real_vrs.len()];
    let mut ints = vec![0; int_vrs.len()];
    let mut bools = vec![false; bool_vrs.len()];
    let mut record = |inst: &mut S, t: f64| -> Res<()> {
        inst.get_reals(&real_vrs, &mut reals)?;
        if !int_vrs.is_empty() {
            inst.get_integers(&int_vrs, &mut ints)?;
        }
        if !bool_vrs.is_empty() {
            inst.get_booleans(&bool_vrs, &mut bools)?;
        }
        write!(csv, "{t:?}")?;
        let (mut r, mut i, mut b) = (reals.iter(), ints.iter(), bools.iter());
        for (_, _, kind) in &plan.outputs {
            match kind {
                Kind::Real => write!(csv, ",{:?}", r.next().unwrap())?,
                Kind::Integer => write!(csv, ",{}", i.next().unwrap())?,
                Kind::Boolean => write!(csv, ",{}", i32::from(*b.next().unwrap()))?,
            }
        }
        csv.push('\n');
        Ok(())
    };
    record(&mut inst, start)?;
    for pair in rows.windows(2) {
        let (now, next) = (&pair[0], &pair[1]);
        inst.set_reals(&plan.input_vrs, &now[1..])?;
        inst.step(now[0], next[0] - now[0])
            .map_err(|e| format!("{} at t = {}: {e}", S::DO_STEP, now[0]))?;
        record(&mut inst, next[0])?;
    }
    fs::write(out, csv)?;

    let past = inst.step(stop, stop - rows[rows.len() - 2][0]);
    println!("step past stop: {past:?}");
    if past.is_err() {
        inst.reset().map_err(fmi_error::<S>)?;
    } else {
        inst.terminate().map_err(fmi_error::<S>)?;
    }
    Ok(())
}
