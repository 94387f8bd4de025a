//! The pore pressure bounded below by a cavitation (vapour) pressure: a step of a Biot
//! coupling with an active set of cavitating cells, and the void they open.
//!
//! # The bound
//!
//! A cell that opens faster than fluid can reach it (the cells of a crack ahead of the
//! fluid front, fluid lag) would otherwise fall to an unbounded suction: its undrained
//! mass balance `M Δp + α ΔV = 0` gives `Δp = −α ΔV / M`, tens of MPa below zero for a
//! small storage `M`. A liquid cannot hold such a tension: below its vapour
//! (cavitation) pressure `p_c` it boils, or the crack fills with vapour and the gas of the
//! rock, and the pressure stays at `p_c`. The volume the cell opens beyond what its fluid
//! fills is then a void `V ≥ 0`.
//!
//! Per cell, with the void `Vⁿ` at the start of a step and its change `ΔV_v` over the step,
//! the mass balance of the fluid (the Biot rows of [`crate::biot`]) becomes
//!
//! ```text
//!   M Δp + α ΔV + Δt A p = Δt b + ΔV_v ,
//!   p ≥ p_c ,   Vⁿ + ΔV_v ≥ 0 ,   (p − p_c) (Vⁿ + ΔV_v) = 0 :
//! ```
//!
//! the void opens only at the cavitation pressure, and a cell above it holds no void. The
//! void change enters the coupled system as a source `ΔV_v / Δt` of the cell
//! ([`BiotSystem::set_void_source`]); since the step is linear in its sources, the
//! complementarity problem is solved by a primal–dual active set on the few cells
//! concerned:
//!
//! * the *cavitating* set `S`: `p = p_c`, the void change `ΔV_v` unknown;
//! * every other cell: the void it held closes, `ΔV_v = −Vⁿ` (the fluid that arrives
//!   fills it first), and its pressure is free.
//!
//! The step without void sources and the response of the pressure to a unit void source
//! in each cell of `S` give the pressure of any choice of sources by superposition. The
//! monolithic scheme gives those responses from its factors without a solve
//! ([`CavitationSolver::responses`], `Monolithic::pressure_responses`: the Schur
//! complement of the coupled matrix on the pressures of `S`); other schemes measure them,
//! one solve each with the same matrix, kept between steps ([`ResponseCache`]);
//! the void changes of `S` solve the small dense system `p_S = p_c`. A cell of `S` whose
//! void would become negative leaves `S`; a cell outside `S` below `p_c` joins it; the
//! iteration starts from the set of the last bounded step (the cells of it that still
//! hold a void or fall below `p_c`) and ends when `S` does not change (at most
//! [`MAX_ACTIVE_SET`] times). The step is
//! then solved once more with the sources found, and the pressure of the cells of `S`
//! set to `p_c` (it differs from it by the rounding of that solve). The fluid volume is
//! balanced to rounding: over a closed domain the injected volume equals the stored one
//! (`Σ M Δp + α ΔV`) less the void change, `Σ ΔV_v`.
//!
//! # The accuracy the bound is held to
//!
//! A cell of `S` meets the bound when its pressure is within `1e-10` of the pressure
//! scale (the largest pressure of the free step) of `p_c`. With the responses of the
//! current system (from the factors, or all measured with it) the step is linear in the
//! sources, so one correction should get there; what is left after it is the error of
//! the solves in those pressures, and further corrections only redraw it. Such a stalled
//! miss (less than halving from one correction to the next, or the last correction) is
//! accepted, the solve of the smallest miss with it, when it is within
//!
//! ```text
//!   max( STALL_FLOOR · scale ,  ACCURACY_MULTIPLE · a ) ,   STALL_FLOOR = 1e-7, ACCURACY_MULTIPLE = 2,
//! ```
//!
//! `a` the accuracy the solves attained in the pressures of `S`
//! ([`CavitationSolver::pressure_accuracy`]): for the monolithic scheme the change one
//! step of iterative refinement would make there, `s |(A⁻¹ (b − A z))_K|`, the first-order
//! estimate of the solve's error in the pressure of `K`. On a well-conditioned system it
//! is at the rounding of the pressures (1e-9 Pa at 1 MPa) and the fixed floor decides.
//! A crack conducting by the cubic law makes the coupled matrix's diagonal span 1e15
//! (see [`crate::biot::Monolithic`]): its solves are judged in the Jacobi-scaled system
//! (scaled residuals of 1e-14 to 1e-10), and the pressures of the cells ahead of its
//! tips, an undrained response `−α ΔV/M` of a tiny storage to the volume change of a
//! cell beside a crack opened by centimetres, come out accurate to a few Pa to tens of
//! Pa at well pressures of 30–60 MPa (1e-7 to 1e-6 of the scale). The misses of a
//! stalled iteration there are of that size (0.6–46 Pa estimated against 3–42 Pa missed on
//! the seed's fluid-lag scene with a toughness of 6 MPa·√m, docs/hydrofrac/validation.md),
//! and the estimate is what lets the step go on instead of the fixed 1 Pa at a scale of
//! 10 MPa. What such a miss means: the pressure of a cavitating cell within tens of Pa of
//! a vapour pressure of 2.3 kPa, in a crack at tens of MPa; the pressure is then set to
//! `p_c` and the void is the one of that solve, wrong by the miss over the cell's
//! response (a few millionths of the cell's volume there). When the corrections end
//! without such a solve, a second pass starts from the voids of the smallest miss with
//! every solve corrected by one step of iterative refinement
//! ([`CavitationSolver::refine`]; the monolithic scheme's factors), which lowers the very
//! error the estimate measures, and is judged the same way. A miss beyond twice the
//! estimate after both passes, or any above the floor when the scheme gives neither
//! estimate nor refinement (the split schemes), is still refused: the iteration failed
//! rather than met the solves' rounding. A step the first pass accepts is unchanged by
//! the second, and so are the scenes whose bounded steps never need it.
//!
//! Without a bound ([`bounded_step`] is not called) the step is the scheme's own, bit for
//! bit.

