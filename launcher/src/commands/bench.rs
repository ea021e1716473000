//! `uio-launcher bench`: the seed-002 closed loop against the bare iceoryx2 ring (the floor), in one
//! process and across processes, with and without recording; or (`--states`) how a step's cost
//! grows with the model.

use std::process::ExitCode;

use launcher::error::LaunchError;
use launcher::run::Mode;
use launcher::{limits, print, println, shipped};
use lockstep::Wait;

use crate::cli::{BenchArgs, OnOff, Pin};

pub fn command(a: BenchArgs) -> Result<ExitCode, LaunchError> {
    limits::bench(a.steps, a.repeat).and_then(|_| limits::states(&a.states))?;
    let wait = a.wait.unwrap_or_else(Wait::default_for_machine);
    let modes: Vec<Mode> = match a.mode {
        Some(m) => vec![Mode::from(m)],
        None => vec![Mode::InProcess, Mode::Processes],
    };
    let rec: Vec<bool> = match a.recording {
        Some(r) => vec![r == OnOff::On],
        None => vec![false, true],
    };
    let pin = a.pin == Pin::Auto;
    if !a.states.is_empty() {
        let runs = launcher::bench::states::states(&a.states, a.steps, wait, pin, &modes, &rec)?;
        if a.json {
            let json = serde_json::json!({ "states": runs });
            println!(
                "{}",
                serde_json::to_string_pretty(&json).expect("serialises")
            );
        } else {
            print!("{}", launcher::bench::states::table(&runs));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let bench = launcher::bench::bench(
        &shipped::dir().join("seed002-sine.toml"),
        a.steps,
        wait,
        pin,
        &modes,
        &rec,
        a.repeat,
        a.bank == OnOff::On,
    )?;
    if a.json {
        let ratios: serde_json::Map<_, _> = launcher::bench::ratios(&bench)
            .into_iter()
            .map(|(n, v)| {
                let figures = serde_json::json!({
                    "min": v.0, "median": v.1, "max": v.2, "repetitions": v.3
                });
                (n, figures)
            })
            .collect();
        let json =
            serde_json::json!({ "runs": bench.runs, "banks": bench.banks, "ratios": ratios });
        println!(
            "{}",
            serde_json::to_string_pretty(&json).expect("serialises")
        );
    } else {
        print!("{}", launcher::bench::table(&bench, wait));
    }
    Ok(ExitCode::SUCCESS)
}
