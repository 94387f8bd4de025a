//! The sparsity pattern and scatter maps against a brute-force construction.
//!
//! For every grid below, with prescribed components and a platen (equations shared by
//! several nodes): every column holds exactly the rows `r ≤ c` that share a cell with `c`,
//! sorted; and every cell's scatter entry for the local pair `i ≤ j` is the position of
//! `(min(e_i, e_j), max(e_i, e_j))` when both are free (flagged to add twice when `i < j`
//! and `e_i = e_j`), `u32::MAX` otherwise. Fills with different chunk counts agree bit
//! for bit.
//! Grids: Voronoi polygons (2D), triangles, cubes and tetrahedra (3D) — node-major
//! equations with 2–8 nodes per cell, which exercises the shortcuts of the builder (the
//! next component of a node, columns of one node sharing their cells).

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::DMatrix;

use porofrac_grid::generate::{cartesian, simplices, voronoi};
use porofrac_grid::{Grid, Point};
use porofrac_law::{CellLaw, GeometryBuffer, Scratch, Stiffness};
use porofrac_sim::pattern::{ScatterBuffer, TWICE, upper_pair};
use porofrac_sim::{Displacement, DofMap, LawMap, Pattern, Platen, ScalarField, assemble};
use porofrac_vem::VemLaw;

/// Local equations of cell `c` (node-major; `None` when prescribed).
fn local_equations<const D: usize>(
    grid: &Grid<D>,
    dofs: &DofMap<D>,
    c: usize,
) -> Vec<Option<usize>> {
    grid.cell_nodes(c)
        .iter()
        .flat_map(|&n| (0..D).map(move |a| (n, a)))
        .map(|(n, a)| dofs.equation(n, a))
        .collect()
}

