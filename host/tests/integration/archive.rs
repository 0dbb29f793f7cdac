//! Unpacking refuses malicious and broken archives, names the problem, and
//! writes nothing outside its temporary directory.

use crate::common;
use common::assert_message;
use fricsim::fmu::archive::{unpack, UnpackOptions, DEFAULT_MAX_BYTES, DEFAULT_MAX_ENTRIES};
use fricsim::{ArchiveProblem, FmuError};
use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use tempfile::TempDir;
use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

const DESCRIPTION: &[u8] = b"<fmiModelDescription fmiVersion=\"2.0\"/>";

fn stored() -> SimpleFileOptions {
    SimpleFileOptions::default().compression_method(CompressionMethod::Stored)
}

fn deflated() -> SimpleFileOptions {
    SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .compression_level(Some(1))
}

/// A zip of `(name, contents)` entries, stored.
fn zip_of(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    for (name, contents) in entries {
        zip.start_file(*name, stored()).unwrap();
        zip.write_all(contents).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// A scratch area: `files` holds the archive, `parent` receives the
/// temporary directory and must stay empty when unpacking fails.
struct Scratch {
    files: TempDir,
    parent: TempDir,
}

impl Scratch {
    fn new() -> Scratch {
        Scratch {
            files: tempfile::tempdir().unwrap(),
            parent: tempfile::tempdir().unwrap(),
        }
    }

    fn write(&self, bytes: &[u8]) -> PathBuf {
        let path = self.files.path().join("model.fmu");
        std::fs::write(&path, bytes).unwrap();
        path
    }

    fn options(&self) -> UnpackOptions {
        UnpackOptions {
            temp_parent: Some(self.parent.path().to_path_buf()),
            ..UnpackOptions::default()
        }
    }

    fn parent_entries(&self) -> Vec<PathBuf> {
        std::fs::read_dir(self.parent.path())
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect()
    }

    /// Unpack `bytes`, expect a refusal, and check that nothing was left behind.
    fn refuse(&self, bytes: &[u8], options: &UnpackOptions) -> FmuError {
        let path = self.write(bytes);
        let error = unpack(&path, options).expect_err("the archive must be refused");
        assert!(
            self.parent_entries().is_empty(),
            "left behind: {:?}",
            self.parent_entries()
        );
        let files: Vec<_> = std::fs::read_dir(self.files.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(
            files,
            vec!["model.fmu"],
            "a file appeared next to the archive"
        );
        error
    }
}

#[test]
fn a_valid_archive_is_unpacked_and_removed_on_drop() {
    let scratch = Scratch::new();
    let path = scratch.write(&zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("binaries/linux64/M.so", b"not really"),
        ("resources/", b""),
        ("./documentation/index.html", b"<html/>"),
    ]));
    let dir = unpack(&path, &scratch.options()).unwrap();
    assert_eq!(dir.path().parent().unwrap(), scratch.parent.path());
    assert_eq!(
        std::fs::read(dir.path().join("modelDescription.xml")).unwrap(),
        DESCRIPTION
    );
    assert_eq!(
        std::fs::read(dir.path().join("binaries/linux64/M.so")).unwrap(),
        b"not really"
    );
    assert!(dir.path().join("resources").is_dir());
    assert!(dir.path().join("documentation/index.html").is_file());
    let kept = dir.path().to_path_buf();
    drop(dir);
    assert!(
        !kept.exists(),
        "the temporary directory must be removed on drop"
    );
    assert!(scratch.parent_entries().is_empty());
}

#[test]
fn skip_unused_writes_only_what_a_running_fmu_reads() {
    let scratch = Scratch::new();
    // a documentation entry that would inflate past the limit: checked by
    // its declared size like any entry, never inflated
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    for (name, contents) in [
        ("modelDescription.xml", DESCRIPTION),
        ("binaries/linux64/M.so", b"the library" as &[u8]),
        ("binaries/linux64/libdep.so", b"what it needs"),
        ("binaries/win64/M.dll", b"another platform"),
        ("resources/table.txt", b"1 2 3"),
        ("model.png", b"png"),
        ("sources/m.c", b"int x;"),
        ("documentation/index.html", b"<html/>"),
    ] {
        zip.start_file(name, stored()).unwrap();
        zip.write_all(contents).unwrap();
    }
    let path = scratch.write(&zip.finish().unwrap().into_inner());
    let options = UnpackOptions {
        skip_unused: true,
        ..scratch.options()
    };
    let dir = unpack(&path, &options).unwrap();
    let written = |name: &str| dir.path().join(name).is_file();
    for name in [
        "modelDescription.xml",
        "binaries/linux64/M.so",
        "binaries/linux64/libdep.so",
        "resources/table.txt",
        "model.png",
    ] {
        assert!(written(name), "{name} must be unpacked");
    }
    for name in [
        "binaries/win64/M.dll",
        "sources/m.c",
        "documentation/index.html",
    ] {
        assert!(!written(name), "{name} must not be unpacked");
    }
    skipped_entries_still_count(&scratch, dir, &options, "documentation/../../evil");
}

/// What unpacking with entries left unwritten must still do: make their
/// folders, so that the platforms an FMU has can be listed (`dir` has a
/// linux64 and a win64 binary), and check every entry, so that `bad`, a
/// traversal among those left unwritten, refuses the archive.
fn skipped_entries_still_count(
    scratch: &Scratch,
    dir: TempDir,
    options: &UnpackOptions,
    bad: &str,
) {
    assert_eq!(
        fricsim::fmu::library::platforms(dir.path()),
        ["linux64", "win64"]
    );
    drop(dir);
    let bad = zip_of(&[("modelDescription.xml", DESCRIPTION), (bad, b"x")]);
    scratch.refuse(&bad, options);
}

#[test]
fn description_only_writes_the_model_description_alone() {
    let scratch = Scratch::new();
    let bytes = zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("binaries/linux64/M.so", b"the library"),
        ("binaries/win64/M.dll", b"another platform"),
        ("resources/table.txt", b"1 2 3"),
    ]);
    let path = scratch.write(&bytes);
    let options = UnpackOptions {
        description_only: true,
        ..scratch.options()
    };
    let dir = unpack(&path, &options).unwrap();
    assert_eq!(
        std::fs::read(dir.path().join("modelDescription.xml")).unwrap(),
        DESCRIPTION
    );
    for name in [
        "binaries/linux64/M.so",
        "binaries/win64/M.dll",
        "resources/table.txt",
    ] {
        assert!(
            !dir.path().join(name).exists(),
            "{name} must not be unpacked"
        );
    }
    skipped_entries_still_count(&scratch, dir, &options, "binaries/../../evil");
}

