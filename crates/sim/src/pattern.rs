//! The sparsity pattern of the reduced stiffness matrix and the per-cell scatter map.
//!
//! The reduced matrix `A = Tᵀ K_ff T` (see [`crate::dofs`]) is symmetric; only its upper
//! triangle (row ≤ column) is stored, in compressed sparse column (CSC) form as faer
//! expects it. Entry `(r, c)` is nonzero when equations `r` and `c` share a cell.
//!
//! The pattern is built once per grid and dof map, with a *scatter map* for every cell
//! over the pairs `i ≤ j` of its local dofs (the upper triangle of the `D·n × D·n` local
//! matrix, column by column: pair `(i, j)` at `i + j(j+1)/2`, see [`upper_pair`]): the
//! position in the values array of global entry `(min(e_i, e_j), max(e_i, e_j))`, or none
//! when a dof is prescribed. The local matrix is symmetric, so `K_ij` stands for `K_ji` as
//! well; a pair `i < j` with `e_i = e_j` (two nodes of one platen) adds to the diagonal
//! twice, which the map marks with its top bit ([`TWICE`]). Filling values is then a loop
//! over cells with no searching and no triplet buffers, and new values (time steps, law
//! switches) reuse the pattern.
//!
//! A cell whose nodes each own `D` consecutive free equations (no prescribed component, no
//! platen) is mapped node block by node block: the components of a node lie in the same
//! cells, so one walk down a column places a whole `D × D` block, and only one column
//! offset per pair of nodes is stored (the position of the first row of node `i` in the
//! first column of node `j`; the rest of the block and the diagonal blocks follow from the
//! column offsets): 3 entries for a triangle and 6 for a tetrahedron instead of 21 and 78
//! pairs. The other cells store the full map, 32 bits per pair. At E2 n = 1000 (2 M
//! triangles) the maps take 24 MB instead of 168 MB.
//!
//! # Parallel fill
//!
//! The columns are split into contiguous *chunks* of about equal numbers of entries
//! (four per thread). A chunk owns its columns' slice of the values array and its
//! equations' slice of the right-hand side, so threads never write the same entry and no
//! atomics or per-thread copies are needed. Each chunk visits the cells touching any of its
//! columns, in increasing cell order, and adds only the entries it owns. A cell touching
//! two chunks is evaluated twice; with equations numbered node by node that is a thin
//! layer of cells per chunk boundary ([`Pattern::duplication`] reports the fraction).
//! Because every entry is summed by one chunk in increasing cell order, the result is
//! bitwise independent of the number of threads.

use std::ops::Range;

use porofrac_grid::Grid;
use porofrac_sparse::UpperPattern;
use rayon::prelude::*;

use crate::dofs::DofMap;
use crate::error::{Result, SimError};

/// Marker of a local pair that writes nothing.
pub(crate) const NONE: u32 = u32::MAX;
/// Flag of a local pair `i < j` whose two dofs are one equation: it adds twice.
pub const TWICE: u32 = 1 << 31;

/// Index of the local pair `i ≤ j` in a cell's scatter map (column-major upper triangle).
#[inline]
pub fn upper_pair(i: usize, j: usize) -> usize {
    i + j * (j + 1) / 2
}

/// A contiguous range of columns (and the matching values and equations).
#[derive(Clone, Debug)]
pub(crate) struct Chunk {
    pub(crate) cols: Range<usize>,
    pub(crate) vals: Range<usize>,
    pub(crate) cells: Range<usize>,
}

/// Upper-triangular CSC pattern of the reduced stiffness with per-cell scatter maps.
#[derive(Clone, Debug)]
pub struct Pattern {
    upper: UpperPattern,
    maps: StoredMaps,
    pub(crate) chunks: Vec<Chunk>,
    pub(crate) chunk_cells: Vec<usize>,
    num_cells: usize,
}

/// The scatter maps of all cells, one after the other: a column offset per pair of nodes
/// for a cell mapped by node blocks, the full upper triangle of positions otherwise.
#[derive(Clone, Debug)]
struct StoredMaps {
    pos: Vec<usize>,
    map: Vec<u32>,
}

