//! `uio-launcher export`: a recording's signals for other tools (CSV, MCAP, NumPy .npz, MATLAB .mat).

use std::path::Path;
use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::{eprintln, println};
use recording::export as ex;

use crate::cli::ExportArgs;

pub fn command(a: ExportArgs) -> Result<ExitCode, LaunchError> {
    let ExportArgs {
        recording,
        csv,
        mcap,
        npz,
        mat,
        deviations,
        force,
    } = a;
    // An export written over its own recording would replace the data it was made from.
    if let Some(p) = [&mcap, &npz, &mat]
        .into_iter()
        .flatten()
        .find(|p| same_file(p, &recording))
    {
        return Err(LaunchError::BadInput(format!(
            "{}: is the recording being exported ({}); refusing to write over it",
            p.display(),
            recording.display()
        )));
    }
    let r = super::read_recording(&recording)
        .and_then(|r| super::shifted(&recording, r, deviations))?;
    // Existing files are replaced only when asked, as `run` replaces its outputs.
    let csv_files = csv.iter().flat_map(|d| {
        recording::export::csv::planned(&r)
            .into_iter()
            .map(move |f| d.join(f))
    });
    if !force
        && let Some(p) = [&mcap, &npz, &mat]
            .into_iter()
            .flatten()
            .cloned()
            .chain(csv_files)
            .find(|p| p.symlink_metadata().is_ok())
    {
        return Err(LaunchError::BadInput(format!(
            "{}: already exists (pass --force to overwrite)",
            p.display()
        )));
    }
    let dt = recording::tools::recorded_dt(&r);
    if !r.complete {
        eprintln!(
            "warning: {}: incomplete recording (its writer did not finish); exporting what it holds",
            recording.display()
        );
    }
    let done = (|| -> Result<(), String> {
        if let Some(d) = &csv {
            println!("{} files in {}", ex::export(&r, d, dt)?.len(), d.display());
        }
        if let Some(p) = &mcap {
            println!("{}: {} channels", p.display(), ex::mcap::export(&r, p, dt)?);
        }
        if let Some(p) = &npz {
            println!("{}: {} arrays", p.display(), ex::npz::export(&r, p, dt)?);
        }
        if let Some(p) = &mat {
            println!("{}: {} variables", p.display(), ex::mat::export(&r, p, dt)?);
        }
        Ok(())
    })();
    done.map_err(LaunchError::BadInput)?;
    Ok(ExitCode::SUCCESS)
}

/// Whether `a` and `b` name one existing file (the same device and inode: links and `..` alike).
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}
