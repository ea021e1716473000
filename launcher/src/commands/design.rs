//! `uio-launcher design`: the existence conditions and the designs of a scenario, as text or JSON.

use std::process::ExitCode;

use launcher::error::{EXIT_BAD_INPUT, LaunchError};
use launcher::{design_report, print, println, shipped};

use crate::cli::DesignArgs;

pub fn command(a: DesignArgs) -> Result<ExitCode, LaunchError> {
    let s = shipped::load(&a.scenario)?;
    let r = design_report::report(&s);
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&r.json()).expect("serialises")
        );
    } else {
        print!("{}", r.text());
    }
    // The report is the answer either way; a design that fails is bad input (exit 2).
    Ok(if r.ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_BAD_INPUT as u8)
    })
}
