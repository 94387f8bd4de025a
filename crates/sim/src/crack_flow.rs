//! Crack flow from the crack's own opening: the aperture of a failed cell measured from
//! the nodal displacements, and the cubic-law permeability it gives the cell.
//!
//! # The smeared opening of a cell
//!
//! A failed cell carries the crack smeared over its width. Its mean strain is the exact
//! volume average of the displacement gradient over the cell (the discrete divergence
//! theorem of the VEM and Biot operators, `Σ_i N_i ⊗ x_i = |K| I`):
//!
//! ```text
//!   ε_K = 1/|K| Σ_i sym(u_i ⊗ N_i),       N_i = ∫_∂K φ_i n dS  (Grid::cell_node_normals)
//! ```
//!
//! The crack opens across the direction `n` of the largest principal strain `ε₁`. A crack
//! of aperture `w` through a cell that spans the band of failed cells, whose extent
//! along `n` is `h_n = max_i n·x_i − min_i n·x_i`, stretches it by `w` over `h_n`: the
//! displacement jump across the cell is `ε_nn h_n`, so
//!
//! ```text
//!   w_K = max(ε₁, 0) · h_n .
//! ```
//!
//! On a rectangle crossed by the crack parallel to a side this is the jump of the
//! displacement between its two sides; on the two triangles of a split rectangle (a band
//! of failed triangles one rectangle wide) each triangle spans the band and gives the same
//! `w`. The elastic strain of the failed cell is part of `ε₁`; under the compression-only
//! law of a failed cell it carries no tension, so it only shortens the measured aperture
//! where the cell is compressed across the crack. A crack narrower than the cells it is
//! smeared over keeps this measure (it is a jump, not a width), but its shape between
//! two cells is not resolved: the opening is one value per cell, and near a tip, where
//! the aperture of a crack closes as `√r`, a cell holds the average of the profile over
//! its width (the Sneddon test of `crates/sim/tests/sneddon.rs` measures what that costs).
//!
//! # Cubic law
//!
//! Between two parallel plates at a distance `w` the flux per unit height is
//! `q = −w³/(12 μ) ∂p/∂s` (Poiseuille): the crack's transmissivity (m³, `k·w` per unit
//! height) is `T(w) = w³/12`. A band of cells of thickness `h_n` conducts `T` along the
//! crack when its permeability is `k = T / h_n`: [`cubic_law_permeability`]. A floor
//! `T_min` (the residual aperture `(12 T_min)^{1/3}` of a closed or just-failed crack)
//! keeps a cell that has not opened yet connected to the crack.

use porofrac_grid::{Grid, Point};
use porofrac_law::{Tensor, principal};

/// The opening of a cell ([`cell_opening`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening<const D: usize> {
    /// The aperture `w = max(ε₁, 0) · h_n` (m).
    pub aperture: f64,
    /// The unit normal `n` of the opening (the direction of the largest principal strain).
    pub normal: Point<D>,
    /// The extent `h_n` of the cell along `n` (m).
    pub thickness: f64,
}

/// The mean strain `ε = 1/|K| Σ_i sym(u_i ⊗ N_i)` of a cell of volume `volume` with node
/// normals `normals` (in the order of its nodes) and nodal displacements `u` (`D` values
/// per node, in the same order). Exact for a linear displacement field.
pub fn cell_strain<const D: usize>(volume: f64, normals: &[Point<D>], u: &[f64]) -> Tensor<D> {
    let mut g = Tensor::<D>::zeros();
    for (k, ni) in normals.iter().enumerate() {
        for a in 0..D {
            for b in 0..D {
                g[(a, b)] += u[D * k + a] * ni[b];
            }
        }
    }
    (g + g.transpose()) * (0.5 / volume)
}

/// The extent `max_i n·x_i − min_i n·x_i` of cell `c` along the unit vector `n`.
pub fn extent<const D: usize>(grid: &Grid<D>, c: usize, n: &Point<D>) -> f64 {
    let (lo, hi) = grid
        .cell_nodes(c)
        .iter()
        .map(|&i| grid.node(i).dot(n))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    hi - lo
}

