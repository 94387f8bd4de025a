//! Smoothed-aggregation AMG across processes.
//!
//! # Setup, level by level
//!
//! 1. **Aggregation inside each process.** The owned block `A_oo` (owned rows and
//!    columns; symmetric) is aggregated by `porofrac-amg`
//!    ([`porofrac_amg::aggregate_tentative`]: block strength of connection, the three
//!    greedy passes, the tentative prolongator `T` by QR of the near-null space on every
//!    aggregate). An aggregate never crosses a process border, so `T` is block diagonal by
//!    process and the coarse equations of process `r`'s aggregates are owned by `r`.
//! 2. **Spectral radius.** `ρ̂ ≈ ρ(D⁻¹A)` by Lanczos in the `D` inner product, with the
//!    distributed product and dot products.
//! 3. **Smoothed prolongator** `P = (I − ω D⁻¹ A) T`, `ω = (4/3)/ρ̂`: row `i` is
//!    `T_i − (ω/a_ii) Σ_j a_ij T_j`; the rows `T_j` of ghost columns `j` are fetched from
//!    their owners once (a record exchange on `A`'s plan).
//! 4. **Galerkin product** `A_c = Pᵀ A P`: the rows `P_j` of `A`'s ghost columns are
//!    fetched, `(AP)_i = Σ_j a_ij P_j` for the owned rows, and `A_c`'s row `I` is
//!    `Σ_i p_iI (AP)_i` over the fine rows `i` with `p_iI ≠ 0`. A process computes these
//!    partial rows for every coarse column its `P` touches; the partial rows of coarse
//!    equations owned elsewhere are sent to their owners (an all-to-all of triplets) and
//!    added there.
//!
//! It stops when the global size is at most `max_coarse` (or the `gather_below` of
//! [`DistAmg::with_gathering`]), at `max_levels`, or when the coarse level would keep more
//! than `min_coarsening` of the equations. The last matrix is gathered whole on every
//! process and factorized there by sparse Cholesky (`porofrac-amg`'s one-level
//! hierarchy, i.e. `porofrac-sparse`) or, above `max_coarse` equations, given to a serial
//! `porofrac-amg` hierarchy (with the gathered node ids and near-null space); its solve
//! or V-cycle is redundant on every process, which costs no communication beyond
//! gathering the right-hand side — on two to a few processes cheaper than the message
//! exchanges of the small levels it replaces (each smoother product and transfer of a
//! distributed level waits for the neighbours).
//!
//! # V-cycle
//!
//! As the serial one: `ν` Chebyshev steps on `[β/30, β]`, `β = 1.1 ρ̂`, before and after
//! the coarse correction (the same polynomial, so the cycle is symmetric), restriction
//! `Pᵀ r` by the transpose product (a reverse exchange) and prolongation `P x_c` (a
//! forward exchange).

use std::cell::RefCell;
use std::collections::HashMap;

use porofrac_amg::{Amg, AmgOptions, NearNullSpace, SymCsr, aggregate_tentative};

use crate::error::{DistError, Result};
use crate::matrix::{Comm, DistCsr, Layout, all_gather_vec, all_to_all_vec, sum, sum_usize};

/// A pseudo-random number in `[-0.5, 0.5)` from a global index (splitmix64).
fn hash_unit(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// One level: its operator, inverse diagonal, Chebyshev interval, and the prolongator to
/// the next level.
#[derive(Debug)]
struct Level {
    a: DistCsr,
    dinv: Vec<f64>,
    /// Upper end `β` of the Chebyshev interval.
    beta: f64,
    p: Option<DistCsr>,
}

/// What one level of a [`DistAmg`] holds, for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct DistLevelInfo {
    /// Global number of equations.
    pub rows: usize,
    /// Global number of stored entries.
    pub nnz: usize,
    /// Equations owned by this process.
    pub local_rows: usize,
    /// Ghost columns of this process.
    pub ghosts: usize,
}