/// Buffers for reading a cell's scatter map ([`Pattern::cell_map`]).
#[derive(Debug, Default)]
pub struct ScatterBuffer {
    eqs: Vec<usize>,
    /// The cell's free equations with their local dofs, increasing.
    sorted: Vec<(usize, usize)>,
    blocks: [(usize, usize); MAX_NODES],
    map: Vec<u32>,
}

/// Equations of a cell's local dofs (`usize::MAX` for prescribed), node-major.
pub(crate) fn cell_equations<const D: usize>(
    grid: &Grid<D>,
    dofs: &DofMap<D>,
    c: usize,
    out: &mut Vec<usize>,
) {
    out.clear();
    let raw = dofs.raw();
    for &n in grid.cell_nodes(c) {
        out.extend_from_slice(&raw[D * n..D * n + D]);
    }
}

/// `(first equation, local node)` of a node whose components are consecutive equations.
type NodeBlock = (usize, usize);

/// The most nodes of a cell the node-block paths handle.
const MAX_NODES: usize = 32;

/// `(first equation, local node)` of the nodes of a cell with the local equations `eqs`
/// (node-major), sorted, when every node has `D` free consecutive equations and the blocks
/// do not overlap — the usual case, without prescribed components or platens — and, with
/// `same_cells`, each node's further components lie in the cells of its first; `None`
/// otherwise.
fn node_blocks<'a, const D: usize>(
    eqs: &[usize],
    same_cells: Option<&[bool]>,
    nodes: &'a mut [(usize, usize); MAX_NODES],
) -> Option<&'a [(usize, usize)]> {
    let n = eqs.len() / D;
    if n > MAX_NODES {
        return None;
    }
    // Sort keys `e0 · 32 + k` (equations are below 2³¹, `k` below 32), sorted by
    // insertion: a cell has a handful of nodes.
    let mut keys = [0u64; MAX_NODES];
    for (k, e) in eqs.chunks_exact(D).enumerate() {
        let e0 = e[0];
        let breaks =
            |a: usize| e[a] != e0.wrapping_add(a) || same_cells.is_some_and(|same| !same[e0 + a]);
        if e0 == usize::MAX || (1..D).any(breaks) {
            return None;
        }
        let key = ((e0 as u64) << 5) | k as u64;
        let mut j = k;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            j -= 1;
        }
        keys[j] = key;
    }
    let nodes = &mut nodes[..n];
    for (node, &key) in nodes.iter_mut().zip(&keys) {
        *node = ((key >> 5) as usize, (key & 31) as usize);
    }
    nodes
        .windows(2)
        .all(|w| w[1].0 >= w[0].0 + D)
        .then_some(&*nodes)
}

/// The stored map of a cell whose nodes passed [`node_blocks`]: for each pair of nodes
/// `ii < jj` (in the sorted order, at `jj(jj − 1)/2 + ii`), the offset of row `e_ii` in
/// column `e_jj`.
///
/// The components `b` of node `k` (equations `e_k + b`) lie in the same cells, so column
/// `e_k + b` holds the rows of column `e_k` below `e_k` at the same offsets, then `e_k …
/// e_k + b` last: one offset places the whole `D × D` block of a pair of nodes, and the
/// diagonal blocks are the ends of the columns ([`for_each_by_nodes`]).
fn offsets_by_nodes(
    nodes: &[(usize, usize)],
    col_ptr: &[usize],
    row_idx: &[usize],
    out: &mut [u32],
) {
    let mut q = 0;
    for (jj, &(eb, _)) in nodes.iter().enumerate() {
        let c0 = col_ptr[eb];
        let mut p = c0;
        for &(ea, _) in &nodes[..jj] {
            // Invariant: row ea is in column eb (a cell holds both), rows sorted.
            while row_idx[p] < ea {
                p += 1;
            }
            out[q] = (p - c0) as u32;
            q += 1;
        }
    }
}

