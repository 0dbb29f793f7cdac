//! Reading a `SystemStructure.ssd` into a [`SystemFile`]: one function per
//! element kind (the system, its components and their connectors, the
//! parameter bindings and their parameter sets, the connections, the
//! default experiment, our annotation), called in document order by
//! [`SystemFile::parse`]. Every refusal names the file, the line and the
//! element. Uses the raw elements of [`super::xml`] and the definitions
//! of [`super`]; opens no FMU (that is [`super::check`]).

use super::xml::{
    self, Lines, RawAnnotations, RawComponent, RawConnection, RawConnector, RawDefaultExperiment,
    RawElements, RawParameter, RawParameterBinding, RawParameterBindings, RawParameterSet,
    RawSimulation, RawSystem, SyntaxError,
};
use super::{
    element, error, list, parse_number, read_parameter_set, ComponentDef, ConnectionDef,
    ConnectorDef, ConnectorKind, ParameterDef, Settings, SspError, SystemFile, Value,
    ANNOTATION_TYPE, FMU_TYPE, MASTERS, NS_SSD,
};

/// Where the elements of the ssd are, for messages.
struct Place<'a> {
    ssd: &'a str,
    lines: &'a Lines,
}

impl Place<'_> {
    /// `ssd:line: what` for the `k`-th element `name` of the ssd
    /// (`ssd: what` when its line is not known).
    fn at(&self, name: &str, k: usize, what: String) -> String {
        match self.lines.of(name, k) {
            Some(line) => format!("{}:{line}: {what}", self.ssd),
            None => format!("{}: {what}", self.ssd),
        }
    }
}

/// The elements met so far of the kinds numbered across components, so
/// that each is found by its index in the document.
#[derive(Default)]
struct Counts {
    component: usize,
    connector: usize,
    binding: usize,
}

/// A parameter binding with its owner (`None`: the system) and its index
/// among the ssd's `ParameterBinding` elements.
type Binding = (Option<String>, RawParameterBinding, usize);

