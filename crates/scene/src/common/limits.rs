//! Bounds on what a scene may ask for, checked before anything big is allocated.
//!
//! - **Steps**: at most [`MAX_STEPS`] output times, and the in-memory series of the
//!   written steps (probe columns, line points) must fit in memory.
//! - **Cells and unknowns**: the grid a scene asks for is counted from its keys before
//!   it is generated (after reading, for mesh files) and refused when the run would need
//!   more memory than the machine has. The estimate is
//!   `BYTES_PER_ITEM · (cells + unknowns)` with [`BYTES_PER_ITEM`] = 600, which is above
//!   the measured peaks of the standard problems (E2 n = 1000: 2.0 M cells, 2.0 M
//!   unknowns, 1.5 GB; E3 n = 40: 0.38 M cells, 0.21 M unknowns, 0.35 GB).
//! - **Memory of the machine**: the smaller of the physical memory (`MemTotal` of
//!   `/proc/meminfo`) and the address-space limit of the process (`ulimit -v`, from
//!   `/proc/self/limits`); where neither can be read, no memory bound applies.
//!
//! The error names the key and says how much memory the request needs against what the
//! machine has.

/// Largest number of output times of a schedule.
pub const MAX_STEPS: u64 = 10_000_000;

/// Largest number of cells of a grid (indices stay far from `u32` limits of the
/// readers and solvers).
pub const MAX_CELLS: u64 = 1_000_000_000;

/// Largest number of points of one output line.
pub const MAX_LINE_POINTS: u64 = 1_000_000;

/// Estimated peak memory per cell of a corner-point deck (bytes): reading and processing
/// take about 1.4 kB per cell (1.3 GB for the faulted 100³ deck of
/// `porofrac-grid/examples/grdecl_speed.rs`), the run about as much again.
pub const BYTES_PER_DECK_CELL: u64 = 3000;

/// Estimated peak memory per cell and per unknown of a run (bytes).
pub const BYTES_PER_ITEM: u64 = 600;

/// Memory a run may use (bytes), if it can be known.
pub fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with("MemTotal:"))
            .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    let address_space = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("Max address space"))
                .and_then(|l| l.split_whitespace().nth(3)?.parse::<u64>().ok())
        });
    match (total, address_space) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// Human-readable bytes: `1.6e17 bytes (150 PB)` style, in GB for the usual sizes.
pub fn bytes_text(b: f64) -> String {
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}

/// `Err(message)` when `bytes` exceed the machine's memory; `what` says what needs it.
pub fn fits_in_memory(bytes: f64, what: &str) -> Result<(), String> {
    match machine_memory() {
        Some(m) if bytes > m as f64 => Err(format!(
            "{what}, which needs about {} of memory; this machine has {} for a run",
            bytes_text(bytes),
            bytes_text(m as f64)
        )),
        _ => Ok(()),
    }
}

/// The memory estimate of a run with `cells` cells and `unknowns` unknowns.
pub fn run_bytes(cells: f64, unknowns: f64) -> f64 {
    BYTES_PER_ITEM as f64 * (cells + unknowns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_requests_do_not_fit_and_small_ones_do() {
        if machine_memory().is_none() {
            return;
        }
        let e = fits_in_memory(run_bytes(1e16, 2e16), "1e16 cells").unwrap_err();
        assert!(e.contains("1e16 cells") && e.contains("GB"), "{e}");
        assert!(fits_in_memory(run_bytes(1e3, 2e3), "a small grid").is_ok());
    }
}