use crate::biot::{BiotError, BiotResult, BiotStep, BiotSystem};

/// The most changes of the cavitating set within one step.
pub const MAX_ACTIVE_SET: usize = 50;

/// A step with the pore pressure bounded below ([`bounded_step`]).
#[derive(Clone, Debug)]
pub struct BoundedStep {
    /// The step, with the pressure of every cavitating cell equal to the bound.
    pub step: BiotStep,
    /// The change of the void of every cell over the step (m³; m² per unit height in 2D):
    /// positive where a cavitating cell opened, `−Vⁿ` where a void closed.
    pub void_change: Vec<f64>,
    /// The cells at the cavitation pressure at the end of the step.
    pub cavitating: Vec<usize>,
    /// Coupled solves done (1 when no cell cavitates).
    pub solves: usize,
}

/// The responses of the pressure to a unit void in a cell, kept from one bounded step to
/// the next (see [`bounded_step`]): the cavitating cells of a crack's tips change little
/// from one solve to the next, and neither does the response of the coupled system to a
/// void in one of them. A kept response only steers the iteration; every state accepted
/// is a solve of the current system.
#[derive(Clone, Debug, Default)]
pub struct ResponseCache {
    /// Per cell: the pressure change of a void of the cell's own volume over a step, as
    /// (cell, value) pairs above a small fraction of the largest.
    entries: Vec<(usize, Vec<(usize, f64)>)>,
    /// The cavitating cells at the end of the last bounded step: the next one starts
    /// from those of them that still hold a void or fall below the bound.
    last: Vec<usize>,
}

