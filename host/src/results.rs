//! Result files: CSV with `time` first and `component.variable` columns
//! (FMPy's convention), numbers written so that they parse back exactly.

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
    out.flush()
}
