//! Fused stream–collide kernels over a padded structure-of-arrays population array.
//!
//! Memory: one `f64` (or `f32`, [`Storage`]) array of `9 · (nx+2)(ny+2)` values, direction-major (`slot · np +
//! node`), with one ghost layer around the `nx × ny` interior nodes.
//!
//! **AA pattern** (Bailey et al. 2009), in place in that one array. An *even* step reads
//! `A[x][i]`, collides and writes `f*_i` to `A[x][ī]`: it touches only its own node. An
//! *odd* step reads `f_i` from `A[x − c_i][ī]`, collides and writes `f*_i` to
//! `A[x + c_i][i]`: node `x` reads and writes the same nine locations `A[x + c_j][j]`, and
//! no other node touches them, so the update is in place and race free. After an even step
//! the value of `f_i(x)` sits at `A[x − c_i][ī]` ([`Layout::Swapped`]); after an odd one at
//! `A[x][i]` ([`Layout::Natural`]). Per node and step the kernel reads 72 bytes and writes
//! the same 72 bytes back (144 B/node, no write-allocate traffic).
//!
//! **Two-array push** (for comparison): read `f_i` at `A[x][i]`, write `f*_i` to
//! `B[x + c_i][i]`, then swap; 72 B read + 72 B written to lines that are not in cache
//! (another 72 B of write-allocate reads): 216 B/node moved, twice the memory.
//!
//! Both kernels run rows in parallel with rayon. The row bands are built so that every band
//! owns disjoint slices of every direction (in an odd step the slice of direction `j` is
//! shifted by `c_jy` rows), so the result does not depend on the number of threads.

use rayon::prelude::*;

use crate::collision::{Rates, collide_with};
use crate::d2q9::{C, OPP, W};
use crate::runs::FluidRuns;

/// The floating-point type populations are stored in; collision always runs in `f64`.
///
/// `f64` stores `f_i` itself. `f32` stores the deviation `f_i − w_i` from the fluid at rest
/// with unit density (zero-centred storage, as lbmpy does): the populations of a slow flow
/// all sit near `w_i`, and storing what they differ by keeps the digits that carry the
/// velocity (a stored `f32` loses about `6·10⁻⁸` of the value it holds).
pub trait Storage: Copy + Send + Sync + Default + std::fmt::Debug + 'static {
    /// `f_i` from the stored value of a slot of weight `w`.
    fn load(self, w: f64) -> f64;
    /// The stored value of `f_i` in a slot of weight `w`.
    fn store(f: f64, w: f64) -> Self;
}

impl Storage for f64 {
    #[inline(always)]
    fn load(self, _w: f64) -> f64 {
        self
    }
    #[inline(always)]
    fn store(f: f64, _w: f64) -> Self {
        f
    }
}

impl Storage for f32 {
    #[inline(always)]
    fn load(self, w: f64) -> f64 {
        self as f64 + w
    }
    #[inline(always)]
    fn store(f: f64, w: f64) -> Self {
        (f - w) as f32
    }
}

/// Where the populations of the interior nodes live after a step (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Layout {
    /// `f_i(x)` at `A[x][i]` (initially and after an odd step).
    #[default]
    Natural,
    /// `f_i(x)` at `A[x − c_i][ī]` (after an even step).
    Swapped,
}

/// The padded grid: `nx × ny` interior nodes plus one ghost layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    /// Interior nodes along x.
    pub nx: usize,
    /// Interior nodes along y.
    pub ny: usize,
}