impl SystemFile {
    /// Parse the text of an ssd (sources relative to `base`): each kind of
    /// element in turn, in the order the checks were always made.
    pub(super) fn parse(&mut self, text: &str) -> Result<(), SspError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let syntax =
            |e: SyntaxError| error(format!("{}:{}:{}", self.ssd, e.line, e.column), e.message);
        let (_, lines) =
            xml::first_pass(text, "SystemStructureDescription", NS_SSD).map_err(syntax)?;
        let raw: xml::RawSsd = xml::deserialize(text).map_err(syntax)?;
        let ssd = self.ssd.clone();
        let place = Place {
            ssd: &ssd,
            lines: &lines,
        };
        self.name = raw.name.clone().unwrap_or_default();
        let system = top_system(raw.system, &raw.name, &place)?;
        let component_bindings = self.elements(system.elements, &place)?;
        if self.components.is_empty() {
            return Err(error(
                place.at("System", 0, element("System", &[("name", &system.name)])),
                "the system has no components",
            ));
        }
        self.parameter_bindings(system.parameter_bindings, component_bindings, &place)?;
        for (k, c) in system
            .connections
            .into_iter()
            .flat_map(|c| c.list)
            .enumerate()
        {
            self.connections.push(connection(c, k, &place)?);
        }
        if let Some(e) = &raw.default_experiment {
            self.default_experiment(e, &place)?;
        }
        let annotations = raw
            .default_experiment
            .and_then(|e| e.annotations)
            .into_iter()
            .chain(raw.annotations);
        if let Some((location, simulation)) = our_annotation(annotations, &place)? {
            self.settings = settings(location, simulation)?;
        }
        Ok(())
    }

    /// The system's `ssd:Elements`: its components, added in document
    /// order (nested systems and signal dictionaries refused). Returns
    /// the components' parameter bindings, numbered among them.
    fn elements(
        &mut self,
        elements: Option<RawElements>,
        place: &Place,
    ) -> Result<Vec<Binding>, SspError> {
        let mut counts = Counts::default();
        let mut bindings = Vec::new();
        for item in elements.map(|e| e.items).unwrap_or_default() {
            let c = match item {
                xml::RawElement::Component(c) => c,
                xml::RawElement::System(s) => {
                    return Err(error(
                        place.at("System", 1, element("System", &[("name", &s.name)])),
                        "nested systems are not supported: put every component in the one top-level system",
                    ))
                }
                xml::RawElement::SignalDictionaryReference(s) => {
                    return Err(error(
                        place.at(
                            "SignalDictionaryReference",
                            0,
                            element("SignalDictionaryReference", &[("name", &s.name)]),
                        ),
                        "signal dictionaries are not supported",
                    ))
                }
            };
            let component = self.component(c, &mut counts, &mut bindings, place)?;
            self.components.push(component);
        }
        Ok(bindings)
    }

    /// One `ssd:Component` with its connectors; its parameter bindings
    /// are added to `bindings`.
    fn component(
        &self,
        c: RawComponent,
        counts: &mut Counts,
        bindings: &mut Vec<Binding>,
        place: &Place,
    ) -> Result<ComponentDef, SspError> {
        let shown = element("Component", &[("name", &c.name), ("source", &c.source)]);
        let location = place.at("Component", counts.component, shown);
        counts.component += 1;
        let name = self.component_name(&c, &location)?;
        check_component_type(&c, &location)?;
        let source_text = c
            .source
            .clone()
            .ok_or_else(|| error(&location, "the source attribute is missing"))?;
        let source = self
            .resolve(&source_text)
            .map_err(|m| error(&location, format!("source=\"{source_text}\": {m}")))?;
        let mut connectors: Vec<ConnectorDef> = Vec::new();
        for raw in c.connectors.map(|c| c.list).unwrap_or_default() {
            let shown = element("Connector", &[("name", &raw.name), ("kind", &raw.kind)]);
            let location = place.at(
                "Connector",
                counts.connector,
                format!("component `{name}`: {shown}"),
            );
            counts.connector += 1;
            let connector = connector(raw, location, &connectors)?;
            connectors.push(connector);
        }
        for b in c.parameter_bindings.map(|b| b.list).unwrap_or_default() {
            bindings.push((Some(name.clone()), b, counts.binding));
            counts.binding += 1;
        }
        Ok(ComponentDef {
            name,
            source_text,
            source,
            connectors,
            location,
        })
    }

    /// A component's name: given, without a `.`, not used before.
    fn component_name(&self, c: &RawComponent, location: &str) -> Result<String, SspError> {
        let name = c
            .name
            .clone()
            .filter(|n| !n.is_empty())
            .ok_or_else(|| error(location, "the name attribute is missing"))?;
        if name.contains('.') {
            return Err(error(
                location,
                format!("component name `{name}` contains a `.`, which separates component and variable in `component.variable`"),
            ));
        }
        if let Some(first) = self.components.iter().find(|x| x.name == name) {
            return Err(error(
                location,
                format!(
                    "component name `{name}` is already used by {}",
                    first.location
                ),
            ));
        }
        Ok(name)
    }

    /// The parameters of every binding, in the order they apply:
    /// component bindings, then the system's, which win (SSP 1.0 §5.3.5).
    /// The system's come first in the document (its ParameterBindings
    /// precede its Elements), so the bindings and their inline parameters
    /// are numbered with the system's first.
    fn parameter_bindings(
        &mut self,
        system: Option<RawParameterBindings>,
        components: Vec<Binding>,
        place: &Place,
    ) -> Result<(), SspError> {
        let system: Vec<Binding> = system
            .map(|b| b.list)
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(k, b)| (None, b, k))
            .collect();
        let n_system = system.len();
        let ordered = system.into_iter().chain(
            components
                .into_iter()
                .map(|(owner, b, k)| (owner, b, k + n_system)),
        );
        let mut first_parameter = 0;
        let mut applied: Vec<(Option<String>, Vec<ParameterDef>)> = Vec::new();
        for (owner, b, k) in ordered {
            let inline = b
                .values
                .as_ref()
                .and_then(|v| v.set.as_ref())
                .and_then(|s| s.parameters.as_ref())
                .map_or(0, |p| p.list.len());
            let shown = element(
                "ParameterBinding",
                &[("source", &b.source), ("prefix", &b.prefix)],
            );
            let owner_text = match &owner {
                Some(c) => format!("component `{c}`: "),
                None => String::new(),
            };
            let location = place.at("ParameterBinding", k, format!("{owner_text}{shown}"));
            if let (Some(source), false) = (&b.source, self.in_archive) {
                if let Ok(path) = self.resolve(source) {
                    self.parameter_files.push(path);
                }
            }
            let params = self.binding(owner.as_deref(), b, &location, place, first_parameter)?;
            first_parameter += inline;
            applied.push((owner, params));
        }
        let (system_params, component_params): (Vec<_>, Vec<_>) =
            applied.into_iter().partition(|(owner, _)| owner.is_none());
        for (_, params) in component_params.into_iter().chain(system_params) {
            self.parameters.extend(params);
        }
        Ok(())
    }

    /// The parameters of one binding (inline set or `.ssv` source) of the
    /// component `owner` (`None`: of the system); `location` names the
    /// binding, `first_parameter` is the index of its first inline
    /// `Parameter` element in the ssd.
    fn binding(
        &self,
        owner: Option<&str>,
        b: RawParameterBinding,
        location: &str,
        place: &Place,
        first_parameter: usize,
    ) -> Result<Vec<ParameterDef>, SspError> {
        check_binding(&b, location)?;
        let prefix = b.prefix.clone().unwrap_or_default();
        let inline = b.values.and_then(|v| v.set);
        let (set, file) = match (&b.source, inline) {
            (Some(_), Some(_)) => {
                return Err(error(
                    location,
                    "the binding has both a source and inline ParameterValues; give one",
                ))
            }
            (None, None) => {
                return Err(error(
                    location,
                    "the binding has neither a source nor inline ParameterValues",
                ))
            }
            (None, Some(set)) => (set, None),
            (Some(source), None) => {
                let (set, lines, shown) = self.binding_source(source, location)?;
                (set, Some((lines, shown)))
            }
        };
        self.parameter_set(owner, set, &prefix, |k, shown| match &file {
            Some((lines, f)) => match lines.of("Parameter", k) {
                Some(line) => format!("{f}:{line}: {shown}"),
                None => format!("{f}: {shown}"),
            },
            None => place.at("Parameter", first_parameter + k, shown.to_string()),
        })
    }

    /// The `.ssv` file a binding's `source` names, read, with the lines
    /// of its elements and its name for messages.
    fn binding_source(
        &self,
        source: &str,
        location: &str,
    ) -> Result<(RawParameterSet, Lines, String), SspError> {
        let path = self
            .resolve(source)
            .map_err(|m| error(location, format!("source=\"{source}\": {m}")))?;
        let shown = if self.in_archive {
            format!("{}!/{}", self.path.display(), source)
        } else {
            path.display().to_string()
        };
        if !path.is_file() {
            return Err(error(
                location,
                format!("source=\"{source}\": {shown} does not exist"),
            ));
        }
        let (set, lines) = read_parameter_set(&path, &shown)?;
        Ok((set, lines, shown))
    }

    /// The parameters of `set` for the component `owner` (`None`: of the
    /// system, named `component.variable`), their names after `prefix`;
    /// `locate(k, element)` says where parameter `k` is, for messages.
    pub(super) fn parameter_set(
        &self,
        owner: Option<&str>,
        set: RawParameterSet,
        prefix: &str,
        locate: impl Fn(usize, &str) -> String,
    ) -> Result<Vec<ParameterDef>, SspError> {
        let parameters = set.parameters.map(|p| p.list).unwrap_or_default();
        let mut out = Vec::with_capacity(parameters.len());
        for (k, p) in parameters.into_iter().enumerate() {
            let here = locate(k, &element("Parameter", &[("name", &p.name)]));
            let name = p
                .name
                .clone()
                .ok_or_else(|| error(&here, "the name attribute is missing"))?;
            let full = format!("{prefix}{name}");
            let (value, unit) = parameter_value(p, &here)?;
            // a component binding names the component's variables; a system
            // binding names `component.variable`
            let (component, variable) = match owner {
                Some(c) => (c.to_string(), full),
                None => self.system_parameter(&full, &here)?,
            };
            out.push(ParameterDef {
                component,
                variable,
                value,
                unit,
                location: here,
            });
        }
        Ok(out)
    }

    /// The component and the variable a system binding's parameter
    /// `full` names: the longest component name followed by a `.`.
    fn system_parameter(&self, full: &str, here: &str) -> Result<(String, String), SspError> {
        let found = self
            .components
            .iter()
            .filter(|c| full.starts_with(&format!("{}.", c.name)))
            .max_by_key(|c| c.name.len());
        match found {
            Some(c) => Ok((c.name.clone(), full[c.name.len() + 1..].to_string())),
            None => {
                let names: Vec<String> = self.components.iter().map(|c| c.name.clone()).collect();
                Err(error(
                    here,
                    format!(
                        "parameter `{full}` of a system binding names no component: system-level names are component.variable (components: {})",
                        list(&names)
                    ),
                ))
            }
        }
    }

    /// `ssd:DefaultExperiment`: the start and stop times.
    fn default_experiment(
        &mut self,
        e: &RawDefaultExperiment,
        place: &Place,
    ) -> Result<(), SspError> {
        let location = place.at(
            "DefaultExperiment",
            0,
            element(
                "DefaultExperiment",
                &[("startTime", &e.start_time), ("stopTime", &e.stop_time)],
            ),
        );
        let time = |name: &str, text: &Option<String>| -> Result<Option<f64>, SspError> {
            match text {
                None => Ok(None),
                Some(t) => parse_number(t).map(Some).ok_or_else(|| {
                    error(&location, format!("{name}=\"{t}\" is not a finite number"))
                }),
            }
        };
        self.start_time = time("startTime", &e.start_time)?;
        self.stop_time = time("stopTime", &e.stop_time)?;
        if let (Some(a), Some(b)) = (self.start_time, self.stop_time) {
            if b <= a {
                return Err(error(
                    &location,
                    format!("stopTime {b} is not after startTime {a}"),
                ));
            }
        }
        Ok(())
    }
}

