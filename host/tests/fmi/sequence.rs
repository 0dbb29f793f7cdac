//! Random FMI call sequences: bytes read as a program of FMI calls (any
//! order, any state, odd values, NULL arrays, unknown value references,
//! stale states, mutated serialized states) run against one FMU. Used by the
//! fuzz target `fuzz/fuzz_targets/fmi_calls.rs` (bytes from libFuzzer) and by
//! `fuzz_bounded.rs` (bytes from a seeded generator).
//!
//! What must hold whatever the bytes: no crash, no hang, no panic across the
//! C ABI (so never `fmi2Fatal`, which this layer returns only for a caught
//! panic), only the five `fmi2Status` values, a refused deserialization
//! hands out no state, an `fmi2OK` `fmi2GetReal` returns no NaN, and every
//! logged message names the FMI function it comes from.

use super::*;

/// Values worth trying for a real: ordinary, extreme and non-finite.
pub const REALS: [f64; 14] = [
    0.0,
    1.0,
    -1.0,
    1e-3,
    -1e-3,
    0.5,
    1e-300,
    1e300,
    -1e300,
    f64::MIN_POSITIVE,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::EPSILON,
];

/// Step sizes worth trying.
pub const STEPS: [f64; 8] = [1e-3, 1e-2, 0.1, 1e-7, 0.0, -1e-3, f64::NAN, 1.0];

/// The byte stream, read from the front; zeros when exhausted.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        match self.0.split_first() {
            Some((b, rest)) => {
                self.0 = rest;
                *b
            }
            None => 0,
        }
    }
    fn index(&mut self, n: usize) -> usize {
        self.byte() as usize % n.max(1)
    }
    fn real(&mut self) -> f64 {
        let k = self.byte();
        if (k as usize) < REALS.len() * 16 {
            REALS[k as usize % REALS.len()]
        } else {
            let mut b = [0u8; 8];
            b.iter_mut().for_each(|x| *x = self.byte());
            f64::from_le_bytes(b)
        }
    }
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

struct Slot {
    instance: Instance,
    /// The time the FMU should be at (tracked from successful calls).
    t: f64,
    states: Vec<FmuState>,
}

fn check_status(what: &str, s: Status) {
    assert!(
        (OK..=FATAL).contains(&s),
        "{what} returned {s}, not an fmi2Status"
    );
    assert_ne!(
        s, FATAL,
        "{what} returned fmi2Fatal (a panic inside the FMU)"
    );
}

fn check_log(slot: &Slot) {
    for m in slot.instance.log.take() {
        assert!(
            m.text.starts_with("fmi2"),
            "message does not name its function: {m:?}"
        );
    }
}

