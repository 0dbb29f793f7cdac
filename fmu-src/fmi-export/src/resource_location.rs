//! `fmuResourceLocation` of `fmi2Instantiate`: the URI of the unpacked
//! FMU's `resources/` directory (FMI 2.0.4 §2.1.5), turned into a path of
//! the platform the binary runs on.
//!
//! Importers write it in several forms: `file:///C:/Users/me/fmu/resources`
//! (RFC 8089 with an empty authority), `file:/C:/Users/me/fmu/resources`
//! (no authority, as FMPy and others write on Windows),
//! `file:///home/me/fmu/resources`, `file://localhost/…`, percent-encoded
//! (`%20` for a space, UTF-8 bytes for other characters), and on Windows
//! also `file://server/share/…` for a UNC path and the non-standard
//! `file:C:/…`. [`to_path`] accepts all of these and refuses the rest
//! with the reason.
//!
//! What `fmi2Instantiate` does with the result is decided by the model
//! ([`crate::Model::needs_resources`]): a model that reads files there
//! refuses an instantiation whose location is not usable; one that reads
//! none (every model of this project) accepts any location, NULL included,
//! and logs what it was given.

/// How the decoded path is written: the convention of the platform the
/// binary runs on ([`PathStyle::NATIVE`]), or either one for tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathStyle {
    /// `C:\dir\resources`, `\\server\share\resources`.
    Windows,
    /// `/dir/resources`.
    Unix,
}

impl PathStyle {
    /// The style of the platform this binary was built for.
    pub const NATIVE: PathStyle = if cfg!(windows) {
        PathStyle::Windows
    } else {
        PathStyle::Unix
    };
}

/// The directory named by the file URI `uri`, written in `style`, or why
/// it names none (the message quotes no part of `uri`: the caller does).
pub fn to_path(uri: &str, style: PathStyle) -> Result<String, String> {
    let Some(rest) = uri
        .get(..5)
        .filter(|scheme| scheme.eq_ignore_ascii_case("file:"))
        .map(|_| &uri[5..])
    else {
        return Err("is not a file: URI".to_string());
    };
    if rest.contains(['?', '#']) {
        return Err(
            "has a query or a fragment (a '?' or '#' in a path is written %3F, %23)".into(),
        );
    }
    let (host, encoded) = if let Some(after) = rest.strip_prefix("//") {
        match after.find('/') {
            Some(i) => (&after[..i], &after[i..]),
            None => (after, ""),
        }
    } else {
        ("", rest)
    };
    let path = percent_decode(encoded, uri.len() - encoded.len())?;
    if path.contains('\0') {
        return Err("contains a NUL character (%00)".into());
    }
    let local = host.is_empty() || host.eq_ignore_ascii_case("localhost");
    match style {
        PathStyle::Unix => {
            if !local {
                return Err(format!(
                    "names the host \"{host}\": only local files (file:///path) can be read"
                ));
            }
            if !path.starts_with('/') {
                return Err("has no absolute path".into());
            }
            Ok(path)
        }
        PathStyle::Windows => {
            let windows = |p: &str| p.replace('/', "\\");
            if !local {
                if path.len() <= 1 {
                    return Err(format!("names the host \"{host}\" but no share on it"));
                }
                return Ok(format!("\\\\{host}{}", windows(&path)));
            }
            // "/C:/dir" (file:///C:/dir, file:/C:/dir) or "C:/dir" (file:C:/dir)
            let drive = path.strip_prefix('/').unwrap_or(&path);
            let bytes = drive.as_bytes();
            if bytes.len() >= 2
                && bytes[0].is_ascii_alphabetic()
                && bytes[1] == b':'
                && (bytes.len() == 2 || bytes[2] == b'/')
            {
                return Ok(windows(drive));
            }
            if !path.starts_with('/') {
                return Err("has no absolute path".into());
            }
            // "/dir": the root of the current drive
            Ok(windows(&path))
        }
    }
}

/// `%XX` escapes decoded; the result must be UTF-8. `offset` is where
/// `s` starts in the URI, for the position in a message.
fn percent_decode(s: &str, offset: usize) -> Result<String, String> {
    fn hex(b: Option<&u8>) -> Option<u8> {
        let c = char::from(*b?);
        c.to_digit(16).map(|d| d as u8)
    }
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let (Some(high), Some(low)) = (hex(bytes.get(i + 1)), hex(bytes.get(i + 2))) else {
                return Err(format!(
                    "has a malformed percent escape at character {} (expected %XX, two hexadecimal digits)",
                    offset + i + 1
                ));
            };
            out.push(high << 4 | low);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "decodes to bytes that are not UTF-8".to_string())
}

