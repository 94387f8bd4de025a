//! Population storage in `f64` or `f32` ([`Precision`]): the array the kernel streams and
//! collides in place, and element access for the boundary rules, which compute in `f64`.

use crate::d2q9::{Q, W};
use crate::kernel::{BandHook, Grid, Layout, Physics, Storage, aa_step, aa_step_hooked};
use crate::runs::FluidRuns;

/// The floating-point type the populations are stored in.
///
/// Collision, boundary rules, forces and every moment are computed in `f64` whatever the
/// storage; [`Precision::Single`] halves the memory and the bytes each step moves (72
/// instead of 144 per node), at the cost of rounding every population to `f32` once per
/// step. It stores `f_i − w_i` (see [`Storage`]) so that this rounding is relative to the
/// disturbance of the fluid, not to its density.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// `f64` populations (default).
    #[default]
    Double,
    /// `f32` populations (zero-centred).
    Single,
}

/// The populations of a lattice, direction-major (`slot · np + node`).
#[derive(Clone, Debug)]
pub(crate) enum Populations {
    /// `f64` values of `f_i`.
    Double(Vec<f64>),
    /// `f32` values of `f_i − w_i`, and the padded nodes per direction.
    Single(Vec<f32>, usize),
}

impl Populations {
    /// `n` values per direction, all `f_i = 0`, stored as `precision`.
    pub(crate) fn new(precision: Precision, np: usize) -> Self {
        match precision {
            Precision::Double => Populations::Double(vec![0.0; Q * np]),
            Precision::Single => {
                let mut v = vec![0.0f32; Q * np];
                for (q, s) in v.chunks_mut(np).enumerate() {
                    s.fill(f32::store(0.0, W[q]));
                }
                Populations::Single(v, np)
            }
        }
    }

    /// The storage type.
    pub(crate) fn precision(&self) -> Precision {
        match self {
            Populations::Double(_) => Precision::Double,
            Populations::Single(..) => Precision::Single,
        }
    }

    /// The same values stored as `precision` (rounded to `f32` for single).
    pub(crate) fn converted(&self, precision: Precision, np: usize) -> Self {
        if precision == self.precision() {
            return self.clone();
        }
        let mut out = Populations::new(precision, np);
        for i in 0..self.len() {
            out.set(i, self.get(i));
        }
        out
    }

    /// Number of stored values.
    pub(crate) fn len(&self) -> usize {
        match self {
            Populations::Double(v) => v.len(),
            Populations::Single(v, _) => v.len(),
        }
    }

    /// Bytes of storage.
    pub(crate) fn bytes(&self) -> usize {
        match self {
            Populations::Double(v) => v.len() * std::mem::size_of::<f64>(),
            Populations::Single(v, _) => v.len() * std::mem::size_of::<f32>(),
        }
    }

    /// `f` at array index `i`.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> f64 {
        match self {
            Populations::Double(v) => v[i],
            Populations::Single(v, np) => v[i].load(W[i / np]),
        }
    }

    /// Set `f` at array index `i`.
    #[inline]
    pub(crate) fn set(&mut self, i: usize, f: f64) {
        match self {
            Populations::Double(v) => v[i] = f,
            Populations::Single(v, np) => v[i] = f32::store(f, W[i / *np]),
        }
    }

    /// `f` in slot `q` of padded node `node`, `np` padded nodes per slot.
    #[inline]
    pub(crate) fn get_slot(&self, np: usize, q: usize, node: usize) -> f64 {
        match self {
            Populations::Double(v) => v[q * np + node],
            Populations::Single(v, _) => v[q * np + node].load(W[q]),
        }
    }

    /// Set slot `q` of padded node `node` to `f`.
    #[inline]
    pub(crate) fn set_slot(&mut self, np: usize, q: usize, node: usize, f: f64) {
        match self {
            Populations::Double(v) => v[q * np + node] = f,
            Populations::Single(v, _) => v[q * np + node] = f32::store(f, W[q]),
        }
    }

    /// Every value as `f64` `f_i`.
    pub(crate) fn to_f64(&self) -> Vec<f64> {
        match self {
            Populations::Double(v) => v.clone(),
            Populations::Single(..) => (0..self.len()).map(|i| self.get(i)).collect(),
        }
    }

    /// One fused AA step ([`aa_step`]) on the stored values.
    pub(crate) fn aa_step(
        &mut self,
        g: Grid,
        layout: Layout,
        mask: Option<&[u8]>,
        phys: Physics,
    ) -> Layout {
        match self {
            Populations::Double(v) => aa_step(v, g, layout, mask, phys),
            Populations::Single(v, _) => aa_step(v, g, layout, mask, phys),
        }
    }

    /// One fused AA step over the bands `ranges` with a hook per band ([`aa_step_hooked`]):
    /// over the segments of `runs` as [`crate::kernel::aa_step_runs`], or every node with
    /// the mask.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn aa_step_hooked<H: BandHook<f64> + BandHook<f32>>(
        &mut self,
        g: Grid,
        layout: Layout,
        mask: &[u8],
        runs: Option<&FluidRuns>,
        phys: Physics,
        ranges: &[(usize, usize)],
        hooks: Vec<H>,
    ) -> Layout {
        match self {
            Populations::Double(v) => aa_step_hooked(v, g, layout, mask, runs, phys, ranges, hooks),
            Populations::Single(v, _) => {
                aa_step_hooked(v, g, layout, mask, runs, phys, ranges, hooks)
            }
        }
    }
}
