//! Bounds on what a scene may ask for, checked before anything big is allocated.
//!
//! - **Steps**: at most [`MAX_STEPS`] output times, and the in-memory series of the
//!   written steps (probe columns, line points) must fit in memory.
//! - **Cells and unknowns**: the grid a scene asks for is counted from its keys before
//!   it is generated (after reading, for mesh files and decks) and refused when the run
//!   would need more memory than the machine has ([`run_bytes_of`]). The estimate is
//!   `b · (cells + unknowns)` plus, for a 3D run that factors its matrix, the factor:
//!   - `b` = [`BYTES_PER_ITEM`] = 600 in 2D, above the measured peaks of the standard
//!     problems (E2 n = 1000: 2.0 M cells, 2.0 M unknowns, 1.5 GB; E3 n = 40: 0.38 M
//!     cells, 0.21 M unknowns, 0.35 GB);
//!   - `b` = [`BYTES_PER_ITEM_3D`] = 1700 in 3D: hexahedra couple every node to 27
//!     others (81 entries per matrix row, against 18 for 2D triangles), and the
//!     multigrid keeps the matrix with both triangles and its coarse levels (measured:
//!     the faulted 40³ deck of `porofrac-grid/examples/grdecl_speed.rs`, mechanics
//!     only, CG-AMG: 57 600 cells, 179 918 unknowns, peak 369 MB = 1.55 kB per item);
//!   - the factor of a direct solve in 3D: nested dissection gives about
//!     `c · n^{4/3}` entries for `n` unknowns, at `e` bytes each at the peak, with
//!     [`FACTOR_ENTRIES_PER_N43`] `c` = 45 and [`BYTES_PER_FACTOR_ENTRY`] `e` = 10
//!     (measured on the same decks with flow and the monolithic coupling, LDLᵀ of
//!     mechanics and pressure: 20³, n = 30 558, 31.7 M entries, peak 434 MB; 40³,
//!     n = 237 518, 609 M entries, peak 6.17 GB; the estimates are 494 MB and
//!     7.1 GB). A 3D run factors when the flow is coupled to the mechanics (every
//!     coupling counts: a conservative choice), or when the mechanics uses the sparse
//!     Cholesky (`linear = "cholesky"`, or `"auto"` below
//!     [`porofrac_sim::linear::AUTO_MIN_EQUATIONS_3D`] equations). The faulted 100³
//!     deck with coupled flow (0.9 M cells, 3.9 M unknowns) needs about 290 GB this
//!     way, and mechanics alone with CG-AMG about 6.7 GB: both are refused under a
//!     4 GB address-space limit before anything big is allocated.
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

/// Estimated peak memory per cell and per unknown of a 2D run (bytes).
pub const BYTES_PER_ITEM: u64 = 600;

/// Estimated peak memory per cell and per unknown of a 3D run, the factor of a direct
/// solve apart (bytes; see the module docs).
pub const BYTES_PER_ITEM_3D: u64 = 1700;

/// Entries of the factor of a 3D direct solve per `n^{4/3}` (`n` unknowns, nested
/// dissection; see the module docs).
pub const FACTOR_ENTRIES_PER_N43: f64 = 45.0;

/// Peak bytes per entry of the factor of a direct solve (value, index, the workspace of
/// the factorization).
pub const BYTES_PER_FACTOR_ENTRY: f64 = 10.0;

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

/// The memory estimate of a 2D run with `cells` cells and `unknowns` unknowns.
pub fn run_bytes(cells: f64, unknowns: f64) -> f64 {
    BYTES_PER_ITEM as f64 * (cells + unknowns)
}

/// The memory estimate of a run (see the module docs): the whole, and the part of it for
/// the factor of a direct solve (0 when there is none or in 2D).
pub fn run_bytes_of(dim: usize, cells: f64, unknowns: f64, direct: bool) -> (f64, f64) {
    if dim < 3 {
        return (run_bytes(cells, unknowns), 0.0);
    }
    let factor = if direct {
        FACTOR_ENTRIES_PER_N43 * unknowns.powf(4.0 / 3.0) * BYTES_PER_FACTOR_ENTRY
    } else {
        0.0
    };
    (
        BYTES_PER_ITEM_3D as f64 * (cells + unknowns) + factor,
        factor,
    )
}

/// What needs the memory, for the error of [`fits_in_memory`]: the counts.
pub fn run_text(cells: f64, unknowns: f64) -> String {
    format!("{cells:.3e} cells and {unknowns:.3e} unknowns")
}

