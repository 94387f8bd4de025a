//! The state of a model at a written step, kept in memory instead of written to VTK: the
//! grid (points, cells, cell types, tags), named point and cell fields, particles and
//! lattice arrays. A run kept in memory ([`crate::Scene::run_in_memory`]) hands one to
//! its observer at every written step ([`crate::Observer::written`]); the Python package
//! turns the arrays into numpy arrays without copying them.
//!
//! Arrays are flat `Vec<f64>` (or `Vec<i64>`), entity after entity, with the number of
//! components beside them: a field of `n` entities and `c` components holds `n·c`
//! values. Units are SI, as in the VTK files.

use std::sync::Arc;

use porofrac_grid::Grid;
use porofrac_particles::Disks;
use porofrac_particles::vtk::ContactLine;

/// A named array: `components` values per entity, entity after entity.
#[derive(Clone, Debug, PartialEq)]
pub struct Array {
    /// The name, as in the VTK files (`displacement`, `stress`, `pressure`).
    pub name: String,
    /// Values per entity (1 for a scalar).
    pub components: usize,
    /// The values (SI units).
    pub values: Vec<f64>,
}

impl Array {
    /// An array named `name` with `components` values per entity.
    pub fn new(name: &str, components: usize, values: Vec<f64>) -> Self {
        Self {
            name: name.to_string(),
            components,
            values,
        }
    }
}

/// VTK cell types used by [`Mesh::cell_types`].
pub mod cell_type {
    /// `VTK_TRIANGLE`.
    pub const TRIANGLE: u8 = 5;
    /// `VTK_POLYGON`.
    pub const POLYGON: u8 = 7;
    /// `VTK_QUAD`.
    pub const QUAD: u8 = 9;
    /// `VTK_TETRA`.
    pub const TETRA: u8 = 10;
    /// `VTK_POLYHEDRON`.
    pub const POLYHEDRON: u8 = 42;
}

/// A grid in VTK terms: points, cell connectivity with offsets, cell types, cell tags.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Dimension of the grid (2 or 3).
    pub dim: usize,
    /// Node coordinates, 3 per node (z = 0 in 2D) (m).
    pub points: Vec<f64>,
    /// The nodes of every cell, cell after cell ([`Grid::cell_nodes`]: counter-clockwise
    /// polygons in 2D).
    pub connectivity: Vec<i64>,
    /// Where each cell's nodes end in `connectivity` (one per cell, VTK's convention).
    pub offsets: Vec<i64>,
    /// The VTK type of every cell ([`cell_type`]): triangles, quadrilaterals and polygons
    /// in 2D by node count; in 3D tetrahedra for cells of 4 triangles and polyhedra for
    /// the others, described by `faces`.
    pub cell_types: Vec<u8>,
    /// 3D: the face stream of every cell, as VTK polyhedra have it (per cell: the number
    /// of faces, then for each face its node count and nodes); empty in 2D.
    pub faces: Vec<i64>,
    /// 3D: where each cell's stream ends in `faces`.
    pub face_offsets: Vec<i64>,
    /// Cell tags: the name and the cells holding it.
    pub tags: Vec<(String, Vec<i64>)>,
}

impl Mesh {
    /// The mesh of `grid`.
    pub fn of<const D: usize>(grid: &Grid<D>) -> Self {
        let nc = grid.num_cells();
        let points = grid
            .nodes()
            .iter()
            .flat_map(|p| (0..3).map(move |a| if a < D { p[a] } else { 0.0 }))
            .collect();
        let mut connectivity = Vec::new();
        let mut offsets = Vec::with_capacity(nc);
        let mut cell_types = Vec::with_capacity(nc);
        let (mut faces, mut face_offsets) = (Vec::new(), Vec::new());
        for c in 0..nc {
            let nodes = grid.cell_nodes(c);
            connectivity.extend(nodes.iter().map(|&n| n as i64));
            offsets.push(connectivity.len() as i64);
            if D == 2 {
                cell_types.push(match nodes.len() {
                    3 => cell_type::TRIANGLE,
                    4 => cell_type::QUAD,
                    _ => cell_type::POLYGON,
                });
            } else {
                let cf = grid.cell_faces(c);
                faces.push(cf.len() as i64);
                for &f in cf {
                    let fnodes = grid.face_nodes(f);
                    faces.push(fnodes.len() as i64);
                    faces.extend(fnodes.iter().map(|&n| n as i64));
                }
                face_offsets.push(faces.len() as i64);
                let tetra = nodes.len() == 4
                    && cf.len() == 4
                    && cf.iter().all(|&f| grid.face_nodes(f).len() == 3);
                cell_types.push(if tetra {
                    cell_type::TETRA
                } else {
                    cell_type::POLYHEDRON
                });
            }
        }
        let tags = grid
            .cell_tags()
            .iter()
            .map(|(name, cells)| (name.clone(), cells.iter().map(|&c| c as i64).collect()))
            .collect();
        Self {
            dim: D,
            points,
            connectivity,
            offsets,
            cell_types,
            faces,
            face_offsets,
            tags,
        }
    }

