//! Heap policy of a process that runs scenes (the `porofrac` command, the Python
//! package): keep freed memory for reuse.
//!
//! A solve allocates and frees many large arrays: the pattern's passes, the strength
//! graph, aggregates and prolongators of each multigrid level, work vectors. glibc's
//! `malloc` serves every block above its mapping threshold (at most 32 MB; 128 kB at
//! first) with a fresh `mmap` and returns it to the kernel on `free`, so the next array
//! of that size faults in and zeroes its pages again, one 4 kB page at a time, and page
//! faults are dear on the virtual machines this runs on. In three interleaved pairs of E2
//! n = 1000 runs (`porofrac-sim`'s `--example solvers`, which applies the same policy,
//! with and without `SYSTEM_HEAP=1`, docs/BENCHMARKS.md) assembly + setup + solve took
//! 4.70 / 4.87 / 4.63 s against 5.87 / 5.35 / 4.94 s, most of the difference in the
//! multigrid setup (1.43–1.52 against 1.60–2.07 s).
//!
//! [`retain_freed_memory`] turns both off for the calling process: blocks come from the
//! heap, and freed memory stays with the process for the next allocation instead of being
//! trimmed. The peak resident size of one E2 n = 1000 run stayed at 1.56–1.60 GB; the
//! resident size after a peak stays at the peak until the process ends, and repeated
//! solves in one process can hold somewhat more than the largest live set (three E2 runs:
//! 1.70–1.89 GB), which suits a batch simulation. A process-wide setting, so it belongs
//! to the program: the command's `main` calls it first thing, before threads start, and
//! the Python package offers it as `porofrac.retain_freed_memory()`. Elsewhere than Linux
//! with glibc it does nothing.

/// Keep freed heap memory in the process (see the module docs). Returns whether the
/// policy was applied (Linux with glibc).
pub fn retain_freed_memory() -> bool {
    apply()
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn apply() -> bool {
    // SAFETY: `mallopt` only sets allocator parameters; it is called with constants glibc
    // documents, and glibc serialises it against concurrent allocation.
    let no_mmap = unsafe { libc::mallopt(libc::M_MMAP_MAX, 0) } == 1;
    // SAFETY: as above.
    let no_trim = unsafe { libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX) } == 1;
    no_mmap && no_trim
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn apply() -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_blocks_still_allocate_and_free_after_the_policy() {
        let applied = retain_freed_memory();
        assert_eq!(
            applied,
            cfg!(all(target_os = "linux", target_env = "gnu")),
            "policy applied where supported"
        );
        // 64 MB blocks (above any mmap threshold) come from the heap now; allocate,
        // write, free and allocate again.
        for round in 0..3 {
            let mut v = vec![0.0f64; 8 << 20];
            v[0] = round as f64;
            *v.last_mut().unwrap() = 1.0;
            assert_eq!(v.iter().sum::<f64>(), round as f64 + 1.0);
        }
    }
}