/// The last level, gathered on every process (factorized, or a serial hierarchy).
#[derive(Debug)]
struct Coarsest {
    layout: Layout,
    solver: RefCell<Amg>,
}

/// A distributed smoothed-aggregation hierarchy (see the module docs).
#[derive(Debug)]
pub struct DistAmg {
    levels: Vec<Level>,
    coarsest: Coarsest,
    options: AmgOptions,
}

/// Maps global column indices to a local index space: owned columns first
/// (`0..n_own`), then the others in the order met.
struct ColMap {
    start: usize,
    n_own: usize,
    map: HashMap<usize, u32>,
    globals: Vec<usize>,
}

impl ColMap {
    fn new(layout: &Layout) -> Self {
        Self {
            start: layout.start(),
            n_own: layout.local(),
            map: HashMap::new(),
            globals: Vec::new(),
        }
    }
    fn index(&mut self, g: usize) -> usize {
        if g >= self.start && g < self.start + self.n_own {
            return g - self.start;
        }
        let next = (self.n_own + self.globals.len()) as u32;
        let k = *self.map.entry(g).or_insert(next);
        if k == next {
            self.globals.push(g);
        }
        k as usize
    }
    fn global(&self, k: usize) -> usize {
        if k < self.n_own {
            self.start + k
        } else {
            self.globals[k - self.n_own]
        }
    }
    fn len(&self) -> usize {
        self.n_own + self.globals.len()
    }
}

/// A dense accumulator over a growing local index space.
#[derive(Default)]
struct Accumulator {
    val: Vec<f64>,
    mark: Vec<bool>,
    touched: Vec<usize>,
}

impl Accumulator {
    fn add(&mut self, k: usize, v: f64) {
        if k >= self.val.len() {
            self.val.resize(k + 1, 0.0);
            self.mark.resize(k + 1, false);
        }
        if !self.mark[k] {
            self.mark[k] = true;
            self.touched.push(k);
        }
        self.val[k] += v;
    }
    /// Append the accumulated entries (local index, value) in the order met; resets.
    fn drain_local(&mut self, col: &mut Vec<u32>, val: &mut Vec<f64>) {
        for &k in &self.touched {
            col.push(k as u32);
            val.push(self.val[k]);
            self.val[k] = 0.0;
            self.mark[k] = false;
        }
        self.touched.clear();
    }
    /// The accumulated entries as (global column, value), sorted by column; resets.
    fn drain(&mut self, cols: &ColMap, out: &mut Vec<(usize, f64)>) {
        out.clear();
        for &k in &self.touched {
            out.push((cols.global(k), self.val[k]));
            self.val[k] = 0.0;
            self.mark[k] = false;
        }
        self.touched.clear();
        out.sort_unstable_by_key(|e| e.0);
    }
}

/// The owned block of `a` as a symmetric matrix for `porofrac-amg` (upper triangle in
/// CSC: column `j` holds row `j`'s entries in columns `≤ j`, by symmetry).
fn owned_block(a: &DistCsr) -> Result<SymCsr> {
    let d = a.diag();
    let n = a.rows().local();
    let mut col_ptr = vec![0usize];
    let mut rows = Vec::with_capacity(d.nnz() / 2 + n);
    let mut vals = Vec::with_capacity(d.nnz() / 2 + n);
    let mut row: Vec<(u32, f64)> = Vec::new();
    for j in 0..n {
        row.clear();
        for p in d.row_ptr[j]..d.row_ptr[j + 1] {
            if d.col[p] as usize <= j {
                row.push((d.col[p], d.val[p]));
            }
        }
        row.sort_unstable_by_key(|e| e.0);
        rows.extend(row.iter().map(|e| e.0 as usize));
        vals.extend(row.iter().map(|e| e.1));
        col_ptr.push(rows.len());
    }
    Ok(SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals)?)
}