/// A coupled step as [`bounded_step`] uses it: solves with the void sources of the system,
/// and, where the scheme can, the responses of the pressure to void sources from the
/// matrix of its last solve without a solve (the Schur complement of the coupled matrix
/// on the pressures of a few cells). Every closure `FnMut(&BiotSystem) -> BiotResult<BiotStep>`
/// is one that has no such responses (they are then measured by solves).
pub trait CavitationSolver<const D: usize> {
    /// One step of `system` with its void sources.
    fn solve(&mut self, system: &BiotSystem<'_, D>) -> BiotResult<BiotStep>;
    /// The pressure change at `cells[i]` of a void of `volumes[j]` opened in `cells[j]`
    /// over the step (row-major `k × k`), with the matrix of the last [`Self::solve`];
    /// `None` when the scheme has no such responses (the default) or `system` is not the
    /// last one solved.
    fn responses(
        &mut self,
        system: &BiotSystem<'_, D>,
        cells: &[usize],
        volumes: &[f64],
    ) -> BiotResult<Option<Vec<f64>>> {
        let _ = (system, cells, volumes);
        Ok(None)
    }
    /// The accuracy (Pa) the last [`Self::solve`] of `system` attained in the pressure of
    /// each cell of `cells`: the size of the change one step of iterative refinement
    /// would make there. `None` when the scheme gives no such estimate (the default):
    /// the bound is then held to [`STALL_FLOOR`] of the pressure scale.
    fn pressure_accuracy(
        &mut self,
        system: &BiotSystem<'_, D>,
        cells: &[usize],
    ) -> BiotResult<Option<Vec<f64>>> {
        let _ = (system, cells);
        Ok(None)
    }
    /// The last [`Self::solve`] of `system` corrected by one step of iterative
    /// refinement with the scheme's factors (`z += A⁻¹ (b − A z)`); `None` when the
    /// scheme has none (the default).
    fn refine(&mut self, system: &BiotSystem<'_, D>) -> BiotResult<Option<BiotStep>> {
        let _ = system;
        Ok(None)
    }
}

impl<const D: usize, F> CavitationSolver<D> for F
where
    F: FnMut(&BiotSystem<'_, D>) -> BiotResult<BiotStep>,
{
    fn solve(&mut self, system: &BiotSystem<'_, D>) -> BiotResult<BiotStep> {
        self(system)
    }
}

/// Responses kept at most; the oldest go first.
const MAX_RESPONSES: usize = 256;

impl ResponseCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }
    /// Forget every response (e.g. for a new grid or system).
    pub fn clear(&mut self) {
        self.entries.clear();
        self.last.clear();
    }
    /// The number of responses kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }
    /// Whether no response is kept.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    fn get(&self, d: usize) -> Option<&[(usize, f64)]> {
        self.entries
            .iter()
            .find(|(e, _)| *e == d)
            .map(|(_, r)| r.as_slice())
    }
    fn put(&mut self, d: usize, dp: &[f64]) {
        self.entries.retain(|(e, _)| *e != d);
        if self.entries.len() >= MAX_RESPONSES {
            self.entries.remove(0);
        }
        let big = dp.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let kept = dp
            .iter()
            .enumerate()
            .filter(|(_, v)| v.abs() > 1e-12 * big)
            .map(|(c, &v)| (c, v))
            .collect();
        self.entries.push((d, kept));
    }
    /// The response at cell `c` of a void in cell `d` (0 when not kept there).
    fn at(&self, d: usize, c: usize) -> f64 {
        self.get(d)
            .and_then(|r| r.iter().find(|(i, _)| *i == c).map(|(_, v)| *v))
            .unwrap_or(0.0)
    }
}

/// One step of a coupling (`step`, called with `system` and the void sources set) with
/// the pore pressure of every cell bounded below by `p_cav` (Pa, absolute) and the void
/// `void` (m³ per cell; m² in 2D) at the start of the step (see the module docs). `dt`
/// is the step (> 0); `cache` keeps the responses of the cavitating cells between calls
/// (they steer the iteration; a stale one costs iterations, not accuracy). The void
/// sources of `system` are reset to none at the end.
///
/// Errors: lengths, a non-finite bound, `dt ≤ 0`, an error of `step`, or a cavitating set
/// that does not settle within [`MAX_ACTIVE_SET`] changes.
pub fn bounded_step<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    p_cav: f64,
    void: &[f64],
    dt: f64,
    cache: &mut ResponseCache,
    mut step: impl CavitationSolver<D>,
) -> BiotResult<BoundedStep> {
    let nc = system.num_cells();
    if void.len() != nc {
        return Err(BiotError::Input(format!(
            "void of {} cells, the system has {nc}",
            void.len()
        )));
    }
    if !p_cav.is_finite() {
        return Err(BiotError::Input(format!(
            "cavitation pressure must be finite, got {p_cav}"
        )));
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(BiotError::Input(format!(
            "a step bounded by a cavitation pressure needs Δt > 0, got {dt}"
        )));
    }
    let volumes = system.mechanics().grid.cell_volumes().to_vec();
    let result = settle(system, p_cav, void, dt, &volumes, cache, &mut step);
    system.set_void_source(None)?;
    result
}

