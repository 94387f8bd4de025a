//! The row-distributed CSR matrix and its ghost exchange.
//!
//! # Layout
//!
//! Indices are global; process `r` owns the contiguous range `starts[r]..starts[r+1]`
//! ([`Layout`]) of the rows, and of the columns under the column layout (the same for a
//! square operator, the coarse layout for a prolongator).
//!
//! # Storage (as PETSc's MPIAIJ)
//!
//! The owned rows are split in two local CSR blocks: `diag` with the owned columns
//! (numbered `0..n_own`) and `offd` with the *ghost* columns — the columns of other
//! processes that the owned rows touch, sorted by global index and numbered `0..n_ghost`.
//! Sorted ghosts are grouped by owner, so the ghosts of one neighbour are one contiguous
//! slot range.
//!
//! # Ghost exchange
//!
//! The plan ([`Exchange`]) is built once: every process tells each owner which of its
//! indices it needs (an all-to-all of counts, then of the indices), so the owner knows the
//! list of its owned entries to send to each neighbour, in the receiver's slot order. A
//! *forward* exchange sends owned values into the neighbours' ghost slots; a *reverse*
//! exchange sends ghost-slot values back and the owner adds them (the transpose product).
//!
//! # Products
//!
//! `y = A x = A_diag x_own + A_offd x_ghost`. The exchange is overlapped with the
//! computation: the sends and receives are posted, `A_diag x_own` is computed while the
//! messages travel, and `A_offd x_ghost` after they arrive. `y = Aᵀ x` (for a prolongator)
//! computes `A_diagᵀ x` into the owned and `A_offdᵀ x` into the ghost slots, then reverse-
//! exchanges the ghost slots.

use std::cell::RefCell;

use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use crate::error::{DistError, Result};

/// The communicator of every distributed object here.
pub type Comm = SimpleCommunicator;

/// Ownership of a global index range: process `r` owns `starts[r]..starts[r+1]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    starts: Vec<usize>,
    rank: usize,
}

impl Layout {
    /// The layout in which this process owns `n_local` indices, following those of the
    /// lower ranks (collective: an all-gather of the counts).
    pub fn from_local(comm: &Comm, n_local: usize) -> Self {
        let size = comm.size() as usize;
        let mut counts = vec![0usize; size];
        comm.all_gather_into(&n_local, &mut counts[..]);
        let mut starts = Vec::with_capacity(size + 1);
        starts.push(0);
        for c in counts {
            starts.push(starts.last().copied().unwrap_or(0) + c);
        }
        Self {
            starts,
            rank: comm.rank() as usize,
        }
    }

    /// Global size.
    pub fn global(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }
    /// First owned global index.
    pub fn start(&self) -> usize {
        self.starts[self.rank]
    }
    /// Number of owned indices.
    pub fn local(&self) -> usize {
        self.starts[self.rank + 1] - self.starts[self.rank]
    }
    /// The range of process `r`.
    pub fn range_of(&self, r: usize) -> std::ops::Range<usize> {
        self.starts[r]..self.starts[r + 1]
    }
    /// This process's rank.
    pub fn rank(&self) -> usize {
        self.rank
    }
    /// Number of processes.
    pub fn size(&self) -> usize {
        self.starts.len() - 1
    }
    /// The process owning global index `g` (`g < global()`).
    pub fn owner(&self, g: usize) -> usize {
        self.starts.partition_point(|&s| s <= g) - 1
    }
    /// Whether this process owns `g`.
    pub fn owns(&self, g: usize) -> bool {
        self.start() <= g && g < self.starts[self.rank + 1]
    }
}

/// A ghost-exchange plan (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Exchange {
    /// Processes this one sends owned values to, with `send_idx[send_ptr[k]..send_ptr[k+1]]`
    /// the owned local indices for `send_ranks[k]`.
    send_ranks: Vec<i32>,
    send_ptr: Vec<usize>,
    send_idx: Vec<usize>,
    /// Processes this one receives ghosts from, with slots `recv_ptr[k]..recv_ptr[k+1]`.
    recv_ranks: Vec<i32>,
    recv_ptr: Vec<usize>,
}