/// The ssd's one `ssd:System`: refused when missing, or when it has
/// connectors of its own (there is no outside to connect them to).
fn top_system(
    system: Option<RawSystem>,
    root_name: &Option<String>,
    place: &Place,
) -> Result<RawSystem, SspError> {
    let Some(system) = system else {
        return Err(error(
            place.at(
                "SystemStructureDescription",
                0,
                element("SystemStructureDescription", &[("name", root_name)]),
            ),
            "it has no <ssd:System> element",
        ));
    };
    if let Some(c) = system.connectors.as_ref().and_then(|c| c.list.first()) {
        let system_element = element("System", &[("name", &system.name)]);
        return Err(error(
            place.at("Connector", 0, element("Connector", &[("name", &c.name), ("kind", &c.kind)])),
            format!(
                "connectors of the system {system_element} are not supported: a system file here is the top level, with nothing outside it; drive unconnected inputs with `fricsim run --input`"
            ),
        ));
    }
    Ok(system)
}

/// A component's `type` (an FMU) and `implementation` (Co-Simulation).
fn check_component_type(c: &RawComponent, location: &str) -> Result<(), SspError> {
    let kind = c.kind.as_deref().unwrap_or(FMU_TYPE);
    if kind != FMU_TYPE {
        return Err(error(
            location,
            format!("type=\"{kind}\" is not supported: only FMUs ({FMU_TYPE})"),
        ));
    }
    if let Some(imp) = c.implementation.as_deref() {
        if imp != "any" && imp != "CoSimulation" {
            return Err(error(
                location,
                format!("implementation=\"{imp}\" is not supported: fricsim runs FMUs as Co-Simulation (\"CoSimulation\" or \"any\")"),
            ));
        }
    }
    Ok(())
}