/// Newton corrections of the voids of one cavitating set before its responses are
/// measured again (kept ones) or the set is given up (fresh ones).
const MAX_CORRECTIONS: usize = 8;

/// A miss of the bound at which a stalled iteration is accepted whatever the solves'
/// estimated accuracy, as a fraction of the pressure scale (see the module docs).
pub const STALL_FLOOR: f64 = 1e-7;

/// A stalled miss is accepted up to this multiple of the accuracy the solves attained in
/// the pressures of the cavitating cells ([`CavitationSolver::pressure_accuracy`]).
pub const ACCURACY_MULTIPLE: f64 = 2.0;

/// The void sources of the amounts of void `amount` (per unit volume) opened over a step
/// of length `dt`: `q_c = amount_c V_c / dt`.
fn set_voids<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    amount: &[f64],
    volumes: &[f64],
    dt: f64,
) -> BiotResult<()> {
    let q = amount
        .iter()
        .zip(volumes)
        .map(|(a, v)| a * v / dt)
        .collect();
    system.set_void_source(Some(q))
}

/// The active-set iteration of [`bounded_step`].
fn settle<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    p_cav: f64,
    void: &[f64],
    dt: f64,
    volumes: &[f64],
    cache: &mut ResponseCache,
    step: &mut impl CavitationSolver<D>,
) -> BiotResult<BoundedStep> {
    let nc = void.len();
    system.set_void_source(None)?;
    let free = step.solve(system)?;
    let mut solves = 1;
    let holds_void = |c: usize| void[c] > 0.0;
    if free.state.pressure.iter().all(|&p| p >= p_cav) && !(0..nc).any(holds_void) {
        return Ok(BoundedStep {
            step: free,
            void_change: vec![0.0; nc],
            cavitating: Vec::new(),
            solves,
        });
    }
    let scale = free
        .state
        .pressure
        .iter()
        .fold(p_cav.abs(), |m, p| m.max(p.abs()));
    let tol = 1e-10 * scale;
    let below = |c: usize| holds_void(c) || free.state.pressure[c] < p_cav - tol;
    // The cells of the last set that still hold a void or are below the bound: the
    // solves of a step (failure rounds, the laws' active set) end at nearly the same set,
    // and the voids of the others then close. Without one, every such cell.
    let mut active: Vec<usize> = cache
        .last
        .iter()
        .copied()
        .filter(|&c| c < nc && below(c))
        .collect();
    if active.is_empty() {
        active = (0..nc).filter(|&c| below(c)).collect();
    }
    // The cells whose response was measured with the system of this call.
    let mut fresh: Vec<usize> = Vec::new();
    let base = Base {
        free: &free.state.pressure,
        volumes,
        dt,
    };
    for _ in 0..MAX_ACTIVE_SET {
        // The responses from the matrix of the free step when the scheme gives them
        // (exact to the rounding of the factors: no cached response steers).
        // With them, the responses of the closing voids outside the set too: the first
        // correction then accounts for them.
        let closing: Vec<usize> = (0..nc)
            .filter(|&c| holds_void(c) && active.binary_search(&c).is_err())
            .collect();
        let asked: Vec<usize> = active.iter().chain(&closing).copied().collect();
        let asked_volumes: Vec<f64> = asked.iter().map(|&c| volumes[c]).collect();
        let all = step.responses(system, &asked, &asked_volumes)?;
        let (m, k_asked) = (active.len(), asked.len());
        // The set's own block and the response of the set to the closing voids.
        let exact = all.as_ref().map(|g| {
            (0..m)
                .flat_map(|i| g[i * k_asked..i * k_asked + m].iter().copied())
                .collect::<Vec<f64>>()
        });
        for &c in active.iter().filter(|_| exact.is_none()) {
            if cache.get(c).is_none() {
                base.measure(c, system, cache, step)?;
                solves += 1;
                fresh.push(c);
            }
        }
        // Void changes in units of each cell's volume: the closing voids outside the set
        // are known, those of the set make its pressure p_c.
        let mut amount = vec![0.0; nc];
        for c in (0..nc).filter(|&c| holds_void(c) && active.binary_search(&c).is_err()) {
            amount[c] = -void[c] / volumes[c];
        }
        let jacobian = |cache: &ResponseCache| {
            let mut g = vec![0.0; m * m];
            for (i, &c) in active.iter().enumerate() {
                for (j, &d) in active.iter().enumerate() {
                    g[i * m + j] = cache.at(d, c);
                }
            }
            g
        };
        let mut g = exact.clone().unwrap_or_else(|| jacobian(cache));
        // The first guess from the free step, then Newton corrections with real solves.
        let mut r: Vec<f64> = active
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let shift: f64 = all.as_ref().map_or(0.0, |g| {
                    closing
                        .iter()
                        .enumerate()
                        .map(|(j, &d)| g[i * k_asked + m + j] * amount[d])
                        .sum()
                });
                p_cav - free.state.pressure[c] - shift
            })
            .collect();
        let mut solved = None;
        let mut last = f64::INFINITY;
        // The solve of the smallest miss with responses of the current system, its miss
        // and its voids: with solves whose rounding in the set's pressures is of the size
        // of the miss, a later correction can land farther from the bound.
        let mut best: Option<(f64, BiotStep, Vec<f64>)> = None;
        let mut attained = 0.0f64;
        // A second pass when the first ends without meeting the bound with responses of
        // the current system: from its best voids, every solve refined once with its own
        // residual ([`CavitationSolver::refine`]), which lowers the solves' error in the
        // pressures of the set that the first pass stalled at.
        let mut refined = false;
        'passes: loop {
            for k in 0..2 * MAX_CORRECTIONS {
                let dx = dense_solve(&mut g.clone(), &mut r.clone(), m).ok_or_else(|| {
                    BiotError::Solver(
                        "cavitation: the response of the cavitating cells is singular".into(),
                    )
                })?;
                for (&c, d) in active.iter().zip(&dx) {
                    amount[c] += d;
                }
                set_voids(system, &amount, volumes, dt)?;
                let mut s = step.solve(system)?;
                solves += 1;
                if refined && let Some(better) = step.refine(system)? {
                    s = better;
                    solves += 1;
                }
                r = active
                    .iter()
                    .map(|&c| p_cav - s.state.pressure[c])
                    .collect();
                let err = r.iter().fold(0.0f64, |e, v| e.max(v.abs()));
                let all_fresh = exact.is_some() || active.iter().all(|c| fresh.contains(c));
                if err <= tol {
                    solved = Some(s);
                    break;
                }
                if all_fresh {
                    if best.as_ref().is_none_or(|(e, _, _)| err < *e) {
                        best = Some((err, s, amount.clone()));
                    }
                    // No progress with responses of the current system: the misses are the
                    // rounding of the solves. Accept the best solve when its miss is within
                    // the floor or the accuracy the solves attained in those pressures.
                    if err > 0.5 * last || k + 1 == 2 * MAX_CORRECTIONS {
                        let e_best = best.as_ref().map_or(f64::INFINITY, |b| b.0);
                        if e_best > STALL_FLOOR * scale && attained == 0.0 {
                            attained = step
                                .pressure_accuracy(system, &active)?
                                .map_or(0.0, |a| a.iter().fold(0.0f64, |m, v| m.max(*v)));
                        }
                        if e_best <= (STALL_FLOOR * scale).max(ACCURACY_MULTIPLE * attained) {
                            let (_, s_best, a_best) = best.take().expect("a best solve");
                            amount = a_best;
                            solved = Some(s_best);
                            break;
                        }
                    }
                }
                // Slow progress with kept responses: measure those of the set again.
                let stale: Vec<usize> = active
                    .iter()
                    .copied()
                    .filter(|c| exact.is_none() && !fresh.contains(c))
                    .collect();
                if (err > 0.1 * last || k + 1 == MAX_CORRECTIONS) && !stale.is_empty() {
                    for c in stale {
                        base.measure(c, system, cache, step)?;
                        solves += 1;
                        fresh.push(c);
                    }
                    g = jacobian(cache);
                }
                last = err;
            }
            if solved.is_some() || refined {
                break 'passes;
            }
            let Some((_, _, voids)) = best.take() else {
                break 'passes;
            };
            amount = voids;
            set_voids(system, &amount, volumes, dt)?;
            step.solve(system)?;
            solves += 1;
            let Some(s) = step.refine(system)? else {
                break 'passes;
            };
            solves += 1;
            refined = true;
            r = active
                .iter()
                .map(|&c| p_cav - s.state.pressure[c])
                .collect();
            let err = r.iter().fold(0.0f64, |e, v| e.max(v.abs()));
            if err <= tol {
                solved = Some(s);
                break 'passes;
            }
            best = Some((err, s, amount.clone()));
            (last, attained) = (err, 0.0);
        }
        let Some(mut s) = solved else {
            return Err(BiotError::Solver(format!(
                "cavitation: the pressure of {m} cavitating cells did not reach the bound \
                 (largest miss {last:.3e} Pa; the solves' estimated accuracy there \
                 {attained:.3e} Pa)"
            )));
        };
        let mut next: Vec<usize> = active
            .iter()
            .copied()
            .filter(|&c| void[c] + amount[c] * volumes[c] >= -1e-12 * volumes[c])
            .collect();
        if next.len() == active.len() {
            next.extend((0..nc).filter(|&c| {
                active.binary_search(&c).is_err() && s.state.pressure[c] < p_cav - tol
            }));
            next.sort_unstable();
        }
        if next == active {
            let mut void_change: Vec<f64> =
                amount.iter().zip(volumes).map(|(a, v)| a * v).collect();
            for &c in &active {
                // The pressure differs from the bound by the rounding of the solve.
                s.state.pressure[c] = p_cav;
                // A void emptied to rounding is closed.
                if void[c] + void_change[c] < 0.0 {
                    void_change[c] = -void[c];
                }
            }
            cache.last.clone_from(&active);
            return Ok(BoundedStep {
                step: s,
                void_change,
                cavitating: active,
                solves,
            });
        }
        active = next;
    }
    Err(BiotError::Solver(format!(
        "the cavitating cells did not settle within {MAX_ACTIVE_SET} changes of the set"
    )))
}