/// `ρ(D⁻¹A)` by `steps` Lanczos steps in the `D` inner product (collective).
fn spectral_radius(comm: &Comm, a: &DistCsr, dinv: &[f64], steps: usize) -> f64 {
    let n = a.rows().local();
    let g0 = a.rows().start();
    let dot_d = |x: &[f64], y: &[f64]| {
        sum(
            comm,
            x.iter().zip(y).zip(dinv).map(|((a, b), d)| a * b / d).sum(),
        )
    };
    let mut q: Vec<f64> = (0..n).map(|i| hash_unit(g0 + i) * dinv[i].sqrt()).collect();
    let nq = dot_d(&q, &q).sqrt();
    if nq == 0.0 || !nq.is_finite() {
        return 1.0;
    }
    q.iter_mut().for_each(|v| *v /= nq);
    let mut q_prev = vec![0.0; n];
    let mut w = vec![0.0; n];
    let (mut alpha, mut beta) = (Vec::new(), Vec::<f64>::new());
    let global = a.rows().global();
    for j in 0..steps.min(global) {
        a.mul(comm, &q, &mut w);
        let bj = if j > 0 { beta[j - 1] } else { 0.0 };
        for i in 0..n {
            w[i] = dinv[i] * w[i] - bj * q_prev[i];
        }
        let aj = dot_d(&w, &q);
        alpha.push(aj);
        for i in 0..n {
            w[i] -= aj * q[i];
        }
        let bn = dot_d(&w, &w).sqrt();
        if bn.is_nan() || bn <= 1e-12 * aj.abs() || j + 1 == steps.min(global) {
            break;
        }
        beta.push(bn);
        std::mem::swap(&mut q_prev, &mut q);
        for i in 0..n {
            q[i] = w[i] / bn;
        }
    }
    let ritz = porofrac_amg::smoother::largest_ritz_value(&alpha, &beta);
    if ritz.is_finite() && ritz > 0.0 {
        ritz
    } else {
        2.0
    }
}

/// `(ptr, global columns, values)` of owned rows.
type Rows = (Vec<usize>, Vec<usize>, Vec<f64>);

/// The tentative prolongator's owned rows under the coarse layout.
fn tentative_rows(agg: &porofrac_amg::LocalAggregation, coarse: &Layout) -> Rows {
    let c0 = coarse.start();
    let n = agg.aggregate.len();
    let mut ptr = vec![0usize];
    let mut col = Vec::with_capacity(agg.values.len());
    for e in 0..n {
        let a = agg.aggregate[e] as usize;
        let k = agg.row_ptr[e + 1] - agg.row_ptr[e];
        col.extend((0..k).map(|j| c0 + agg.coarse_ptr[a] + j));
        ptr.push(col.len());
    }
    (ptr, col, agg.values.clone())
}

/// `P = (I − ω D⁻¹A) T` on the owned rows.
fn smooth_prolongator(
    comm: &Comm,
    a: &DistCsr,
    dinv: &[f64],
    omega: f64,
    t: &Rows,
    cols: &mut ColMap,
) -> Rows {
    let (tp, tc, tv) = t;
    let plan = a.plan();
    let (gp, gc) = plan.forward_records(comm, tp, tc);
    let (_, gv) = plan.forward_records(comm, tp, tv);
    // Local column indices, looked up once.
    let tk: Vec<usize> = tc.iter().map(|&g| cols.index(g)).collect();
    let gk: Vec<usize> = gc.iter().map(|&g| cols.index(g)).collect();
    let (d, o) = (a.diag(), a.offd());
    let n = a.rows().local();
    let mut acc = Accumulator::default();
    let mut row = Vec::new();
    let (mut ptr, mut col, mut val) = (vec![0usize], Vec::new(), Vec::new());
    for i in 0..n {
        for q in tp[i]..tp[i + 1] {
            acc.add(tk[q], tv[q]);
        }
        let s = -omega * dinv[i];
        for p in d.row_ptr[i]..d.row_ptr[i + 1] {
            let j = d.col[p] as usize;
            let w = s * d.val[p];
            for q in tp[j]..tp[j + 1] {
                acc.add(tk[q], w * tv[q]);
            }
        }
        for p in o.row_ptr[i]..o.row_ptr[i + 1] {
            let j = o.col[p] as usize;
            let w = s * o.val[p];
            for q in gp[j]..gp[j + 1] {
                acc.add(gk[q], w * gv[q]);
            }
        }
        acc.drain(cols, &mut row);
        col.extend(row.iter().map(|e| e.0));
        val.extend(row.iter().map(|e| e.1));
        ptr.push(col.len());
    }
    (ptr, col, val)
}

