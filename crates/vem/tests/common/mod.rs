//! Single-cell grids for the VEM tests and benchmarks.
#![allow(dead_code)]

use porofrac_grid::{CellFaceLoops, Grid, Point};

/// A 2D grid of one polygon (nodes counter-clockwise).
pub fn polygon(pts: Vec<Point<2>>) -> Grid<2> {
    let n = pts.len();
    let idx: Vec<usize> = (0..n).collect();
    Grid::from_polygons(pts, &[0, n], &idx).expect("valid polygon")
}

/// The unit square.
pub fn unit_square() -> Vec<Point<2>> {
    vec![
        Point::<2>::new(0.0, 0.0),
        Point::<2>::new(1.0, 0.0),
        Point::<2>::new(1.0, 1.0),
        Point::<2>::new(0.0, 1.0),
    ]
}

/// A regular polygon with `n` vertices on a circle of radius `r` about `c`.
pub fn regular(n: usize, r: f64, c: Point<2>) -> Vec<Point<2>> {
    (0..n)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            c + Point::<2>::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

/// Points at the given increasing angles on an ellipse, then a shear: a convex polygon.
pub fn convex(angles: &[f64], a: f64, b: f64, shear: f64, c: Point<2>) -> Vec<Point<2>> {
    angles
        .iter()
        .map(|t| {
            let p = Point::<2>::new(a * t.cos(), b * t.sin());
            c + Point::<2>::new(p[0] + shear * p[1], p[1])
        })
        .collect()
}

/// A star with `tips` tips, alternating radii `r_out` and `r_in` (non-convex).
pub fn star(tips: usize, r_out: f64, r_in: f64) -> Vec<Point<2>> {
    (0..2 * tips)
        .map(|k| {
            let t = std::f64::consts::PI * k as f64 / tips as f64;
            let r = if k % 2 == 0 { r_out } else { r_in };
            Point::<2>::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

/// Insert `extra[k]` equally spaced hanging nodes on edge `k` (from vertex k to k+1).
pub fn with_hanging(pts: &[Point<2>], extra: &[usize]) -> Vec<Point<2>> {
    let n = pts.len();
    let mut out = Vec::new();
    for k in 0..n {
        let (a, b) = (pts[k], pts[(k + 1) % n]);
        out.push(a);
        let m = extra.get(k).copied().unwrap_or(0);
        for s in 1..=m {
            let t = s as f64 / (m + 1) as f64;
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// A 3D grid of one cell given by outward face loops.
pub fn polyhedron(nodes: Vec<Point<3>>, faces: &[&[usize]]) -> Grid<3> {
    let mut loops = CellFaceLoops::new();
    for f in faces {
        loops.push_face(f);
    }
    loops.finish_cell();
    Grid::from_cell_faces(nodes, &loops).expect("valid polyhedron")
}

/// A tetrahedron (any orientation of the 4 points; degenerate ones fail).
pub fn tetrahedron(p: [Point<3>; 4]) -> Result<Grid<3>, porofrac_grid::GridError> {
    let vol = (p[1] - p[0]).cross(&(p[2] - p[0])).dot(&(p[3] - p[0]));
    let p = if vol < 0.0 {
        [p[0], p[2], p[1], p[3]]
    } else {
        p
    };
    let mut loops = CellFaceLoops::new();
    for f in [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] {
        loops.push_face(&f);
    }
    loops.finish_cell();
    Grid::from_cell_faces(p.to_vec(), &loops)
}

/// The corners of the unit cube, bottom counter-clockwise then top.
pub fn cube_corners() -> Vec<Point<3>> {
    let mut v = Vec::new();
    for z in [0.0, 1.0] {
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            v.push(Point::<3>::new(x, y, z));
        }
    }
    v
}

/// Face loops of a hexahedron with corners ordered as [`cube_corners`].
pub const HEX_FACES: [&[usize]; 6] = [
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
    &[0, 1, 5, 4],
    &[1, 2, 6, 5],
    &[2, 3, 7, 6],
    &[3, 0, 4, 7],
];

/// A hexahedron (faces may be non-planar).
pub fn hexahedron(corners: Vec<Point<3>>) -> Grid<3> {
    polyhedron(corners, &HEX_FACES)
}

/// A triangular prism: bottom triangle `p[0..3]` counter-clockwise seen from above, top
/// `p[3..6]`.
pub fn prism(p: Vec<Point<3>>) -> Grid<3> {
    polyhedron(
        p,
        &[
            &[0, 2, 1],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
    )
}

fn mid(p: &[Point<3>], a: usize, b: usize) -> Point<3> {
    (p[a] + p[b]) * 0.5
}

/// The unit cube whose top face is split into four quadrilaterals (as next to a refined
/// neighbour): 13 nodes, 9 faces, hanging nodes on the top edges (in the side faces) and
/// in the middle of the top face.
pub fn cube_split_top() -> Grid<3> {
    let mut p = cube_corners();
    let m = [mid(&p, 4, 5), mid(&p, 5, 6), mid(&p, 6, 7), mid(&p, 7, 4)];
    p.extend(m);
    p.push(Point::<3>::new(0.5, 0.5, 1.0));
    polyhedron(
        p,
        &[
            &[0, 3, 2, 1],
            &[4, 8, 12, 11],
            &[8, 5, 9, 12],
            &[12, 9, 6, 10],
            &[11, 12, 10, 7],
            &[0, 1, 5, 8, 4],
            &[1, 2, 6, 9, 5],
            &[2, 3, 7, 10, 6],
            &[3, 0, 4, 11, 7],
        ],
    )
}

/// A 12-face polyhedron: the unit cube with top and bottom faces each split into four,
/// 18 nodes, every node moved by `perturb(k)` (so faces become non-planar if non-zero).
pub fn twelve_faces(perturb: impl Fn(usize) -> Point<3>) -> Grid<3> {
    let mut p = cube_corners();
    let top = [mid(&p, 4, 5), mid(&p, 5, 6), mid(&p, 6, 7), mid(&p, 7, 4)];
    p.extend(top);
    p.push(Point::<3>::new(0.5, 0.5, 1.0)); // 12
    let bottom = [mid(&p, 0, 1), mid(&p, 1, 2), mid(&p, 2, 3), mid(&p, 3, 0)];
    p.extend(bottom); // 13..16
    p.push(Point::<3>::new(0.5, 0.5, 0.0)); // 17
    for (k, x) in p.iter_mut().enumerate() {
        *x += perturb(k);
    }
    polyhedron(
        p,
        &[
            &[0, 16, 17, 13],
            &[13, 17, 14, 1],
            &[17, 15, 2, 14],
            &[16, 3, 15, 17],
            &[4, 8, 12, 11],
            &[8, 5, 9, 12],
            &[12, 9, 6, 10],
            &[11, 12, 10, 7],
            &[0, 13, 1, 5, 8, 4],
            &[1, 14, 2, 6, 9, 5],
            &[2, 15, 3, 7, 10, 6],
            &[3, 16, 0, 4, 11, 7],
        ],
    )
}

/// A deterministic pseudo-random perturbation of size `s` for node `k`.
pub fn jitter(k: usize, s: f64) -> Point<3> {
    let h = |m: u64| {
        let mut z = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ m;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    Point::<3>::new(h(1), h(2), h(3)) * s
}

use nalgebra::DMatrix;
use porofrac_law::{CellGeometry, CellLaw, Scratch, Stiffness, Tensor};
use porofrac_vem::VemLaw;

/// Spectrum summary of a symmetric local matrix.
#[derive(Debug)]
pub struct Spectrum {
    /// max |A − Aᵀ| / max |A|.
    pub asymmetry: f64,
    /// Eigenvalues below `1e-10 λ_max` in absolute value.
    pub zeros: usize,
    /// Largest |λ| / λ_max among those counted as zero.
    pub worst_zero: f64,
    /// Smallest λ / λ_max among the others.
    pub smallest_nonzero: f64,
    /// Smallest λ / λ_max overall (negative means indefinite).
    pub min: f64,
}

/// Eigen-analysis with the thresholds of the tests: null if `|λ| < 1e-10 λ_max`.
pub fn spectrum(a: &DMatrix<f64>) -> Spectrum {
    let asym = (a - a.transpose()).amax() / a.amax();
    let ev = a.clone().symmetric_eigenvalues();
    let lmax = ev.max();
    let mut s = Spectrum {
        asymmetry: asym,
        zeros: 0,
        worst_zero: 0.0,
        smallest_nonzero: f64::INFINITY,
        min: ev.min() / lmax,
    };
    for &l in ev.iter() {
        let r = l / lmax;
        if r.abs() < 1e-10 {
            s.zeros += 1;
            s.worst_zero = s.worst_zero.max(r.abs());
        } else {
            s.smallest_nonzero = s.smallest_nonzero.min(r);
        }
    }
    s
}

/// Assert the local matrix is symmetric PSD with exactly `D(D+1)/2` null modes:
/// asymmetry < 1e-13, null eigenvalues < 1e-10 λ_max, others > 1e-8 λ_max.
pub fn assert_spectrum<const D: usize>(a: &DMatrix<f64>, what: &str) -> Spectrum {
    let s = spectrum(a);
    let rigid = D * (D + 1) / 2;
    assert!(s.asymmetry < 1e-13, "{what}: {s:?}");
    assert_eq!(s.zeros, rigid, "{what}: {s:?}");
    assert!(s.smallest_nonzero > 1e-8, "{what}: {s:?}");
    s
}

/// Local patch test for `u = A x + b`: returns the relative force error
/// `max_i |(A_K u)_i − σ N_i| / max_i |σ N_i|` and the relative stress error
/// `max |σ_h − C:sym(A)| / max |C:sym(A)|`.
pub fn patch_errors<const D: usize>(
    law: &VemLaw<D>,
    cell: &CellGeometry<'_, D>,
    grad: &Tensor<D>,
    shift: &nalgebra::SVector<f64, D>,
) -> (f64, f64) {
    let n = cell.coords.len();
    let mut u = vec![0.0; D * n];
    porofrac_law::testkit::linear_field(cell, grad, shift, &mut u);
    let mut a = DMatrix::zeros(0, 0);
    let mut scratch = Scratch::default();
    law.local_stiffness(cell, &mut a, &mut scratch);
    let au = &a * nalgebra::DVector::from_column_slice(&u);
    let sigma = law.material().stress(&((grad + grad.transpose()) * 0.5));
    let mut err: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for i in 0..n {
        let load = sigma * cell.node_normals[i];
        for c in 0..D {
            err = err.max((au[D * i + c] - load[c]).abs());
            scale = scale.max(load[c].abs());
        }
    }
    let s = law.stress(cell, &u, &mut scratch).unwrap();
    ((err / scale), (s - sigma).amax() / sigma.amax())
}

/// P1 FEM stiffness of a simplex from the Jacobian (independent of the node normals):
/// `K = |K| Bᵀ D B` with the gradients of the barycentric coordinates.
pub fn p1_stiffness<const D: usize>(
    coords: &[nalgebra::SVector<f64, D>],
    m: &Stiffness<D>,
) -> DMatrix<f64> {
    let mut j = Tensor::<D>::zeros();
    for k in 0..D {
        j.set_column(k, &(coords[k + 1] - coords[0]));
    }
    let jd = DMatrix::from_fn(D, D, |r, c| j[(r, c)]);
    let vol = jd.determinant().abs() / if D == 2 { 2.0 } else { 6.0 };
    let jinv = jd.try_inverse().expect("non-degenerate simplex");
    // ∇φ_k = row k−1 of J⁻¹ for k ≥ 1; ∇φ_0 = −Σ.
    let mut grads = vec![nalgebra::SVector::<f64, D>::zeros(); D + 1];
    for k in 1..=D {
        grads[k] = nalgebra::SVector::<f64, D>::from_fn(|c, _| jinv[(k - 1, c)]);
        let gk = grads[k];
        grads[0] -= gk;
    }
    let nd = D * (D + 1);
    let mut out = DMatrix::zeros(nd, nd);
    for i in 0..=D {
        for a in 0..D {
            let mut ea = nalgebra::SVector::<f64, D>::zeros();
            ea[a] = 1.0;
            let bi = porofrac_law::kelvin::kelvin_sym_outer::<D>(&ea, &grads[i]);
            let dbi = m.stress_kelvin(&bi);
            for k in 0..=D {
                for b in 0..D {
                    let mut eb = nalgebra::SVector::<f64, D>::zeros();
                    eb[b] = 1.0;
                    let bk = porofrac_law::kelvin::kelvin_sym_outer::<D>(&eb, &grads[k]);
                    out[(D * i + a, D * k + b)] = vol * dbi.dot(&bk);
                }
            }
        }
    }
    out
}
