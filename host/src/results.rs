//! Result files: CSV with `time` first and `component.variable` columns
//! (FMPy's convention), numbers written so that they parse back exactly.
//! A run that stopped early keeps its rows and ends with a comment line
//! `# INCOMPLETE: …` (CSV readers such as numpy's skip `#` lines).

use crate::master::Run;
use std::io::Write;
use std::path::Path;

pub fn write_csv(run: &Run, path: &Path) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "time,{}", run.columns.join(","))?;
    for (t, row) in run.time.iter().zip(&run.rows) {
        write!(out, "{t:?}")?;
        for x in row {
            write!(out, ",{x:?}")?;
        }
        writeln!(out)?;
    }
    if let Some(e) = &run.error {
        let one_line = e.replace(['\n', '\r'], " ");
        writeln!(out, "# INCOMPLETE: the run stopped early: {one_line}")?;
    }
    out.flush()
}
