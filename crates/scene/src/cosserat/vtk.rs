//! VTK output of the Cosserat model: an ASCII `.vtu` with cell data `displacement`,
//! `rotation` (3 components; 2D: `(0, 0, φ)`), `stress` and `couple_stress` (full,
//! non-symmetric, 9 components row-major `T_ij` at `3i + j`; 2D couple stress: row z
//! holds `(m_3x, m_3y, 0)`). The grid crate's writer knows symmetric tensors only.

use std::fmt::Write as _;
use std::path::Path;

use porofrac_cosserat::{components, strain_index};
use porofrac_grid::Grid;

use crate::common::output::{OutputError, write_atomic};

/// Write `path` for the cell field `w` (`n` per cell) and the cell stresses `stress`.
pub fn write<const D: usize>(
    path: &Path,
    grid: &Grid<D>,
    w: &[f64],
    stress: &[[f64; 18]],
) -> Result<(), OutputError> {
    let n = components(D);
    let nc = grid.num_cells();
    let mut s = String::with_capacity(256 * nc);
    let _ = writeln!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{nc}\">",
        grid.num_nodes()
    );
    s.push_str(
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for x in grid.nodes() {
        let _ = writeln!(s, "{} {} {}", x[0], x[1], if D == 3 { x[2] } else { 0.0 });
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n");
    s.push_str("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for c in 0..nc {
        let nodes: Vec<String> = grid.cell_nodes(c).iter().map(|v| v.to_string()).collect();
        let _ = writeln!(s, "{}", nodes.join(" "));
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let mut off = 0;
    for c in 0..nc {
        off += grid.cell_nodes(c).len();
        let _ = write!(s, "{off} ");
    }
    s.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    let ty = if D == 2 { 5 } else { 10 };
    for _ in 0..nc {
        let _ = write!(s, "{ty} ");
    }
    s.push_str("\n</DataArray>\n</Cells>\n<CellData>\n");
    let mut array = |name: &str, comps: usize, value: &dyn Fn(usize, usize) -> f64| {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"ascii\">"
        );
        for c in 0..nc {
            let row: Vec<String> = (0..comps).map(|k| value(c, k).to_string()).collect();
            let _ = writeln!(s, "{}", row.join(" "));
        }
        s.push_str("</DataArray>\n");
    };
    array("displacement", 3, &|c, k| {
        if k < D { w[c * n + k] } else { 0.0 }
    });
    array("rotation", 3, &|c, k| {
        if D == 2 {
            if k == 2 { w[c * n + 2] } else { 0.0 }
        } else {
            w[c * n + 3 + k]
        }
    });
    array("stress", 9, &|c, k| {
        let (i, j) = (k / 3, k % 3);
        if i < D && j < D {
            stress[c][strain_index(D, i, j)]
        } else {
            0.0
        }
    });
    array("couple_stress", 9, &|c, k| {
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
    s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    write_atomic(path, s.as_bytes())
}