/// `Pᵀ A P` with the owned rows of `P` in `p` (see the module docs).
fn galerkin(comm: &Comm, a: &DistCsr, p: &Rows, coarse: &Layout, cols: &mut ColMap) -> Rows {
    let (pp, pc, pv) = p;
    let plan = a.plan();
    let (gp, gc) = plan.forward_records(comm, pp, pc);
    let (_, gv) = plan.forward_records(comm, pp, pv);
    // Local column indices, looked up once.
    let pk: Vec<usize> = pc.iter().map(|&g| cols.index(g)).collect();
    let gk: Vec<usize> = gc.iter().map(|&g| cols.index(g)).collect();
    let (d, o) = (a.diag(), a.offd());
    let n = a.rows().local();
    // AP, owned rows, columns in the local index space of `cols`.
    let mut acc = Accumulator::default();
    let mut row = Vec::new();
    let (mut ap_ptr, mut ap_col, mut ap_val) = (vec![0usize], Vec::<u32>::new(), Vec::new());
    for i in 0..n {
        for q in d.row_ptr[i]..d.row_ptr[i + 1] {
            let j = d.col[q] as usize;
            for r in pp[j]..pp[j + 1] {
                acc.add(pk[r], d.val[q] * pv[r]);
            }
        }
        for q in o.row_ptr[i]..o.row_ptr[i + 1] {
            let j = o.col[q] as usize;
            for r in gp[j]..gp[j + 1] {
                acc.add(gk[r], o.val[q] * gv[r]);
            }
        }
        acc.drain_local(&mut ap_col, &mut ap_val);
        ap_ptr.push(ap_col.len());
    }
    // Pᵀ by coarse column: the fine rows (and values) of every local coarse index.
    let nk = cols.len();
    let mut tptr = vec![0usize; nk + 1];
    for &k in &pk {
        tptr[k + 1] += 1;
    }
    for k in 0..nk {
        tptr[k + 1] += tptr[k];
    }
    let mut next = tptr.clone();
    let mut trow = vec![0usize; pk.len()];
    let mut tval = vec![0.0; pk.len()];
    for i in 0..n {
        for r in pp[i]..pp[i + 1] {
            let k = pk[r];
            trow[next[k]] = i;
            tval[next[k]] = pv[r];
            next[k] += 1;
        }
    }
    let partial_row = |k: usize, acc: &mut Accumulator| {
        for s in tptr[k]..tptr[k + 1] {
            let (i, w) = (trow[s], tval[s]);
            for q in ap_ptr[i]..ap_ptr[i + 1] {
                acc.add(ap_col[q] as usize, w * ap_val[q]);
            }
        }
    };
    // Partial rows of coarse equations owned elsewhere go to their owners.
    let size = coarse.size();
    let mut s_row: Vec<Vec<usize>> = vec![Vec::new(); size];
    let mut s_col: Vec<Vec<usize>> = vec![Vec::new(); size];
    let mut s_val: Vec<Vec<f64>> = vec![Vec::new(); size];
    let n_own = coarse.local();
    for k in n_own..nk {
        partial_row(k, &mut acc);
        let g = cols.global(k);
        let r = coarse.owner(g);
        acc.drain(cols, &mut row);
        for &(c, v) in &row {
            s_row[r].push(g);
            s_col[r].push(c);
            s_val[r].push(v);
        }
    }
    let (r_row, _) = all_to_all_vec(comm, &s_row);
    let (r_col, _) = all_to_all_vec(comm, &s_col);
    let (r_val, _) = all_to_all_vec(comm, &s_val);
    drop((s_row, s_col, s_val));
    // Incoming triplets grouped by owned coarse row.
    let c0 = coarse.start();
    let mut iptr = vec![0usize; n_own + 1];
    for &g in &r_row {
        iptr[g - c0 + 1] += 1;
    }
    for k in 0..n_own {
        iptr[k + 1] += iptr[k];
    }
    let mut inext = iptr.clone();
    let mut iidx = vec![0usize; r_row.len()];
    for (t, &g) in r_row.iter().enumerate() {
        iidx[inext[g - c0]] = t;
        inext[g - c0] += 1;
    }
    let (mut cptr, mut ccol, mut cval) = (vec![0usize], Vec::new(), Vec::new());
    for k in 0..n_own {
        partial_row(k, &mut acc);
        for &t in &iidx[iptr[k]..iptr[k + 1]] {
            let c = cols.index(r_col[t]);
            acc.add(c, r_val[t]);
        }
        acc.drain(cols, &mut row);
        ccol.extend(row.iter().map(|e| e.0));
        cval.extend(row.iter().map(|e| e.1));
        cptr.push(ccol.len());
    }
    (cptr, ccol, cval)
}

