//! The .fmu archive: modelDescription.xml, binaries/<platform>/<modelIdentifier>.so and
//! resources/observer.json, written to a temporary name beside the target and renamed into
//! place, so a failed export leaves nothing behind.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

use crate::model_description::Fmi;
use crate::resource;

/// The archive's contents.
pub struct Contents<'a> {
    /// modelDescription.xml.
    pub model_description: &'a str,
    /// resources/observer.json.
    pub resource_json: &'a str,
    /// The shared library's bytes.
    pub library: &'a [u8],
    /// Its name (without `.so`) in binaries/<platform>/.
    pub model_identifier: &'a str,
    /// Which binaries folder.
    pub fmi: Fmi,
}

/// Writes `path` atomically (`outputs::write`: a new file at an unpredictable name in the same
/// folder, renamed over it).
pub fn write(path: &Path, c: &Contents) -> Result<(), String> {
    outputs::write(path, |w| write_zip(w, path, c))
}

fn write_zip(w: &mut BufWriter<File>, path: &Path, c: &Contents) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let mut zip = ZipWriter::new(&mut *w);
    // A fixed timestamp: the same export gives the same bytes.
    let opts = SimpleFileOptions::default()
        .compression_method(CompressionMethod::Deflated)
        .last_modified_time(DateTime::default());
    let library = format!("binaries/{}/{}.so", c.fmi.platform(), c.model_identifier);
    let entries: [(&str, &[u8], u32); 3] = [
        (
            "modelDescription.xml",
            c.model_description.as_bytes(),
            0o644,
        ),
        (&library, c.library, 0o755),
        (
            &format!("resources/{}", resource::FILE),
            c.resource_json.as_bytes(),
            0o644,
        ),
    ];
    for (name, bytes, mode) in entries {
        zip.start_file(name, opts.unix_permissions(mode))
            .map_err(|e| err(&e))?;
        zip.write_all(bytes).map_err(|e| err(&e))?;
    }
    zip.finish().map_err(|e| err(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_the_three_entries_and_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("fmu-export-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("o.fmu");
        let c = Contents {
            model_description: "<x/>",
            resource_json: "{}",
            library: b"\x7fELF",
            model_identifier: "o",
            fmi: Fmi::V3,
        };
        write(&path, &c).unwrap();
        let mut z = zip::ZipArchive::new(File::open(&path).unwrap()).unwrap();
        let mut names: Vec<String> = z.file_names().map(String::from).collect();
        names.sort();
        assert_eq!(
            names,
            [
                "binaries/x86_64-linux/o.so",
                "modelDescription.xml",
                "resources/observer.json"
            ]
        );
        let mut text = String::new();
        std::io::Read::read_to_string(&mut z.by_name("modelDescription.xml").unwrap(), &mut text)
            .unwrap();
        assert_eq!(text, "<x/>");
        // A folder that does not exist: an error, and nothing written.
        assert!(write(&dir.join("missing").join("o.fmu"), &c).is_err());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