#[test]
fn defaults_are_as_documented() {
    let o = UnpackOptions::default();
    assert_eq!(
        (o.max_bytes, o.max_entries),
        (DEFAULT_MAX_BYTES, DEFAULT_MAX_ENTRIES)
    );
    assert_eq!(DEFAULT_MAX_BYTES, 512 * 1024 * 1024);
    assert_eq!(DEFAULT_MAX_ENTRIES, 10_000);
    assert!(!o.skip_unused, "unpack writes every entry unless told");
    assert!(!o.description_only, "unpack writes every entry unless told");
}

#[test]
fn path_traversal_is_refused() {
    let scratch = Scratch::new();
    for name in ["../evil", "resources/../../evil", "resources\\..\\..\\evil"] {
        let bytes = zip_of(&[("modelDescription.xml", DESCRIPTION), (name, b"gotcha")]);
        let e = scratch.refuse(&bytes, &scratch.options());
        assert!(
            matches!(
                &e,
                FmuError::Archive {
                    problem: ArchiveProblem::ParentComponent,
                    ..
                }
            ),
            "{e}"
        );
        assert_message(&e, &[name, "`..`"]);
    }
    // `../evil` from the temporary directory would land in `parent`.
    assert!(!scratch.parent.path().join("evil").exists());
}

#[test]
fn absolute_paths_and_drive_prefixes_are_refused() {
    let scratch = Scratch::new();
    let target = std::env::temp_dir().join(format!("fricsim-evil-{}", std::process::id()));
    let absolute = target.to_str().unwrap().to_string();
    let e = scratch.refuse(
        &zip_of(&[("modelDescription.xml", DESCRIPTION), (&absolute, b"x")]),
        &scratch.options(),
    );
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::AbsolutePath,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &[&absolute, "absolute"]);
    assert!(!target.exists());

    for name in ["C:/evil", "c:\\Windows\\evil"] {
        let e = scratch.refuse(
            &zip_of(&[("modelDescription.xml", DESCRIPTION), (name, b"x")]),
            &scratch.options(),
        );
        assert!(
            matches!(
                &e,
                FmuError::Archive {
                    problem: ArchiveProblem::DrivePrefix,
                    ..
                }
            ),
            "{e}"
        );
        assert_message(&e, &[name, "drive"]);
    }
}