impl DistAmg {
    /// Build the hierarchy for the distributed SPD matrix `a` (collective).
    /// `node_of_equation[i]` groups the owned equations into nodes (any ids; the
    /// components of one grid node are aggregated together) and `near_null` holds the
    /// near-null space on the owned equations (rigid-body modes, constants).
    ///
    /// Errors: lengths that disagree, a non-positive diagonal, options out of range, a
    /// coarsest operator that is not positive definite.
    pub fn new(
        comm: &Comm,
        a: DistCsr,
        node_of_equation: &[usize],
        near_null: &NearNullSpace,
        options: &AmgOptions,
    ) -> Result<Self> {
        Self::with_gathering(comm, a, node_of_equation, near_null, options, 0)
    }

    /// [`Self::new`], but the first coarse level (not the finest) with at most
    /// `gather_below` equations (in all) is gathered on every process and handled there by a serial `porofrac-amg`
    /// hierarchy built with the same options (its V-cycle, redundant on every process,
    /// is this level's correction); with `gather_below ≤ options.max_coarse` this is
    /// [`Self::new`]. Each level left distributed costs a message exchange per smoother
    /// product and per transfer; a gathered level costs one gather of its right-hand
    /// side per cycle. Node ids of the finest level must be unique across processes
    /// (grid nodes are); the coarse levels number theirs globally.
    ///
    /// Errors: as [`Self::new`].
    pub fn with_gathering(
        comm: &Comm,
        a: DistCsr,
        node_of_equation: &[usize],
        near_null: &NearNullSpace,
        options: &AmgOptions,
        gather_below: usize,
    ) -> Result<Self> {
        let gather_below = gather_below.max(options.max_coarse);
        let n = a.rows().local();
        if node_of_equation.len() != n || (n > 0 && near_null.len() != n) {
            return Err(DistError::Input(format!(
                "{n} owned equations with {} node ids and near-null vectors of length {}",
                node_of_equation.len(),
                near_null.len()
            )));
        }
        if a.rows() != a.cols() {
            return Err(DistError::Input("the operator is not square".into()));
        }
        let mut nodes: Vec<usize> = node_of_equation.to_vec();
        let mut null = if n > 0 { Some(near_null.clone()) } else { None };
        let mut a = a;
        let mut levels = Vec::new();
        loop {
            let nl = a.rows().local();
            let diag = a.diagonal();
            let bad = diag.iter().position(|&d| !(d > 0.0 && d.is_finite()));
            let any_bad = sum_usize(comm, usize::from(bad.is_some()));
            if any_bad > 0 {
                return Err(DistError::NotPositiveDefinite(format!(
                    "a non-positive diagonal entry on level {}{}",
                    levels.len(),
                    bad.map_or(String::new(), |i| format!(
                        " (equation {})",
                        a.rows().start() + i
                    ))
                )));
            }
            let dinv: Vec<f64> = diag.iter().map(|d| 1.0 / d).collect();
            let global = a.rows().global();
            // The finest level is never gathered (that would be the serial solve).
            let limit = if levels.is_empty() {
                options.max_coarse
            } else {
                gather_below
            };
            if global <= limit || levels.len() + 1 >= options.max_levels {
                return Self::finish(comm, levels, a, &nodes, null.as_ref(), options);
            }
            let agg = if nl > 0 {
                let block = owned_block(&a)?;
                let nn = null.as_ref().ok_or_else(|| {
                    DistError::Input("near-null space missing on a non-empty level".into())
                })?;
                Some(aggregate_tentative(
                    block.matrix(),
                    &nodes,
                    nn,
                    options.strength_threshold,
                    levels.len() < options.aggressive_levels,
                )?)
            } else {
                None
            };
            let nc_local = agg
                .as_ref()
                .map_or(0, |g| g.coarse_ptr.last().copied().unwrap_or(0));
            let coarse = Layout::from_local(comm, nc_local);
            let nc = coarse.global();
            if nc == 0 || nc as f64 > options.min_coarsening * global as f64 {
                return Self::finish(comm, levels, a, &nodes, null.as_ref(), options);
            }
            let rho = spectral_radius(comm, &a, &dinv, options.lanczos_steps);
            let omega = options.prolongation_damping / rho;
            let t = match &agg {
                Some(g) => tentative_rows(g, &coarse),
                None => (vec![0], Vec::new(), Vec::new()),
            };
            let mut cols = ColMap::new(&coarse);
            let p_rows = smooth_prolongator(comm, &a, &dinv, omega, &t, &mut cols);
            drop(t);
            let (cp, cc, cv) = galerkin(comm, &a, &p_rows, &coarse, &mut cols);
            let p = DistCsr::from_rows(
                comm,
                a.rows().clone(),
                coarse.clone(),
                &p_rows.0,
                &p_rows.1,
                &p_rows.2,
            )?;
            drop(p_rows);
            let ac = DistCsr::from_rows(comm, coarse.clone(), coarse.clone(), &cp, &cc, &cv)?;
            // The next level's nodes (the aggregates) and near-null space.
            match agg {
                Some(g) => {
                    // An aggregate's id is the global index of its first coarse equation
                    // (unique across processes, for a gathered level).
                    let c0 = coarse.start();
                    nodes = (0..g.coarse_ptr.len() - 1)
                        .flat_map(|ag| {
                            std::iter::repeat_n(
                                c0 + g.coarse_ptr[ag],
                                g.coarse_ptr[ag + 1] - g.coarse_ptr[ag],
                            )
                        })
                        .collect();
                    null = if nc_local > 0 {
                        Some(g.coarse_null)
                    } else {
                        None
                    };
                }
                None => {
                    nodes.clear();
                    null = None;
                }
            }
            levels.push(Level {
                a,
                dinv,
                beta: options.chebyshev_upper * rho,
                p: Some(p),
            });
            a = ac;
        }
    }

