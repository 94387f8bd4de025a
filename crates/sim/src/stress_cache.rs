//! Cell stresses of linear laws as one cached product.
//!
//! For a law whose stiffness does not depend on the displacement
//! ([`CellLaw::is_linear`](porofrac_law::CellLaw::is_linear)) the cell stress is linear in the cell's nodal displacements
//! (Nilsen et al. (2017) eq. 18 for MDEM, the projected strain for VEM):
//!
//! ```text
//!   σ(u_K) = Σ_j u_j σ(e_j) = B_K u_K,   B_K = [σ(e_1) … σ(e_m)]   (D² × m)
//! ```
//!
//! with `e_j` the unit displacement of local dof `j`. [`StressCache`] probes `B_K` once
//! from the law for every cell with a linear law, so a cell's stress is a `D² × m`
//! product instead of a law evaluation (MDEM builds its frame from the coordinates on
//! every call). Entries are keyed by the index of the law in the [`LawMap`] like
//! [`crate::assembly::ElementCache`] (the cache serves the maps over the same list of
//! laws, which differ only in the law of each cell): a cell whose law changed since (a
//! failed cell takes its post-failure law) is evaluated by its law. A law with
//! `σ(0) ≠ 0` or a probe that fails is not cached. The product sums in another order than the law, so
//! the stresses agree with the law's to rounding.

use porofrac_grid::Point;
use porofrac_law::{CellGeometry, Scratch, Tensor};
use rayon::prelude::*;

use crate::biot::Operators;
use crate::laws::LawMap;

/// Cells per block of the parallel construction.
const BLOCK: usize = 1024;

/// The stress operators `B_K` of the cells with a linear law (see the module docs).
pub(crate) struct StressCache {
    /// Per cell: the index in the law map of the law `B_K` belongs to, [`NONE`] when
    /// none is kept.
    law: Vec<usize>,
    /// Per cell: the start of `B_K` in `values` (column-major, `D²` rows); `len + 1`.
    start: Vec<usize>,
    values: Vec<f64>,
}

/// The key of a cell without a kept operator.
const NONE: usize = usize::MAX;

/// The geometry of cell `c` from the coupling data.
fn geometry<'g, const D: usize>(
    ops: &'g Operators<D>,
    coords: &'g [Point<D>],
    volumes: &[f64],
    c: usize,
) -> CellGeometry<'g, D> {
    let k = ops.node_ptr[c]..ops.node_ptr[c + 1];
    CellGeometry {
        coords: &coords[k.clone()],
        node_normals: &ops.normals[k],
        volume: volumes[c],
    }
}

impl StressCache {
    /// Probe `B_K` for every cell whose law in `map` is linear; `coords` are the node
    /// coordinates of every cell aligned with the node normals of `ops`.
    pub(crate) fn new<const D: usize>(
        map: &LawMap<'_, D>,
        ops: &Operators<D>,
        coords: &[Point<D>],
        volumes: &[f64],
    ) -> Self {
        let nc = volumes.len();
        let mut start = Vec::with_capacity(nc + 1);
        start.push(0);
        for c in 0..nc {
            let m = D * (ops.node_ptr[c + 1] - ops.node_ptr[c]);
            let len = if map.law(c).is_linear() { D * D * m } else { 0 };
            start.push(start[c] + len);
        }
        let mut values = vec![0.0; start[nc]];
        let mut law = vec![NONE; nc];
        // Per block of cells: its slice of `values` and of `law`.
        let mut parts = Vec::with_capacity(nc.div_ceil(BLOCK));
        let (mut vrest, mut lrest) = (&mut values[..], &mut law[..]);
        for b in 0..nc.div_ceil(BLOCK) {
            let cells = b * BLOCK..((b + 1) * BLOCK).min(nc);
            let (v, vr) = vrest.split_at_mut(start[cells.end] - start[cells.start]);
            let (l, lr) = lrest.split_at_mut(cells.len());
            parts.push((cells, v, l));
            vrest = vr;
            lrest = lr;
        }
        parts.into_par_iter().for_each(|(cells, vals, laws)| {
            let mut scratch = Scratch::default();
            let mut uc = Vec::new();
            let first = start[cells.start];
            for (i, c) in cells.enumerate() {
                let b = &mut vals[start[c] - first..start[c + 1] - first];
                if b.is_empty() {
                    continue;
                }
                let l = map.law(c);
                let geo = geometry(ops, coords, volumes, c);
                let m = b.len() / (D * D);
                uc.clear();
                uc.resize(m, 0.0);
                let at_rest = l.stress(&geo, &uc, &mut scratch);
                let mut ok = at_rest.is_ok_and(|s| s.iter().all(|&s| s == 0.0));
                for j in 0..m {
                    if !ok {
                        break;
                    }
                    uc[j] = 1.0;
                    let s = l.stress(&geo, &uc, &mut scratch);
                    uc[j] = 0.0;
                    match s {
                        Ok(s) => b[D * D * j..D * D * (j + 1)].copy_from_slice(s.as_slice()),
                        Err(_) => ok = false,
                    }
                }
                if ok {
                    laws[i] = map.law_index(c);
                }
            }
        });
        Self { law, start, values }
    }