impl Grid {
    /// Row stride of the padded array, `nx + 2`.
    #[inline(always)]
    pub fn stride(&self) -> usize {
        self.nx + 2
    }
    /// Padded nodes per direction, `(nx+2)(ny+2)`.
    #[inline(always)]
    pub fn np(&self) -> usize {
        (self.nx + 2) * (self.ny + 2)
    }
    /// Padded index of interior node `(i, j)`; `i` and `j` may be −1 or `n` (ghosts).
    #[inline(always)]
    pub fn node(&self, i: isize, j: isize) -> usize {
        ((j + 1) as usize) * self.stride() + (i + 1) as usize
    }
    /// Padded index of the neighbour of `node` along `c_i`.
    #[inline(always)]
    pub fn shift(&self, node: usize, i: usize) -> usize {
        (node as isize + C[i][1] as isize * self.stride() as isize + C[i][0] as isize) as usize
    }
    /// Index in the population array of `f_i(node)` in `layout`.
    #[inline(always)]
    pub fn loc(&self, layout: Layout, node: usize, i: usize) -> usize {
        match layout {
            Layout::Natural => i * self.np() + node,
            Layout::Swapped => OPP[i] * self.np() + self.shift(node, OPP[i]),
        }
    }
    /// Slot and padded node where `f_i(node)` is stored in `layout` ([`Grid::loc`] is
    /// `slot · np + node` of these).
    #[inline(always)]
    pub(crate) fn slot(&self, layout: Layout, node: usize, i: usize) -> (usize, usize) {
        match layout {
            Layout::Natural => (i, node),
            Layout::Swapped => (OPP[i], self.shift(node, OPP[i])),
        }
    }
}

/// What the kernel applies at every node.
#[derive(Clone, Copy, Debug)]
pub struct Physics {
    /// Relaxation rates.
    pub rates: Rates,
    /// Body acceleration (lattice units).
    pub accel: [f64; 2],
}

/// Rows per band: a few bands per thread keep the load balanced.
fn band_rows(ny: usize) -> usize {
    let t = rayon::current_num_threads().max(1);
    ny.div_ceil(4 * t).max(1)
}

/// The row bands a step of an `ny`-row lattice runs in parallel, as `(first row, rows)`
/// in interior rows.
fn band_ranges(ny: usize) -> Vec<(usize, usize)> {
    let rows = band_rows(ny);
    (0..ny)
        .step_by(rows)
        .map(|row0| (row0, rows.min(ny - row0)))
        .collect()
}

/// Work a band of a step does on its own rows as soon as they are final.
///
/// Every location of the array is read and written in a step by one node only: node `x`
/// by `A[x][j]` in an even step, by `A[x + c_j][j]` in an odd one (module docs); call it
/// the location's node. After the band has stepped its rows `row0 ..= last` (interior
/// rows), every location whose node lies in those rows holds its value after the step,
/// no later row touches it, and it lies in the band's slices. [`BandHook::rows_done`] is
/// called after every row with the band's view of the array.
pub(crate) trait BandHook<T>: Send {
    /// Rows `row0 ..= last` of the band are stepped.
    fn rows_done(&mut self, last: usize, view: &mut BandView<'_, '_, T>);
}

/// No work between rows.
impl<T> BandHook<T> for () {
    #[inline(always)]
    fn rows_done(&mut self, _last: usize, _view: &mut BandView<'_, '_, T>) {}
}

/// A band's slices of the population array, addressed by slot and padded node.
pub(crate) struct BandView<'s, 'a, T> {
    s: &'s mut [&'a mut [T]; 9],
    /// Padded node of the first element of each slot's slice.
    start: [usize; 9],
}

impl<T: Storage> BandView<'_, '_, T> {
    /// `f` in slot `q` of padded node `node` (a location whose node is in the band).
    #[inline(always)]
    pub(crate) fn get(&self, q: usize, node: usize) -> f64 {
        self.s[q][node - self.start[q]].load(W[q])
    }
    /// Set slot `q` of padded node `node` to `f`.
    #[inline(always)]
    pub(crate) fn set(&mut self, q: usize, node: usize, f: f64) {
        self.s[q][node - self.start[q]] = T::store(f, W[q]);
    }
}

