//! `uio-launcher list`: the shipped scenarios, one line each.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::{println, shipped};

use crate::cli::ListArgs;

pub fn command(a: ListArgs) -> Result<ExitCode, LaunchError> {
    for e in &shipped::list(&a.dir.unwrap_or_else(shipped::dir))? {
        println!("{}", e.line());
    }
    Ok(ExitCode::SUCCESS)
}
