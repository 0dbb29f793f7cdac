//! The documentation a user reads (README.md, CHANGELOG.md, docs/*.md)
//! stays inside the repository and matches the program:
//!
//! - every Markdown link, and every backticked relative path, resolves
//!   inside the repository and to a file that exists (paths into what the
//!   build writes, `out/`, `dist/`, `target/`, `.venv/`, need not exist in a
//!   clone; placeholders such as `examples/<name>.ssd` are not checked), and
//!   a link's `#section` names a heading of the page it points at;
//! - nothing a user reads cites a paper by its old internal number
//!   ("seed 000" … "seed 004", `seed004_planar.ssd`): neither a page
//!   (README.md, CHANGELOG.md, BENCHMARKS.md, docs/*.md), nor a file of
//!   `examples/` or `modelDescription/`, nor the `--help` of `fricsim`, of
//!   its commands and of the table programs; papers are cited by author and
//!   year (docs/models.md, References). No file of the repository is named
//!   by such a number either: a file is named after what it shows;
//! - docs/fmu-reference.md exists (that it equals what the code generates
//!   is checked by fmu-src/fmu-packager/tests/model_descriptions.rs);
//! - the README's command table names only commands and options that
//!   `fricsim <command> --help` lists, and every command.
//!
//! Standard library only, no FMU loaded: it reads text files, lists the
//! repository's files with `git ls-files` (or walks the tree without git)
//! and runs the programs' `--help`.

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};
use std::process::Command;

/// The repository root (host/ is one level down).
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host/ has a parent")
        .to_path_buf()
}

