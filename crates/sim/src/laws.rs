//! Which cell law each cell uses.

use porofrac_grid::Grid;
use porofrac_law::CellLaw;

use crate::error::{Result, SimError};

/// The cell laws of a problem and the law of each cell.
///
/// Laws are borrowed trait objects, so laws from other crates plug in unchanged. The
/// per-cell index is plain data: a fracturing cell switches law by changing its index
/// ([`Self::set_law`]), which changes stiffness values but not the sparsity pattern.
#[derive(Clone)]
pub struct LawMap<'a, const D: usize> {
    laws: Vec<&'a dyn CellLaw<D>>,
    law_of_cell: Vec<usize>,
}

impl<'a, const D: usize> LawMap<'a, D> {
    /// One law for every cell.
    pub fn uniform(grid: &Grid<D>, law: &'a dyn CellLaw<D>) -> Result<Self> {
        Self::new(grid, vec![law], vec![0; grid.num_cells()])
    }

    /// Laws and the index of each cell's law. Errors: a length mismatch, an index out of
    /// range, or a law that does not support a cell's number of nodes (naming the cell).
    pub fn new(
        grid: &Grid<D>,
        laws: Vec<&'a dyn CellLaw<D>>,
        law_of_cell: Vec<usize>,
    ) -> Result<Self> {
        if law_of_cell.len() != grid.num_cells() {
            return Err(SimError::Input(format!(
                "{} law indices for {} cells",
                law_of_cell.len(),
                grid.num_cells()
            )));
        }
        let map = Self { laws, law_of_cell };
        for c in 0..grid.num_cells() {
            map.check_cell(grid, c)?;
        }
        Ok(map)
    }

    fn check_cell(&self, grid: &Grid<D>, c: usize) -> Result<()> {
        let k = self.law_of_cell[c];
        let Some(law) = self.laws.get(k) else {
            return Err(SimError::Input(format!(
                "cell {c}: law index {k}, but there are {} laws",
                self.laws.len()
            )));
        };
        let n = grid.cell_nodes(c).len();
        if !law.supports(n) {
            return Err(SimError::Cell {
                cell: c,
                law: law.name().to_string(),
                what: format!("the law does not support a cell with {n} nodes"),
            });
        }
        Ok(())
    }

    /// Switch cell `c` to law `law` (an index into the laws), with the same checks as
    /// [`Self::new`].
    pub fn set_law(&mut self, grid: &Grid<D>, c: usize, law: usize) -> Result<()> {
        if c >= self.law_of_cell.len() {
            return Err(SimError::Input(format!("cell {c} out of range")));
        }
        let old = std::mem::replace(&mut self.law_of_cell[c], law);
        self.check_cell(grid, c)
            .inspect_err(|_| self.law_of_cell[c] = old)
    }

    /// The law of cell `c`.
    #[inline]
    pub fn law(&self, c: usize) -> &'a dyn CellLaw<D> {
        self.laws[self.law_of_cell[c]]
    }
    /// The index (into the laws of the map) of the law of cell `c`.
    #[inline]
    pub fn law_index(&self, c: usize) -> usize {
        self.law_of_cell[c]
    }
    /// The number of laws of the map.
    pub fn num_laws(&self) -> usize {
        self.laws.len()
    }
    /// The index of the law of every cell.
    pub fn law_of_cell(&self) -> &[usize] {
        &self.law_of_cell
    }
    /// Whether every law is linear.
    pub fn all_linear(&self) -> bool {
        self.laws.iter().all(|l| l.is_linear())
    }
    /// Whether every law is piecewise linear ([`CellLaw::is_piecewise_linear`]).
    pub fn all_piecewise_linear(&self) -> bool {
        self.laws.iter().all(|l| l.is_piecewise_linear())
    }
}