/// Split the nine direction slices of `pop` into row bands; direction `j` of band `b`
/// starts at padded row `1 + row0 + shift(j)`.
#[allow(clippy::type_complexity)]
fn bands<'a, T>(
    pop: &'a mut [T],
    g: Grid,
    shift: impl Fn(usize) -> usize,
    ranges: &[(usize, usize)],
) -> Vec<(usize, usize, [&'a mut [T]; 9])> {
    let (w, np) = (g.stride(), g.np());
    let mut rest: Vec<&'a mut [T]> = pop
        .chunks_mut(np)
        .enumerate()
        .map(|(j, s)| &mut s[shift(j) * w..])
        .collect();
    let mut out = Vec::with_capacity(ranges.len());
    let mut next = 0;
    for &(row0, n) in ranges {
        assert_eq!(row0, next, "bands cover the rows in order");
        next = row0 + n;
        let slices: [&'a mut [T]; 9] = std::array::from_fn(|j| {
            let s = std::mem::take(&mut rest[j]);
            let (head, tail) = s.split_at_mut(n * w);
            rest[j] = tail;
            head
        });
        out.push((row0, n, slices));
    }
    assert_eq!(next, g.ny, "bands cover every row");
    out
}

/// One fused AA step over all interior nodes; `layout` is the layout before the step
/// (Natural: even step, Swapped: odd step). `mask` (1 fluid, 0 solid, padded) may be
/// omitted when every node is fluid. Returns the layout after the step. `pop` holds `f64`
/// or `f32` values ([`Storage`]); the collision runs in `f64` either way.
pub fn aa_step<T: Storage>(
    pop: &mut [T],
    g: Grid,
    layout: Layout,
    mask: Option<&[u8]>,
    phys: Physics,
) -> Layout {
    aa_dispatch(
        pop,
        g,
        layout,
        mask,
        None,
        phys,
        &band_ranges(g.ny),
        vec![(); band_ranges(g.ny).len()],
    )
}

/// [`aa_step`] over the segments of `runs` only (built from `mask`, see [`crate::runs`]):
/// every fluid node gets the same bits as from [`aa_step`] with `mask`; solid nodes in
/// long stretches between segments are not touched.
pub fn aa_step_runs<T: Storage>(
    pop: &mut [T],
    g: Grid,
    layout: Layout,
    mask: &[u8],
    runs: &FluidRuns,
    phys: Physics,
) -> Layout {
    aa_dispatch(
        pop,
        g,
        layout,
        Some(mask),
        Some(runs),
        phys,
        &band_ranges(g.ny),
        vec![(); band_ranges(g.ny).len()],
    )
}

/// [`aa_step`] (with `runs`: [`aa_step_runs`]) over the row bands `ranges` (`(first
/// row, rows)`, in order, covering every row; any split gives the same bits), handing
/// band `b` its hook `hooks[b]`, called after every row of the band.
#[allow(clippy::too_many_arguments)]
pub(crate) fn aa_step_hooked<T: Storage, H: BandHook<T>>(
    pop: &mut [T],
    g: Grid,
    layout: Layout,
    mask: &[u8],
    runs: Option<&FluidRuns>,
    phys: Physics,
    ranges: &[(usize, usize)],
    hooks: Vec<H>,
) -> Layout {
    aa_dispatch(pop, g, layout, Some(mask), runs, phys, ranges, hooks)
}

#[allow(clippy::too_many_arguments)]
fn aa_dispatch<T: Storage, H: BandHook<T>>(
    pop: &mut [T],
    g: Grid,
    layout: Layout,
    mask: Option<&[u8]>,
    runs: Option<&FluidRuns>,
    phys: Physics,
    ranges: &[(usize, usize)],
    hooks: Vec<H>,
) -> Layout {
    let force = phys.accel != [0.0, 0.0];
    let (r, h) = (runs, (ranges, hooks));
    match (layout, mask, force) {
        (Layout::Natural, None, false) => aa::<T, H, false, false, false>(pop, g, &[], r, phys, h),
        (Layout::Natural, Some(m), false) => aa::<T, H, false, true, false>(pop, g, m, r, phys, h),
        (Layout::Swapped, None, false) => aa::<T, H, true, false, false>(pop, g, &[], r, phys, h),
        (Layout::Swapped, Some(m), false) => aa::<T, H, true, true, false>(pop, g, m, r, phys, h),
        (Layout::Natural, None, true) => aa::<T, H, false, false, true>(pop, g, &[], r, phys, h),
        (Layout::Natural, Some(m), true) => aa::<T, H, false, true, true>(pop, g, m, r, phys, h),
        (Layout::Swapped, None, true) => aa::<T, H, true, false, true>(pop, g, &[], r, phys, h),
        (Layout::Swapped, Some(m), true) => aa::<T, H, true, true, true>(pop, g, m, r, phys, h),
    }
    match layout {
        Layout::Natural => Layout::Swapped,
        Layout::Swapped => Layout::Natural,
    }
}