    /// Gather the last operator on every process and factorize it (at most
    /// `options.max_coarse` equations) or build a serial hierarchy for it from the
    /// gathered node ids `nodes` and near-null space `null` (the owned parts).
    fn finish(
        comm: &Comm,
        mut levels: Vec<Level>,
        a: DistCsr,
        nodes: &[usize],
        null: Option<&NearNullSpace>,
        options: &AmgOptions,
    ) -> Result<Self> {
        let (ptr, col, val) = a.global_rows();
        let lens: Vec<usize> = (0..ptr.len() - 1).map(|i| ptr[i + 1] - ptr[i]).collect();
        let all_len = all_gather_vec(comm, &lens);
        let all_col = all_gather_vec(comm, &col);
        let all_val = all_gather_vec(comm, &val);
        let n = all_len.len();
        // Upper triangle in CSC: column j holds row j's entries in columns ≤ j.
        let mut col_ptr = vec![0usize];
        let (mut rows, mut vals) = (Vec::new(), Vec::new());
        let mut at = 0usize;
        for &len in &all_len {
            let j = col_ptr.len() - 1;
            for q in at..at + len {
                if all_col[q] <= j {
                    rows.push(all_col[q]);
                    vals.push(all_val[q]);
                }
            }
            at += len;
            col_ptr.push(rows.len());
        }
        let sym = SymCsr::from_upper_csc(n, &col_ptr, &rows, &vals)?;
        let solver = if n <= options.max_coarse {
            let one = AmgOptions {
                max_coarse: n.max(1),
                ..options.clone()
            };
            Amg::scalar(sym, &one)?
        } else {
            let all_nodes = all_gather_vec(comm, nodes);
            let m_local = null.map_or(0, NearNullSpace::num_vectors);
            let m = all_gather_vec(comm, &[m_local])
                .into_iter()
                .max()
                .unwrap_or(0);
            let mut data = Vec::with_capacity(n * m);
            for k in 0..m {
                let part: &[f64] = match null {
                    Some(b) if k < m_local => b.vector(k),
                    _ => &[],
                };
                data.extend(all_gather_vec(comm, part));
            }
            if data.len() != n * m || all_nodes.len() != n {
                return Err(DistError::Input(format!(
                    "a gathered level of {n} equations with {} node ids and {} near-null \
                     entries",
                    all_nodes.len(),
                    data.len()
                )));
            }
            let null = NearNullSpace::from_vectors(n, data)?;
            let serial = AmgOptions {
                aggressive_levels: options.aggressive_levels.saturating_sub(levels.len()),
                max_levels: options.max_levels.saturating_sub(levels.len()).max(1),
                ..options.clone()
            };
            Amg::new(sym, &all_nodes, &null, &serial)?
        };
        let dinv = a.diagonal().iter().map(|d| 1.0 / d).collect();
        let layout = a.rows().clone();
        levels.push(Level {
            a,
            dinv,
            beta: 0.0,
            p: None,
        });
        Ok(Self {
            levels,
            coarsest: Coarsest {
                layout,
                solver: RefCell::new(solver),
            },
            options: options.clone(),
        })
    }