/// `f(i, j, p)` for every local pair `i ≤ j` of a cell mapped by node blocks, with `p`
/// the value position of its entry (see [`offsets_by_nodes`]). Every pair has its own
/// entry: the equations of the cell are distinct.
#[inline]
fn for_each_by_nodes<const D: usize>(
    nodes: &[(usize, usize)],
    col_ptr: &[usize],
    offsets: &[u32],
    mut f: impl FnMut(usize, usize, usize),
) {
    let mut q = 0;
    for (jj, &(eb, kb)) in nodes.iter().enumerate() {
        for b in 0..D {
            let end = col_ptr[eb + b + 1];
            for a in 0..=b {
                f(D * kb + a, D * kb + b, end - 1 - (b - a));
            }
        }
        for &(_, ka) in &nodes[..jj] {
            let delta = offsets[q] as usize;
            q += 1;
            for b in 0..D {
                let base = col_ptr[eb + b] + delta;
                for a in 0..D {
                    let (i, j) = (D * ka + a, D * kb + b);
                    f(i.min(j), i.max(j), base + a);
                }
            }
        }
    }
}

/// The column structure a scatter map is read from: column offsets, row indices and
/// whether each equation lies in the same cells as the one before it.
type Columns<'a> = (&'a [usize], &'a [usize], &'a [bool]);

/// Length of the stored map of cell `c` (`buf.eqs` receives its equations).
fn stored_len<const D: usize>(
    grid: &Grid<D>,
    dofs: &DofMap<D>,
    c: usize,
    same_cells: &[bool],
    buf: &mut ScatterBuffer,
) -> usize {
    cell_equations(grid, dofs, c, &mut buf.eqs);
    let m = buf.eqs.len();
    match node_blocks::<D>(&buf.eqs, Some(same_cells), &mut buf.blocks) {
        Some(nodes) => nodes.len() * (nodes.len() - 1) / 2,
        None => m * (m + 1) / 2,
    }
}

/// Write the stored map of cell `c` into `out` (of [`stored_len`]).
fn store_cell<const D: usize>(
    grid: &Grid<D>,
    dofs: &DofMap<D>,
    c: usize,
    (col_ptr, row_idx, same_cells): Columns<'_>,
    buf: &mut ScatterBuffer,
    out: &mut [u32],
) {
    cell_equations(grid, dofs, c, &mut buf.eqs);
    let eqs = &buf.eqs;
    if let Some(nodes) = node_blocks::<D>(eqs, Some(same_cells), &mut buf.blocks) {
        offsets_by_nodes(nodes, col_ptr, row_idx, out);
        return;
    }
    debug_assert_eq!(out.len(), eqs.len() * (eqs.len() + 1) / 2);
    out.fill(NONE);
    let sorted = &mut buf.sorted;
    sorted.clear();
    sorted.extend(
        eqs.iter()
            .enumerate()
            .filter(|&(_, &e)| e != usize::MAX)
            .map(|(i, &e)| (e, i)),
    );
    sorted.sort_unstable();
    // Column `e_j` holds the rows `e_i ≤ e_j` of the cell in increasing order, so one
    // forward walk down the column finds them all.
    for (jj, &(col, j)) in sorted.iter().enumerate() {
        let mut p = col_ptr[col];
        for &(r, i) in &sorted[..=jj] {
            // Invariant: (r, col) is in the pattern since both are in cell c, and the
            // column ends with its diagonal.
            while row_idx[p] < r {
                p += 1;
            }
            let twice = if i != j && r == col { TWICE } else { 0 };
            out[upper_pair(i.min(j), i.max(j))] = p as u32 | twice;
        }
    }
}

/// Prefix sums `[0, n0, n0 + n1, …]` of `counts`.
fn offsets(counts: &[usize]) -> Vec<usize> {
    let mut pos = Vec::with_capacity(counts.len() + 1);
    pos.push(0);
    let mut sum = 0;
    for &k in counts {
        sum += k;
        pos.push(sum);
    }
    pos
}

/// `out` cut into consecutive slices of the lengths `lens`.
fn split_mut<T>(mut out: &mut [T], lens: impl IntoIterator<Item = usize>) -> Vec<&mut [T]> {
    lens.into_iter()
        .map(|len| {
            let (head, tail) = std::mem::take(&mut out).split_at_mut(len);
            out = tail;
            head
        })
        .collect()
}

