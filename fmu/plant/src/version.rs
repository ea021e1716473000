//! Which FMI standard an FMU follows.

/// FMI 2.0 or 3.0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    Two,
    Three,
}
