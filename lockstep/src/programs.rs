//! The names of this workspace's programs, in one style (`uio-…`, so that none collides with
//! another program on a PATH), and the bare names they had before 2026-11-29, which a
//! scenario's `command` may still give for one release.

/// The command-line tool: reads scenarios, designs, runs, records.
pub const LAUNCHER: &str = "uio-launcher";
/// The two-host bridge (Zenoh), started by the launcher beside itself.
pub const BRIDGE: &str = "uio-bridge";
/// An FMU as the true plant.
pub const FMU_PLANT: &str = "uio-fmu-plant";
/// A recorded log as the true plant.
pub const REPLAY_PLANT: &str = "uio-replay-plant";

/// A built-in component's program: `uio-plant`, `uio-observer`, `uio-controller`.
pub fn builtin(kind: &str) -> String {
    format!("uio-{kind}")
}

/// The program an old bare name stands for (`plant` → `uio-plant`, `fmu_plant` →
/// `uio-fmu-plant`, …); `None` for any other name.
pub fn renamed(old: &str) -> Option<String> {
    match old {
        "launcher" => Some(LAUNCHER.into()),
        "plant" | "observer" | "controller" => Some(builtin(old)),
        "fmu_plant" => Some(FMU_PLANT.into()),
        "replay_plant" => Some(REPLAY_PLANT.into()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_old_name_maps_to_a_uio_name_and_others_to_none() {
        for old in [
            "launcher",
            "plant",
            "observer",
            "controller",
            "fmu_plant",
            "replay_plant",
        ] {
            let new = renamed(old).unwrap();
            assert!(
                new.starts_with("uio-") && new.ends_with(&old.replace('_', "-")),
                "{old} → {new}"
            );
        }
        assert_eq!(renamed("python3"), None);
        assert_eq!(renamed("uio-plant"), None);
    }
}