/// Fill `out` in parallel: items `i` own `out[pos[i]..pos[i + 1]]`; `fill(items, slice)`
/// is called on contiguous blocks of items with the slice they own.
fn fill_blocks<T: Send>(
    out: &mut [T],
    pos: &[usize],
    fill: impl Fn(Range<usize>, &mut [T]) + Sync,
) {
    const ITEMS: usize = 4096;
    let items = pos.len() - 1;
    let ranges: Vec<Range<usize>> = (0..items)
        .step_by(ITEMS)
        .map(|start| start..(start + ITEMS).min(items))
        .collect();
    let slices = split_mut(out, ranges.iter().map(|r| pos[r.end] - pos[r.start]));
    let blocks: Vec<_> = ranges.into_iter().zip(slices).collect();
    blocks
        .into_par_iter()
        .for_each(|(range, slice)| fill(range, slice));
}

impl Pattern {
    /// Build the pattern, scatter maps and fill chunks for `grid` and `dofs`, using the
    /// current rayon thread count for the number of chunks.
    pub fn new<const D: usize>(grid: &Grid<D>, dofs: &DofMap<D>) -> Result<Self> {
        Self::with_chunks(grid, dofs, 4 * rayon::current_num_threads())
    }

    /// As [`Self::new`] with a given number of fill chunks (at least 1).
    pub fn with_chunks<const D: usize>(
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        num_chunks: usize,
    ) -> Result<Self> {
        if dofs.num_dofs() != D * grid.num_nodes() {
            return Err(SimError::Input(format!(
                "dof map has {} dofs, grid has {} nodes",
                dofs.num_dofs(),
                grid.num_nodes()
            )));
        }
        let n = dofs.num_equations();
        if n >= TWICE as usize {
            return Err(SimError::Input(format!(
                "{n} equations exceed the 31-bit scatter map"
            )));
        }
        let nc = grid.num_cells();
        // Cell → sorted unique free equations: counts, then values, both in parallel.
        // (Buffers: the equations, the node blocks.)
        type Bufs = (Vec<usize>, [(usize, usize); MAX_NODES]);
        let new_bufs = || -> Bufs { (Vec::new(), [(0, 0); MAX_NODES]) };
        let sorted_free = |c: usize, (buf, blocks): &mut Bufs| {
            cell_equations(grid, dofs, c, buf);
            match node_blocks::<D>(buf, None, blocks) {
                // Sorted node blocks are the sorted equations.
                Some(nodes) => {
                    for (e, &(first, _)) in buf.chunks_exact_mut(D).zip(nodes) {
                        for (a, ea) in e.iter_mut().enumerate() {
                            *ea = first + a;
                        }
                    }
                }
                None => {
                    buf.retain(|&e| e != usize::MAX);
                    buf.sort_unstable();
                    buf.dedup();
                }
            }
        };
        let counts: Vec<usize> = (0..nc)
            .into_par_iter()
            .map_init(new_bufs, |bufs, c| {
                sorted_free(c, bufs);
                bufs.0.len()
            })
            .collect();
        let cell_eq_pos = offsets(&counts);
        let mut cell_eqs = vec![0usize; cell_eq_pos[nc]];
        fill_blocks(&mut cell_eqs, &cell_eq_pos, |cells, out| {
            let mut bufs = new_bufs();
            let mut k = 0;
            for c in cells {
                sorted_free(c, &mut bufs);
                let buf = &bufs.0;
                out[k..k + buf.len()].copy_from_slice(buf);
                k += buf.len();
            }
        });
        let eqs_of = |c: usize| &cell_eqs[cell_eq_pos[c]..cell_eq_pos[c + 1]];
        // Equation → cells, each list increasing. The equations are split into one range
        // per thread; every range scans all cells in order and keeps its own equations
        // (counts, then cells), so no atomics are needed and every list comes out sorted.
        let ranges: Vec<Range<usize>> = {
            let parts = rayon::current_num_threads().clamp(1, n.max(1));
            (0..parts)
                .map(|k| n * k / parts..n * (k + 1) / parts)
                .collect()
        };
        let eq_cell_pos = {
            let mut counts = vec![0usize; n];
            let slices = split_mut(&mut counts, ranges.iter().map(|r| r.len()));
            let firsts = ranges.iter().map(|r| r.start);
            let parts: Vec<_> = firsts.zip(slices).collect();
            parts.into_par_iter().for_each(|(first, counts)| {
                for &e in &cell_eqs {
                    if let Some(k) = e.checked_sub(first)
                        && k < counts.len()
                    {
                        counts[k] += 1;
                    }
                }
            });
            offsets(&counts)
        };
        let mut eq_cells = vec![0usize; cell_eqs.len()];
        {
            let lens = ranges
                .iter()
                .map(|r| eq_cell_pos[r.end] - eq_cell_pos[r.start]);
            let slices = split_mut(&mut eq_cells, lens);
            let parts: Vec<_> = ranges.iter().cloned().zip(slices).collect();
            parts.into_par_iter().for_each(|(eqs, out)| {
                let base = eq_cell_pos[eqs.start];
                let mut next: Vec<usize> =
                    eq_cell_pos[eqs.clone()].iter().map(|p| p - base).collect();
                for c in 0..nc {
                    for &e in eqs_of(c) {
                        if eqs.contains(&e) {
                            let at = &mut next[e - eqs.start];
                            out[*at] = c;
                            *at += 1;
                        }
                    }
                }
            });
        }
        // Columns: rows r ≤ c of the cells containing c. Counted first and then written
        // into the final array (both in parallel), so that no per-block buffers are left
        // behind in the allocator.
        let cells_of = |c: usize| &eq_cells[eq_cell_pos[c]..eq_cell_pos[c + 1]];
        let column = |c: usize, first: usize, col: &mut Vec<usize>| {
            if c > first && cells_of(c) == cells_of(c - 1) {
                // Another component of the same node: the same cells, so the rows are
                // those of column c − 1 and c itself.
                col.push(c);
            } else {
                col.clear();
                for &cell in cells_of(c) {
                    col.extend(eqs_of(cell).iter().copied().filter(|&r| r <= c));
                }
                col.sort_unstable();
                col.dedup();
            }
        };
        const BLOCK: usize = 4096;
        // Counts with a marker per row (no sorting); a column of the same node as the
        // previous one has one row more.
        let mut col_counts = vec![0usize; n];
        col_counts.par_chunks_mut(BLOCK).enumerate().for_each_init(
            || vec![0u32; n],
            |mark, (b, out)| {
                let first = b * BLOCK;
                let mut count = 0;
                for (k, slot) in out.iter_mut().enumerate() {
                    let c = first + k;
                    if c > first && cells_of(c) == cells_of(c - 1) {
                        count += 1;
                    } else {
                        let stamp = c as u32 + 1;
                        count = 0;
                        for &cell in cells_of(c) {
                            for &r in eqs_of(cell) {
                                if r <= c && mark[r] != stamp {
                                    mark[r] = stamp;
                                    count += 1;
                                }
                            }
                        }
                    }
                    *slot = count;
                }
            },
        );
        let col_ptr = offsets(&col_counts);
        drop(col_counts);
        let mut row_idx = vec![0usize; col_ptr[n]];
        fill_blocks(&mut row_idx, &col_ptr, |cols, out| {
            let first = cols.start;
            let mut col = Vec::new();
            let mut k = 0;
            for c in cols {
                column(c, first, &mut col);
                out[k..k + col.len()].copy_from_slice(&col);
                k += col.len();
            }
        });
        let nnz = row_idx.len();
        if nnz >= TWICE as usize {
            return Err(SimError::Input(format!(
                "{nnz} stiffness entries exceed the 31-bit scatter map"
            )));
        }
        // Equations with the cells (hence the column rows below the node) of the equation
        // before them: the further components of a node.
        let mut same_cells = vec![false; n];
        same_cells
            .par_chunks_mut(BLOCK)
            .enumerate()
            .for_each(|(b, out)| {
                for (k, same) in out.iter_mut().enumerate() {
                    let c = b * BLOCK + k;
                    *same = c > 0 && cells_of(c) == cells_of(c - 1);
                }
            });
        // Scatter maps: the lengths, then the maps, in parallel blocks of cells.
        let sizes: Vec<usize> = (0..nc)
            .into_par_iter()
            .map_init(ScatterBuffer::default, |buf, c| {
                stored_len(grid, dofs, c, &same_cells, buf)
            })
            .collect();
        let pos = offsets(&sizes);
        drop(sizes);
        // Zeroed memory comes from the kernel untouched, so the pages are first written
        // by the parallel fill (which writes every entry) instead of a serial fill here.
        let mut map = vec![0u32; pos[nc]];
        fill_blocks(&mut map, &pos, |cells, out| {
            let mut buf = ScatterBuffer::default();
            let cols = (&col_ptr[..], &row_idx[..], &same_cells[..]);
            let first = pos[cells.start];
            for c in cells {
                let at = pos[c] - first..pos[c + 1] - first;
                store_cell(grid, dofs, c, cols, &mut buf, &mut out[at]);
            }
        });
        let maps = StoredMaps { pos, map };
        // Fill chunks: contiguous columns with about nnz / num_chunks entries each.
        let num_chunks = num_chunks.clamp(1, n.max(1));
        let mut bounds = vec![0usize];
        for k in 1..num_chunks {
            let target = nnz * k / num_chunks;
            let c = col_ptr.partition_point(|&p| p < target).min(n);
            if c > *bounds.last().unwrap_or(&0) {
                bounds.push(c);
            }
        }
        if n > *bounds.last().unwrap_or(&0) || bounds.len() == 1 {
            bounds.push(n);
        }
        let chunk_of = |e: usize| bounds.partition_point(|&b| b <= e) - 1;
        let nch = bounds.len() - 1;
        // The cells of every chunk, increasing: per block of cells in parallel, then
        // concatenated chunk by chunk in block order.
        let block_lists: Vec<Vec<Vec<usize>>> = (0..nc.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let mut lists = vec![Vec::new(); nch];
                for c in b * BLOCK..((b + 1) * BLOCK).min(nc) {
                    let eqs = eqs_of(c);
                    // The equations are sorted: a cell inside one chunk (most) is seen
                    // from its first and last equation.
                    let (Some(&lo), Some(&hi)) = (eqs.first(), eqs.last()) else {
                        continue;
                    };
                    let k = chunk_of(lo);
                    if hi < bounds[k + 1] {
                        lists[k].push(c);
                        continue;
                    }
                    let mut last = usize::MAX;
                    for &e in eqs {
                        let k = chunk_of(e);
                        if k != last {
                            lists[k].push(c);
                            last = k;
                        }
                    }
                }
                lists
            })
            .collect();
        let mut chunks = Vec::with_capacity(nch);
        let mut chunk_cells =
            Vec::with_capacity(block_lists.iter().flatten().map(Vec::len).sum::<usize>());
        for k in 0..nch {
            let start = chunk_cells.len();
            for lists in &block_lists {
                chunk_cells.extend_from_slice(&lists[k]);
            }
            chunks.push(Chunk {
                cols: bounds[k]..bounds[k + 1],
                vals: col_ptr[bounds[k]]..col_ptr[bounds[k + 1]],
                cells: start..chunk_cells.len(),
            });
        }
        Ok(Self {
            upper: UpperPattern::new(n, col_ptr, row_idx),
            maps,
            chunks,
            chunk_cells,
            num_cells: nc,
        })
    }

    /// The upper-triangle CSC pattern itself (for the sparse factorizations).
    pub fn upper(&self) -> &UpperPattern {
        &self.upper
    }
    /// Number of equations (rows and columns).
    pub fn num_equations(&self) -> usize {
        self.upper.dim()
    }
    /// Number of stored entries (upper triangle with diagonal).
    pub fn nnz(&self) -> usize {
        self.upper.nnz()
    }
    /// Column offsets (length `n + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        self.upper.col_ptr()
    }
    /// Row index of each stored entry, sorted within each column.
    pub fn row_idx(&self) -> &[usize] {
        self.upper.row_idx()
    }
    /// The scatter map of cell `c` of the `grid` and `dofs` the pattern was built for,
    /// written to `buf`: for the local pair `i ≤ j` at [`upper_pair`]`(i, j)`, the value
    /// position, with [`TWICE`] set when the pair adds twice; `u32::MAX` = none.
    pub fn cell_map<'a, const D: usize>(
        &self,
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        c: usize,
        buf: &'a mut ScatterBuffer,
    ) -> &'a [u32] {
        let (stored, nodes) = self.stored_map(grid, dofs, c, &mut buf.eqs, &mut buf.blocks);
        let m = buf.eqs.len();
        let mut map = std::mem::take(&mut buf.map);
        map.clear();
        match nodes {
            Some(nodes) => {
                map.resize(m * (m + 1) / 2, NONE);
                for_each_by_nodes::<D>(nodes, self.upper.col_ptr(), stored, |i, j, p| {
                    map[upper_pair(i, j)] = p as u32;
                });
            }
            None => map.extend_from_slice(stored),
        }
        buf.map = map;
        &buf.map
    }
    /// The stored map of cell `c` and, for a cell mapped by node blocks, its sorted nodes;
    /// `eqs` receives the cell's equations. A full map has `m(m + 1)/2` entries, more than
    /// the `n(n − 1)/2` of a node-block map (`m = D n`), so the length tells the format;
    /// the builder checked the column structure of node-block cells.
    fn stored_map<'s, 'b, const D: usize>(
        &'s self,
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        c: usize,
        eqs: &mut Vec<usize>,
        blocks: &'b mut [(usize, usize); MAX_NODES],
    ) -> (&'s [u32], Option<&'b [NodeBlock]>) {
        let stored = &self.maps.map[self.maps.pos[c]..self.maps.pos[c + 1]];
        cell_equations(grid, dofs, c, eqs);
        let m = eqs.len();
        let nodes = if stored.len() == m * (m + 1) / 2 {
            None
        } else {
            node_blocks::<D>(eqs, None, blocks)
        };
        (stored, nodes)
    }
    /// Add the upper triangle of cell `c`'s local matrix `k` (`m × m`, column-major) into
    /// `vals`, which holds the values from position `v0` on; entries outside are skipped.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn add_cell<const D: usize>(
        &self,
        grid: &Grid<D>,
        dofs: &DofMap<D>,
        c: usize,
        k: &[f64],
        buf: &mut ScatterBuffer,
        v0: usize,
        vals: &mut [f64],
    ) {
        let (stored, nodes) = self.stored_map(grid, dofs, c, &mut buf.eqs, &mut buf.blocks);
        let m = buf.eqs.len();
        let vlen = vals.len();
        if let Some(nodes) = nodes {
            for_each_by_nodes::<D>(nodes, self.upper.col_ptr(), stored, |i, j, p| {
                let at = p.wrapping_sub(v0);
                if at < vlen {
                    vals[at] += k[i + m * j];
                }
            });
            return;
        }
        let mut q = 0;
        for j in 0..m {
            for i in 0..=j {
                let p = stored[q];
                q += 1;
                if p == NONE {
                    continue;
                }
                let at = ((p & !TWICE) as usize).wrapping_sub(v0);
                if at < vlen {
                    let v = k[i + m * j];
                    vals[at] += if p & TWICE != 0 { 2.0 * v } else { v };
                }
            }
        }
    }
    /// Number of cells of the grid the pattern was built for.
    pub fn num_cells(&self) -> usize {
        self.num_cells
    }
    /// Number of fill chunks.
    pub fn num_chunks(&self) -> usize {
        self.chunks.len()
    }
    /// Cell evaluations per fill divided by the number of cells (1 = no duplication).
    pub fn duplication(&self) -> f64 {
        self.chunk_cells.len() as f64 / self.num_cells.max(1) as f64
    }
    /// `y += A x` for the symmetric matrix with these upper-triangle `values`
    /// ([`UpperPattern::mul_add`]).
    pub fn mul_add(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        self.upper.mul_add(values, x, y);
    }
}