/// The end of a refusal when a direct solve's factor is part of the estimate (empty
/// without one): its share and the way around it.
pub fn factor_note(factor: f64) -> String {
    if factor > 0.0 {
        format!(
            "; the factor of the direct solve alone, which grows as unknowns^(4/3) in 3D, \
             needs about {} (the mechanics alone with linear = \"cg-amg\" has no factor)",
            bytes_text(factor)
        )
    } else {
        String::new()
    }
}

/// Seconds per factor entry ([`factor_entries`]) and output time of a continuum run
/// without failure criteria (measured: `mandel`, 2D, 4 840 unknowns, 201 times, 0.09 s
/// = 7.6e-9; `corner_point/injection`, 3D, 1 949 unknowns, 21 times, 0.16 s = 7e-9).
pub const CONTINUUM_SECONDS_PER_ENTRY: f64 = 1e-8;

/// Seconds per factor entry and output time of a 2D continuum run whose cells can fail:
/// failures are resolved by repeated solves and factor updates within a step (measured:
/// `hydrofrac_seed` 2.1e-7, `hydrofrac_seed_fluid_lag` 1.9e-7, `hydrofrac_composite`
/// 9.8e-8).
pub const CONTINUUM_SECONDS_PER_ENTRY_FAILING_2D: f64 = 1.5e-7;

/// Seconds per factor entry and output time of a 3D continuum run whose cells can fail
/// (measured: `hydrofrac_3d` 1.1e-8, `corner_point/hydrofrac` 6.9e-9).
pub const CONTINUUM_SECONDS_PER_ENTRY_FAILING_3D: f64 = 1e-8;

/// Seconds per unknown and integrator step of a Cosserat run (measured:
/// `cosserat_lamb`, 60 000 unknowns, 250 steps of 6 sub-steps, 36.8 s = 4.1e-7).
pub const COSSERAT_SECONDS_PER_UNKNOWN_STEP: f64 = 4e-7;

/// Seconds per lattice node and lattice step of a lattice Boltzmann run (measured:
/// `lbm/schaefer_turek_2d1`, 36 080 nodes, 40 000 steps, 8.5 s = 5.9e-9;
/// `lbm/taylor_green` 5.3e-9).
pub const LBM_SECONDS_PER_NODE_STEP: f64 = 6e-9;

/// Seconds per lattice node and lattice step of the fluid of a lattice solid run (the
/// coupling's moving walls, refills and heat make it slower than a plain lattice;
/// measured: `lsm_heat` 7.1e-8, `lsm_hydrofrac` 2.2e-8).
pub const LSM_FLUID_SECONDS_PER_NODE_STEP: f64 = 4e-8;

/// Seconds per particle and lattice solid step (measured: `lsm/borehole_dry` 1.6e-7,
/// `lsm/brazilian` 1.1e-7, `lsm/borehole_flooded` 1.7e-7).
pub const LSM_SECONDS_PER_PARTICLE_STEP: f64 = 1.5e-7;

/// Seconds per disk and contact dynamics step (measured: `nscd/fault` 2.0e-5,
/// `nscd/fault_gamma0` 7.3e-6: the sweeps of the contact solver vary with the scene).
pub const NSCD_SECONDS_PER_DISK_STEP: f64 = 1.2e-5;

/// Peak bytes per unknown of a Cosserat run, the sparse LU factor included (measured:
/// 6.8 kB for `cosserat_plate_hole`, 2.2 kB for the explicit `cosserat_lamb`).
pub const COSSERAT_BYTES_PER_UNKNOWN: f64 = 5000.0;

/// Peak bytes per lattice node of a lattice Boltzmann fluid (9 populations, the node's
/// flags and fields; measured: 140 B for `lbm/schaefer_turek_2d1`, 120 B for the fluid
/// of `lsm_hydrofrac`), without and with the temperature distribution.
pub const LBM_BYTES_PER_NODE: [f64; 2] = [150.0, 200.0];

/// Peak bytes per particle and per bond of a lattice solid run.
pub const LSM_BYTES_PER_PARTICLE_AND_BOND: [f64; 2] = [2000.0, 1000.0];

/// Peak bytes per disk of a contact dynamics run (its contacts included).
pub const NSCD_BYTES_PER_DISK: f64 = 2000.0;

/// Peak bytes per cell and unknown of a 2D continuum run whose flow is coupled to the
/// mechanics: the factor of the Biot system and its updates (measured:
/// `hydrofrac_seed` 3.5 kB, `hydrofrac_composite` 3.8 kB). A check's estimate only:
/// the refusal of a scene too big for the machine keeps [`run_bytes_of`].
pub const COUPLED_2D_BYTES_PER_ITEM: f64 = 4000.0;