/// An all-to-all of variable-length messages: `send[k]` goes to process `k`; returns the
/// messages received from every process, concatenated in rank order, with their offsets.
pub fn all_to_all_vec<T: Equivalence + Copy + Default>(
    comm: &Comm,
    send: &[Vec<T>],
) -> (Vec<T>, Vec<usize>) {
    let size = comm.size() as usize;
    let scounts: Vec<i32> = send.iter().map(|v| v.len() as i32).collect();
    let mut rcounts = vec![0i32; size];
    comm.all_to_all_into(&scounts[..], &mut rcounts[..]);
    let displs = |c: &[i32]| -> Vec<i32> {
        c.iter()
            .scan(0i32, |acc, &x| {
                let d = *acc;
                *acc += x;
                Some(d)
            })
            .collect()
    };
    let (sd, rd) = (displs(&scounts), displs(&rcounts));
    let flat: Vec<T> = send.iter().flatten().copied().collect();
    let total: usize = rcounts.iter().map(|&c| c as usize).sum();
    let mut recv = vec![T::default(); total];
    {
        let sp = Partition::new(&flat[..], &scounts[..], &sd[..]);
        let mut rp = PartitionMut::new(&mut recv[..], &rcounts[..], &rd[..]);
        comm.all_to_all_varcount_into(&sp, &mut rp);
    }
    let mut ptr = vec![0usize];
    for &c in &rcounts {
        ptr.push(ptr.last().copied().unwrap_or(0) + c as usize);
    }
    (recv, ptr)
}

/// Gather every process's `local` slice on every process, in rank order.
pub fn all_gather_vec<T: Equivalence + Copy + Default>(comm: &Comm, local: &[T]) -> Vec<T> {
    let size = comm.size() as usize;
    let n = local.len() as i32;
    let mut counts = vec![0i32; size];
    comm.all_gather_into(&n, &mut counts[..]);
    let displs: Vec<i32> = counts
        .iter()
        .scan(0i32, |acc, &x| {
            let d = *acc;
            *acc += x;
            Some(d)
        })
        .collect();
    let total: usize = counts.iter().map(|&c| c as usize).sum();
    let mut out = vec![T::default(); total];
    {
        let mut p = PartitionMut::new(&mut out[..], &counts[..], &displs[..]);
        comm.all_gather_varcount_into(local, &mut p);
    }
    out
}

/// Global sum of a local number.
pub fn sum(comm: &Comm, x: f64) -> f64 {
    let mut s = 0.0;
    comm.all_reduce_into(&x, &mut s, mpi::collective::SystemOperation::sum());
    s
}

/// Global sum of a local count.
pub fn sum_usize(comm: &Comm, x: usize) -> usize {
    let mut s = 0usize;
    comm.all_reduce_into(&x, &mut s, mpi::collective::SystemOperation::sum());
    s
}

/// Global maximum of a local number.
pub fn max(comm: &Comm, x: f64) -> f64 {
    let mut s = 0.0;
    comm.all_reduce_into(&x, &mut s, mpi::collective::SystemOperation::max());
    s
}

/// Global dot product of two distributed vectors (owned parts).
pub fn dot(comm: &Comm, a: &[f64], b: &[f64]) -> f64 {
    sum(comm, a.iter().zip(b).map(|(x, y)| x * y).sum())
}

/// Post the messages `send` (blocks of `width` items per index of `to_ptr`) to `to`, the
/// receives from `from` into `recv`, run `during`, and wait for all of them.
fn post_and_wait<T: Equivalence>(
    comm: &Comm,
    to: (&[i32], &[usize], &[T]),
    from: (&[i32], &[usize], &mut [T]),
    width: usize,
    during: impl FnOnce(),
) {
    let (to_ranks, to_ptr, send) = to;
    let (from_ranks, from_ptr, recv) = from;
    mpi::request::scope(|scope| {
        let mut rreqs = Vec::with_capacity(from_ranks.len());
        let mut rest: &mut [T] = recv;
        for (k, &r) in from_ranks.iter().enumerate() {
            let len = (from_ptr[k + 1] - from_ptr[k]) * width;
            let (head, tail) = rest.split_at_mut(len);
            rest = tail;
            rreqs.push(comm.process_at_rank(r).immediate_receive_into(scope, head));
        }
        let mut sreqs = Vec::with_capacity(to_ranks.len());
        for (k, &r) in to_ranks.iter().enumerate() {
            let s = &send[to_ptr[k] * width..to_ptr[k + 1] * width];
            sreqs.push(comm.process_at_rank(r).immediate_send(scope, s));
        }
        during();
        for q in rreqs {
            q.wait();
        }
        for q in sreqs {
            q.wait();
        }
    });
}