/// The smeared opening of cell `c` (see the module docs) from its node normals `normals`
/// and nodal displacements `u` (`D` per node, in the order of [`Grid::cell_nodes`]).
pub fn cell_opening<const D: usize>(
    grid: &Grid<D>,
    c: usize,
    normals: &[Point<D>],
    u: &[f64],
) -> Opening<D> {
    let strain = cell_strain(grid.cell_volume(c), normals, u);
    let p = principal(&strain);
    let normal = Point::<D>::from_fn(|a, _| p.directions[0][a]);
    let thickness = extent(grid, c, &normal);
    Opening {
        aperture: p.values[0].max(0.0) * thickness,
        normal,
        thickness,
    }
}

/// The crack transmissivity `w³/12` (m³: `k·w` per unit height) of an aperture `w`.
pub fn cubic_law_transmissivity(aperture: f64) -> f64 {
    aperture * aperture * aperture / 12.0
}

/// The permeability (m²) of a cell of thickness `h_n` carrying a crack of aperture `w`:
/// `max(w³/12, T_min) / h_n`, so that a band of such cells conducts the crack's
/// transmissivity along it (at least `t_min`).
pub fn cubic_law_permeability<const D: usize>(opening: &Opening<D>, t_min: f64) -> f64 {
    cubic_law_transmissivity(opening.aperture).max(t_min) / opening.thickness
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock};
    use porofrac_grid::generate::{cartesian, simplices};

    fn normals<const D: usize>(grid: &Grid<D>, c: usize) -> Vec<Point<D>> {
        let mut n = vec![Point::<D>::zeros(); grid.cell_nodes(c).len()];
        grid.cell_node_normals(c, &mut n);
        n
    }

    fn nodal<const D: usize>(
        grid: &Grid<D>,
        c: usize,
        f: impl Fn(&Point<D>) -> Point<D>,
    ) -> Vec<f64> {
        grid.cell_nodes(c)
            .iter()
            .flat_map(|&i| {
                let v = f(grid.node(i));
                (0..D).map(move |a| v[a])
            })
            .collect()
    }

    #[test]
    fn strain_of_a_linear_field_is_exact_on_polygons_and_tetrahedra() {
        let g2 = simplices(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [3, 2]).unwrap();
        let q2 = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [3, 2]).unwrap();
        let a = nalgebra::Matrix2::new(1e-3, -4e-4, 2e-4, 3e-3);
        let exact = (a + a.transpose()) * 0.5;
        for g in [&g2, &q2] {
            for c in 0..g.num_cells() {
                let u = nodal(g, c, |x| a * x + Point::<2>::new(0.3, -0.1));
                let e = cell_strain(g.cell_volume(c), &normals(g, c), &u);
                assert!((e - exact).norm() < 1e-15, "cell {c}: {e} vs {exact}");
            }
        }
        let g3 = simplices(
            Point::<3>::new(0.0, 0.0, 0.0),
            Point::<3>::new(1.0, 2.0, 1.0),
            [2, 2, 2],
        )
        .unwrap();
        let a3 = nalgebra::Matrix3::from_fn(|i, j| 1e-3 * (1.0 + i as f64 - 0.7 * j as f64));
        let exact3 = (a3 + a3.transpose()) * 0.5;
        for c in 0..g3.num_cells() {
            let u = nodal(&g3, c, |x| a3 * x);
            let e = cell_strain(g3.cell_volume(c), &normals(&g3, c), &u);
            assert!((e - exact3).norm() < 1e-15, "cell {c}");
        }
    }

    #[test]
    fn a_band_opened_by_a_jump_has_that_aperture_on_rectangles_and_on_split_triangles() {
        // One row of cells of height h = 0.25 between y = 0 and y = h; the top nodes move
        // up by w: the jump across the band is the aperture, whatever the cell shape.
        let (h, w) = (0.25, 1e-4);
        let jump = move |x: &Point<2>| Point::<2>::new(0.0, w * x[1] / h);
        for grid in [
            cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, h), [8, 1]).unwrap(),
            simplices(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, h), [8, 1]).unwrap(),
        ] {
            for c in 0..grid.num_cells() {
                let o = cell_opening(&grid, c, &normals(&grid, c), &nodal(&grid, c, jump));
                assert!(
                    (o.aperture - w).abs() < 1e-12 * w + 1e-18,
                    "cell {c}: {o:?}"
                );
                assert!((o.thickness - h).abs() < 1e-14);
                assert!((o.normal[1].abs() - 1.0).abs() < 1e-12);
            }
        }
        // A band along a diagonal: rotate the rectangle's jump by 30°; the extent along the
        // rotated normal of a rotated rectangle is still its height.
        let th = 30f64.to_radians();
        let r = nalgebra::Matrix2::new(th.cos(), -th.sin(), th.sin(), th.cos());
        // Two rectangles 0.5 × h, counter-clockwise, rotated.
        let corners = [
            (0.0, 0.0),
            (0.5, 0.0),
            (1.0, 0.0),
            (0.0, h),
            (0.5, h),
            (1.0, h),
        ];
        let nodes: Vec<Point<2>> = corners
            .iter()
            .map(|&(x, y)| r * Point::<2>::new(x, y))
            .collect();
        let pos = [0, 4, 8];
        let cn = [0, 1, 4, 3, 1, 2, 5, 4];
        let rot = Grid::from_polygons(nodes, &pos, &cn).unwrap();
        let rt = r.transpose();
        for c in 0..rot.num_cells() {
            let u = nodal(&rot, c, |x| r * jump(&(rt * x)));
            let o = cell_opening(&rot, c, &normals(&rot, c), &u);
            assert!((o.aperture - w).abs() < 1e-12 * w, "{o:?}");
        }
    }

    #[test]
    fn a_compressed_cell_has_no_aperture() {
        let g = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(1.0, 1.0), [1, 1]).unwrap();
        let u = nodal(&g, 0, |x| -1e-3 * x);
        assert_eq!(cell_opening(&g, 0, &normals(&g, 0), &u).aperture, 0.0);
    }

    /// A slot of aperture `w` between two plates at distance `L`: a row of cells of
    /// thickness `h` with `k = w³/(12 h)`, pressures `p₁`, `p₂` at its ends, carries the
    /// flux `w³ Δp / (12 μ L)` per unit height (Poiseuille), to rounding.
    #[test]
    fn a_slot_of_cells_with_the_cubic_law_permeability_carries_the_poiseuille_flux() {
        let (len, h, w, mu, dp) = (3.0, 0.2, 2e-4, 1e-3, 1e5);
        let grid = cartesian(Point::<2>::new(0.0, 0.0), Point::<2>::new(len, h), [12, 1]).unwrap();
        let opening = Opening {
            aperture: w,
            normal: Point::<2>::new(0.0, 1.0),
            thickness: h,
        };
        let k = cubic_law_permeability(&opening, 0.0);
        let nc = grid.num_cells();
        let rock = Rock::new(vec![0.1; nc], Permeability::uniform(nc, k).unwrap());
        let fluid = Fluid {
            viscosity: mu,
            compressibility: 0.0,
        };
        let problem = FlowProblem::new(rock, fluid)
            .pressure_bc(grid.boundary("xmin").unwrap(), 2.0 * dp)
            .pressure_bc(grid.boundary("xmax").unwrap(), dp);
        let mut model = FlowModel::new(&grid, &problem).unwrap();
        let res = model.solve_steady(0.0).unwrap();
        let out: f64 = grid
            .boundary("xmax")
            .unwrap()
            .iter()
            .map(|&f| res.face_flux[f])
            .sum();
        let exact = w * w * w * dp / (12.0 * mu * len);
        assert!((out - exact).abs() < 1e-12 * exact, "{out} vs {exact}");
        // The floor: a closed slot conducts T_min.
        let closed = Opening {
            aperture: 0.0,
            ..opening
        };
        assert_eq!(cubic_law_permeability(&closed, 1e-13), 1e-13 / h);
    }
}