/// README.md, CHANGELOG.md and every docs/*.md, as paths relative to the
/// repository root.
fn pages() -> Vec<PathBuf> {
    let root = repo();
    let mut pages = vec![PathBuf::from("README.md"), PathBuf::from("CHANGELOG.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/ exists")
        .map(|e| e.expect("readable docs/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .map(|p| Path::new("docs").join(p.file_name().unwrap()))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

fn read(rel: &Path) -> String {
    let path = repo().join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Directories the build, the scripts and the commands create: a path into
/// one of them names a product, not a file of a clone.
const GENERATED: &[&str] = &["out", "dist", "target", ".venv", ".venv-baseline"];

/// Characters that make a path a pattern or a placeholder
/// (`examples/<name>.ssd`, `fmu-src/friction-laws/src/*.rs`).
const PLACEHOLDER: &[char] = &['<', '>', '*', '{', '}', '…', '$', '?', '[', ']', '|'];

/// `target` joined to the directory `dir` (both relative to the repository
/// root), lexically: `None` when `..` climbs above the root or `target` is
/// absolute.
fn resolve(dir: &Path, target: &str) -> Option<PathBuf> {
    if target.starts_with('/') {
        return None;
    }
    let mut parts: Vec<String> = dir
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    for c in Path::new(target).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop()?;
            }
            Component::Normal(s) => parts.push(s.to_string_lossy().into_owned()),
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(parts.iter().collect())
}

/// The text of a page without its fenced code blocks (``` … ```), with
/// each kept line's number: commands and file contents there are examples,
/// not references.
fn prose(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            lines.push((i + 1, line));
        }
    }
    lines
}

/// Markdown link targets `[text](target)` and `![alt](target)` of the
/// prose, with their line numbers (a title after the target is dropped).
fn links(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in prose(text) {
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            let target = after[..end].split_whitespace().next().unwrap_or("");
            found.push((n, target.to_string()));
            rest = &after[end..];
        }
        // reference-style definitions: `[name]: target`
        let t = line.trim_start();
        if t.starts_with('[') {
            if let Some(i) = t.find("]: ") {
                let target = t[i + 3..].split_whitespace().next().unwrap_or("");
                found.push((n, target.to_string()));
            }
        }
    }
    found
}

/// Inline code spans of the prose, each with the line it starts on. As in
/// CommonMark, a span opens with a run of backticks and closes at the next
/// run of the same length in the same paragraph (so it may run over a line
/// break); a run with no partner is literal text.
fn code_spans(text: &str) -> Vec<(usize, String)> {
    // paragraphs: runs of non-blank prose lines
    let mut paragraphs: Vec<(usize, String)> = Vec::new();
    let mut last = 0;
    for (n, line) in prose(text) {
        match paragraphs.last_mut() {
            Some((_, p)) if n == last + 1 && !line.trim().is_empty() && !p.is_empty() => {
                p.push('\n');
                p.push_str(line);
            }
            _ if line.trim().is_empty() => paragraphs.push((n, String::new())),
            _ => paragraphs.push((n, line.to_string())),
        }
        last = n;
    }
    let mut spans = Vec::new();
    for (first_line, p) in paragraphs {
        let chars: Vec<char> = p.chars().collect();
        let run_at = |i: usize| chars[i..].iter().take_while(|&&c| c == '`').count();
        let mut i = 0;
        while i < chars.len() {
            if chars[i] != '`' {
                i += 1;
                continue;
            }
            let k = run_at(i);
            let mut j = i + k;
            let mut close = None;
            while j < chars.len() {
                if chars[j] == '`' {
                    let m = run_at(j);
                    if m == k {
                        close = Some(j);
                        break;
                    }
                    j += m;
                } else {
                    j += 1;
                }
            }
            match close {
                Some(j) => {
                    let line = first_line + chars[..i].iter().filter(|&&c| c == '\n').count();
                    spans.push((line, chars[i + k..j].iter().collect()));
                    i = j + k;
                }
                None => i += k,
            }
        }
    }
    spans
}

/// A code span that is a relative path: no whitespace, a `/` in it, and
/// either starting with `./` or `../` or with a top-level entry of the
/// repository (or a generated directory) as its first component. Units
/// (`m/s`, `N.s/m`) and names (`component.variable`) are not paths.
fn as_path(span: &str, top_level: &BTreeSet<String>) -> Option<String> {
    if span.is_empty() || span.chars().any(char::is_whitespace) || !span.contains('/') {
        return None;
    }
    if span.starts_with("./") || span.starts_with("../") {
        return Some(span.to_string());
    }
    let first = span.split('/').next().unwrap_or("");
    (top_level.contains(first) || GENERATED.contains(&first)).then(|| span.to_string())
}

/// GitHub's anchor of a heading: lower case, letters, digits, `-` and `_`
/// kept, spaces made `-`, everything else dropped.
fn slug(heading: &str) -> String {
    heading
        .chars()
        .filter_map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                Some(c.to_lowercase().collect::<String>())
            } else if c == ' ' {
                Some("-".to_string())
            } else {
                None
            }
        })
        .collect()
}

/// The anchors of a Markdown page's headings (a repeated heading gets
/// `-1`, `-2`, … as on GitHub).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for (_, line) in prose(text) {
        let t = line.trim_start();
        if !t.starts_with('#') {
            continue;
        }
        let heading = t.trim_start_matches('#');
        if !heading.starts_with(' ') {
            continue;
        }
        let base = slug(heading.trim());
        let mut anchor = base.clone();
        let mut k = 0;
        while seen.contains(&anchor) {
            k += 1;
            anchor = format!("{base}-{k}");
        }
        seen.insert(anchor);
    }
    seen
}

fn is_generated(rel: &Path) -> bool {
    rel.components()
        .next()
        .is_some_and(|c| GENERATED.iter().any(|g| c.as_os_str() == *g))
}

