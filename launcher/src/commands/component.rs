//! `uio-launcher component` (hidden): a component's shell in this process, the fallback when its
//! binary is not installed beside the launcher.

use std::process::ExitCode;

use launcher::eprintln;
use launcher::error::LaunchError;
use lockstep::component::main_with_args;

use crate::cli::ComponentArgs;

pub fn command(a: ComponentArgs) -> Result<ExitCode, LaunchError> {
    let kind = a.kind.as_str();
    if let Ok(name) = std::ffi::CString::new(kind) {
        // SAFETY: PR_SET_NAME copies at most 16 bytes from a valid C string.
        unsafe { libc::prctl(libc::PR_SET_NAME, name.as_ptr()) };
    }
    // The component's own exit code (lockstep's codes), passed on as it is.
    Ok(match kind {
        "plant" => main_with_args::<plant::shell::PlantComponent>(kind, a.args),
        "observer" => main_with_args::<observer::shell::ObserverComponent>(kind, a.args),
        "controller" => main_with_args::<controller::shell::ControllerComponent>(kind, a.args),
        other => {
            eprintln!("unknown component {}", scenario::untrusted::quoted(other));
            ExitCode::from(lockstep::EXIT_USAGE as u8)
        }
    })
}