/// The memory a run needs besides its model: the program itself (bytes; 11–17 MB
/// measured for the smallest scenes).
pub const BASE_BYTES: f64 = 15e6;

/// Entries of the factor of a direct solve of `n` unknowns, the unit of work of a
/// continuum run's time estimate: `n log₂ n` in 2D, [`FACTOR_ENTRIES_PER_N43`]
/// `· n^{4/3}` in 3D (nested dissection).
pub fn factor_entries(dim: usize, n: f64) -> f64 {
    if dim >= 3 {
        FACTOR_ENTRIES_PER_N43 * n.powf(4.0 / 3.0)
    } else {
        n * n.max(2.0).log2()
    }
}

/// The peak memory estimate of a continuum run for a check (bytes, the program apart):
/// [`run_bytes_of`], or [`COUPLED_2D_BYTES_PER_ITEM`] per cell and unknown for a 2D
/// run with coupled flow.
pub fn continuum_bytes(dim: usize, cells: f64, unknowns: f64, direct: bool, coupled: bool) -> f64 {
    if dim < 3 && coupled {
        COUPLED_2D_BYTES_PER_ITEM * (cells + unknowns)
    } else {
        run_bytes_of(dim, cells, unknowns, direct).0
    }
}

/// The peak memory estimate of a Cosserat run with `unknowns` unknowns (bytes, the
/// program apart).
pub fn cosserat_bytes(unknowns: f64) -> f64 {
    COSSERAT_BYTES_PER_UNKNOWN * unknowns
}

/// The peak memory estimate of a lattice Boltzmann fluid on `nodes` lattice nodes, with
/// the temperature distribution or not (bytes).
pub fn lbm_bytes(nodes: f64, thermal: bool) -> f64 {
    LBM_BYTES_PER_NODE[usize::from(thermal)] * nodes
}

/// The peak memory estimate of a lattice solid (its fluid apart; bytes).
pub fn lsm_bytes(particles: f64, bonds: f64) -> f64 {
    let [p, b] = LSM_BYTES_PER_PARTICLE_AND_BOND;
    p * particles + b * bonds
}

/// The peak memory estimate of a contact dynamics run with `disks` disks (bytes).
pub fn nscd_bytes(disks: f64) -> f64 {
    NSCD_BYTES_PER_DISK * disks
}

/// The work of a run for the time estimate of a check: units of work, and the seconds
/// per unit with the factor the estimate is good to.
#[derive(Clone, Copy, Debug)]
pub struct Work {
    /// Units of work of the whole schedule.
    pub units: f64,
    /// Seconds per unit.
    pub seconds_per_unit: f64,
    /// The unit.
    pub unit: &'static str,
    /// The measured times of the bundled scenes are within this factor of the estimate.
    pub factor: f64,
}

impl Work {
    /// The estimated time of the steps (s).
    pub fn seconds(&self) -> f64 {
        self.units * self.seconds_per_unit
    }
}

/// Seconds of a run besides its build and steps: start-up, the output files and plots
/// (0.04–0.2 s measured for the smallest bundled scenes).
pub const RUN_OVERHEAD_SECONDS: f64 = 0.1;

/// The measured peaks of the bundled scenes are within this factor of the estimates
/// of a check ([`crate::common::plan`]).
pub const MEMORY_FACTOR: f64 = 2.5;

#[cfg(test)]
mod tests {
    use super::*;

