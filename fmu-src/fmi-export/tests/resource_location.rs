//! `fmuResourceLocation` through `fmi2Instantiate`: a model that reads no
//! resources (every model of this project) is instantiated whatever the
//! location, NULL and malformed URIs included, and logs what it was given
//! at the debug level (`logCalls`); a model that reads its resources is
//! refused a location that names no directory, with the reason, and gets
//! the directory of a good one as a path of this platform.

use fmi_export::ffi::*;
use fmi_export::{
    Capabilities, DefaultExperiment, Model, ModelFactory, ModelInfo, Values, Variable,
};
use std::cell::RefCell;
use std::ffi::{CStr, CString};
use std::ptr::null;

static VARIABLES: [Variable; 2] = [
    Variable::input(0, "u", 0.0, "", 1.0, "input"),
    Variable::output(1, "y", "", "the state", &[]),
];

const fn info(name: &'static str, guid: &'static str) -> ModelInfo {
    ModelInfo {
        model_name: name,
        model_identifier: name,
        guid,
        description: "test model",
        source: "test",
        variables: &VARIABLES,
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 0.1,
        },
        capabilities: Capabilities::FULL,
        co_simulation_states: &[],
        model_exchange: None,
    }
}
static PLAIN: ModelInfo = info("Plain", "{plain}");
static READER: ModelInfo = info("Reader", "{reader}");

thread_local! {
    /// The directories handed to `Reader` models on this thread (each
    /// test runs on a thread of its own), in order.
    static DIRECTORIES: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
}

fn directories() -> Vec<String> {
    DIRECTORIES.with(|d| d.borrow().clone())
}

#[derive(Clone)]
struct Toy {
    reads_resources: bool,
    s: f64,
}

impl Model for Toy {
    fn info(&self) -> &'static ModelInfo {
        if self.reads_resources {
            &READER
        } else {
            &PLAIN
        }
    }
    fn initialize(&mut self, _: &Values) -> Result<(), String> {
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(1, self.s);
    }
    fn do_step(&mut self, _: &Values, _: &[f64], _: f64) -> Result<(), String> {
        Ok(())
    }
    toy_instance::one_value_toy_state!();
    fn needs_resources(&self) -> bool {
        self.reads_resources
    }
    fn set_resource_dir(&mut self, dir: &str) {
        assert!(
            self.reads_resources,
            "only a model that reads resources gets the directory"
        );
        DIRECTORIES.with(|d| d.borrow_mut().push(dir.to_string()));
    }
}

static REGISTRY: [ModelFactory; 2] = [
    ModelFactory {
        info: &PLAIN,
        create: || {
            Box::new(Toy {
                reads_resources: false,
                s: 0.0,
            })
        },
        create_model_exchange: None,
    },
    ModelFactory {
        info: &READER,
        create: || {
            Box::new(Toy {
                reads_resources: true,
                s: 0.0,
            })
        },
        create_model_exchange: None,
    },
];
fmi_export::export_fmi2!(&REGISTRY[..]);
use fmi2_exports::*;

#[path = "support/toy_instance.rs"]
#[allow(dead_code)] // its instance helpers: this test goes through the C API
mod toy_instance;

#[path = "support/recording_logger.rs"]
mod recording_logger;
use recording_logger::{callbacks, log_clear, log_snapshot};

/// Instantiate `guid` with `location` (None: a NULL pointer) and logging
/// on or off; the instance (NULL if refused) and the messages logged.
fn instantiate(
    guid: &CStr,
    location: Option<&str>,
    logging_on: bool,
) -> (fmi2Component, Vec<(i32, String, String)>) {
    log_clear();
    let callbacks = callbacks();
    let location = location.map(|l| CString::new(l).unwrap());
    let c = unsafe {
        fmi2Instantiate(
            c"probe".as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            location.as_ref().map_or(null(), |l| l.as_ptr()),
            &callbacks,
            fmi2False,
            if logging_on { fmi2True } else { fmi2False },
        )
    };
    (c, log_snapshot())
}

/// A Windows path in the binary's own convention.
fn native(windows: &str, unix: &str) -> String {
    if cfg!(windows) {
        windows.to_string()
    } else {
        unix.to_string()
    }
}

