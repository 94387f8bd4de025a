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
//! in each cell of `S` (one solve each, with the same matrix: a back-substitution for
//! the monolithic scheme) give the pressure of any choice of sources by superposition;
//! the void changes of `S` solve the small dense system `p_S = p_c`. A cell of `S` whose
//! void would become negative leaves `S`; a cell outside `S` below `p_c` joins it; the
//! iteration ends when `S` does not change (at most [`MAX_ACTIVE_SET`] times). The step is
//! then solved once more with the sources found, and the pressure of the cells of `S`
//! set to `p_c` (it differs from it by the rounding of that solve). The fluid volume is
//! balanced to rounding: over a closed domain the injected volume equals the stored one
//! (`Σ M Δp + α ΔV`) less the void change, `Σ ΔV_v`.
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

/// One step of a coupling (`step`, called with `system` and the void sources set) with
/// the pore pressure of every cell bounded below by `p_cav` (Pa, absolute) and the void
/// `void` (m³ per cell; m² in 2D) at the start of the step (see the module docs). `dt`
/// is the step (> 0). The void sources of `system` are reset to none at the end.
///
/// Errors: lengths, a non-finite bound, `dt ≤ 0`, an error of `step`, or a cavitating set
/// that does not settle within [`MAX_ACTIVE_SET`] changes.
pub fn bounded_step<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    p_cav: f64,
    void: &[f64],
    dt: f64,
    mut step: impl FnMut(&BiotSystem<'_, D>) -> BiotResult<BiotStep>,
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
    let result = settle(system, p_cav, void, dt, &volumes, &mut step);
    system.set_void_source(None)?;
    result
}

/// The active-set iteration of [`bounded_step`].
fn settle<const D: usize>(
    system: &mut BiotSystem<'_, D>,
    p_cav: f64,
    void: &[f64],
    dt: f64,
    volumes: &[f64],
    step: &mut impl FnMut(&BiotSystem<'_, D>) -> BiotResult<BiotStep>,
) -> BiotResult<BoundedStep> {
    let nc = void.len();
    system.set_void_source(None)?;
    let free = step(system)?;
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
    let mut active: Vec<usize> = (0..nc).filter(|&c| holds_void(c)).collect();
    active.extend((0..nc).filter(|&c| !holds_void(c) && free.state.pressure[c] < p_cav - tol));
    active.sort_unstable();
    // The pressure change of a void source of `volumes[d] / dt` in cell `d` (the cell's
    // own volume opened in the step), computed once per cell.
    let mut response: Vec<(usize, Vec<f64>)> = Vec::new();
    let mut cx = Responses {
        free: &free.state.pressure,
        volumes,
        dt,
    };
    for c in (0..nc).filter(|&c| holds_void(c)) {
        solves += cx.respond(system, step, c, &mut response)?;
    }
    for _ in 0..MAX_ACTIVE_SET {
        for &c in &active {
            solves += cx.respond(system, step, c, &mut response)?;
        }
        // Void changes in units of each cell's volume: the closing voids outside S are
        // known, those of S solve p_S = p_c.
        let mut amount = vec![0.0; nc];
        for c in (0..nc).filter(|&c| holds_void(c) && active.binary_search(&c).is_err()) {
            amount[c] = -void[c] / volumes[c];
        }
        let pressure_of = |amount: &[f64]| -> Vec<f64> {
            let mut p = free.state.pressure.clone();
            for (d, dp) in &response {
                if amount[*d] != 0.0 {
                    p.iter_mut().zip(dp).for_each(|(p, r)| *p += amount[*d] * r);
                }
            }
            p
        };
        let base = pressure_of(&amount);
        let m = active.len();
        let mut g = vec![0.0; m * m];
        let mut rhs = vec![0.0; m];
        for (i, &c) in active.iter().enumerate() {
            rhs[i] = p_cav - base[c];
            for (j, &d) in active.iter().enumerate() {
                let Some((_, dp)) = response.iter().find(|(e, _)| *e == d) else {
                    return Err(BiotError::Solver(format!(
                        "cavitation: no response of cell {d}"
                    )));
                };
                g[i * m + j] = dp[c];
            }
        }
        let x = dense_solve(&mut g, &mut rhs, m).ok_or_else(|| {
            BiotError::Solver("cavitation: the response of the cavitating cells is singular".into())
        })?;
        for (&c, &a) in active.iter().zip(&x) {
            amount[c] = a;
        }
        let p = pressure_of(&amount);
        let mut next: Vec<usize> = active
            .iter()
            .zip(&x)
            .filter(|&(&c, &a)| void[c] + a * volumes[c] >= -1e-12 * volumes[c])
            .map(|(&c, _)| c)
            .collect();
        let released = next.len() != active.len();
        if !released {
            next.extend(
                (0..nc).filter(|&c| active.binary_search(&c).is_err() && p[c] < p_cav - tol),
            );
            next.sort_unstable();
        }
        if next == active {
            // Solve the step once more with the sources found: the state is that of the
            // coupled system, the mass balance exact to rounding.
            let q: Vec<f64> = amount
                .iter()
                .zip(volumes)
                .map(|(a, v)| a * v / dt)
                .collect();
            system.set_void_source(Some(q))?;
            let mut s = step(system)?;
            solves += 1;
            let mut void_change: Vec<f64> =
                amount.iter().zip(volumes).map(|(a, v)| a * v).collect();
            for &c in &active {
                s.state.pressure[c] = p_cav;
                // A void emptied to rounding is closed.
                if void[c] + void_change[c] < 0.0 {
                    void_change[c] = -void[c];
                }
            }
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

/// What the responses of the pressure to unit void sources are measured against.
struct Responses<'r> {
    free: &'r [f64],
    volumes: &'r [f64],
    dt: f64,
}

impl Responses<'_> {
    /// Add the pressure change of a void source of `volumes[d] / dt` in cell `d` to
    /// `response` unless it is there; returns the solves done (0 or 1).
    fn respond<const D: usize>(
        &mut self,
        system: &mut BiotSystem<'_, D>,
        step: &mut impl FnMut(&BiotSystem<'_, D>) -> BiotResult<BiotStep>,
        d: usize,
        response: &mut Vec<(usize, Vec<f64>)>,
    ) -> BiotResult<usize> {
        if response.iter().any(|(e, _)| *e == d) {
            return Ok(0);
        }
        let mut q = vec![0.0; self.free.len()];
        q[d] = self.volumes[d] / self.dt;
        system.set_void_source(Some(q))?;
        let s = step(system)?;
        let dp = s
            .state
            .pressure
            .iter()
            .zip(self.free)
            .map(|(a, b)| a - b)
            .collect();
        response.push((d, dp));
        Ok(1)
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