/// Run the program `data` against the FMU `model` behind `api`. Panics on a
/// broken invariant; returns the number of FMI calls made.
pub fn run(api: Api, model: &Model, data: &[u8]) -> usize {
    let mut b = Bytes(data);
    let mut slots: Vec<Slot> = Vec::new();
    let mut blobs: Vec<Vec<u8>> = Vec::new();
    let mut calls = 0usize;
    let vars = &model.vars;
    let unknown = model.unknown_vr();
    // FMI_SEQUENCE_TRACE=1 prints every call and its messages (to replay a finding).
    let trace = std::env::var_os("FMI_SEQUENCE_TRACE").is_some();
    while !b.is_empty() && calls < 400 {
        let op = b.index(24);
        calls += 1;
        if op == 0 || slots.is_empty() {
            if slots.len() < 2 {
                let guid = if b.byte() == 255 {
                    "{not-a-guid}".to_string()
                } else {
                    model.guid.clone()
                };
                if let Ok(instance) = Instance::new(api, "fuzz", &guid, b.byte() & 1 == 1) {
                    slots.push(Slot {
                        instance,
                        t: 0.0,
                        states: Vec::new(),
                    });
                }
            }
            continue;
        }
        let k = b.index(slots.len());
        if op == 1 {
            let mut slot = slots.remove(k);
            for mut s in slot.states.drain(..) {
                unsafe { (api.free_fmu_state)(slot.instance.c, &mut s) };
            }
            continue;
        }
        let slot = &mut slots[k];
        let c = slot.instance.c;
        let a = api;
        // Pick a value reference: mostly a declared one, sometimes unknown.
        let pick_vr = |b: &mut Bytes| -> Vr {
            let i = b.byte() as usize;
            if i >= 250 {
                unknown + i as Vr
            } else {
                vars[i % vars.len()].vr
            }
        };
        let status = unsafe {
            match op {
                2 => {
                    let start = b.real();
                    let s = slot.instance.setup(start);
                    if s == OK {
                        slot.t = start;
                    }
                    s
                }
                3 => slot.instance.enter_init(),
                4 => slot.instance.exit_init(),
                5 => slot.instance.terminate(),
                6 => {
                    let s = slot.instance.reset();
                    if s == OK {
                        slot.t = 0.0;
                    }
                    s
                }
                7 | 8 => {
                    let n = 1 + b.index(3);
                    let vrs: Vec<Vr> = (0..n).map(|_| pick_vr(&mut b)).collect();
                    let values: Vec<f64> = (0..n).map(|_| b.real()).collect();
                    if trace {
                        eprintln!("fmi2SetReal {vrs:?} = {values:?}");
                    }
                    slot.instance.set_real(&vrs, &values)
                }
                9 => {
                    let n = 1 + b.index(4);
                    let vrs: Vec<Vr> = (0..n).map(|_| pick_vr(&mut b)).collect();
                    let (s, values) = slot.instance.get_real(&vrs);
                    if s == OK {
                        assert!(
                            values.iter().all(|v| !v.is_nan()),
                            "fmi2GetReal returned fmi2OK with NaN: {vrs:?} -> {values:?}"
                        );
                    }
                    s
                }
                10 => {
                    let vr = [pick_vr(&mut b)];
                    let v = [b.byte() as c_int - 2];
                    if b.byte() & 1 == 0 {
                        (a.set_integer)(c, vr.as_ptr(), 1, v.as_ptr())
                    } else {
                        (a.set_boolean)(c, vr.as_ptr(), 1, v.as_ptr())
                    }
                }
                11 => {
                    let vr = [pick_vr(&mut b)];
                    let mut v = [0 as c_int];
                    if b.byte() & 1 == 0 {
                        (a.get_integer)(c, vr.as_ptr(), 1, v.as_mut_ptr())
                    } else {
                        (a.get_boolean)(c, vr.as_ptr(), 1, v.as_mut_ptr())
                    }
                }
                12..=14 => {
                    let h = STEPS[b.index(STEPS.len())];
                    let t = if b.byte() < 240 { slot.t } else { b.real() };
                    let s = slot.instance.do_step(t, h);
                    if s == OK {
                        slot.t = t + h;
                    }
                    s
                }
                15 => {
                    let (s, st) = slot.instance.get_state();
                    if s == OK {
                        assert!(!st.is_null());
                        slot.states.push(st);
                    }
                    s
                }
                16 => match slot.states.last() {
                    Some(st) => {
                        let s = (a.set_fmu_state)(c, *st);
                        if s == OK {
                            // The restored time is unknown here: ask the FMU.
                            let mut t = 0.0;
                            if (a.get_real_status)(c, 2, &mut t) == OK {
                                slot.t = t;
                            }
                        }
                        s
                    }
                    None => (a.set_fmu_state)(c, null_mut()),
                },
                17 => {
                    let mut st = slot.states.pop().unwrap_or(null_mut());
                    (a.free_fmu_state)(c, &mut st)
                }
                18 => match slot.states.last() {
                    Some(st) => {
                        let mut size = 0usize;
                        let s = (a.serialized_fmu_state_size)(c, *st, &mut size);
                        if s != OK {
                            s
                        } else {
                            assert!(size < 1 << 20, "serialized size {size}");
                            let mut bytes = vec![0u8; size];
                            let s = (a.serialize_fmu_state)(
                                c,
                                *st,
                                bytes.as_mut_ptr() as *mut c_char,
                                size,
                            );
                            if s == OK && blobs.len() < 4 {
                                blobs.push(bytes);
                            }
                            s
                        }
                    }
                    None => OK,
                },
                19 => {
                    // A stored serialization, mutated, or raw bytes.
                    let mut bytes = if blobs.is_empty() || b.byte() < 64 {
                        let n = b.index(200);
                        (0..n).map(|_| b.byte()).collect()
                    } else {
                        blobs[b.index(blobs.len())].clone()
                    };
                    for _ in 0..b.index(4) {
                        if bytes.is_empty() {
                            break;
                        }
                        let i = b.index(bytes.len());
                        match b.byte() % 3 {
                            0 => bytes[i] ^= 1 << (b.byte() % 8),
                            1 => bytes.truncate(i),
                            _ => bytes[i] = b.byte(),
                        }
                    }
                    let mut st: FmuState = null_mut();
                    let s = (a.deserialize_fmu_state)(
                        c,
                        bytes.as_ptr() as *const c_char,
                        bytes.len(),
                        &mut st,
                    );
                    if s == OK {
                        assert!(!st.is_null());
                        slot.states.push(st);
                    } else {
                        assert!(st.is_null(), "refused state handed out");
                    }
                    s
                }
                20 => {
                    let unknown_vrs = [pick_vr(&mut b)];
                    let known = [pick_vr(&mut b)];
                    let dv = [b.real()];
                    let mut out = [0.0];
                    (a.get_directional_derivative)(
                        c,
                        unknown_vrs.as_ptr(),
                        1,
                        known.as_ptr(),
                        1,
                        dv.as_ptr(),
                        out.as_mut_ptr(),
                    )
                }
                21 => {
                    let vr = [pick_vr(&mut b)];
                    let order = [b.byte() as c_int % 4 - 1];
                    let v = [b.real()];
                    if b.byte() & 1 == 0 {
                        (a.set_real_input_derivatives)(
                            c,
                            vr.as_ptr(),
                            1,
                            order.as_ptr(),
                            v.as_ptr(),
                        )
                    } else {
                        let mut out = [0.0];
                        (a.get_real_output_derivatives)(
                            c,
                            vr.as_ptr(),
                            1,
                            order.as_ptr(),
                            out.as_mut_ptr(),
                        )
                    }
                }
                22 => {
                    let mut names: Vec<&str> =
                        model.log_categories.iter().map(String::as_str).collect();
                    names.push("noSuchCategory");
                    let n = b.index(3);
                    let chosen: Vec<&str> = (0..n).map(|_| names[b.index(names.len())]).collect();
                    slot.instance.set_debug_logging(b.byte() & 1 == 1, &chosen)
                }
                _ => {
                    // NULL arrays with a non-zero length, a huge length, the
                    // status queries and fmi2CancelStep.
                    let vr = [pick_vr(&mut b)];
                    let mut out = [0.0f64];
                    let mut i = 0 as c_int;
                    match b.byte() % 8 {
                        0 => (a.get_real)(c, null(), 1, out.as_mut_ptr()),
                        1 => (a.get_real)(c, vr.as_ptr(), 1, null_mut()),
                        2 => (a.set_real)(c, vr.as_ptr(), usize::MAX, out.as_ptr()),
                        3 => (a.set_real)(c, null(), 3, null()),
                        4 => (a.cancel_step)(c),
                        5 => (a.get_status)(c, b.byte() as c_int % 5, &mut i),
                        6 => (a.get_real_status)(c, b.byte() as c_int % 5, out.as_mut_ptr()),
                        _ => (a.get_boolean_status)(c, b.byte() as c_int % 5, &mut i),
                    }
                }
            }
        };
        if trace {
            eprintln!(
                "op {op} on instance {k} (t = {}): status {status}",
                slots[k].t
            );
            for m in slots[k].instance.log.messages.lock().unwrap().iter() {
                eprintln!("    {}", m.text);
            }
        }
        check_status(&format!("operation {op}"), status);
        check_log(&slots[k.min(slots.len() - 1)]);
    }
    for slot in slots.iter_mut() {
        for mut s in slot.states.drain(..) {
            unsafe { (api.free_fmu_state)(slot.instance.c, &mut s) };
        }
    }
    calls
}