#[cfg(test)]
mod tests {
    use super::PathStyle::{Unix, Windows};
    use super::*;

    #[test]
    fn windows_drive_paths_in_every_form() {
        for uri in [
            "file:///C:/Users/me/fmu/resources",
            "file:/C:/Users/me/fmu/resources",
            "file://localhost/C:/Users/me/fmu/resources",
            "FILE:///C:/Users/me/fmu/resources",
            "file:C:/Users/me/fmu/resources",
            "file:///C%3A/Users/me/fmu/resources",
        ] {
            assert_eq!(
                to_path(uri, Windows).as_deref(),
                Ok("C:\\Users\\me\\fmu\\resources"),
                "{uri}"
            );
        }
        assert_eq!(to_path("file:///d:/", Windows).as_deref(), Ok("d:\\"));
        assert_eq!(to_path("file:///D:", Windows).as_deref(), Ok("D:"));
    }

    #[test]
    fn percent_escapes_decode_to_utf8() {
        assert_eq!(
            to_path("file:///C:/fmu%20tests/Fl%C3%BCgel%25/resources/", Windows).as_deref(),
            Ok("C:\\fmu tests\\Flügel%\\resources\\")
        );
        assert_eq!(
            to_path("file:///home/me/fmu%20tests/r%c3%a9sum%C3%A9", Unix).as_deref(),
            Ok("/home/me/fmu tests/résumé")
        );
    }

    #[test]
    fn unix_paths() {
        for uri in [
            "file:///home/me/fmu/resources",
            "file:/home/me/fmu/resources",
            "file://localhost/home/me/fmu/resources",
            "file://LOCALHOST/home/me/fmu/resources",
        ] {
            assert_eq!(
                to_path(uri, Unix).as_deref(),
                Ok("/home/me/fmu/resources"),
                "{uri}"
            );
        }
        // A Windows drive means nothing on Unix: it stays a path component.
        assert_eq!(to_path("file:///C:/x", Unix).as_deref(), Ok("/C:/x"));
    }

    #[test]
    fn hosts_are_unc_paths_on_windows_and_refused_on_unix() {
        assert_eq!(
            to_path("file://server/share/fmu/resources", Windows).as_deref(),
            Ok("\\\\server\\share\\fmu\\resources")
        );
        let e = to_path("file://server/share/fmu", Unix).unwrap_err();
        assert!(e.contains("host \"server\""), "{e}");
        let e = to_path("file://server", Windows).unwrap_err();
        assert!(e.contains("no share"), "{e}");
    }

    #[test]
    fn a_rooted_path_without_drive_on_windows() {
        assert_eq!(
            to_path("file:///fmu/res", Windows).as_deref(),
            Ok("\\fmu\\res")
        );
    }

    #[test]
    fn malformed_locations_are_refused_with_the_reason() {
        for (uri, reason) in [
            ("", "not a file: URI"),
            ("C:\\Users\\me\\resources", "not a file: URI"),
            ("/home/me/resources", "not a file: URI"),
            ("http://example.org/resources", "not a file: URI"),
            ("fil", "not a file: URI"),
            ("file:relative/dir", "no absolute path"),
            ("file:///C:/a%2", "malformed percent escape at character 13"),
            (
                "file:///C:/a%G0/b",
                "malformed percent escape at character 13",
            ),
            ("file:///C:/a%+1/b", "malformed percent escape"),
            ("file:///C:/a%FF", "not UTF-8"),
            ("file:///C:/a%00b", "NUL"),
            ("file:///C:/dir?x=1", "query or a fragment"),
            ("file:///C:/dir#top", "query or a fragment"),
        ] {
            for style in [Windows, Unix] {
                let e = to_path(uri, style).expect_err(uri);
                assert!(e.contains(reason), "{uri} ({style:?}): {e}");
            }
        }
        assert!(to_path("file://", Unix)
            .unwrap_err()
            .contains("no absolute path"));
    }

    #[test]
    fn the_native_style_is_the_target_platforms() {
        assert_eq!(
            PathStyle::NATIVE,
            if cfg!(windows) { Windows } else { Unix }
        );
    }
}