#[test]
fn symlinks_are_refused() {
    let scratch = Scratch::new();
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    zip.start_file("modelDescription.xml", stored()).unwrap();
    zip.write_all(DESCRIPTION).unwrap();
    zip.add_symlink("resources/link", "/etc/passwd", stored())
        .unwrap();
    let bytes = zip.finish().unwrap().into_inner();
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::Symlink,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["resources/link", "symbolic link"]);
}

/// Replace every occurrence of `from` by `to` (same length) in `bytes`.
fn patch(bytes: &mut [u8], from: &[u8], to: &[u8]) -> usize {
    assert_eq!(from.len(), to.len());
    let mut count = 0;
    let mut i = 0;
    while i + from.len() <= bytes.len() {
        if &bytes[i..i + from.len()] == from {
            bytes[i..i + from.len()].copy_from_slice(to);
            count += 1;
            i += from.len();
        } else {
            i += 1;
        }
    }
    count
}

#[test]
fn duplicated_names_are_refused() {
    let scratch = Scratch::new();
    // The zip writer refuses duplicates, so rename the second entry in both
    // its local and its central header.
    let mut bytes = zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("resources/a.txt", b"1"),
        ("resources/b.txt", b"2"),
    ]);
    assert_eq!(patch(&mut bytes, b"resources/b.txt", b"resources/a.txt"), 2);
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::Duplicate,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["resources/a.txt", "more than once"]);

    // Names that differ only in spelling but unpack to the same path.
    let bytes = zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("a/b.txt", b"1"),
        ("a//b.txt", b"2"),
    ]);
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::Duplicate,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["a//b.txt"]);
}

/// Writes `n` zero bytes through `w` without holding them in memory.
fn write_zeros(w: &mut impl Write, n: u64) {
    let chunk = vec![0u8; 1 << 20];
    let mut left = n;
    while left > 0 {
        let k = left.min(chunk.len() as u64) as usize;
        w.write_all(&chunk[..k]).unwrap();
        left -= k as u64;
    }
}

/// CRC-32 (IEEE) register update for one byte, without pre/post inversion.
fn crc_register(mut register: u32, byte: u8) -> u32 {
    register ^= byte as u32;
    for _ in 0..8 {
        register = (register >> 1) ^ (0xEDB8_8320 & (register & 1).wrapping_neg());
    }
    register
}

fn crc32(bytes: &[u8]) -> u32 {
    !bytes.iter().fold(u32::MAX, |r, &b| crc_register(r, b))
}

/// CRC-32 of `n` zero bytes in O(log n): the register update for a zero
/// byte is linear over GF(2), so it is raised to the n-th power as a matrix.
fn crc32_of_zeros(n: u64) -> u32 {
    type Matrix = [u32; 32]; // column i = image of bit i
    fn apply(m: &Matrix, v: u32) -> u32 {
        (0..32)
            .filter(|i| v >> i & 1 == 1)
            .fold(0, |acc, i| acc ^ m[i])
    }
    fn compose(a: &Matrix, b: &Matrix) -> Matrix {
        std::array::from_fn(|i| apply(a, b[i]))
    }
    let mut power: Matrix = std::array::from_fn(|i| crc_register(1 << i, 0));
    let mut result: Matrix = std::array::from_fn(|i| 1 << i);
    let mut k = n;
    while k > 0 {
        if k & 1 == 1 {
            result = compose(&power, &result);
        }
        power = compose(&power, &power);
        k >>= 1;
    }
    !apply(&result, u32::MAX)
}

/// A raw deflate stream (RFC 1951) of `n` zero bytes: one fixed-Huffman
/// block holding a literal 0 and then matches of length 258 at distance 1,
/// 13 bits per 258 bytes.
fn deflate_zeros(n: u64) -> Vec<u8> {
    struct Bits {
        out: Vec<u8>,
        acc: u64,
        len: u32,
    }
    impl Bits {
        fn put(&mut self, value: u32, bits: u32) {
            self.acc |= (value as u64) << self.len;
            self.len += bits;
            while self.len >= 8 {
                self.out.push(self.acc as u8);
                self.acc >>= 8;
                self.len -= 8;
            }
        }
        /// Huffman codes go most-significant bit first.
        fn code(&mut self, code: u32, bits: u32) {
            self.put(code.reverse_bits() >> (32 - bits), bits);
        }
    }
    let mut b = Bits {
        out: Vec::new(),
        acc: 0,
        len: 0,
    };
    b.put(1, 1); // BFINAL
    b.put(1, 2); // BTYPE = fixed Huffman
    let literal_zero = |b: &mut Bits| b.code(0x30, 8);
    literal_zero(&mut b);
    let rest = n - 1;
    for _ in 0..rest / 258 {
        b.code(0xC5, 8); // length code 285 = 258
        b.code(0, 5); // distance code 0 = 1
    }
    for _ in 0..rest % 258 {
        literal_zero(&mut b);
    }
    b.code(0, 7); // end of block (256)
    b.put(0, 7); // flush
    b.out
}