fn aa<T: Storage, H: BandHook<T>, const ODD: bool, const MASK: bool, const FORCE: bool>(
    pop: &mut [T],
    g: Grid,
    mask: &[u8],
    runs: Option<&FluidRuns>,
    phys: Physics,
    (ranges, hooks): (&[(usize, usize)], Vec<H>),
) {
    let w = g.stride();
    let nx = g.nx;
    let shift = |j: usize| if ODD { (1 + C[j][1]) as usize } else { 1 };
    let bands = bands(pop, g, shift, ranges);
    assert_eq!(bands.len(), hooks.len(), "one hook per band");
    let arch = pulp::Arch::new();
    bands
        .into_par_iter()
        .zip(hooks)
        .for_each(|((row0, n, s), hook)| {
            arch.dispatch(AaBand::<T, H, ODD, MASK, FORCE> {
                s,
                start: std::array::from_fn(|j| (shift(j) + row0) * w),
                row0,
                n,
                w,
                nx,
                mask,
                runs,
                phys,
                hook,
            });
        });
}

/// One band of an AA step, compiled for the widest vector instructions of the processor
/// (`pulp` picks AVX2 or plain code at run time; the arithmetic is the same, so are the
/// results).
struct AaBand<'a, T, H, const ODD: bool, const MASK: bool, const FORCE: bool> {
    s: [&'a mut [T]; 9],
    /// Padded node of the first element of each slice.
    start: [usize; 9],
    row0: usize,
    n: usize,
    w: usize,
    nx: usize,
    mask: &'a [u8],
    /// With `MASK`: visit only the segments of each row.
    runs: Option<&'a FluidRuns>,
    phys: Physics,
    hook: H,
}

impl<T: Storage, H: BandHook<T>, const ODD: bool, const MASK: bool, const FORCE: bool>
    pulp::WithSimd for AaBand<'_, T, H, ODD, MASK, FORCE>
{
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let AaBand {
            mut s,
            start,
            row0,
            n,
            w,
            nx,
            mask,
            runs,
            phys,
            mut hook,
        } = self;
        for r in 0..n {
            if r > 0 {
                hook.rows_done(row0 + r - 1, &mut BandView { s: &mut s, start });
            }
            let m = if MASK {
                &mask[(row0 + r + 1) * w + 1..][..nx]
            } else {
                &[][..]
            };
            let col = |j: usize| r * w + if ODD { (1 + C[j][0]) as usize } else { 1 };
            let [s0, s1, s2, s3, s4, s5, s6, s7, s8] = &mut s;
            if MASK && let Some(runs) = runs {
                // the segments only; a segment of fluid nodes alone has `on = 1` exactly,
                // so the unmasked collision gives the masked one's bits
                for seg in runs.row(row0 + r) {
                    let (a, len) = (seg.a as usize, (seg.b - seg.a) as usize);
                    let sl = [
                        &mut s0[col(0) + a..][..len],
                        &mut s1[col(1) + a..][..len],
                        &mut s2[col(2) + a..][..len],
                        &mut s3[col(3) + a..][..len],
                        &mut s4[col(4) + a..][..len],
                        &mut s5[col(5) + a..][..len],
                        &mut s6[col(6) + a..][..len],
                        &mut s7[col(7) + a..][..len],
                        &mut s8[col(8) + a..][..len],
                    ];
                    if seg.masked {
                        aa_row::<T, ODD, true, FORCE>(sl, &m[a..][..len], phys);
                    } else {
                        aa_row::<T, ODD, false, FORCE>(sl, &[], phys);
                    }
                }
                continue;
            }
            aa_row::<T, ODD, MASK, FORCE>(
                [
                    &mut s0[col(0)..][..nx],
                    &mut s1[col(1)..][..nx],
                    &mut s2[col(2)..][..nx],
                    &mut s3[col(3)..][..nx],
                    &mut s4[col(4)..][..nx],
                    &mut s5[col(5)..][..nx],
                    &mut s6[col(6)..][..nx],
                    &mut s7[col(7)..][..nx],
                    &mut s8[col(8)..][..nx],
                ],
                m,
                phys,
            );
        }
        hook.rows_done(row0 + n - 1, &mut BandView { s: &mut s, start });
    }
}

