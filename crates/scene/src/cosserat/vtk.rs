//! VTK output of the Cosserat model: a `.vtu` (through the grid's writer, binary) with
//! cell data `displacement`, `rotation` (3 components; 2D: `(0, 0, φ)`), `stress` and
//! `couple_stress` (full, non-symmetric, 9 components row-major `T_ij` at `3i + j`; 2D
//! couple stress: row z holds `(m_3x, m_3y, 0)`).

use std::path::Path;

use porofrac_cosserat::{components, strain_index};
use porofrac_grid::io::{Field, write_vtu};
use porofrac_grid::{Grid, GridError};

/// Write `path` for the cell field `w` (`n` per cell) and the cell stresses `stress`.
pub fn write<const D: usize>(
    path: &Path,
    grid: &Grid<D>,
    w: &[f64],
    stress: &[[f64; 18]],
) -> Result<(), GridError> {
    let [displacement, rotation, force_stress, couple_stress] = cell_arrays(grid, w, stress);
    let field = |components, values| Field::Components { components, values };
    write_vtu(
        path,
        grid,
        &[],
        &[
            ("displacement", field(3, &displacement)),
            ("rotation", field(3, &rotation)),
            ("stress", field(9, &force_stress)),
            ("couple_stress", field(9, &couple_stress)),
        ],
    )
}

/// The cell arrays of the VTK files and the in-memory snapshots: displacement and
/// rotation (3 per cell), force and couple stress (9 per cell, row-major).
pub fn cell_arrays<const D: usize>(
    grid: &Grid<D>,
    w: &[f64],
    stress: &[[f64; 18]],
) -> [Vec<f64>; 4] {
    let n = components(D);
    let nc = grid.num_cells();
    let per_cell = |comps: usize, value: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
        (0..nc)
            .flat_map(|c| (0..comps).map(move |k| (c, k)))
            .map(|(c, k)| value(c, k))
            .collect()
    };
    let displacement = per_cell(3, &|c, k| if k < D { w[c * n + k] } else { 0.0 });
    let rotation = per_cell(3, &|c, k| {
        if D == 2 {
            if k == 2 { w[c * n + 2] } else { 0.0 }
        } else {
            w[c * n + 3 + k]
        }
    });
    let force_stress = per_cell(9, &|c, k| {
        let (i, j) = (k / 3, k % 3);
        if i < D && j < D {
            stress[c][strain_index(D, i, j)]
        } else {
            0.0
        }
    });
    let couple_stress = per_cell(9, &|c, k| {
        let (i, j) = (k / 3, k % 3);
        if D == 2 {
            if i == 2 && j < 2 {
                stress[c][strain_index(2, 2, j)]
            } else {
                0.0
            }
        } else {
            stress[c][strain_index(3, 3 + i, j)]
        }
    });
    [displacement, rotation, force_stress, couple_stress]
}