impl Exchange {
    /// The plan for the sorted `ghosts` (global indices not owned here) under `layout`
    /// (collective).
    pub fn new(comm: &Comm, layout: &Layout, ghosts: &[usize]) -> Self {
        let size = layout.size();
        let mut want: Vec<Vec<usize>> = vec![Vec::new(); size];
        let mut recv_ranks = Vec::new();
        let mut recv_ptr = vec![0usize];
        for (slot, &g) in ghosts.iter().enumerate() {
            let r = layout.owner(g);
            if recv_ranks.last() != Some(&(r as i32)) {
                if !recv_ranks.is_empty() {
                    recv_ptr.push(slot);
                }
                recv_ranks.push(r as i32);
            }
            want[r].push(g);
        }
        if !recv_ranks.is_empty() {
            recv_ptr.push(ghosts.len());
        }
        let (asked, ptr) = all_to_all_vec(comm, &want);
        let start = layout.start();
        let mut send_ranks = Vec::new();
        let mut send_ptr = vec![0usize];
        let mut send_idx = Vec::with_capacity(asked.len());
        for r in 0..size {
            if ptr[r + 1] > ptr[r] {
                send_ranks.push(r as i32);
                send_idx.extend(asked[ptr[r]..ptr[r + 1]].iter().map(|&g| g - start));
                send_ptr.push(send_idx.len());
            }
        }
        Self {
            send_ranks,
            send_ptr,
            send_idx,
            recv_ranks,
            recv_ptr,
        }
    }

    /// Number of ghost slots.
    pub fn num_ghosts(&self) -> usize {
        self.recv_ptr.last().copied().unwrap_or(0)
    }
    /// Number of owned entries sent per exchange.
    pub fn num_sent(&self) -> usize {
        self.send_idx.len()
    }
    /// Number of neighbours sent to and received from.
    pub fn num_neighbours(&self) -> (usize, usize) {
        (self.send_ranks.len(), self.recv_ranks.len())
    }

    /// Forward exchange of `width` items per index: `ghost[s·width..]` receives the owned
    /// items `owned[i·width..]` of the process owning ghost slot `s`. `during` runs while
    /// the messages travel.
    pub fn forward<T: Equivalence + Copy + Default>(
        &self,
        comm: &Comm,
        owned: &[T],
        width: usize,
        ghost: &mut [T],
        during: impl FnOnce(),
    ) {
        let mut send = Vec::with_capacity(self.send_idx.len() * width);
        for &i in &self.send_idx {
            send.extend_from_slice(&owned[i * width..(i + 1) * width]);
        }
        post_and_wait(
            comm,
            (&self.send_ranks, &self.send_ptr, &send),
            (&self.recv_ranks, &self.recv_ptr, ghost),
            width,
            during,
        );
    }

    /// Reverse exchange: the owners add the ghost-slot values `ghost` to `owned`.
    pub fn reverse_add(&self, comm: &Comm, ghost: &[f64], owned: &mut [f64]) {
        let mut recv = vec![0.0; self.send_idx.len()];
        post_and_wait(
            comm,
            (&self.recv_ranks, &self.recv_ptr, ghost),
            (&self.send_ranks, &self.send_ptr, &mut recv),
            1,
            || {},
        );
        for (&i, v) in self.send_idx.iter().zip(&recv) {
            owned[i] += v;
        }
    }

