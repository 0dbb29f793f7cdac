//! The benchmark programs' help texts work and cite the papers by author
//! and year, never by an internal number ("seed 000"), as every text a
//! user reads (host/tests/integration/docs.rs checks fricsim's and the documents).

use std::process::Command;

/// Where `text` cites a paper by number: "seed" then an optional space,
/// `_` or `-`, then "0" and a digit (a random seed such as "seed 7" is not
/// one).
fn paper_numbers(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let bytes = lower.as_bytes();
    let mut found = Vec::new();
    for (i, _) in lower.match_indices("seed") {
        let mut k = i + 4;
        if matches!(bytes.get(k), Some(b' ' | b'_' | b'-')) {
            k += 1;
        }
        if bytes.get(k) == Some(&b'0') && bytes.get(k + 1).is_some_and(u8::is_ascii_digit) {
            found.push(lower[i..(k + 2).min(lower.len())].to_string());
        }
    }
    found
}

#[test]
fn the_check_tells_paper_numbers_from_random_seeds() {
    assert_eq!(
        paper_numbers("Seed 000 and seed003_x"),
        ["seed 00", "seed00"]
    );
    assert!(paper_numbers("--seeds 3, seed 7, seed 0 or 1").is_empty());
}

#[test]
fn help_texts_cite_no_paper_by_number() {
    for (name, program) in [
        ("accuracy-table", env!("CARGO_BIN_EXE_accuracy-table")),
        ("speed-table", env!("CARGO_BIN_EXE_speed-table")),
        (
            "hidden-effect-suite",
            env!("CARGO_BIN_EXE_hidden-effect-suite"),
        ),
    ] {
        let out = Command::new(program).arg("--help").output().unwrap();
        assert!(out.status.success(), "{name} --help failed");
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.len() > 100, "{name} --help is nearly empty");
        let found = paper_numbers(&text);
        assert!(found.is_empty(), "{name} --help: {found:?}");
    }
}