/// One `ssd:Connector` of a component whose connectors so far are
/// `declared`.
fn connector(
    raw: RawConnector,
    location: String,
    declared: &[ConnectorDef],
) -> Result<ConnectorDef, SspError> {
    let name = raw
        .name
        .clone()
        .ok_or_else(|| error(&location, "the name attribute is missing"))?;
    if declared.iter().any(|x| x.name == name) {
        return Err(error(
            &location,
            format!("connector `{name}` is declared twice"),
        ));
    }
    let kind_text = raw.kind.clone().unwrap_or_default();
    let kind = ConnectorKind::parse(&kind_text).ok_or_else(|| {
        error(
            &location,
            format!("kind=\"{kind_text}\" is not supported (input, output, parameter, calculatedParameter)"),
        )
    })?;
    let type_name = connector_type(&raw, &location)?;
    Ok(ConnectorDef {
        name,
        kind,
        type_name,
        unit: raw.real.and_then(|r| r.unit),
        location,
    })
}

/// The type a connector gives (`ssc:Real`, …), if it gives one.
fn connector_type(raw: &RawConnector, location: &str) -> Result<Option<&'static str>, SspError> {
    Ok(if raw.real.is_some() {
        Some("Real")
    } else if raw.integer.is_some() {
        Some("Integer")
    } else if raw.boolean.is_some() {
        Some("Boolean")
    } else if raw.string.is_some() {
        Some("String")
    } else if raw.enumeration.is_some() || raw.binary.is_some() {
        return Err(error(
            location,
            "Enumeration and Binary connectors are not supported",
        ));
    } else {
        None
    })
}