fn check<const D: usize>(grid: &Grid<D>, what: &str) {
    // x fixed on xmin, every component on ymin, a platen on ymax.
    let fix = |name: &str, comps: &[usize]| Displacement {
        name: name.into(),
        faces: grid.boundary(name).unwrap(),
        components: std::array::from_fn(|a| comps.contains(&a).then(|| ScalarField::from(0.01))),
    };
    let all: Vec<usize> = (0..D).collect();
    let bcs = [fix("xmin", &[0]), fix("ymin", &all)];
    let platen = Platen {
        name: "ymax".into(),
        faces: grid.boundary("ymax").unwrap(),
        force: std::array::from_fn(|a| (a == 1).then(|| ScalarField::from(-1.0))),
    };
    let dofs = DofMap::new(grid, &bcs, std::slice::from_ref(&platen)).unwrap();
    let n = dofs.num_equations();
    // Brute force: the upper-triangle entries of every cell.
    let mut cols: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for c in 0..grid.num_cells() {
        let eqs: Vec<usize> = local_equations(grid, &dofs, c)
            .into_iter()
            .flatten()
            .collect();
        for &ej in &eqs {
            for &ei in &eqs {
                if ei <= ej {
                    cols[ej].insert(ei);
                }
            }
        }
    }
    let patterns = [
        Pattern::with_chunks(grid, &dofs, 1).unwrap(),
        Pattern::with_chunks(grid, &dofs, 5).unwrap(),
        Pattern::with_chunks(grid, &dofs, 13).unwrap(),
    ];
    let mut buf = ScatterBuffer::default();
    for pattern in &patterns {
        let (ptr, rows) = (pattern.col_ptr(), pattern.row_idx());
        assert_eq!(pattern.num_equations(), n, "{what}");
        for (c, want) in cols.iter().enumerate() {
            let got = &rows[ptr[c]..ptr[c + 1]];
            assert!(
                got.iter().copied().eq(want.iter().copied()),
                "{what}: column {c} has rows {got:?}, want {want:?}"
            );
        }
        for c in 0..grid.num_cells() {
            let eqs = local_equations(grid, &dofs, c);
            let m = eqs.len();
            let scatter = pattern.cell_map(grid, &dofs, c, &mut buf);
            assert_eq!(scatter.len(), m * (m + 1) / 2, "{what}: cell {c}");
            for j in 0..m {
                for i in 0..=j {
                    let got = scatter[upper_pair(i, j)];
                    match (eqs[i], eqs[j]) {
                        (Some(ei), Some(ej)) => {
                            let (r, col) = (ei.min(ej), ei.max(ej));
                            let twice = i != j && ei == ej;
                            assert_eq!(got & TWICE != 0, twice, "{what}: cell {c} pair ({i}, {j})");
                            let p = (got & !TWICE) as usize;
                            assert!(
                                (ptr[col]..ptr[col + 1]).contains(&p) && rows[p] == r,
                                "{what}: cell {c} pair ({i}, {j}) -> {got}, want entry ({r}, {col})"
                            );
                        }
                        _ => assert_eq!(got, u32::MAX, "{what}: cell {c} pair ({i}, {j})"),
                    }
                }
            }
        }
    }
    // Fills with 1, 5 and 13 chunks: the same values and forces bit for bit (every entry
    // is summed by one chunk in cell order).
    let law = VemLaw::new(Stiffness::<D>::isotropic(1.0, 0.3).unwrap());
    let laws = LawMap::uniform(grid, &law).unwrap();
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(grid, 0.0, &mut u);
    let fill = |pattern: &Pattern| {
        let (mut values, mut forces) = (vec![0.0; pattern.nnz()], vec![0.0; n]);
        assemble(grid, &laws, &dofs, pattern, &u, &mut values, &mut forces).unwrap();
        (values, forces)
    };
    let first = fill(&patterns[0]);
    // The values against a brute-force sum of the local upper triangles.
    let mut want: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    let (mut geo, mut scratch, mut k) = (
        GeometryBuffer::default(),
        Scratch::default(),
        DMatrix::zeros(0, 0),
    );
    for c in 0..grid.num_cells() {
        let eqs = local_equations(grid, &dofs, c);
        let cell = geo.load(grid, c);
        law.stiffness(&cell, &vec![0.0; eqs.len()], &mut k, &mut scratch)
            .unwrap();
        for j in 0..eqs.len() {
            for i in 0..=j {
                if let (Some(ei), Some(ej)) = (eqs[i], eqs[j]) {
                    let twice = if i != j && ei == ej { 2.0 } else { 1.0 };
                    *want.entry((ei.min(ej), ei.max(ej))).or_default() += twice * k[(i, j)];
                }
            }
        }
    }
    let (ptr, rows) = (patterns[0].col_ptr(), patterns[0].row_idx());
    let scale = want.values().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..n {
        for p in ptr[col]..ptr[col + 1] {
            let w = want.get(&(rows[p], col)).copied().unwrap_or(0.0);
            assert!(
                (first.0[p] - w).abs() <= 1e-13 * scale,
                "{what}: entry ({}, {col}) = {}, brute force {w}",
                rows[p],
                first.0[p]
            );
        }
    }
    assert!(
        first.1.iter().any(|&f| f != 0.0),
        "{what}: prescribed values load"
    );
    for pattern in &patterns[1..] {
        let (values, forces) = fill(pattern);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&values), bits(&first.0), "{what}: values");
        assert_eq!(bits(&forces), bits(&first.1), "{what}: forces");
    }
}

#[test]
fn scatter_maps_match_brute_force() {
    let (lo2, hi2) = (Point::<2>::zeros(), Point::<2>::repeat(1.0));
    let (lo3, hi3) = (Point::<3>::zeros(), Point::<3>::repeat(1.0));
    check(&simplices::<2>(lo2, hi2, [7, 5]).unwrap(), "2D triangles");
    check(&voronoi(lo2, hi2, 60, 3, 2).unwrap(), "2D Voronoi");
    check(
        &simplices::<3>(lo3, hi3, [3, 4, 2]).unwrap(),
        "3D tetrahedra",
    );
    check(&cartesian::<3>(lo3, hi3, [3, 2, 3]).unwrap(), "3D cubes");
}
