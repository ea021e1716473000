//! iceoryx2's own log. Every run builds its iceoryx2 configuration in code, on purpose (runs
//! must not depend on what a config file in /etc or $HOME says), yet iceoryx2 falls back to
//! its global configuration in a few paths (e.g. cleaning up a dead node whose details it
//! cannot read), and then warns "No config file was loaded" on stderr. Its warnings are not
//! the user's business: only errors are shown, unless `IOX2_LOG_LEVEL` asks for more.

use std::sync::Once;

use iceoryx2::prelude::{LogLevel, set_log_level_from_env_or};

/// Shows only iceoryx2's errors (or the level `IOX2_LOG_LEVEL` names); idempotent.
pub fn quiet_iceoryx2() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| set_log_level_from_env_or(LogLevel::Error));
}