    /// Forward exchange of variable-length records: owned index `i` has the record
    /// `data[ptr[i]..ptr[i+1]]`; returns the records of the ghost slots, concatenated in
    /// slot order, with their offsets.
    pub fn forward_records<T: Equivalence + Copy + Default>(
        &self,
        comm: &Comm,
        ptr: &[usize],
        data: &[T],
    ) -> (Vec<usize>, Vec<T>) {
        let owned_len: Vec<usize> = (0..ptr.len() - 1).map(|i| ptr[i + 1] - ptr[i]).collect();
        let mut ghost_len = vec![0usize; self.num_ghosts()];
        self.forward(comm, &owned_len, 1, &mut ghost_len, || {});
        // Per-neighbour message sizes in items.
        let mut send = Vec::new();
        let mut sptr = vec![0usize];
        for k in 0..self.send_ranks.len() {
            for &i in &self.send_idx[self.send_ptr[k]..self.send_ptr[k + 1]] {
                send.extend_from_slice(&data[ptr[i]..ptr[i + 1]]);
            }
            sptr.push(send.len());
        }
        let mut gptr = vec![0usize];
        for &l in &ghost_len {
            gptr.push(gptr.last().copied().unwrap_or(0) + l);
        }
        let rptr: Vec<usize> = self.recv_ptr.iter().map(|&s| gptr[s]).collect();
        let mut recv = vec![T::default(); gptr.last().copied().unwrap_or(0)];
        post_and_wait(
            comm,
            (&self.send_ranks, &sptr, &send),
            (&self.recv_ranks, &rptr, &mut recv),
            1,
            || {},
        );
        (gptr, recv)
    }
}

/// A local CSR block.
#[derive(Clone, Debug, Default)]
pub struct LocalCsr {
    /// Row offsets.
    pub row_ptr: Vec<usize>,
    /// Column indices (local numbering of the block).
    pub col: Vec<u32>,
    /// Values.
    pub val: Vec<f64>,
}

impl LocalCsr {
    /// `y = M x` (`add`: `y += M x`).
    pub fn mul(&self, x: &[f64], y: &mut [f64], add: bool) {
        for (i, yi) in y.iter_mut().enumerate() {
            let mut s = 0.0;
            for p in self.row_ptr[i]..self.row_ptr[i + 1] {
                s += self.val[p] * x[self.col[p] as usize];
            }
            if add {
                *yi += s;
            } else {
                *yi = s;
            }
        }
    }

    /// `y += Mᵀ x`.
    pub fn mul_transpose_add(&self, x: &[f64], y: &mut [f64]) {
        for (i, &xi) in x.iter().enumerate() {
            for p in self.row_ptr[i]..self.row_ptr[i + 1] {
                y[self.col[p] as usize] += self.val[p] * xi;
            }
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.val.len()
    }

    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        self.row_ptr.capacity() * 8 + self.col.capacity() * 4 + self.val.capacity() * 8
    }
}

/// A row-distributed sparse matrix (see the module docs).
#[derive(Debug)]
pub struct DistCsr {
    rows: Layout,
    cols: Layout,
    diag: LocalCsr,
    offd: LocalCsr,
    ghosts: Vec<usize>,
    plan: Exchange,
    ghost_buf: RefCell<Vec<f64>>,
}

impl DistCsr {
    /// The matrix whose owned rows (under `rows`) have the entries `gcol[row_ptr[i]..
    /// row_ptr[i+1]]` (global columns under `cols`, any order, no duplicates) with values
    /// `val` (collective: builds the exchange plan).
    ///
    /// Errors: lengths that disagree with the layouts, a column out of range.
    pub fn from_rows(
        comm: &Comm,
        rows: Layout,
        cols: Layout,
        row_ptr: &[usize],
        gcol: &[usize],
        val: &[f64],
    ) -> Result<Self> {
        let n = rows.local();
        if row_ptr.len() != n + 1 || gcol.len() != val.len() || row_ptr[n] != gcol.len() {
            return Err(DistError::Input(format!(
                "{n} owned rows with {} row offsets, {} columns and {} values",
                row_ptr.len(),
                gcol.len(),
                val.len()
            )));
        }
        let ncg = cols.global();
        if let Some(&g) = gcol.iter().find(|&&g| g >= ncg) {
            return Err(DistError::Input(format!(
                "column {g} of a matrix with {ncg} columns"
            )));
        }
        let mut ghosts: Vec<usize> = gcol.iter().copied().filter(|&g| !cols.owns(g)).collect();
        ghosts.sort_unstable();
        ghosts.dedup();
        let c0 = cols.start();
        let mut diag = LocalCsr {
            row_ptr: vec![0],
            ..Default::default()
        };
        let mut offd = diag.clone();
        for i in 0..n {
            for p in row_ptr[i]..row_ptr[i + 1] {
                let g = gcol[p];
                if cols.owns(g) {
                    diag.col.push((g - c0) as u32);
                    diag.val.push(val[p]);
                } else {
                    let s = ghosts.binary_search(&g).unwrap_or(0);
                    offd.col.push(s as u32);
                    offd.val.push(val[p]);
                }
            }
            diag.row_ptr.push(diag.col.len());
            offd.row_ptr.push(offd.col.len());
        }
        let plan = Exchange::new(comm, &cols, &ghosts);
        let ghost_buf = RefCell::new(vec![0.0; ghosts.len()]);
        Ok(Self {
            rows,
            cols,
            diag,
            offd,
            ghosts,
            plan,
            ghost_buf,
        })
    }

