//! Fracture toughness at crack tips: a strength criterion that does not depend on the
//! cell size.
//!
//! A smeared crack is a band of failed cells. Ahead of its tip the stress is singular,
//! `σ₁ ≈ K_I / √(2π r)` (Irwin), so the stress a cell next to the tip carries grows as
//! the cells shrink: a pure strength criterion `σ₁ > σ_t` on that cell lets the crack grow
//! at `K_I ≈ σ_t √(2π r_h)`, an apparent toughness that falls as `√h`. A crack driven by
//! a fluid volume then reaches farther on finer grids (in the toughness-dominated regime
//! of a plane-strain fracture, reach ∝ K^(−2/3), so `∝ h^(−1/3)`).
//!
//! The remedy used here is the coupled stress–energy view of crack onset (Leguillon
//! 2002): a crack *starts* where the stress exceeds the tensile strength (a smooth field,
//! e.g. the hoop stress at a well wall, converges with `h`), and a crack *grows* only
//! where, in addition, the tip's stress intensity reaches the toughness `K_Ic`. A cell
//! that shares a node with a failed cell is a *tip cell*; its stress intensity is
//! estimated from its own stress at its equivalent radius `r_c` (the radius of the disk,
//! or ball, of its area or volume):
//!
//! ```text
//! K_c = σ₁ √(2π r_c),   tip cell fails in tension  ⇔  σ₁ > σ_t  and  K_c > K_Ic.
//! ```
//!
//! The estimate is not a converged `K_I` (its constant depends on the cell shape), but it
//! scales as the singular field does, so the growth threshold is the same physical `K_Ic`
//! on every grid that resolves the tip (`σ_t √(2π r_c) < K_Ic`, i.e. cells smaller than
//! the material length `K_Ic² / (2π σ_t²)`); on coarser cells the strength governs.
//! Shear (Mohr–Coulomb) failure is unchanged.

use porofrac_grid::Grid;
use porofrac_law::Tensor;

use crate::FracError;
use crate::recovery::NodeCells;

/// The fracture toughness `K_Ic` (Pa·√m) of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Toughness {
    k_ic: f64,
}

impl Toughness {
    /// Toughness `k_ic` (Pa·√m, > 0).
    pub fn new(k_ic: f64) -> Result<Self, FracError> {
        if !(k_ic.is_finite() && k_ic > 0.0) {
            return Err(FracError::Parameter {
                name: "fracture_toughness",
                value: k_ic,
                reason: "must be > 0",
            });
        }
        Ok(Self { k_ic })
    }

    /// `K_Ic` (Pa·√m).
    pub fn value(&self) -> f64 {
        self.k_ic
    }

    /// `K_c / K_Ic` of a tip cell with largest principal stress `sigma_1` and equivalent
    /// radius `r` (see the module docs).
    pub fn utilization(&self, sigma_1: f64, r: f64) -> f64 {
        sigma_1 * (2.0 * std::f64::consts::PI * r).sqrt() / self.k_ic
    }
}

/// Which cells are at a crack tip, and their equivalent radii; built once per grid.
#[derive(Clone, Debug)]
pub struct CrackTips {
    /// Cells sharing a node with each cell (CSR: `pos`, `cells`), the cell itself excluded.
    pos: Vec<usize>,
    cells: Vec<usize>,
    radius: Vec<f64>,
}

impl CrackTips {
    /// The node neighbours and equivalent radii of the cells of `grid`.
    pub fn new<const D: usize>(grid: &Grid<D>) -> Self {
        let adj = NodeCells::new(grid);
        let mut pos = vec![0];
        let mut cells = Vec::new();
        let mut around = Vec::new();
        for c in 0..grid.num_cells() {
            around.clear();
            around.extend(
                grid.cell_nodes(c)
                    .iter()
                    .flat_map(|&n| adj.of(n).iter().copied())
                    .filter(|&o| o != c),
            );
            around.sort_unstable();
            around.dedup();
            cells.extend_from_slice(&around);
            pos.push(cells.len());
        }
        let radius = grid
            .cell_volumes()
            .iter()
            .map(|&v| equivalent_radius::<D>(v))
            .collect();
        Self { pos, cells, radius }
    }

    /// Whether cell `c` shares a node with a failed cell (`failed`: one flag per cell).
    pub fn is_tip(&self, c: usize, failed: &[bool]) -> bool {
        self.cells[self.pos[c]..self.pos[c + 1]]
            .iter()
            .any(|&o| failed[o])
    }

    /// The equivalent radius of cell `c`: that of the disk (2D) or ball (3D) of its area
    /// or volume.
    pub fn radius(&self, c: usize) -> f64 {
        self.radius[c]
    }

    /// `Some(radius)` when `c` is a tip cell, else `None` (the argument of
    /// [`crate::Combined::check_at`]).
    pub fn tip_radius(&self, c: usize, failed: &[bool]) -> Option<f64> {
        self.is_tip(c, failed).then(|| self.radius[c])
    }
}

/// The radius of the disk (`D = 2`) or ball (`D = 3`) of measure `v`.
pub fn equivalent_radius<const D: usize>(v: f64) -> f64 {
    if D == 2 {
        (v / std::f64::consts::PI).sqrt()
    } else {
        (3.0 * v / (4.0 * std::f64::consts::PI)).cbrt()
    }
}

/// The largest principal stress of `s` (tension positive).
pub(crate) fn sigma_1<const D: usize>(s: &Tensor<D>) -> f64 {
    crate::principal_stresses(s)[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use porofrac_grid::generate::cartesian;

    #[test]
    fn equivalent_radius_of_a_disk_and_a_ball() {
        let r = 0.3f64;
        let pi = std::f64::consts::PI;
        assert!((equivalent_radius::<2>(pi * r * r) - r).abs() < 1e-15);
        assert!((equivalent_radius::<3>(4.0 / 3.0 * pi * r.powi(3)) - r).abs() < 1e-15);
    }

    #[test]
    fn tip_cells_share_a_node_with_a_failed_cell() {
        // 4 × 4 unit squares; fail the cell at (1, 1): its 8 node neighbours are tips.
        let g = cartesian([0.0, 0.0].into(), [4.0, 4.0].into(), [4, 4]).unwrap();
        let tips = CrackTips::new(&g);
        let mut failed = vec![false; 16];
        failed[5] = true;
        let expect = [0, 1, 2, 4, 6, 8, 9, 10];
        for c in 0..16 {
            assert_eq!(tips.is_tip(c, &failed), expect.contains(&c), "cell {c}");
        }
        // A failed cell is not its own neighbour.
        assert!(!tips.is_tip(5, &failed));
        assert!((tips.radius(0) - (1.0 / std::f64::consts::PI).sqrt()).abs() < 1e-15);
        assert_eq!(tips.tip_radius(15, &failed), None);
    }

    #[test]
    fn toughness_utilization_is_the_irwin_estimate() {
        let t = Toughness::new(1e5).unwrap();
        // σ₁ = K/√(2πr) gives utilization 1.
        let r = 0.04;
        let s = 1e5 / (2.0 * std::f64::consts::PI * r).sqrt();
        assert!((t.utilization(s, r) - 1.0).abs() < 1e-14);
        assert!(Toughness::new(0.0).is_err() && Toughness::new(f64::INFINITY).is_err());
    }
}
