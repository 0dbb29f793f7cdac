//! The bounded version of `scripts/leak-check.sh` (which runs 10 000
//! cycles per FMU): 100 instantiate / run / state round trip / free cycles
//! of every shipped FMU under valgrind (natively when valgrind is not
//! installed), with no byte lost and nothing more in use at exit than after
//! one cycle.

use std::path::Path;
use std::process::Command;

#[test]
fn a_hundred_cycles_of_every_shipped_fmu_leak_nothing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let output = Command::new(root.join("scripts/leak-check.sh"))
        .arg("100")
        .output()
        .expect("running scripts/leak-check.sh");
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "leak check failed:\n{stdout}");
    assert_eq!(
        stdout.lines().filter(|l| l.contains("100 cycles")).count(),
        crate::fmi::SHIPPED.len(),
        "{stdout}"
    );
    if !stdout.contains("no valgrind") {
        assert_eq!(
            stdout
                .matches("definitely 0 B,indirectly 0 B,possibly 0 B")
                .count(),
            crate::fmi::SHIPPED.len()
        );
    }
}
