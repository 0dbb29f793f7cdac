//! Instances share nothing: two instances of the same shipped FMU stepped
//! alternately in one thread, and eight instances on eight threads at once,
//! give outputs equal bit for bit to one instance alone (FMI 2.0.4 §2.1.5:
//! an FMU that does not set `canBeInstantiatedOnlyOncePerProcess` must
//! support several instances; ours keep no global state besides the table
//! of live instances).

use crate::fmi;
use fmi::*;

const STEPS: usize = 400;
const H: f64 = 1e-3;

/// Every real input of the model, driven by its own sine (amplitudes small
/// enough for every law: bristle displacements are micrometres), kept
/// positive (a normal force must be >= 0).
fn inputs(model: &Model, t: f64) -> (Vec<Vr>, Vec<f64>) {
    model
        .with("Real", "input")
        .iter()
        .enumerate()
        .map(|(k, v)| (v.vr, 1e-6 * (1.5 + (20.0 * t + k as f64).sin())))
        .unzip()
}

/// Bits of every real output after each step of one run.
struct Run<'a> {
    model: &'a Model,
    instance: Instance,
    t: f64,
    bits: Vec<u64>,
}

impl<'a> Run<'a> {
    fn new(loaded: &'a Loaded, name: &str) -> Run<'a> {
        let instance = Instance::new(loaded.api, name, &loaded.model.guid, false)
            .ok()
            .unwrap();
        assert_eq!(instance.initialize(), OK);
        Run {
            model: &loaded.model,
            instance,
            t: 0.0,
            bits: Vec::new(),
        }
    }

    fn step(&mut self) {
        let (vrs, values) = inputs(self.model, self.t);
        assert_eq!(
            self.instance.set_real(&vrs, &values),
            OK,
            "{:?}",
            self.instance.log.take_errors()
        );
        assert_eq!(
            self.instance.do_step(self.t, H),
            OK,
            "{:?}",
            self.instance.log.take_errors()
        );
        self.t += H;
        let outputs: Vec<Vr> = self
            .model
            .with("Real", "output")
            .iter()
            .map(|v| v.vr)
            .collect();
        let (s, y) = self.instance.get_real(&outputs);
        assert_eq!(s, OK);
        self.bits.extend(y.iter().map(|x| x.to_bits()));
    }
}

#[test]
fn instances_in_one_thread_and_across_threads_equal_one_alone() {
    for &name in SHIPPED.iter() {
        let loaded = load_shipped(name);
        let mut alone = Run::new(&loaded, "alone");
        for _ in 0..STEPS {
            alone.step();
        }

        // Two instances, steps interleaved.
        let mut a = Run::new(&loaded, "a");
        let mut b = Run::new(&loaded, "b");
        for _ in 0..STEPS {
            a.step();
            b.step();
        }
        assert_eq!(a.bits, alone.bits, "{name}: first of two instances");
        assert_eq!(b.bits, alone.bits, "{name}: second of two instances");

        // Eight threads, each with its own instance, all running at once.
        let results: Vec<Vec<u64>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..8)
                .map(|k| {
                    let loaded = &loaded;
                    scope.spawn(move || {
                        let mut run = Run::new(loaded, &format!("thread{k}"));
                        for _ in 0..STEPS {
                            run.step();
                        }
                        run.bits
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (k, bits) in results.iter().enumerate() {
            assert_eq!(bits, &alone.bits, "{name}: thread {k}");
        }
    }
}