#[test]
fn a_model_without_resources_takes_any_location_and_logs_it() {
    let cases: Vec<(Option<&str>, String)> = vec![
        (
            Some("file:///C:/fmu%20tests/LuGre/resources"),
            format!(
                "fmuResourceLocation \"file:///C:/fmu%20tests/LuGre/resources\" is the directory \"{}\" (not read: this model uses no resources)",
                native("C:\\fmu tests\\LuGre\\resources", "/C:/fmu tests/LuGre/resources")
            ),
        ),
        (
            Some("file:/home/me/fmu/resources"),
            format!(
                "is the directory \"{}\"",
                native("\\home\\me\\fmu\\resources", "/home/me/fmu/resources")
            ),
        ),
        (
            Some("resources"),
            "fmuResourceLocation \"resources\" is not a file: URI; accepted: this model uses no resources".into(),
        ),
        (
            Some("file:///C:/a%2"),
            "malformed percent escape at character 13 (expected %XX, two hexadecimal digits); accepted".into(),
        ),
        (
            Some(""),
            "fmuResourceLocation \"\" is not a file: URI; accepted".into(),
        ),
        (
            None,
            "argument fmuResourceLocation is NULL; accepted: this model uses no resources".into(),
        ),
    ];
    for (location, expected) in cases {
        // The message is a format string: its '%' come doubled (C
        // importers print it through vsnprintf).
        let expected = expected.replace('%', "%%");
        let (c, log) = instantiate(c"{plain}", location, true);
        assert!(!c.is_null(), "{location:?} refused: {log:?}");
        assert!(
            log.iter().any(|(s, cat, m)| *s == fmi2Status::fmi2OK as i32
                && cat == "logCalls"
                && m.starts_with("fmi2Instantiate: ")
                && m.contains(&expected)),
            "{location:?}: no logCalls message containing {expected:?} in {log:?}"
        );
        assert!(log.iter().all(|(s, _, _)| *s == 0), "{log:?}");
        unsafe { fmi2FreeInstance(c) };

        // With logging off, the same, silently.
        let (c, log) = instantiate(c"{plain}", location, false);
        assert!(!c.is_null());
        assert!(log.is_empty(), "{log:?}");
        unsafe { fmi2FreeInstance(c) };
    }
    assert!(directories().is_empty());
}

#[test]
fn a_model_that_reads_resources_needs_a_directory() {
    for (location, reason) in [
        (Some("resources"), "\"resources\" is not a file: URI"),
        (
            Some("http://example.org/fmu/resources"),
            "is not a file: URI",
        ),
        (Some("file:///C:/a%G0"), "malformed percent escape"),
        (Some("file:relative/resources"), "has no absolute path"),
        (None, "argument fmuResourceLocation is NULL"),
    ] {
        // Refused even with logging off: errors are always logged.
        for logging_on in [true, false] {
            let (c, log) = instantiate(c"{reader}", location, logging_on);
            assert!(c.is_null(), "{location:?} accepted");
            let errors: Vec<&String> = log
                .iter()
                .filter(|(s, cat, _)| *s == fmi2Status::fmi2Error as i32 && cat == "logStatusError")
                .map(|(_, _, m)| m)
                .collect();
            assert!(
                errors.len() == 1
                    && errors[0].starts_with("fmi2Instantiate: ")
                    && errors[0].contains(reason)
                    && errors[0].contains("Reader reads its resources from there"),
                "{location:?}: {log:?}"
            );
        }
    }
    assert!(directories().is_empty());

    let (c, log) = instantiate(
        c"{reader}",
        Some("file:///C:/fmu%20tests/R%C3%A9f/resources/"),
        true,
    );
    assert!(!c.is_null(), "{log:?}");
    let dir = native(
        "C:\\fmu tests\\Réf\\resources\\",
        "/C:/fmu tests/Réf/resources/",
    );
    assert_eq!(directories(), vec![dir.clone()]);
    assert!(
        log.iter()
            .any(|(_, _, m)| m.ends_with(&format!("is the directory \"{dir}\""))),
        "{log:?}"
    );
    // The instance runs as any other.
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::fmi2OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, fmi2True), fmi2Status::fmi2OK);
        fmi2FreeInstance(c);
    }
}