/// Every problem with the links and paths of the page `page`.
fn check_references(page: &Path) -> Vec<String> {
    let root = repo();
    let text = read(page);
    let dir = page.parent().unwrap_or(Path::new("")).to_path_buf();
    let top_level: BTreeSet<String> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    let mut problems = Vec::new();
    let at = |n: usize| format!("{}:{n}", page.display());

    for (n, target) in links(&text) {
        if target.is_empty()
            || target.contains("://")
            || target.starts_with("mailto:")
            || target.contains(PLACEHOLDER)
        {
            continue;
        }
        let (file, fragment) = match target.split_once('#') {
            Some((f, a)) => (f, Some(a)),
            None => (target.as_str(), None),
        };
        let rel = if file.is_empty() {
            page.to_path_buf()
        } else {
            match resolve(&dir, file) {
                Some(rel) => rel,
                None => {
                    problems.push(format!(
                        "{}: link `{target}` points outside the repository",
                        at(n)
                    ));
                    continue;
                }
            }
        };
        if is_generated(&rel) {
            continue;
        }
        if !root.join(&rel).exists() {
            problems.push(format!(
                "{}: link `{target}`: {} does not exist",
                at(n),
                rel.display()
            ));
            continue;
        }
        if let Some(anchor) = fragment {
            if rel.extension().is_some_and(|e| e == "md") {
                let known = anchors(&read(&rel));
                if !known.contains(anchor) {
                    problems.push(format!(
                        "{}: link `{target}`: {} has no heading `#{anchor}`",
                        at(n),
                        rel.display()
                    ));
                }
            }
        }
    }

    for (n, span) in code_spans(&text) {
        let Some(path) = as_path(&span, &top_level) else {
            continue;
        };
        let from_page = resolve(&dir, &path);
        if path.starts_with("../") && from_page.is_none() {
            problems.push(format!("{}: `{path}` points outside the repository", at(n)));
            continue;
        }
        if path.contains(PLACEHOLDER) {
            continue;
        }
        // a backticked path is relative to the repository root, or to the
        // page's own directory
        let candidates: Vec<PathBuf> = [resolve(Path::new(""), &path), from_page]
            .into_iter()
            .flatten()
            .collect();
        if candidates.iter().any(|c| is_generated(c)) {
            continue;
        }
        if !candidates.iter().any(|c| root.join(c).exists()) {
            problems.push(format!("{}: `{path}` does not exist", at(n)));
        }
    }
    problems
}