/// Collide one row: slot `j` of node `x` is `r[j][x]` (see the module docs).
#[inline(always)]
fn aa_row<T: Storage, const ODD: bool, const MASK: bool, const FORCE: bool>(
    r: [&mut [T]; 9],
    m: &[u8],
    phys: Physics,
) {
    let [r0, r1, r2, r3, r4, r5, r6, r7, r8] = r;
    let nx = r0.len();
    let (r1, r2, r3, r4) = (&mut r1[..nx], &mut r2[..nx], &mut r3[..nx], &mut r4[..nx]);
    let (r5, r6, r7, r8) = (&mut r5[..nx], &mut r6[..nx], &mut r7[..nx], &mut r8[..nx]);
    let m = if MASK { &m[..nx] } else { m };
    for x in 0..nx {
        let on = if MASK { m[x] as f64 } else { 1.0 };
        // slot j holds direction j or its opposite: the same weight W[j] either way
        let ld = |v: T, j: usize| v.load(W[j]);
        let st = |v: f64, j: usize| T::store(v, W[j]);
        if ODD {
            let f = [
                ld(r0[x], 0),
                ld(r3[x], 3),
                ld(r4[x], 4),
                ld(r1[x], 1),
                ld(r2[x], 2),
                ld(r7[x], 7),
                ld(r8[x], 8),
                ld(r5[x], 5),
                ld(r6[x], 6),
            ];
            let o = collide_with::<FORCE>(f, phys.rates, phys.accel, on);
            r0[x] = st(o[0], 0);
            r1[x] = st(o[1], 1);
            r2[x] = st(o[2], 2);
            r3[x] = st(o[3], 3);
            r4[x] = st(o[4], 4);
            r5[x] = st(o[5], 5);
            r6[x] = st(o[6], 6);
            r7[x] = st(o[7], 7);
            r8[x] = st(o[8], 8);
        } else {
            let f = [
                ld(r0[x], 0),
                ld(r1[x], 1),
                ld(r2[x], 2),
                ld(r3[x], 3),
                ld(r4[x], 4),
                ld(r5[x], 5),
                ld(r6[x], 6),
                ld(r7[x], 7),
                ld(r8[x], 8),
            ];
            let o = collide_with::<FORCE>(f, phys.rates, phys.accel, on);
            r0[x] = st(o[0], 0);
            r1[x] = st(o[3], 1);
            r2[x] = st(o[4], 2);
            r3[x] = st(o[1], 3);
            r4[x] = st(o[2], 4);
            r5[x] = st(o[7], 5);
            r6[x] = st(o[8], 6);
            r7[x] = st(o[5], 7);
            r8[x] = st(o[6], 8);
        }
    }
}