    /// The throughput constants against the runs they were measured on (the figures in
    /// their docs): each estimate within the factor a check states (5 for the continuum,
    /// Cosserat and contact dynamics, 3 for the lattices and the lattice solid).
    #[test]
    fn throughput_constants_cover_their_measured_runs() {
        // (seconds per unit, units, measured seconds, stated factor)
        let e2 = |n: f64, times: f64| factor_entries(2, n) * times;
        let e3 = |n: f64, times: f64| factor_entries(3, n) * times;
        let cases = [
            // mandel: 3 240 + 1 600 unknowns, 201 times, 0.09 s
            (CONTINUUM_SECONDS_PER_ENTRY, e2(4840.0, 201.0), 0.09, 5.0),
            // corner_point/injection: 1 511 + 438 unknowns, 21 times, 0.16 s
            (CONTINUUM_SECONDS_PER_ENTRY, e3(1949.0, 21.0), 0.16, 5.0),
            // hydrofrac_seed: 20 657 + 19 500, 41 times, 5.38 s
            (
                CONTINUUM_SECONDS_PER_ENTRY_FAILING_2D,
                e2(40157.0, 41.0),
                5.38,
                5.0,
            ),
            // hydrofrac_composite: 12 389 + 11 232, 41 times, 1.37 s
            (
                CONTINUUM_SECONDS_PER_ENTRY_FAILING_2D,
                e2(23621.0, 41.0),
                1.37,
                5.0,
            ),
            // hydrofrac_3d: 19 981 + 24 328, 41 times, 31.2 s
            (
                CONTINUUM_SECONDS_PER_ENTRY_FAILING_3D,
                e3(44309.0, 41.0),
                31.2,
                5.0,
            ),
            // cosserat_lamb: 60 000 unknowns, 1 500 steps, 36.8 s
            (COSSERAT_SECONDS_PER_UNKNOWN_STEP, 6e4 * 1500.0, 36.8, 5.0),
            // lbm/schaefer_turek_2d1: 36 080 nodes, 40 000 steps, 8.5 s
            (LBM_SECONDS_PER_NODE_STEP, 36080.0 * 4e4, 8.5, 3.0),
            // lsm_heat: 16 000 nodes, 4 000 steps, 4.6 s; lsm_hydrofrac: 810 000, 2 280, 40 s
            (LSM_FLUID_SECONDS_PER_NODE_STEP, 16000.0 * 4000.0, 4.6, 3.0),
            (
                LSM_FLUID_SECONDS_PER_NODE_STEP,
                810000.0 * 2280.0,
                40.0,
                3.0,
            ),
            // lsm/brazilian: 1 008 particles, 33 000 steps, 3.8 s
            (LSM_SECONDS_PER_PARTICLE_STEP, 1008.0 * 33000.0, 3.8, 3.0),
            // nscd/fault: 968 disks, 300 steps, 5.9 s; fault_gamma0: 597, 4 000, 17.5 s
            (NSCD_SECONDS_PER_DISK_STEP, 968.0 * 300.0, 5.9, 5.0),
            (NSCD_SECONDS_PER_DISK_STEP, 597.0 * 4000.0, 17.5, 5.0),
        ];
        for (k, (per_unit, units, measured, factor)) in cases.into_iter().enumerate() {
            let est = per_unit * units;
            assert!(
                est <= factor * measured && measured <= factor * est,
                "case {k}: estimate {est} s, measured {measured} s"
            );
        }
        // 2D: n log2 n; 3D: 45 n^(4/3).
        assert_eq!(factor_entries(2, 1024.0), 10240.0);
        assert!((factor_entries(3, 1000.0) - 45.0 * 1e4).abs() < 1e-6);
    }

    #[test]
    fn absurd_requests_do_not_fit_and_small_ones_do() {
        if machine_memory().is_none() {
            return;
        }
        let e = fits_in_memory(run_bytes(1e16, 2e16), "1e16 cells").unwrap_err();
        assert!(e.contains("1e16 cells") && e.contains("GB"), "{e}");
        assert!(fits_in_memory(run_bytes(1e3, 2e3), "a small grid").is_ok());
    }

    /// The 3D model against the peaks it was fitted to (module docs): above each, by less
    /// than 25 %; 2D unchanged.
    #[test]
    fn three_d_estimates_cover_the_measured_peaks() {
        let cases = [
            // cells, unknowns, direct, measured peak (bytes)
            (7_200.0, 30_558.0, true, 434e6),
            (57_600.0, 237_518.0, true, 6.17e9),
            (57_600.0, 179_918.0, false, 369e6),
        ];
        for (cells, unknowns, direct, peak) in cases {
            let (b, factor) = run_bytes_of(3, cells, unknowns, direct);
            assert!(
                b >= peak && b <= 1.25 * peak,
                "{cells} {unknowns}: {b} vs {peak}"
            );
            assert_eq!(factor > 0.0, direct);
        }
        assert_eq!(run_bytes_of(2, 1e6, 2e6, true), (run_bytes(1e6, 2e6), 0.0));
        // The factor grows as n^(4/3): 8 times the unknowns, 16 times the factor.
        let (_, f1) = run_bytes_of(3, 0.0, 1e6, true);
        let (_, f8) = run_bytes_of(3, 0.0, 8e6, true);
        assert!((f8 / f1 - 16.0).abs() < 1e-9);
        assert_eq!(factor_note(0.0), "");
        let t = factor_note(2.8e11);
        assert!(
            t.contains(
                "direct solve alone, which grows as unknowns^(4/3) in 3D, needs about 280.0 GB"
            ),
            "{t}"
        );
    }
}
