//! `uio-launcher design`: the existence conditions and the designs of a scenario, as text or JSON.

use std::process::ExitCode;

use launcher::error::{EXIT_BAD_INPUT, LaunchError};
use launcher::{design_report, print, println, shipped};

use crate::cli::DesignArgs;

pub fn command(a: DesignArgs) -> Result<ExitCode, LaunchError> {
    let s = shipped::load(&a.scenario)?;
    let r = design_report::report(&s);
    let freq = a.freq.then(|| design_report::freq::freq(&s, &r));
    if let (Some(f), Some(dir)) = (&freq, &a.out) {
        launcher::run::create_output_dir(dir)?;
        let written = f
            .plots(dir, &s.name)
            .map_err(|e| LaunchError::BadInput(format!("{}: {e}", dir.display())))?;
        eprintln!("design: {} σ plot(s) in {}", written.len(), dir.display());
    }
    if a.json {
        let mut v = r.json();
        if let Some(f) = &freq {
            v["freq"] = f.json();
        }
        println!("{}", serde_json::to_string_pretty(&v).expect("serialises"));
    } else {
        print!("{}", r.text());
        if let Some(f) = &freq {
            print!("{}", f.text(r.dt));
        }
    }
    // The report is the answer either way; a design that fails is bad input (exit 2).
    Ok(if r.ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(EXIT_BAD_INPUT as u8)
    })
}