/// A zip archive written field by field: `(name, method, crc, size, data)`
/// with `data` already compressed.
fn raw_zip(entries: &[(&str, u16, u32, u32, &[u8])]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (name, method, crc, size, data) in entries {
        let offset = out.len() as u32;
        let common = |v: &mut Vec<u8>| {
            v.extend(20u16.to_le_bytes()); // version needed
            v.extend(0u16.to_le_bytes()); // flags
            v.extend(method.to_le_bytes());
            v.extend([0u8; 4]); // time, date
            v.extend(crc.to_le_bytes());
            v.extend((data.len() as u32).to_le_bytes());
            v.extend(size.to_le_bytes());
            v.extend((name.len() as u16).to_le_bytes());
            v.extend(0u16.to_le_bytes()); // extra length
        };
        out.extend(0x0403_4b50u32.to_le_bytes());
        common(&mut out);
        out.extend(name.as_bytes());
        out.extend(*data);
        central.extend(0x0201_4b50u32.to_le_bytes());
        central.extend(20u16.to_le_bytes()); // version made by
        common(&mut central);
        central.extend([0u8; 10]); // comment length, disk, internal and external attributes
        central.extend(offset.to_le_bytes());
        central.extend(name.as_bytes());
    }
    let directory_start = out.len() as u32;
    out.extend(&central);
    out.extend(0x0605_4b50u32.to_le_bytes());
    out.extend([0u8; 4]); // disk numbers
    out.extend((entries.len() as u16).to_le_bytes());
    out.extend((entries.len() as u16).to_le_bytes());
    out.extend((central.len() as u32).to_le_bytes());
    out.extend(directory_start.to_le_bytes());
    out.extend(0u16.to_le_bytes()); // comment length
    out
}

fn bomb(n: u64) -> Vec<u8> {
    let zeros = deflate_zeros(n);
    raw_zip(&[
        (
            "modelDescription.xml",
            0,
            crc32(DESCRIPTION),
            DESCRIPTION.len() as u32,
            DESCRIPTION,
        ),
        (
            "resources/zeros.bin",
            8,
            crc32_of_zeros(n),
            n as u32,
            &zeros,
        ),
    ])
}

/// The hand-made archive is a correct zip: a small one unpacks to zeros.
#[test]
fn the_test_bomb_is_a_valid_archive() {
    let scratch = Scratch::new();
    assert_eq!(crc32_of_zeros(1000), crc32(&[0u8; 1000]));
    let n = 1_000_003;
    let dir = unpack(&scratch.write(&bomb(n)), &scratch.options()).unwrap();
    let zeros = std::fs::read(dir.path().join("resources/zeros.bin")).unwrap();
    assert_eq!(zeros.len() as u64, n);
    assert!(zeros.iter().all(|&b| b == 0));
}

#[test]
fn a_zip_bomb_is_refused() {
    let scratch = Scratch::new();
    // 600 MiB of zeros in a 4 MB archive.
    let n = 600 << 20;
    let bytes = bomb(n);
    assert!(
        bytes.len() < 4_000_000,
        "the bomb should be small, is {} bytes",
        bytes.len()
    );
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::EntryTooLarge { .. },
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["resources/zeros.bin", "536870912 bytes"]);

    // The same bomb declaring 1000 bytes: the bytes that come out count.
    let lying = raw_zip(&[
        (
            "modelDescription.xml",
            0,
            crc32(DESCRIPTION),
            DESCRIPTION.len() as u32,
            DESCRIPTION,
        ),
        (
            "resources/zeros.bin",
            8,
            crc32_of_zeros(n),
            1000,
            &deflate_zeros(n),
        ),
    ]);
    let e = scratch.refuse(&lying, &scratch.options());
    assert_message(&e, &["resources/zeros.bin"]);
    assert_corrupt_or_too_large(&e);
}

#[test]
fn the_total_size_is_limited() {
    let scratch = Scratch::new();
    let big = vec![1u8; 600 * 1024];
    let bytes = zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("a.bin", &big),
        ("b.bin", &big),
    ]);
    let options = UnpackOptions {
        max_bytes: 1 << 20,
        ..scratch.options()
    };
    let e = scratch.refuse(&bytes, &options);
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::TotalTooLarge { .. },
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["b.bin", "in total"]);
}

