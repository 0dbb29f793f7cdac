//! Packing a `.ssd` into a self-contained `.ssp`: the zip holds
//! `SystemStructure.ssd` and, under `resources/`, every file a `source`
//! attribute points at (the FMUs, `.ssv` parameter files), with the
//! attributes rewritten to `resources/<file name>`. Everything else in the
//! ssd (comments, annotations, layout) is copied unchanged. The system is
//! checked against its FMUs first, so a packed archive is a valid one.

use super::{error, SspError, SystemFile};
use quick_xml::events::{BytesStart, Event};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Pack the system file `ssd` into the archive `out`.
pub fn pack(ssd: &Path, out: &Path) -> Result<(), SspError> {
    let shown = ssd.display().to_string();
    if ssd
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ssp"))
    {
        return Err(error(
            &shown,
            "already an .ssp archive; give the .ssd to pack",
        ));
    }
    let file = SystemFile::open(ssd)?;
    file.check()?;
    let text =
        std::fs::read_to_string(ssd).map_err(|e| error(&shown, format!("cannot read: {e}")))?;

    // rewrite every `source` attribute, collecting the files to include
    let mut files: Vec<(String, PathBuf)> = Vec::new();
    let mut reader = quick_xml::Reader::from_str(&text);
    let mut writer = quick_xml::Writer::new(Vec::new());
    loop {
        let event = reader
            .read_event()
            .map_err(|e| error(&shown, format!("cannot re-read the XML: {e}")))?;
        let rewrite = |e: &BytesStart,
                       files: &mut Vec<(String, PathBuf)>|
         -> Result<BytesStart<'static>, SspError> {
            let name = e.name().as_ref().to_string();
            let mut copy = BytesStart::new(name);
            for a in e.attributes() {
                let a = a.map_err(|err| error(&shown, err.to_string()))?;
                let key = a.key.as_ref().to_string();
                let value = a
                    .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                    .map_err(|err| error(&shown, err.to_string()))?
                    .into_owned();
                if key == "source" {
                    let path = file
                        .resolve(&value)
                        .map_err(|m| error(&shown, format!("source=\"{value}\": {m}")))?;
                    let base = path
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .ok_or_else(|| {
                            error(&shown, format!("source=\"{value}\" names no file"))
                        })?;
                    let entry = format!("resources/{base}");
                    match files.iter().find(|(n, _)| *n == entry) {
                        Some((_, p)) if *p != path => {
                            return Err(error(
                                &shown,
                                format!(
                                    "sources {} and {} have the same file name {base}; rename one",
                                    p.display(),
                                    path.display()
                                ),
                            ))
                        }
                        Some(_) => {}
                        None => files.push((entry.clone(), path)),
                    }
                    copy.push_attribute(("source", entry.as_str()));
                } else {
                    copy.push_attribute((key.as_str(), value.as_str()));
                }
            }
            Ok(copy)
        };
        let written = match event {
            Event::Eof => break,
            Event::Start(e) => writer.write_event(Event::Start(rewrite(&e, &mut files)?)),
            Event::Empty(e) => writer.write_event(Event::Empty(rewrite(&e, &mut files)?)),
            other => writer.write_event(other),
        };
        written.map_err(|e| error(&shown, e.to_string()))?;
    }
    let ssd_bytes = writer.into_inner();

    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| error(dir.display().to_string(), e.to_string()))?;
    }
    let out_shown = out.display().to_string();
    let fail = |e: &dyn std::fmt::Display| error(&out_shown, e.to_string());
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out).map_err(|e| fail(&e))?);
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    zip.start_file("SystemStructure.ssd", options)
        .map_err(|e| fail(&e))?;
    zip.write_all(&ssd_bytes).map_err(|e| fail(&e))?;
    for (entry, path) in &files {
        let bytes =
            std::fs::read(path).map_err(|e| error(path.display().to_string(), e.to_string()))?;
        zip.start_file(entry.as_str(), options)
            .map_err(|e| fail(&e))?;
        zip.write_all(&bytes).map_err(|e| fail(&e))?;
    }
    zip.finish().map_err(|e| fail(&e))?;
    Ok(())
}
