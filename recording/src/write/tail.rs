//! The tail of a run: its last quarter of steps, or the stretch at its end its scenario's
//! `tail` sets (L steps in place of ⌊K/4⌋ below), where transients have died out and the
//! figures of merit (tail max|e|, tail max|r|) are taken.
//!
//! A run that completed all its K planned steps has the tail [K − ⌊K/4⌋, K), exactly (its
//! maxima are kept from that step on as it runs). A run that stopped early after K' steps has
//! the tail of the steps it completed: [K' − ⌊K'/4⌋, K'), with its start rounded down to a block
//! of [`block_len`] steps — those figures are kept as block maxima so that memory stays bounded;
//! for runs of up to [`MAX_BLOCKS`] planned steps a block is one step and that tail is exact
//! too. With ⌊K'/4⌋ = 0 (fewer than 4 steps) there is no tail.

use crate::nan::nan_max;

/// Most blocks kept per figure (512 KiB each).
pub const MAX_BLOCKS: u64 = 1 << 16;

/// Steps per block for a run of `planned` steps: 1 up to [`MAX_BLOCKS`] steps, then the power
/// of two that keeps at most [`MAX_BLOCKS`] blocks.
pub fn block_len(planned: u64) -> u64 {
    planned.div_ceil(MAX_BLOCKS).next_power_of_two().max(1)
}

/// The first step of the tail of a run that completed `completed` of `planned` steps: its last
/// `len` steps (all of them if fewer), or without `len` its last quarter; `None` when that is
/// no step (a quarter of fewer than 4).
pub fn tail_start(completed: u64, planned: u64, len: Option<u64>) -> Option<u64> {
    let len = len.map_or(completed / 4, |l| l.min(completed));
    if len == 0 {
        return None;
    }
    let start = completed - len;
    if completed >= planned {
        Some(start)
    } else {
        Some(start - start % block_len(planned))
    }
}

/// Maxima of one figure per block of steps, allocated once for the whole run.
#[derive(Debug, Clone)]
pub struct BlockMax {
    /// log₂ of the block length (a power of two): k's block is k >> shift.
    shift: u32,
    blocks: Vec<f64>,
}

impl BlockMax {
    /// For a run of `planned` steps.
    pub fn new(planned: u64) -> Self {
        let len = block_len(planned);
        BlockMax {
            shift: len.trailing_zeros(),
            blocks: vec![0.0; planned.div_ceil(len).max(1) as usize],
        }
    }

    /// Takes the value of step `k` into its block (steps beyond the plan are ignored).
    #[inline]
    pub fn push(&mut self, k: u64, v: f64) {
        if let Some(b) = self.blocks.get_mut((k >> self.shift) as usize) {
            *b = nan_max(*b, v);
        }
    }

    /// The largest value from step `start` (a block boundary) on.
    pub fn max_from(&self, start: u64) -> f64 {
        self.blocks
            .iter()
            .skip((start >> self.shift) as usize)
            .fold(0.0, |m, &v| nan_max(m, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn completed_run_has_exact_last_quarter() {
        assert_eq!(tail_start(20_000, 20_000, None), Some(15_000));
        assert_eq!(tail_start(7, 7, None), Some(6));
        assert_eq!(tail_start(3, 10, None), None);
    }

    /// A set tail is the last L steps of those completed, all of them if fewer, and exact for a
    /// completed run.
    #[test]
    fn a_set_tail_takes_its_last_steps() {
        assert_eq!(tail_start(20_000, 20_000, Some(720)), Some(19_280));
        assert_eq!(tail_start(3, 10, Some(720)), Some(0));
        assert_eq!(tail_start(2_880, 2_880, Some(2_880)), Some(0));
        assert_eq!(tail_start(100, 100, Some(0)), None);
    }

    #[test]
    fn early_stop_takes_last_quarter_of_completed_steps() {
        assert_eq!(tail_start(1_000, 20_000, None), Some(750));
        // Beyond MAX_BLOCKS planned steps the start is rounded down to a block.
        let planned = 10 * MAX_BLOCKS;
        let b = block_len(planned);
        assert_eq!(b, 16);
        assert_eq!(tail_start(1_003, planned, None), Some(753 - 753 % 16));
    }

    #[test]
    fn block_maxima_cover_from_start() {
        let mut m = BlockMax::new(100);
        for k in 0..100 {
            m.push(k, if k == 10 { 5.0 } else { 1.0 / (k + 1) as f64 });
        }
        assert_eq!(m.max_from(11), 1.0 / 12.0);
        assert_eq!(m.max_from(10), 5.0);
        m.push(50, f64::NAN);
        assert!(m.max_from(20).is_nan());
    }
}