    /// The finest operator.
    pub fn matrix(&self) -> &DistCsr {
        &self.levels[0].a
    }

    /// Global sizes and this process's share of every level.
    pub fn level_info(&self, comm: &Comm) -> Vec<DistLevelInfo> {
        self.levels
            .iter()
            .map(|l| DistLevelInfo {
                rows: l.a.rows().global(),
                nnz: sum_usize(comm, l.a.local_nnz()),
                local_rows: l.a.rows().local(),
                ghosts: l.a.ghosts().len(),
            })
            .collect()
    }

    /// The levels of the serial hierarchy of the gathered last level (one level when it
    /// is factorized directly).
    pub fn gathered_levels(&self) -> Vec<porofrac_amg::LevelInfo> {
        self.coarsest.solver.borrow().level_info()
    }

    /// Heap bytes held on this process (operators, prolongators, the gathered coarsest
    /// matrix and its factor).
    pub fn bytes(&self) -> usize {
        let lev: usize = self
            .levels
            .iter()
            .map(|l| l.a.bytes() + l.p.as_ref().map_or(0, DistCsr::bytes) + l.dinv.capacity() * 8)
            .sum();
        lev + self.coarsest.solver.borrow().memory().total()
    }

    /// `ν` Chebyshev steps on level `l` from `x` (`zero`: from `x = 0`); returns the
    /// residual `b − A x` after the steps (when `zero`: the pre-smoother's residual is
    /// restricted; the post-smoother's is not needed).
    fn smooth(&self, comm: &Comm, l: usize, b: &[f64], x: &mut [f64], zero: bool) -> Vec<f64> {
        let lev = &self.levels[l];
        let n = b.len();
        let beta = lev.beta;
        let alpha = beta / self.options.chebyshev_ratio;
        let theta = 0.5 * (beta + alpha);
        let delta = 0.5 * (beta - alpha);
        let sigma = theta / delta;
        let mut r = vec![0.0; n];
        let mut ad = vec![0.0; n];
        if zero {
            x.fill(0.0);
            r.copy_from_slice(b);
        } else {
            lev.a.mul(comm, x, &mut ad);
            for i in 0..n {
                r[i] = b[i] - ad[i];
            }
        }
        let mut d: Vec<f64> = (0..n).map(|i| lev.dinv[i] * r[i] / theta).collect();
        let mut rho = 1.0 / sigma;
        for i in 0..n {
            x[i] += d[i];
        }
        for _ in 1..self.options.smoother_degree {
            lev.a.mul(comm, &d, &mut ad);
            for i in 0..n {
                r[i] -= ad[i];
            }
            let rn = 1.0 / (2.0 * sigma - rho);
            let (c1, c2) = (rn * rho, 2.0 * rn / delta);
            for i in 0..n {
                d[i] = c1 * d[i] + c2 * lev.dinv[i] * r[i];
                x[i] += d[i];
            }
            rho = rn;
        }
        if zero {
            lev.a.mul(comm, &d, &mut ad);
            for i in 0..n {
                r[i] -= ad[i];
            }
        }
        r
    }

