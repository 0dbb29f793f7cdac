//! What the programs that write BENCHMARKS.md share (`accuracy-table`,
//! `speed-table`): replacing the generated part of a markdown file between
//! two markers, and naming the machine and the date of a measurement.

use std::path::Path;

/// Replace the text between the markers `begin` and `end` of `path` with
/// `block` (which holds the markers), keeping the rest; a missing file is
/// created with a title, a file without the markers is refused. With no
/// `block`, only check that this can be done.
pub fn splice(path: &Path, begin: &str, end: &str, block: Option<&str>) -> Result<(), String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            format!("# Benchmarks\n\n{begin}\n{end}\n")
        }
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let (Some(b), Some(e)) = (text.find(begin), text.find(end)) else {
        return Err(format!(
            "{}: the markers `{begin}` and `{end}` are missing: add them where the table goes",
            path.display()
        ));
    };
    if e < b {
        return Err(format!(
            "{}: the end marker comes before the begin marker",
            path.display()
        ));
    }
    let Some(block) = block else {
        return Ok(());
    };
    let mut out = String::with_capacity(text.len() + block.len());
    out.push_str(&text[..b]);
    out.push_str(block.trim_end_matches('\n'));
    out.push_str(&text[e + end.len()..]);
    std::fs::write(path, out).map_err(|e| format!("{}: {e}", path.display()))
}

/// CPU model (from /proc/cpuinfo), cores the process may use, OS.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism()
        .map(|n| n.get().to_string())
        .unwrap_or_else(|_| "?".into());
    format!(
        "{model}, {cores} cores, {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// Today's date (UTC), YYYY-MM-DD, from the system clock (civil-from-days,
/// H. Hinnant's algorithm).
pub fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let z = secs.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The command line a table records: `variable` when the script that ran
/// the program set it (the script names itself), else the program's own.
pub fn command_line(variable: &str, program: &str) -> String {
    std::env::var(variable).unwrap_or_else(|_| {
        std::iter::once(program.to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" ")
    })
}
