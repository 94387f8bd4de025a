//! Structured generators (one code path for 2D and 3D).

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::point::{Point, assert_dim, facet_area_vector};

/// Validate the extent and counts and return the node lattice.
fn lattice<const D: usize>(lo: Point<D>, hi: Point<D>, n: [usize; D]) -> Result<Vec<Point<D>>> {
    const { assert_dim::<D>() };
    for a in 0..D {
        if n[a] == 0 {
            return Err(GridError::Input(format!(
                "cells per axis must be ≥ 1, got {n:?}"
            )));
        }
        if !(lo[a].is_finite() && hi[a].is_finite() && hi[a] > lo[a]) {
            return Err(GridError::Input(format!(
                "extent must have min < max on every axis, got axis {a}: [{}, {}]",
                lo[a], hi[a]
            )));
        }
    }
    let count: usize = n.iter().map(|k| k + 1).product();
    let mut nodes = Vec::with_capacity(count);
    for idx in 0..count {
        let ijk = unravel::<D>(idx, n);
        nodes.push(Point::<D>::from_fn(|a, _| {
            // Exact end points, uniform spacing in between.
            if ijk[a] == n[a] {
                hi[a]
            } else {
                lo[a] + (hi[a] - lo[a]) * ijk[a] as f64 / n[a] as f64
            }
        }));
    }
    Ok(nodes)
}

/// Node lattice index (i, j[, k]) of a flat node number (x fastest).
fn unravel<const D: usize>(mut idx: usize, n: [usize; D]) -> [usize; D] {
    let mut ijk = [0; D];
    for a in 0..D {
        ijk[a] = idx % (n[a] + 1);
        idx /= n[a] + 1;
    }
    ijk
}

fn node_id<const D: usize>(ijk: [usize; D], n: [usize; D]) -> usize {
    let mut id = 0;
    for a in (0..D).rev() {
        id = id * (n[a] + 1) + ijk[a];
    }
    id
}

/// The corners of cell `(i, j[, k])` offset by a bit pattern (bit a = +1 along axis a).
fn corner<const D: usize>(cell: [usize; D], bits: usize, n: [usize; D]) -> usize {
    let mut ijk = cell;
    for a in 0..D {
        ijk[a] += (bits >> a) & 1;
    }
    node_id(ijk, n)
}

fn cells_iter<const D: usize>(n: [usize; D]) -> impl Iterator<Item = [usize; D]> {
    let total: usize = n.iter().product();
    (0..total).map(move |mut idx| {
        let mut ijk = [0; D];
        for a in 0..D {
            ijk[a] = idx % n[a];
            idx /= n[a];
        }
        ijk
    })
}

/// A Cartesian grid of `n[0] × n[1] (× n[2])` squares or cubes on the box `[lo, hi]`.
///
/// Cells are numbered with x fastest; nodes likewise.
pub fn cartesian<const D: usize>(lo: Point<D>, hi: Point<D>, n: [usize; D]) -> Result<Grid<D>> {
    let nodes = lattice(lo, hi, n)?;
    let mut loops = CellFaceLoops::new();
    for cell in cells_iter(n) {
        let v = |bits: usize| corner(cell, bits, n);
        if D == 2 {
            loops.push_polygon(&[v(0b00), v(0b01), v(0b11), v(0b10)]);
        } else {
            // Outward loops of the six faces of a hexahedron (bit 0 = x, 1 = y, 2 = z).
            for f in [
                [0b000, 0b010, 0b011, 0b001], // zmin... x-y face at z = 0, normal −z
                [0b100, 0b101, 0b111, 0b110], // z = 1, normal +z
                [0b000, 0b001, 0b101, 0b100], // y = 0, normal −y
                [0b010, 0b110, 0b111, 0b011], // y = 1, normal +y
                [0b000, 0b100, 0b110, 0b010], // x = 0, normal −x
                [0b001, 0b011, 0b111, 0b101], // x = 1, normal +x
            ] {
                loops.push_face(&f.map(v));
            }
            loops.finish_cell();
        }
    }
    Grid::from_cell_faces(nodes, &loops)
}

/// Append the simplex with the given `D + 1` vertices, each face oriented outward.
pub(crate) fn push_simplex<const D: usize>(
    loops: &mut CellFaceLoops,
    nodes: &[Point<D>],
    v: &[usize],
) {
    debug_assert_eq!(v.len(), D + 1);
    // Orientation: sign of the volume of (v1 − v0, ..., vD − v0).
    let mut face0 = [Point::<D>::zeros(); 3];
    for (p, &i) in face0.iter_mut().zip(&v[1..]) {
        *p = nodes[i];
    }
    let a = facet_area_vector::<D>(&face0[..D]);
    let positive = a.dot(&(nodes[v[1]] - nodes[v[0]])) > 0.0;
    // Face opposite vertex k: the other vertices, in an order whose normal points away
    // from vertex k. For a positively oriented simplex, the loop v[1..] is outward for the
    // face opposite v0; opposite vk alternates sign with k.
    let mut face = [0usize; 3];
    for k in 0..=D {
        let mut m = 0;
        for (i, &vi) in v.iter().enumerate() {
            if i != k {
                face[m] = vi;
                m += 1;
            }
        }
        let flip = (k % 2 == 1) == positive;
        if flip {
            face[..D].swap(0, 1);
        }
        loops.push_face(&face[..D]);
    }
    loops.finish_cell();
}

/// A simplex grid: each square split into 2 triangles by the diagonal (i, j)–(i+1, j+1),
/// each cube into 6 tetrahedra around the diagonal (i, j, k)–(i+1, j+1, k+1).
pub fn simplices<const D: usize>(lo: Point<D>, hi: Point<D>, n: [usize; D]) -> Result<Grid<D>> {
    let nodes = lattice(lo, hi, n)?;
    let perms: &[&[usize]] = if D == 2 {
        &[&[0, 1], &[1, 0]]
    } else {
        &[
            &[0, 1, 2],
            &[0, 2, 1],
            &[1, 0, 2],
            &[1, 2, 0],
            &[2, 0, 1],
            &[2, 1, 0],
        ]
    };
    let mut loops = CellFaceLoops::new();
    let simplices_total = n.iter().product::<usize>() * perms.len();
    loops.cell_pos.reserve(simplices_total);
    loops.loop_pos.reserve(simplices_total * (D + 1));
    loops.loop_nodes.reserve(simplices_total * (D + 1) * D);
    let mut v = [0usize; 4];
    for cell in cells_iter(n) {
        for perm in perms {
            let mut bits = 0;
            v[0] = corner(cell, 0, n);
            for (s, &axis) in perm.iter().enumerate() {
                bits |= 1 << axis;
                v[s + 1] = corner(cell, bits, n);
            }
            push_simplex(&mut loops, &nodes, &v[..=D]);
        }
    }
    Grid::from_cell_faces(nodes, &loops)
}