    /// One V-cycle `z = M r` from level `l` (collective).
    fn vcycle(&self, comm: &Comm, l: usize, b: &[f64], x: &mut [f64]) -> Result<()> {
        let lev = &self.levels[l];
        let Some(p) = lev.p.as_ref() else {
            // Coarsest: gather the right-hand side, solve, keep the owned part.
            let all = all_gather_vec(comm, b);
            let mut z = vec![0.0; all.len()];
            // The gathered operator's serial hierarchy was built at setup (the V-cycle of
            // a one-level hierarchy is the direct solve).
            self.coarsest.solver.borrow_mut().apply(&all, &mut z)?;
            let r = self.coarsest.layout.range_of(self.coarsest.layout.rank());
            x.copy_from_slice(&z[r]);
            return Ok(());
        };
        let r = self.smooth(comm, l, b, x, true);
        let nc = p.cols().local();
        let mut bc = vec![0.0; nc];
        p.mul_transpose(comm, &r, &mut bc);
        let mut xc = vec![0.0; nc];
        self.vcycle(comm, l + 1, &bc, &mut xc)?;
        let mut px = vec![0.0; b.len()];
        p.mul(comm, &xc, &mut px);
        for (xi, pi) in x.iter_mut().zip(&px) {
            *xi += pi;
        }
        self.smooth(comm, l, b, x, false);
        Ok(())
    }

    /// Apply the preconditioner: `z = M r` on the owned parts (collective).
    ///
    /// Errors: a non-finite right-hand side on the coarsest level.
    pub fn apply(&self, comm: &Comm, r: &[f64], z: &mut [f64]) -> Result<()> {
        self.vcycle(comm, 0, r, z)
    }

    /// The options the hierarchy was built with.
    pub fn options(&self) -> &AmgOptions {
        &self.options
    }
}
