//! The disk's own write rate, in the same session as the recorded runs: what `dd if=/dev/zero
//! of=FILE bs=1M count=64 conv=fsync` does — 64 blocks of 1 MiB written to a new file in the
//! folder the recordings go to, and synced — so that a recording's rate (its bytes over the run
//! and the sync of its file, [`sync`]) is given as a share of what the same folder takes at the
//! same moment. Both are synced: without it the rate is the page cache's, which swings ten-fold
//! with how much the runs before left dirty (4.2 GB/s and 0.48 GB/s measured minutes apart here).

use std::fs;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

use crate::error::LaunchError;

/// Blocks written, of [`BLOCK`] bytes: 64 MiB, more than a 100 000-step recording (≈ 44 MB).
pub const BLOCKS: usize = 64;
/// One block, as `dd bs=1M`.
pub const BLOCK: usize = 1 << 20;

/// Bytes per second written to a new file in `dir` (removed afterwards).
pub fn write_rate(dir: &Path) -> Result<f64, LaunchError> {
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let path = dir.join(format!("dd-{}.bin", std::process::id()));
    // A pattern, not zeros: nothing on the way may treat the blocks as holes.
    let block: Vec<u8> = (0..BLOCK).map(|i| (i % 251) as u8).collect();
    let start = Instant::now();
    let written = (|| {
        let mut f = fs::File::create(&path)?;
        for _ in 0..BLOCKS {
            f.write_all(&block)?;
        }
        f.flush()?;
        f.sync_all()
    })();
    let s = start.elapsed().as_secs_f64();
    let _ = fs::remove_file(&path);
    written.map_err(|e| io(&path, e))?;
    Ok((BLOCKS * BLOCK) as f64 / s.max(1e-9))
}

/// Syncs the file at `path` (a recording just closed) to the disk.
pub fn sync(path: &Path) -> Result<(), LaunchError> {
    fs::File::open(path)
        .and_then(|f| f.sync_all())
        .map_err(|e| io(path, e))
}

fn io(p: &Path, e: std::io::Error) -> LaunchError {
    LaunchError::BadInput(format!("{}: the disk's write rate: {e}", p.display()))
}