#[test]
fn the_pages_link_to_nothing_outside_the_repository_or_missing() {
    let problems: Vec<String> = pages().iter().flat_map(|p| check_references(p)).collect();
    assert!(
        problems.is_empty(),
        "{} broken reference(s):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// Whether `text` names a paper by its old internal number: "seed", at
/// most one separator (` `, `_`, `-`), then `0` and a digit, in any case
/// ("Seed 000's piezo push", `seed004_planar.ssd`, `seed-003`). A random
/// seed ("the `seed` parameter", "--seeds 20", "seed 7") is not one.
fn has_paper_number(text: &str) -> bool {
    let lower = text.to_lowercase();
    let bytes = lower.as_bytes();
    lower.match_indices("seed").any(|(i, _)| {
        let mut j = i + "seed".len();
        if matches!(bytes.get(j), Some(b' ' | b'_' | b'-')) {
            j += 1;
        }
        bytes.get(j) == Some(&b'0') && bytes.get(j + 1).is_some_and(u8::is_ascii_digit)
    })
}

/// Every file of the repository, relative to its root: `git ls-files`
/// where git and the history are at hand, else a walk of the tree without
/// hidden entries and the directories the build writes.
fn repository_files() -> Vec<PathBuf> {
    let root = repo();
    let listed = Command::new("git")
        .args(["ls-files", "-z"])
        .current_dir(&root)
        .output()
        .ok()
        .filter(|out| out.status.success() && !out.stdout.is_empty());
    if let Some(out) = listed {
        return String::from_utf8_lossy(&out.stdout)
            .split('\0')
            .filter(|p| !p.is_empty())
            .map(PathBuf::from)
            .collect();
    }
    let mut files = Vec::new();
    let mut dirs = vec![PathBuf::new()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(root.join(&dir)).expect("readable directory") {
            let entry = entry.expect("readable entry");
            let name = entry.file_name().to_string_lossy().into_owned();
            let rel = dir.join(&name);
            if name.starts_with('.') || is_generated(&rel) {
                continue;
            }
            if entry.file_type().expect("file type").is_dir() {
                dirs.push(rel);
            } else {
                files.push(rel);
            }
        }
    }
    files.sort();
    files
}

/// The lines of `text` that cite a paper by its old number, as
/// `label:line: text`.
fn paper_numbers(label: &str, text: &str) -> Vec<String> {
    text.lines()
        .enumerate()
        .filter(|(_, line)| has_paper_number(line))
        .map(|(i, line)| format!("{label}:{}: {}", i + 1, line.trim()))
        .collect()
}

#[test]
fn no_file_is_named_by_a_paper_number() {
    let named: Vec<String> = repository_files()
        .iter()
        .map(|p| p.display().to_string())
        .filter(|p| has_paper_number(p))
        .collect();
    assert!(
        named.is_empty(),
        "name the file after what it shows, not by a paper's old number (seed 000 … 004):\n{}",
        named.join("\n")
    );
}

#[test]
fn no_page_example_or_model_description_cites_a_paper_by_a_seed_number() {
    let mut texts = pages();
    texts.push(PathBuf::from("BENCHMARKS.md"));
    texts.extend(
        repository_files()
            .into_iter()
            .filter(|p| p.starts_with("examples") || p.starts_with("modelDescription")),
    );
    let mut problems = Vec::new();
    for rel in texts {
        let path = repo().join(&rel);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        problems.extend(paper_numbers(
            &rel.display().to_string(),
            &String::from_utf8_lossy(&bytes),
        ));
    }
    assert!(
        problems.is_empty(),
        "cite the paper by author and year (docs/models.md, References), not by a seed number:\n{}",
        problems.join("\n")
    );
}

/// The `--help` of a program of this package, which must succeed.
fn help(program: &str, args: &[&str]) -> String {
    let out = Command::new(program)
        .args(args)
        .arg("--help")
        .output()
        .unwrap_or_else(|e| panic!("{program}: {e}"));
    assert!(
        out.status.success(),
        "{program} {} --help: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 help")
}

#[test]
fn no_help_text_cites_a_paper_by_a_seed_number() {
    let fricsim = env!("CARGO_BIN_EXE_fricsim");
    let top = help(fricsim, &[]);
    let mut problems = paper_numbers("fricsim --help", &top);
    for command in help_commands(&top) {
        problems.extend(paper_numbers(
            &format!("fricsim {command} --help"),
            &help(fricsim, &[&command]),
        ));
    }
    // (the benchmark programs' help: bench/tests/help.rs)
    assert!(
        problems.is_empty(),
        "cite the paper by author and year, not by a seed number:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_fmu_reference_exists() {
    let path = repo().join("docs/fmu-reference.md");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}: the FMU reference is missing", path.display()));
    assert!(
        text.contains("## Variables") && text.contains("| variable | causality |"),
        "{} has no variable tables: paste `cargo run -p fmu-packager -- variables-md`",
        path.display()
    );
}

/// The output of `fricsim ARGS`, which must succeed.
fn fricsim(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(args)
        .output()
        .expect("fricsim runs");
    assert!(
        out.status.success(),
        "fricsim {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 help")
}

/// The long options a `--help` text lists (`--step`, `--quiet` from
/// `-q, --quiet`).
fn help_options(help: &str) -> BTreeSet<String> {
    help.lines()
        .filter_map(|line| {
            let t = line.trim_start();
            let t = match t.strip_prefix('-') {
                Some(rest) if !rest.starts_with('-') => rest.split_once(", ")?.1,
                _ => t,
            };
            let option = t.split_whitespace().next()?;
            option.starts_with("--").then(|| option.to_string())
        })
        .collect()
}

/// The subcommands `fricsim --help` lists (without `help`).
fn help_commands(help: &str) -> BTreeSet<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// The README's command table: each row's command and the options it
/// names.
fn readme_commands() -> Vec<(String, Vec<String>)> {
    let text = read(Path::new("README.md"));
    let section = text
        .split("\n## ")
        .find(|s| s.starts_with("Commands\n"))
        .expect("README.md has a section `## Commands`");
    section
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|row| {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let command = cells[1].trim_matches('`').to_string();
            let options = cells[3]
                .split('`')
                .filter(|s| s.starts_with("--"))
                .map(str::to_string)
                .collect();
            (command, options)
        })
        .collect()
}

#[test]
fn the_readme_command_table_matches_the_help_texts() {
    let table = readme_commands();
    assert!(!table.is_empty(), "README.md's command table has no rows");
    let listed: BTreeSet<String> = table.iter().map(|(c, _)| c.clone()).collect();
    let commands = help_commands(&fricsim(&["--help"]));
    assert_eq!(
        listed, commands,
        "README.md's command table and `fricsim --help` list different commands"
    );
    let mut problems = Vec::new();
    for (command, options) in &table {
        let known = help_options(&fricsim(&[command, "--help"]));
        for option in options {
            if !known.contains(option) {
                problems.push(format!(
                    "`fricsim {command}` has no option {option} (its options: {})",
                    known.iter().cloned().collect::<Vec<_>>().join(" ")
                ));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "README.md, ## Commands:\n{}",
        problems.join("\n")
    );
}

#[test]
fn the_checks_themselves_catch_what_they_should() {
    // a link out of the repository, from the root and from docs/
    assert_eq!(resolve(Path::new(""), "../elsewhere/MODELS.md"), None);
    assert_eq!(resolve(Path::new("docs"), "../../elsewhere/x.md"), None);
    assert_eq!(
        resolve(Path::new("docs"), "../BENCHMARKS.md"),
        Some(PathBuf::from("BENCHMARKS.md"))
    );
    assert_eq!(resolve(Path::new(""), "/etc/passwd"), None);
    // paths in code spans, but not units or names
    let top: BTreeSet<String> = ["host", "docs"].iter().map(|s| s.to_string()).collect();
    assert_eq!(
        as_path("host/src/main.rs", &top).as_deref(),
        Some("host/src/main.rs")
    );
    assert_eq!(
        as_path("../elsewhere/data/", &top).as_deref(),
        Some("../elsewhere/data/")
    );
    assert_eq!(as_path("m/s", &top), None);
    assert_eq!(as_path("N.s/m", &top), None);
    assert_eq!(as_path("fricsim run x.ssd", &top), None);
    // fenced blocks are skipped, spans may wrap but not cross a blank
    // line, and a longer run of backticks holds single ones
    let text = "a `host/x`\n```\n`docs/y`\n```\nb `docs/\nz` [t](../u.md#v \"title\")\n\n\
                `` a `b` `` and ` alone\n\nthen `c/d`\n";
    let spans: Vec<(usize, String)> = code_spans(text);
    let texts: Vec<&str> = spans.iter().map(|(_, s)| s.as_str()).collect();
    assert_eq!(texts, ["host/x", "docs/\nz", " a `b` ", "c/d"]);
    assert_eq!(spans[1].0, 5);
    assert_eq!(spans[3].0, 10);
    assert_eq!(links(text), [(6, "../u.md#v".to_string())]);
    // GitHub's anchors
    assert_eq!(
        slug("Connecting FMUs from the command line: `fricsim cosim`"),
        "connecting-fmus-from-the-command-line-fricsim-cosim"
    );
    assert_eq!(
        slug("How the FMUs behave, for importers"),
        "how-the-fmus-behave-for-importers"
    );
    assert!(anchors("# A\n## A\n").contains("a-1"));
    // options from a help text
    let help = "Options:\n      --step <STEP>  Macro step\n  -q, --quiet  No bar\n  -h, --help  Print help\n";
    let options = help_options(help);
    assert!(
        options.contains("--step") && options.contains("--quiet") && options.contains("--help")
    );
    // a paper's old number, in a name or in prose, but not a random seed
    for labelled in [
        "Seed 000's piezo push",
        "examples/seed004_planar.ssd",
        "host/tests/seed000.rs",
        "lugre_seed001.ssv",
        "the Table of seed-003",
        "SEED 002",
    ] {
        assert!(has_paper_number(labelled), "{labelled}");
    }
    for seed in [
        "the `seed` parameter of Bristle.fmu",
        "--seeds 20 --seed-param friction.seed",
        "seed 7",
        "(seed {SEED:#x})",
        "random seed 0 or 1",
        "3 seeds, 0 failures",
    ] {
        assert!(!has_paper_number(seed), "{seed}");
    }
}