/// A binding's `type`, `sourceBase` and the parameter mapping it must not
/// have.
fn check_binding(b: &RawParameterBinding, location: &str) -> Result<(), SspError> {
    if let Some(kind) = b.kind.as_deref() {
        if kind != "application/x-ssp-parameter-set" {
            return Err(error(
                location,
                format!("type=\"{kind}\" is not supported: only application/x-ssp-parameter-set"),
            ));
        }
    }
    if b.mapping.is_some() {
        return Err(error(location, "parameter mappings (<ssd:ParameterMapping>) are not supported: use the variable names in the parameter set"));
    }
    if let Some(base) = b.source_base.as_deref() {
        if base != "SSD" {
            return Err(error(location, format!("sourceBase=\"{base}\" is not supported: sources are relative to the ssd (\"SSD\")")));
        }
    }
    Ok(())
}

/// A parameter's value element (`ssv:Real`, …) and its unit.
fn parameter_value(p: RawParameter, here: &str) -> Result<(Value, Option<String>), SspError> {
    let (kind, raw) = if let Some(v) = p.real {
        ("Real", v)
    } else if let Some(v) = p.integer {
        ("Integer", v)
    } else if let Some(v) = p.boolean {
        ("Boolean", v)
    } else if let Some(v) = p.string {
        ("String", v)
    } else if p.enumeration.is_some() || p.binary.is_some() {
        return Err(error(
            here,
            "Enumeration and Binary parameter values are not supported",
        ));
    } else {
        return Err(error(
            here,
            "the parameter has no value element (ssv:Real, ssv:Integer, ssv:Boolean or ssv:String)",
        ));
    };
    let text = raw
        .value
        .ok_or_else(|| error(here, format!("<ssv:{kind}> has no value attribute")))?;
    let value = match kind {
        "Real" => Value::Real(parse_number(&text).ok_or_else(|| {
            error(
                here,
                format!("<ssv:Real value=\"{text}\">: not a finite number"),
            )
        })?),
        "Integer" => Value::Integer(text.trim().parse().map_err(|_| {
            error(
                here,
                format!("<ssv:Integer value=\"{text}\">: not a 32-bit integer"),
            )
        })?),
        "Boolean" => Value::Boolean(match text.trim() {
            "true" | "1" => true,
            "false" | "0" => false,
            _ => {
                return Err(error(
                    here,
                    format!("<ssv:Boolean value=\"{text}\">: not true, false, 1 or 0"),
                ))
            }
        }),
        _ => Value::String(text),
    };
    Ok((value, raw.unit))
}

