//! The launcher's one-shot requests to this program (`--check`, `--linearize`): JSON on stdin,
//! the answer on stdout, exit 0; or one line on stderr and exit 2.

use std::io::Read;

/// The request on stdin, `what` naming it in a refusal.
pub fn read<T: serde::de::DeserializeOwned>(what: &str) -> Result<T, String> {
    let mut text = String::new();
    std::io::stdin()
        .read_to_string(&mut text)
        .map_err(|e| format!("stdin: {e}"))?;
    serde_json::from_str(&text).map_err(|e| format!("{what}: {e}"))
}

/// Prints the answer (if any) and ends the process: exit 0, or 2 with the refusal's line.
pub fn answer(outcome: Result<Option<String>, String>) -> std::process::ExitCode {
    match outcome {
        Ok(text) => {
            if let Some(text) = text {
                println!("{text}");
            }
            crate::exit::end(0)
        }
        Err(e) => {
            eprintln!("{e}");
            crate::exit::end(2)
        }
    }
}
