//! Supervision: stalls, component failures (crashes, hangs, protocol breaks), early stops, a diverging observer, external components.

mod component_failures;
mod early_stop;
mod external;
mod observer_divergence;
mod stalls;