    /// Row layout.
    pub fn rows(&self) -> &Layout {
        &self.rows
    }
    /// Column layout.
    pub fn cols(&self) -> &Layout {
        &self.cols
    }
    /// The block of owned columns.
    pub fn diag(&self) -> &LocalCsr {
        &self.diag
    }
    /// The block of ghost columns.
    pub fn offd(&self) -> &LocalCsr {
        &self.offd
    }
    /// Global indices of the ghost columns, sorted.
    pub fn ghosts(&self) -> &[usize] {
        &self.ghosts
    }
    /// The ghost-exchange plan.
    pub fn plan(&self) -> &Exchange {
        &self.plan
    }
    /// Owned entries.
    pub fn local_nnz(&self) -> usize {
        self.diag.nnz() + self.offd.nnz()
    }
    /// Heap bytes held on this process.
    pub fn bytes(&self) -> usize {
        self.diag.bytes()
            + self.offd.bytes()
            + self.ghosts.capacity() * 8
            + (self.plan.send_idx.capacity() + self.plan.send_ptr.capacity()) * 8
            + self.ghost_buf.borrow().capacity() * 8
    }

    /// The owned diagonal entries (square matrices).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows.local())
            .map(|i| {
                (self.diag.row_ptr[i]..self.diag.row_ptr[i + 1])
                    .find(|&p| self.diag.col[p] as usize == i)
                    .map_or(0.0, |p| self.diag.val[p])
            })
            .collect()
    }

    /// `y = A x` on the owned parts (collective), the exchange overlapped with the
    /// product of the owned columns.
    pub fn mul(&self, comm: &Comm, x: &[f64], y: &mut [f64]) {
        let mut g = self.ghost_buf.borrow_mut();
        let diag = &self.diag;
        self.plan
            .forward(comm, x, 1, &mut g, || diag.mul(x, y, false));
        self.offd.mul(&g, y, true);
    }

    /// `y = Aᵀ x` (`x` under the row layout, `y` under the column layout; collective).
    pub fn mul_transpose(&self, comm: &Comm, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        self.diag.mul_transpose_add(x, y);
        let mut g = self.ghost_buf.borrow_mut();
        g.fill(0.0);
        self.offd.mul_transpose_add(x, &mut g);
        self.plan.reverse_add(comm, &g, y);
    }

    /// The owned rows with global column indices: `(row_ptr, columns, values)`, each
    /// row's columns sorted.
    pub fn global_rows(&self) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let c0 = self.cols.start();
        let mut ptr = vec![0];
        let mut col = Vec::with_capacity(self.local_nnz());
        let mut val = Vec::with_capacity(self.local_nnz());
        let mut row: Vec<(usize, f64)> = Vec::new();
        for i in 0..self.rows.local() {
            row.clear();
            for p in self.diag.row_ptr[i]..self.diag.row_ptr[i + 1] {
                row.push((c0 + self.diag.col[p] as usize, self.diag.val[p]));
            }
            for p in self.offd.row_ptr[i]..self.offd.row_ptr[i + 1] {
                row.push((self.ghosts[self.offd.col[p] as usize], self.offd.val[p]));
            }
            row.sort_unstable_by_key(|e| e.0);
            col.extend(row.iter().map(|e| e.0));
            val.extend(row.iter().map(|e| e.1));
            ptr.push(col.len());
        }
        (ptr, col, val)
    }
}