/// Offsets of the 4-byte little-endian `signature` in `bytes`.
fn find_signature(bytes: &[u8], signature: u32) -> Vec<usize> {
    let s = signature.to_le_bytes();
    (0..bytes.len().saturating_sub(3))
        .filter(|&i| bytes[i..i + 4] == s)
        .collect()
}

#[test]
fn a_header_that_understates_the_size_is_refused() {
    let scratch = Scratch::new();
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    zip.start_file("modelDescription.xml", stored()).unwrap();
    zip.write_all(DESCRIPTION).unwrap();
    zip.start_file("resources/liar.bin", deflated()).unwrap();
    write_zeros(&mut zip, 4 << 20);
    let mut bytes = zip.finish().unwrap().into_inner();

    // Declare 1000 bytes in the local (offset 22) and central (offset 24)
    // headers of the second entry; it inflates to 4 MiB.
    let local = find_signature(&bytes, 0x0403_4b50);
    let central = find_signature(&bytes, 0x0201_4b50);
    assert_eq!((local.len(), central.len()), (2, 2));
    let declared = 1000u32.to_le_bytes();
    assert_eq!(
        bytes[local[1] + 22..local[1] + 26],
        (4u32 << 20).to_le_bytes()
    );
    bytes[local[1] + 22..local[1] + 26].copy_from_slice(&declared);
    bytes[central[1] + 24..central[1] + 28].copy_from_slice(&declared);

    // With a 1 MiB limit the declared size passes the checks before
    // inflating; the bytes that actually come out must not.
    let options = UnpackOptions {
        max_bytes: 1 << 20,
        ..scratch.options()
    };
    let e = scratch.refuse(&bytes, &options);
    assert_message(&e, &["resources/liar.bin"]);
    assert_corrupt_or_too_large(&e);
}

#[test]
fn too_many_entries_are_refused() {
    let scratch = Scratch::new();
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    zip.start_file("modelDescription.xml", stored()).unwrap();
    for i in 0..DEFAULT_MAX_ENTRIES {
        zip.start_file(format!("resources/{i}"), stored()).unwrap();
    }
    let bytes = zip.finish().unwrap().into_inner();
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::TooManyEntries {
                    count: 10_001,
                    limit: 10_000
                },
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["10001 entries", "limit of 10000"]);
}

#[test]
fn a_missing_model_description_is_refused() {
    let scratch = Scratch::new();
    let bytes = zip_of(&[
        ("sub/modelDescription.xml", DESCRIPTION),
        ("binaries/linux64/M.so", b"x"),
    ]);
    let e = scratch.refuse(&bytes, &scratch.options());
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::MissingModelDescription,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["no modelDescription.xml"]);
}

#[test]
fn a_file_that_is_not_a_zip_is_refused() {
    let scratch = Scratch::new();
    let e = scratch.refuse(
        b"this is not a zip archive, just text\n",
        &scratch.options(),
    );
    assert!(
        matches!(
            &e,
            FmuError::Archive {
                problem: ArchiveProblem::NotAZip(_),
                entry: None,
                ..
            }
        ),
        "{e}"
    );
    assert_message(&e, &["model.fmu", "not a readable zip archive"]);
}

#[test]
fn a_truncated_zip_is_refused() {
    let scratch = Scratch::new();
    let big: Vec<u8> = (0..100_000u32).map(|i| (i * 7919 % 251) as u8).collect();
    let bytes = zip_of(&[
        ("modelDescription.xml", DESCRIPTION),
        ("resources/data.bin", &big),
    ]);
    for cut in [bytes.len() / 2, bytes.len() - 10] {
        let e = scratch.refuse(&bytes[..cut], &scratch.options());
        assert!(matches!(&e, FmuError::Archive { .. }), "{e}");
        assert_message(&e, &["model.fmu"]);
    }
}

#[test]
fn a_missing_file_is_an_io_error() {
    let e = unpack(
        Path::new("/nonexistent/model.fmu"),
        &UnpackOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(&e, FmuError::Io { .. }), "{e}");
    assert_message(&e, &["/nonexistent/model.fmu"]);
}

/// A size lie is caught either by the zip reader (corrupt) or by our byte
/// counter (entry too large), depending on which reads past it first.
fn assert_corrupt_or_too_large(e: &FmuError) {
    assert!(
        matches!(
            e,
            FmuError::Archive {
                problem: ArchiveProblem::Corrupt(_) | ArchiveProblem::EntryTooLarge { .. },
                ..
            }
        ),
        "{e}"
    );
}