    /// The stress of cell `c` at its gathered displacement `uc` if `B_K` is kept for its
    /// law, the law of index `law` in the map.
    #[inline]
    pub(crate) fn stress<const D: usize>(
        &self,
        c: usize,
        law: usize,
        uc: &[f64],
    ) -> Option<Tensor<D>> {
        let a = *self.law.get(c)?;
        if a == NONE || a != law {
            return None;
        }
        let b = &self.values[self.start[c]..self.start[c + 1]];
        if b.len() != D * D * uc.len() {
            return None;
        }
        let mut s = Tensor::<D>::zeros();
        for (col, &x) in b.chunks_exact(D * D).zip(uc) {
            if x != 0.0 {
                for (si, bi) in s.iter_mut().zip(col) {
                    *si += bi * x;
                }
            }
        }
        Some(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::generate::simplices;
    use porofrac_law::{CellLaw, Stiffness};
    use porofrac_mdem::{DemLaw, DemMode, MdemLaw};
    use porofrac_vem::VemLaw;

    /// The kept operators give the laws' stresses to rounding (1e-13 of the largest) on
    /// VEM and MDEM tetrahedra at an arbitrary displacement; the nonlinear (DEM) cells
    /// and a cell whose law changed after the cache was built are left to their laws.
    #[test]
    fn kept_operators_give_the_law_stresses() {
        let grid = simplices::<3>(
            Point::<3>::zeros(),
            Point::<3>::new(2.0, 1.0, 1.0),
            [4, 2, 2],
        )
        .unwrap();
        let st = Stiffness::<3>::isotropic(1.0e9, 0.3).unwrap();
        let vem = VemLaw::new(st.clone());
        let mdem = MdemLaw::new(&st).unwrap();
        let dem = DemLaw::new(&st, DemMode::CompressionOnly).unwrap();
        let nc = grid.num_cells();
        let laws: Vec<&dyn CellLaw<3>> = vec![&vem, &mdem, &dem];
        let of = |c: usize| match c % 5 {
            0 => 2,
            1 | 2 => 0,
            _ => 1,
        };
        let mut map = LawMap::new(&grid, laws, (0..nc).map(of).collect()).unwrap();
        let mut node_ptr = vec![0];
        let (mut normals, mut coords, mut buf) = (Vec::new(), Vec::new(), Vec::new());
        for c in 0..nc {
            buf.clear();
            buf.resize(grid.cell_nodes(c).len(), Point::<3>::zeros());
            grid.cell_node_normals(c, &mut buf);
            normals.extend_from_slice(&buf);
            coords.extend(grid.cell_nodes(c).iter().map(|&n| *grid.node(n)));
            node_ptr.push(normals.len());
        }
        let ops = Operators {
            alpha: vec![],
            p0: vec![],
            node_ptr,
            normals,
            weights: vec![],
            dofs: vec![],
            free_ptr: vec![],
            free_eq: vec![],
            free_w: vec![],
        };
        let cache = StressCache::new(&map, &ops, &coords, grid.cell_volumes());
        let u = |c: usize, m: usize| -> Vec<f64> {
            (0..m)
                .map(|i| 1e-4 * ((((c + 3) * 37 + i * 11) % 23) as f64 - 11.0))
                .collect()
        };
        let mut scratch = Scratch::default();
        let mut kept = 0;
        for c in 0..nc {
            let law = map.law(c);
            let geo = geometry(&ops, &coords, grid.cell_volumes(), c);
            let uc = u(c, 3 * geo.coords.len());
            let want = law.stress(&geo, &uc, &mut scratch).unwrap();
            match cache.stress(c, map.law_index(c), &uc) {
                Some(got) => {
                    kept += 1;
                    assert!(law.is_linear(), "cell {c}");
                    let big = want.amax();
                    assert!(big > 0.0);
                    assert!(
                        (got - want).amax() <= 1e-13 * big,
                        "cell {c}: {got} vs {want}"
                    );
                }
                None => assert!(!law.is_linear(), "cell {c}"),
            }
        }
        assert_eq!(kept, (0..nc).filter(|&c| of(c) != 2).count());
        // Cell 3 (MDEM when cached) fails: its kept operator must not serve it.
        map.set_law(&grid, 3, 2).unwrap();
        assert!(cache.stress::<3>(3, map.law_index(3), &u(3, 12)).is_none());
        map.set_law(&grid, 3, 1).unwrap();
        assert!(cache.stress::<3>(3, map.law_index(3), &u(3, 12)).is_some());
    }
}