/// What the responses of the pressure to unit voids are measured against.
struct Base<'r> {
    free: &'r [f64],
    volumes: &'r [f64],
    dt: f64,
}

impl Base<'_> {
    /// Measure and keep the pressure change of a void of cell `d`'s volume over the step.
    fn measure<const D: usize>(
        &self,
        d: usize,
        system: &mut BiotSystem<'_, D>,
        cache: &mut ResponseCache,
        step: &mut impl CavitationSolver<D>,
    ) -> BiotResult<()> {
        let mut q = vec![0.0; self.free.len()];
        q[d] = self.volumes[d] / self.dt;
        system.set_void_source(Some(q))?;
        let s = step.solve(system)?;
        let dp: Vec<f64> = s
            .state
            .pressure
            .iter()
            .zip(self.free)
            .map(|(a, b)| a - b)
            .collect();
        cache.put(d, &dp);
        Ok(())
    }
}

/// Solve the dense `m × m` system `g x = b` (row-major `g`, overwritten) by Gaussian
/// elimination with partial pivoting; `None` when a pivot vanishes.
fn dense_solve(g: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    for k in 0..m {
        let piv = (k..m).max_by(|&i, &j| g[i * m + k].abs().total_cmp(&g[j * m + k].abs()))?;
        if g[piv * m + k] == 0.0 || !g[piv * m + k].is_finite() {
            return None;
        }
        if piv != k {
            for j in 0..m {
                g.swap(k * m + j, piv * m + j);
            }
            b.swap(k, piv);
        }
        for i in k + 1..m {
            let f = g[i * m + k] / g[k * m + k];
            if f != 0.0 {
                for j in k..m {
                    g[i * m + j] -= f * g[k * m + j];
                }
                b[i] -= f * b[k];
            }
        }
    }
    let mut x = vec![0.0; m];
    for k in (0..m).rev() {
        let s: f64 = (k + 1..m).map(|j| g[k * m + j] * x[j]).sum();
        x[k] = (b[k] - s) / g[k * m + k];
    }
    Some(x)
}