/// One fused two-array push step for a fully periodic lattice without obstacles: collide
/// `src` (Natural layout), push into `dst`, wrap the ghost layer of `dst` back into the
/// interior. Used by the benchmarks and to check the AA kernel.
pub fn push_step_periodic(src: &[f64], dst: &mut [f64], g: Grid, phys: Physics) {
    let bands = bands(dst, g, |j| (1 + C[j][1]) as usize, &band_ranges(g.ny));
    let arch = pulp::Arch::new();
    bands.into_par_iter().for_each(|(row0, n, s)| {
        arch.dispatch(PushBand {
            src,
            s,
            row0,
            n,
            g,
            phys,
        });
    });
    wrap_ghosts(dst, g);
}

/// One band of a push step, compiled like [`AaBand`].
struct PushBand<'a> {
    src: &'a [f64],
    s: [&'a mut [f64]; 9],
    row0: usize,
    n: usize,
    g: Grid,
    phys: Physics,
}

impl pulp::WithSimd for PushBand<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let PushBand {
            src,
            mut s,
            row0,
            n,
            g,
            phys,
        } = self;
        let (w, np, nx) = (g.stride(), g.np(), g.nx);
        for r in 0..n {
            let base = (row0 + r + 1) * w + 1;
            let f_in: [&[f64]; 9] = std::array::from_fn(|j| &src[j * np + base..][..nx]);
            let col = |j: usize| r * w + (1 + C[j][0]) as usize;
            let [s0, s1, s2, s3, s4, s5, s6, s7, s8] = &mut s;
            let rows = push_row::<true>;
            let rows = if phys.accel == [0.0, 0.0] {
                push_row::<false>
            } else {
                rows
            };
            rows(
                f_in,
                [
                    &mut s0[col(0)..][..nx],
                    &mut s1[col(1)..][..nx],
                    &mut s2[col(2)..][..nx],
                    &mut s3[col(3)..][..nx],
                    &mut s4[col(4)..][..nx],
                    &mut s5[col(5)..][..nx],
                    &mut s6[col(6)..][..nx],
                    &mut s7[col(7)..][..nx],
                    &mut s8[col(8)..][..nx],
                ],
                phys,
            );
        }
    }
}

#[inline(always)]
fn push_row<const FORCE: bool>(f_in: [&[f64]; 9], d: [&mut [f64]; 9], phys: Physics) {
    let [d0, d1, d2, d3, d4, d5, d6, d7, d8] = d;
    let nx = d0.len();
    let (d1, d2, d3, d4) = (&mut d1[..nx], &mut d2[..nx], &mut d3[..nx], &mut d4[..nx]);
    let (d5, d6, d7, d8) = (&mut d5[..nx], &mut d6[..nx], &mut d7[..nx], &mut d8[..nx]);
    let f_in: [&[f64]; 9] = std::array::from_fn(|j| &f_in[j][..nx]);
    for x in 0..nx {
        let f = std::array::from_fn(|j| f_in[j][x]);
        let o = collide_with::<FORCE>(f, phys.rates, phys.accel, 1.0);
        d0[x] = o[0];
        d1[x] = o[1];
        d2[x] = o[2];
        d3[x] = o[3];
        d4[x] = o[4];
        d5[x] = o[5];
        d6[x] = o[6];
        d7[x] = o[7];
        d8[x] = o[8];
    }
}

/// Move what a push step wrote into the ghost layer to the interior node on the other side.
fn wrap_ghosts(pop: &mut [f64], g: Grid) {
    let (nx, ny) = (g.nx as isize, g.ny as isize);
    let np = g.np();
    for j in 1..9 {
        let (cx, cy) = (C[j][0] as isize, C[j][1] as isize);
        let mut ghost = |i: isize, jj: isize| {
            let wi = i.rem_euclid(nx);
            let wj = jj.rem_euclid(ny);
            pop[j * np + g.node(wi, wj)] = pop[j * np + g.node(i, jj)];
        };
        if cx != 0 {
            let i = if cx > 0 { nx } else { -1 };
            for jj in cy..ny + cy {
                ghost(i, jj);
            }
        }
        if cy != 0 {
            let jj = if cy > 0 { ny } else { -1 };
            for i in cx..nx + cx {
                ghost(i, jj);
            }
        }
    }
}
