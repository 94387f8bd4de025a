//! What `porofrac check` reports of a scene: the model built as a run builds it, up to
//! its first step, described — its sizes, the steps and files a run would write, and
//! estimates of the run's peak memory and time ([`crate::common::limits`] holds the
//! per-model constants behind them and how good they are).

use crate::common::limits::{self, Work};
use crate::common::loaded::LoadedScene;
use crate::common::model::Model;

/// A built model, described: what a run of the scene computes and writes.
#[derive(Clone, Debug)]
pub struct Plan {
    /// `[scene] model`.
    pub model: String,
    /// The dimension.
    pub dim: usize,
    /// The sizes in the model's own words (`cells`, `nodes`, `unknowns`; `particles`,
    /// `bonds`; `lattice nodes`; `disks`, `contacts`), in the order they are printed.
    pub counts: Vec<(&'static str, usize)>,
    /// Output steps of the schedule (the initial state apart).
    pub steps: usize,
    /// Output times written (the initial state, every `[output] every`-th step, the
    /// last): rows of each line, VTK files when `[output] vtk`.
    pub written: usize,
    /// Output times the probes are sampled at (the written ones and every
    /// `[output] probe_every`-th step): rows of `probes.csv`.
    pub sampled: usize,
    /// VTK files a run writes (0 without `[output] vtk`).
    pub vtk_files: usize,
    /// `[[output.probe]]` entries.
    pub probes: usize,
    /// `[[output.line]]` entries.
    pub lines: usize,
    /// Estimated peak memory of the run (bytes), the program itself
    /// ([`limits::BASE_BYTES`]) included.
    pub peak_bytes: f64,
    /// Time the build took in this check (s): a run spends it again before its first
    /// step.
    pub build_seconds: f64,
    /// The work of the steps of a run, behind the estimate of their time
    /// ([`Work::seconds`]).
    pub work: Work,
}

impl Plan {
    /// Describe a built `model` of `ls`, built in `build_seconds`.
    pub fn of(ls: &LoadedScene, model: &dyn Model, dim: usize, build_seconds: f64) -> Self {
        let s = &ls.scene;
        let times = model.times().len();
        let written = written_steps(times, s.output.every.max(1) as usize);
        Self {
            model: ls.model().to_string(),
            dim,
            counts: model.sizes().counts,
            steps: times.saturating_sub(1),
            written,
            sampled: sampled_steps(
                times,
                s.output.every.max(1) as usize,
                s.output.probe_every.max(1) as usize,
            ),
            vtk_files: if s.output.vtk { written } else { 0 },
            probes: s.output.probe.len(),
            lines: s.output.line.len(),
            peak_bytes: limits::BASE_BYTES + model.peak_bytes(),
            build_seconds,
            work: model.work(),
        }
    }

    /// The lines `porofrac check` prints below its `ok` line.
    pub fn lines_text(&self) -> Vec<String> {
        let counts: Vec<String> = self
            .counts
            .iter()
            .map(|(what, n)| format!("{n} {what}"))
            .collect();
        let mut out = vec![
            format!(
                "model {} ({}D): {}",
                self.model,
                self.dim,
                counts.join(", ")
            ),
            format!(
                "steps: {}; written: {} ({} VTK files, {} lines); probes.csv: {} rows of {} probes",
                self.steps, self.written, self.vtk_files, self.lines, self.sampled, self.probes
            ),
        ];
        out.push(format!(
            "estimated peak memory: {} (within a factor of {} of the measured peaks)",
            limits::bytes_text(self.peak_bytes),
            limits::MEMORY_FACTOR
        ));
        let steps = self.work.seconds() + limits::RUN_OVERHEAD_SECONDS;
        out.push(format!(
            "estimated run time: {} = build {} (measured by this check) + steps and files {} \
             (estimate within a factor of {} on a 2-core machine: {:.2e} {} at {:.1e} s each)",
            seconds_text(self.build_seconds + steps),
            seconds_text(self.build_seconds),
            seconds_text(steps),
            self.work.factor,
            self.work.units,
            self.work.unit,
            self.work.seconds_per_unit,
        ));
        out
    }
}

/// Output times a run writes out of `times` (the initial one included) with
/// `[output] every = every`: step 0, every `every`-th step and the last.
pub fn written_steps(times: usize, every: usize) -> usize {
    if times == 0 {
        return 0;
    }
    let last = times - 1;
    let every = every.max(1);
    last / every + 1 + usize::from(!last.is_multiple_of(every))
}

/// Output times at which a run samples its probes out of `times`: the written ones
/// ([`written_steps`]) and every `probe_every`-th step.
pub fn sampled_steps(times: usize, every: usize, probe_every: usize) -> usize {
    let (every, probe_every) = (every.max(1), probe_every.max(1));
    if times == 0 {
        return 0;
    }
    let last = times - 1;
    // Steps 1..last-1 that are a multiple of either interval, by inclusion–exclusion.
    let lcm = every / gcd(every, probe_every) * probe_every;
    let inner = last.saturating_sub(1);
    let multiples = inner / every + inner / probe_every - inner / lcm;
    multiples + 1 + usize::from(last > 0)
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// `0.12 s`, `42 s`, `1.5 min`, `3.2 h`.
pub fn seconds_text(s: f64) -> String {
    if s < 1.0 {
        format!("{s:.2} s")
    } else if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sampled steps are those the driver samples: 0, every `every`-th, every
    /// `probe_every`-th, the last.
    #[test]
    fn sampled_steps_match_the_driver() {
        for times in 0..40 {
            for every in 1..7 {
                for probe_every in 1..7 {
                    let expected = (0..times)
                        .filter(|&s| {
                            s == 0 || s % every == 0 || s % probe_every == 0 || s + 1 == times
                        })
                        .count();
                    assert_eq!(
                        sampled_steps(times, every, probe_every),
                        expected,
                        "{times} {every} {probe_every}"
                    );
                }
            }
        }
    }

    /// The written steps are those the driver writes: 0, every `every`-th, the last.
    #[test]
    fn written_steps_match_the_driver() {
        for times in 0..30 {
            for every in 1..7 {
                let expected = (0..times)
                    .filter(|&s| s == 0 || s % every == 0 || s + 1 == times)
                    .count();
                assert_eq!(written_steps(times, every), expected, "{times} {every}");
            }
        }
    }

    #[test]
    fn seconds_are_in_readable_units() {
        assert_eq!(seconds_text(0.123), "0.12 s");
        assert_eq!(seconds_text(42.4), "42 s");
        assert_eq!(seconds_text(150.0), "2.5 min");
        assert_eq!(seconds_text(3.0 * 3600.0), "3.0 h");
    }
}
