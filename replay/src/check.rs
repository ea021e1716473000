//! `uio-replay-plant --check`: the launcher's pre-flight. Parameters (JSON) on stdin; the whole
//! file is read as the run would read it; the facts the summary reports go to stdout as JSON.

use std::io::Read;
use std::process::ExitCode;

/// Exit 0 with the facts on stdout, or 2 with one line on stderr.
pub fn main() -> ExitCode {
    let mut text = String::new();
    let run = std::io::stdin()
        .read_to_string(&mut text)
        .map_err(|e| format!("uio-replay-plant --check: stdin: {e}"))
        .and_then(|_| {
            serde_json::from_str::<replay::Params>(&text)
                .map_err(|e| format!("uio-replay-plant --check: parameters: {e}"))
        })
        .and_then(|p| replay::load(&p));
    match run {
        Ok(t) => {
            println!("{}", serde_json::to_string(&t.facts).expect("serialises"));
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{}", e.replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
