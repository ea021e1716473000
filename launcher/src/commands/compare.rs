//! `uio-launcher compare`: two recordings signal by signal, step by step (bit for bit without
//! tolerances); exit 1 when they differ.

use std::process::ExitCode;

use launcher::error::{EXIT_DIFFER, LaunchError};
use launcher::{eprintln, println};

use crate::cli::CompareArgs;

pub fn command(a: CompareArgs) -> Result<ExitCode, LaunchError> {
    let (ra, rb) = match (super::read_recording(&a.a), super::read_recording(&a.b)) {
        (Ok(ra), Ok(rb)) => (ra, rb),
        (Err(e), Ok(_)) | (Ok(_), Err(e)) => return Err(e),
        // Both named, the first one's code.
        (Err(ea), Err(eb)) => {
            eprintln!("error: {ea}");
            eprintln!("error: {eb}");
            return Ok(ExitCode::from(ea.exit_code() as u8));
        }
    };
    for (p, r) in [(&a.a, &ra), (&a.b, &rb)] {
        if !r.complete {
            eprintln!("warning: {}: incomplete recording", p.display());
        }
    }
    match recording::compare::compare(&ra, &rb, a.abs_tol, a.rel_tol) {
        Ok(n) => {
            println!(
                "same: {n} values of {} signals{}",
                ra.series
                    .keys()
                    .filter(|k| !k.starts_with("/latency"))
                    .count(),
                if a.abs_tol.is_none() && a.rel_tol.is_none() {
                    ", bit for bit"
                } else {
                    ", within tolerance"
                }
            );
            Ok(ExitCode::SUCCESS)
        }
        Err(d) => {
            println!("differ: {d}");
            Ok(ExitCode::from(EXIT_DIFFER as u8))
        }
    }
}