/// One `ssd:Connection`, the `k`-th: its two ends as written (ordered
/// by data flow only when checked against the FMUs).
fn connection(c: RawConnection, k: usize, place: &Place) -> Result<ConnectionDef, SspError> {
    let shown = element(
        "Connection",
        &[
            ("startElement", &c.start_element),
            ("startConnector", &c.start_connector),
            ("endElement", &c.end_element),
            ("endConnector", &c.end_connector),
        ],
    );
    let location = place.at("Connection", k, shown);
    let transformation = if c.linear.is_some() {
        Some("LinearTransformation")
    } else if c.boolean_mapping.is_some() {
        Some("BooleanMappingTransformation")
    } else if c.integer_mapping.is_some() {
        Some("IntegerMappingTransformation")
    } else if c.enumeration_mapping.is_some() {
        Some("EnumerationMappingTransformation")
    } else {
        None
    };
    let start = c
        .start_connector
        .ok_or_else(|| error(&location, "the startConnector attribute is missing"))?;
    let end = c
        .end_connector
        .ok_or_else(|| error(&location, "the endConnector attribute is missing"))?;
    Ok(ConnectionDef {
        start: (c.start_element, start),
        end: (c.end_element, end),
        transformation,
        location,
    })
}

/// Our annotation ([`ANNOTATION_TYPE`]) among `annotations` (those of
/// `ssd:DefaultExperiment`, then the root's: numbered in document order),
/// with its location; another tool's annotations are passed over, a
/// second of ours refused.
fn our_annotation(
    annotations: impl Iterator<Item = RawAnnotations>,
    place: &Place,
) -> Result<Option<(String, RawSimulation)>, SspError> {
    let mut found: Option<(String, RawSimulation)> = None;
    for (k_all, a) in annotations.flat_map(|a| a.list).enumerate() {
        let location = place.at(
            "Annotation",
            k_all,
            element("ssc:Annotation", &[("type", &a.kind)]),
        );
        if a.kind.as_deref() != Some(ANNOTATION_TYPE) {
            continue; // another tool's annotation
        }
        if let Some((first, _)) = &found {
            return Err(error(
                &location,
                format!("a second {ANNOTATION_TYPE} annotation (the first is at {first})"),
            ));
        }
        let simulation = a.simulation.ok_or_else(|| {
            error(
                &location,
                format!("the {ANNOTATION_TYPE} annotation has no <Simulation> element"),
            )
        })?;
        found = Some((location, simulation));
    }
    Ok(found)
}

/// The settings of our annotation's `Simulation` element at `location`:
/// step size, master, the signals to plot and record.
fn settings(location: String, s: RawSimulation) -> Result<Settings, SspError> {
    let shown = format!(
        "{location}: {}",
        element(
            "Simulation",
            &[("stepSize", &s.step_size), ("master", &s.master)]
        )
    );
    let mut settings = Settings::default();
    if let Some(t) = &s.step_size {
        let h = parse_number(t)
            .filter(|h| *h > 0.0)
            .ok_or_else(|| error(&shown, format!("stepSize=\"{t}\" is not a positive number")))?;
        settings.step_size = Some(h);
    }
    if let Some(m) = &s.master {
        if !MASTERS.contains(&m.as_str()) {
            return Err(error(
                &shown,
                format!("master=\"{m}\" is not one of {}", MASTERS.join(", ")),
            ));
        }
        settings.master = Some(m.clone());
    }
    for item in s.items {
        let (what, signal, list) = match item {
            xml::RawSimulationItem::Plot(p) => ("Plot", p.signal, &mut settings.plot),
            xml::RawSimulationItem::Record(r) => ("Record", r.signal, &mut settings.record),
        };
        let signal = signal.ok_or_else(|| {
            error(
                &shown,
                format!("a <{what}> element has no signal attribute"),
            )
        })?;
        list.push(signal);
    }
    settings.location = Some(location);
    Ok(settings)
}