    /// Number of nodes.
    pub fn num_points(&self) -> usize {
        self.points.len() / 3
    }

    /// Number of cells.
    pub fn num_cells(&self) -> usize {
        self.offsets.len()
    }
}

/// Disks of a particle model at a written step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Particles {
    /// Centres, 2 per disk (m).
    pub positions: Vec<f64>,
    /// Radii (m).
    pub radii: Vec<f64>,
    /// Velocities, 2 per disk (m/s).
    pub velocities: Vec<f64>,
    /// Rotation angles (rad, counter-clockwise).
    pub angles: Vec<f64>,
    /// Angular velocities (rad/s).
    pub angular_velocities: Vec<f64>,
    /// Per-disk fields of the model (e.g. `broken_bonds`).
    pub fields: Vec<Array>,
    /// Contacts and bonds as segments between the centres, 4 per link `ax, ay, bx, by`
    /// (m), as in `contacts_NNNN.vtp`.
    pub links: Vec<f64>,
    /// Normal force of every link (N/m, positive in compression).
    pub normal_force: Vec<f64>,
    /// Tangential force of every link (N/m).
    pub tangential_force: Vec<f64>,
    /// 1 for a bond, 0 for a contact.
    pub bonded: Vec<f64>,
}

impl Particles {
    /// The disks `d` with the per-disk fields `extra` and the links `lines`.
    pub fn of(d: &Disks, extra: &[(&str, &[f64])], lines: &[ContactLine]) -> Self {
        Self {
            positions: d.x.iter().flatten().copied().collect(),
            radii: d.r.clone(),
            velocities: d.v.iter().flatten().copied().collect(),
            angles: d.angle.clone(),
            angular_velocities: d.omega.clone(),
            fields: extra
                .iter()
                .map(|(name, v)| Array::new(name, 1, v.to_vec()))
                .collect(),
            links: lines
                .iter()
                .flat_map(|l| [l.a[0], l.a[1], l.b[0], l.b[1]])
                .collect(),
            normal_force: lines.iter().map(|l| l.normal_force).collect(),
            tangential_force: lines.iter().map(|l| l.tangential_force).collect(),
            bonded: lines
                .iter()
                .map(|l| f64::from(u8::from(l.bonded)))
                .collect(),
        }
    }
}

/// The nodes of a 2D lattice at a written step: every field holds `nx·ny` values, row
/// after row (`j` slow, `i` fast), so it reads as an array of shape `(ny, nx)`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lattice {
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
    /// Position of node (0, 0) (m).
    pub origin: [f64; 2],
    /// Node spacing (m).
    pub spacing: f64,
    /// Fields: `vx`, `vy` (m/s), `pressure` (Pa), `density` (kg/m³), `solid` (1 in a
    /// solid), `temperature` (K, with heat).
    pub fields: Vec<Array>,
}

/// A model's state at a written step (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Snapshot {
    /// The time (s; set by the driver).
    pub time: f64,
    /// The grid (grid models; `None` at steps after the first, where it is unchanged).
    pub mesh: Option<Arc<Mesh>>,
    /// Fields on the grid's nodes.
    pub point_data: Vec<Array>,
    /// Fields on the grid's cells.
    pub cell_data: Vec<Array>,
    /// The disks (particle models).
    pub particles: Option<Particles>,
    /// The lattice (lattice Boltzmann).
    pub lattice: Option<Lattice>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mesh of a 2×1 grid of unit squares: 6 points at z = 0, two quadrilaterals of
    /// 4 nodes, offsets 4 and 8.
    #[test]
    fn the_mesh_of_two_squares_has_two_quadrilaterals() {
        let g = porofrac_grid::generate::cartesian(
            porofrac_grid::Point::<2>::new(0.0, 0.0),
            porofrac_grid::Point::<2>::new(2.0, 1.0),
            [2, 1],
        )
        .unwrap();
        let m = Mesh::of(&g);
        assert_eq!(m.dim, 2);
        assert_eq!(m.num_points(), 6);
        assert_eq!(m.num_cells(), 2);
        assert_eq!(m.offsets, vec![4, 8]);
        assert_eq!(m.cell_types, vec![cell_type::QUAD; 2]);
        assert!(m.points.chunks(3).all(|p| p[2] == 0.0));
        assert!(m.faces.is_empty());
    }
}
