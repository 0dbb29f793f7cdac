//! Bytes to `fmi2DeSerializeFMUstate`: the first byte picks the model, the
//! second how the rest is used (raw bytes, or XORed onto / spliced into a
//! genuine serialized state, so the fuzzer explores near-valid states
//! without a corpus). Anything but the genuine bytes must be refused with
//! fmi2Error and no state handed out; the instance must still step.
#![no_main]
use fricsim_fuzz::fmi::{Instance, ERROR, OK};
use fricsim_fuzz::{api, MODELS};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let [which, how, rest @ ..] = data else {
        return;
    };
    let model = &MODELS[*which as usize % MODELS.len()];
    let i = Instance::new(api(), "fuzz", &model.guid, false).ok().unwrap();
    assert_eq!(i.initialize(), OK);
    assert_eq!(i.do_step(0.0, 1e-3), OK);
    let genuine = i.serialize();
    let bytes = match how % 3 {
        0 => rest.to_vec(),
        1 => {
            let mut b = genuine.clone();
            for (k, x) in rest.iter().enumerate() {
                let n = b.len();
                b[k % n] ^= x;
            }
            b
        }
        _ => {
            let mut b = genuine.clone();
            let at = rest.first().map_or(0, |x| *x as usize % (b.len() + 1));
            b.truncate(at);
            b.extend_from_slice(rest);
            b
        }
    };
    let status = i.restore(&bytes);
    if bytes == genuine {
        assert_eq!(status, OK);
    } else {
        assert_eq!(status, ERROR, "a changed state was accepted");
        assert_eq!(i.do_step(1e-3, 1e-3), OK);
    }
});
