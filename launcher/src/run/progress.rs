//! A progress bar on stderr for runs that take a while: shown only when stderr is a terminal
//! (never in a log or a pipe), and only once a run has gone on for a second, so short runs
//! print exactly what they always did.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a run goes before its bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);
/// Steps between looks at the clock (cheap enough for every step of the fastest runs).
const EVERY: u64 = 1024;

/// The progress of one run.
pub struct Progress {
    total: u64,
    start: Instant,
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A progress for `total` steps, or `None` when stderr is not a terminal.
    pub fn new(total: u64) -> Option<Self> {
        std::io::stderr().is_terminal().then(|| Progress {
            total,
            start: Instant::now(),
            bar: None,
        })
    }

    /// Notes that `done` steps are complete.
    #[inline]
    pub fn tick(&mut self, done: u64) {
        if !done.is_multiple_of(EVERY) {
            return;
        }
        match &self.bar {
            Some(bar) => bar.set_position(done),
            None if self.start.elapsed() >= SHOW_AFTER => {
                let bar =
                    ProgressBar::with_draw_target(Some(self.total), ProgressDrawTarget::stderr());
                let style = ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} steps  {elapsed} elapsed, eta {eta}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar());
                bar.set_style(style);
                bar.set_position(done);
                self.bar = Some(bar);
            }
            None => {}
        }
    }

    /// Removes the bar, leaving the terminal as it was for the summary.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
