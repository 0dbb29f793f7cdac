//! The host and the shipped FMUs' logging together: categories switched per
//! instance with `fmi2SetDebugLogging` reach the host's log attributed to
//! the instance that sent them (`[name] status [category]: message`), and
//! an FMU error carries the FMU's message and the instance name.

use crate::common;
use fricsim::fmu::{Fmu, Status};

#[test]
fn each_instance_logs_only_its_switched_on_categories_under_its_own_name() {
    let fmu = Fmu::open(common::lugre_fmu()).unwrap();
    assert_eq!(
        fmu.description()
            .log_categories
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>(),
        [
            "logStatusError",
            "logStatusFatal",
            "logStatusWarning",
            "logCalls"
        ]
    );
    let mut front = fmu.instantiate("front").unwrap();
    let mut back = fmu.instantiate("back").unwrap();
    for i in [&mut front, &mut back] {
        i.setup_experiment(0.0, None).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
    }
    // Only `back` logs its calls.
    back.set_debug_logging(true, &["logCalls"]).unwrap();
    front.do_step(0.0, 1e-3).unwrap();
    back.do_step(0.0, 1e-3).unwrap();
    assert!(fmu.log().messages_of("front").is_empty());
    let calls = fmu.log().messages_of("back");
    assert!(!calls.is_empty());
    assert!(calls
        .iter()
        .all(|m| m.category == "logCalls" && m.status == Status::Ok));
    assert!(calls.iter().any(|m| m
        .to_string()
        .starts_with("[back] fmi2OK [logCalls]: fmi2DoStep")));

    // An error of `front` names it, with the FMU's own message.
    let e = front.do_step(0.5, 1e-3).unwrap_err();
    let text = e.to_string();
    assert!(
        text.starts_with("fmi2DoStep failed for instance \"front\" with fmi2Error: fmi2DoStep: expected currentCommunicationPoint = 0.001 but was 0.5"),
        "{text}"
    );
    let errors = fmu.log().messages_of("front");
    assert_eq!(errors.len(), 1);
    assert!(errors[0]
        .to_string()
        .starts_with("[front] fmi2Error [logStatusError]: fmi2DoStep"));

    // Calls switched off again: nothing more from `back`; an unknown
    // category is refused, naming it and the known ones.
    back.set_debug_logging(false, &["logCalls"]).unwrap();
    fmu.log().clear();
    back.do_step(1e-3, 1e-3).unwrap();
    assert!(fmu.log().messages_of("back").is_empty());
    let e = back
        .set_debug_logging(true, &["logEverything"])
        .unwrap_err();
    common::assert_message(&e, &["\"back\"", "logEverything", "logStatusWarning"]);
}
