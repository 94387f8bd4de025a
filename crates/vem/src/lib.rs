//! The first-order virtual element method (VEM) for linear elasticity as a cell law, on
//! any polygon (2D) or polyhedron (3D): convex or not, with hanging nodes (extra
//! collinear or coplanar vertices) and, in 3D, non-planar faces.
//!
//! # The method (Nilsen et al. 2017, §2.3, eqs. 22–26; Gain, Talischi & Paulino 2014)
//!
//! The paper: H. M. Nilsen, I. Larsen, X. Raynaud (2017), arXiv:1702.01552.
//!
//! The degrees of freedom are the nodal displacements `u_i`. The only geometry needed is
//! the cell volume `|K|`, the node coordinates `x_i`, their *vertex average*
//! `x̄ = (1/n) Σ_i x_i`, `d_i = x_i − x̄`, and the node normals
//! `N_i = ∫_∂K φ_i n dS` ([`CellGeometry::node_normals`]), which satisfy
//! `Σ_i N_i = 0` and `Σ_i x_i ⊗ N_i = |K| I` exactly (discrete divergence theorem, on the
//! same face triangulation the grid uses for volumes).
//!
//! **Projection.** By the divergence theorem the cell average of the displacement
//! gradient is computable from the degrees of freedom,
//! `G(u) = (1/|K|) ∫_K ∇u = (1/|K|) Σ_j u_j ⊗ N_j`. The projection onto linear fields
//! `P = P_R + P_C` (§2.3) is
//!
//! ```text
//!   (P u)(x) = ū + G(u) (x − x̄),     ū = (1/n) Σ_j u_j,
//! ```
//!
//! where the skew part of `G` with the mean `ū` is the rigid-body part `P_R u`
//! (translations and rotations about `x̄`) and the symmetric part
//! `ε(u) = sym G(u)` gives `P_C u = ε (x − x̄)`. In the matrix notation of Gain et al.,
//! `P_R = N_r W_rᵀ`, `P_C = N_c W_cᵀ`: the columns of `N_r`, `N_c` are the rigid and the
//! constant-strain modes at the nodes, `W_r` holds the averaging weights `1/n` and the
//! rotation weights `q_i = N_i/(2|K|)` (2D), and `W_c` maps nodal displacements to the
//! Kelvin strain, `ε_K = W_cᵀ u`, `(W_c)_{(i,a),k} = (B_k N_i)_a / |K|` with `B_k` the
//! Kelvin basis of [`porofrac_law::kelvin`]. `W_rᵀ N_r = I`, `W_cᵀ N_c = I` and the cross
//! products vanish *because* `x̄` is the vertex average and `Σ N_i = 0`, so `P² = P`,
//! `P` reproduces linear fields, and on a simplex (`n = D + 1`, rank of `P` = `n`) `P = I`.
//! Nodal form: `(P u)_i = Σ_j p_ij u_j` with the scalar weights
//! `p_ij = 1/n + d_i · N_j / |K|`, i.e. `P = p ⊗ I_D` ([`projection_matrix`]).
//!
//! **Local stiffness** (eq. 26):
//!
//! ```text
//!   A_K = |K| W_c D W_cᵀ + (I − P)ᵀ S (I − P)
//! ```
//!
//! * Consistency, computed directly from the elasticity tensor `C` (no dense products):
//!   `(A_c)_{(j,a),(k,b)} = (1/|K|) Σ_{c,d} N_jc C_acbd N_kd`. For a linear field
//!   `u = A x + b` it gives the energy `|K| · ½ ε : C : ε` with `ε = sym A` and the nodal
//!   forces `−σ N_i` (the patch test), and the stabilization does not see it because
//!   `(I − P) u = 0`.
//! * Stabilization `S = α I` ([`Stabilization::Mrst`], [`Stabilization::Trace`]):
//!   `(I − P)ᵀ(I − P) = s ⊗ I_D` with the closed form (using `Σ d_i = 0`,
//!   `Σ_i d_i ⊗ N_i = |K| I`, `M = Σ_i d_i d_iᵀ`)
//!
//!   ```text
//!     s_jk = δ_jk − 1/n − (d_j · N_k + d_k · N_j)/|K| + N_jᵀ M N_k / |K|²,
//!   ```
//!
//!   so the whole local matrix costs `O(n² D³)` flops without any `nD × nD` products.
//!   A per-dof diagonal `S` ([`Stabilization::DRecipe`]) uses `q = I − p` explicitly.
//!
//! Energy, forces and stress are evaluated matrix-free in `O(n D²)`:
//! `E = ½ |K| ε_K · D ε_K + ½ Σ_i r_i · S_i r_i` with the non-linear remainder
//! `r_i = u_i − ū − G d_i = ((I − P) u)_i`, forces
//! `F_j = −σ N_j − (t_j − t̄ − (1/|K|) (Σ_i t_i ⊗ d_i) N_j)` with `t_i = S_i r_i`, and the
//! stress `σ = C : ε(u)` is the constant stress of the projection (for an isotropic
//! material `λ tr(ε) I + 2μ ε` directly, without the Kelvin product).
//!
//! # Stabilization
//!
//! The default ([`Stabilization::Mrst`]) is the one Nilsen et al. (2017) used (MRST's
//! `vemmech`), so results compare node by node: `S = α_K I` with
//!
//! ```text
//!   2D:  α_K = |K| (D₁₁ + D₂₂ + 2 D₃₃) / (2 Σ_i |x_i − x̄|²)
//!   3D:  α_K = |K| (D₁₁ + D₂₂ + D₃₃ + 2 (D₄₄ + D₅₅ + D₆₆)) / (3 Σ_i |x_i − x̄|²)
//! ```
//!
//! with `D` in Kelvin form. Unit square, `E = 1`, `ν = 0.3`, plane strain:
//! `α = 55/52 ≈ 1.0577`; unit cube, same material: `α = 25/52 ≈ 0.48077`. A scale factor
//! multiplies `S` for every choice ([`VemLaw::with_stabilization`]).
//!
//! # Biot coupling
//!
//! [`volumetric_strain`] is the trace of the projected strain,
//! `tr ε(u) = (1/|K|) Σ_i N_i · u_i`, the exact relative volume change of the cell under
//! the nodal displacements (the `div_d` of Nilsen et al. (2017) eqs. 29–30 per unit volume);
//! [`volumetric_strain_weights`] gives its coefficient vector.

use nalgebra::DMatrix;
use porofrac_grid::Point;
use porofrac_law::kelvin::{Kelvin, from_kelvin, kelvin_len, kelvin_pair, to_kelvin};
use porofrac_law::{CellGeometry, CellLaw, LawError, Scratch, Stiffness, Tensor, zero_matrix};

/// Errors of the VEM crate.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VemError {
    /// The stabilization scale factor must be finite and positive.
    #[error("invalid stabilization scale {value}: must be finite and positive")]
    InvalidScale {
        /// The rejected value.
        value: f64,
    },
}

/// Choice of the stabilization matrix `S` in `A_K = A_c + (I − P)ᵀ S (I − P)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Stabilization {
    /// MRST `vemmech` (the choice of Nilsen et al. (2017)): `S = α_K I`,
    /// `α_K = |K| (Σ_normal D_kk + 2 Σ_shear D_kk) / (D · Σ_i |x_i − x̄|²)`.
    #[default]
    Mrst,
    /// The trace recipe of Gain, Talischi & Paulino (2014): `S = α_K I` with
    /// `α_K = |K| tr(D) / tr(N_cᵀ N_c)`, `tr(N_cᵀ N_c) = (D+1)/2 · Σ_i |x_i − x̄|²` in
    /// Kelvin form.
    Trace,
    /// The "D-recipe" (Beirão da Veiga, Dassi & Russo 2017): a diagonal `S` whose entry
    /// for dof `(i, a)` is the consistency diagonal `(A_c)_{(i,a),(i,a)}`, floored at
    /// [`DRECIPE_FLOOR`] times the mean of that diagonal so degenerate nodes stay
    /// coercive.
    DRecipe,
}

/// Floor of the [`Stabilization::DRecipe`] diagonal, relative to its mean.
pub const DRECIPE_FLOOR: f64 = 1e-2;

/// The first-order VEM cell law for a linear elastic material.
#[derive(Clone, Debug)]
pub struct VemLaw<const D: usize> {
    material: Stiffness<D>,
    /// `C_abcd` at `((a·3 + b)·3 + c)·3 + d`.
    c: [f64; 81],
    stabilization: Stabilization,
    scale: f64,
    /// `Σ_normal D_kk + 2 Σ_shear D_kk` (MRST numerator).
    mrst_num: f64,
    /// `tr D`.
    trace: f64,
    /// Lamé parameters of an isotropic material (fast path of the consistency part).
    lame: Option<(f64, f64)>,
}

/// Index of `C_abcd` in the flat tensor.
#[inline(always)]
fn ci(a: usize, b: usize, c: usize, d: usize) -> usize {
    ((a * 3 + b) * 3 + c) * 3 + d
}

/// Per-cell geometric quantities.
struct Frame<const D: usize> {
    n: usize,
    xbar: Point<D>,
    /// Mean of the computed `x_i − x̄` (rounding of `x̄`), taken out of every `d_i`.
    dbar: Point<D>,
    /// `M = Σ_i d_i d_iᵀ`.
    m: Tensor<D>,
    inv_vol: f64,
}

impl<const D: usize> Frame<D> {
    #[inline]
    fn new(cell: &CellGeometry<'_, D>) -> Self {
        let n = cell.coords.len();
        let xbar = cell.coords.iter().sum::<Point<D>>() / n as f64;
        // `x̄` is rounded to the spacing of doubles at `|x̄|`, so `Σ_i (x_i − x̄)` is of
        // order `ε |x̄|`, not zero; the closed forms rely on `Σ_i d_i = 0` (a translation
        // must leave no remainder), so the mean of the differences — small numbers,
        // exactly representable to `ε · diam` — is taken out of every `d_i`.
        let dbar = cell.coords.iter().map(|x| x - xbar).sum::<Point<D>>() / n as f64;
        let mut f = Self {
            n,
            xbar,
            dbar,
            m: Tensor::<D>::zeros(),
            inv_vol: 1.0 / cell.volume,
        };
        for x in cell.coords {
            let d = f.d(x);
            f.m += d * d.transpose();
        }
        f
    }

    /// `d = x − x̄` for a node `x` of the cell (with `Σ_i d_i = 0` to `ε · diam`).
    #[inline]
    fn d(&self, x: &Point<D>) -> Point<D> {
        (x - self.xbar) - self.dbar
    }
}

/// How `S` acts: a uniform `α`, or a per-dof diagonal.
#[derive(Clone, Copy)]
enum StabWeights {
    Uniform(f64),
    Diagonal { floor: f64, scale: f64 },
}

impl<const D: usize> VemLaw<D> {
    /// The VEM law for `material` with the default stabilization
    /// ([`Stabilization::Mrst`], scale 1).
    pub fn new(material: Stiffness<D>) -> Self {
        let k = kelvin_len(D);
        let km = material.kelvin();
        let mut mrst_num = 0.0;
        let mut trace = 0.0;
        for i in 0..k {
            trace += km[(i, i)];
            mrst_num += if i < D { km[(i, i)] } else { 2.0 * km[(i, i)] };
        }
        let c = material.tensor4();
        let lame = material.lame();
        Self {
            material,
            c,
            stabilization: Stabilization::Mrst,
            scale: 1.0,
            mrst_num,
            trace,
            lame,
        }
    }

    /// Select the stabilization and a scale factor that multiplies `S`.
    /// Errors if `scale` is not finite and positive.
    pub fn with_stabilization(
        mut self,
        stabilization: Stabilization,
        scale: f64,
    ) -> Result<Self, VemError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(VemError::InvalidScale { value: scale });
        }
        self.stabilization = stabilization;
        self.scale = scale;
        Ok(self)
    }

    /// The material.
    pub fn material(&self) -> &Stiffness<D> {
        &self.material
    }

    /// The stabilization choice.
    pub fn stabilization(&self) -> Stabilization {
        self.stabilization
    }

    /// The stabilization scale factor.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The scalar `α_K` (scale included) of the uniform stabilizations
    /// ([`Stabilization::Mrst`], [`Stabilization::Trace`]); `None` for
    /// [`Stabilization::DRecipe`].
    pub fn alpha(&self, cell: &CellGeometry<'_, D>) -> Option<f64> {
        let f = Frame::new(cell);
        match self.weights(cell, &f) {
            StabWeights::Uniform(a) => Some(a),
            StabWeights::Diagonal { .. } => None,
        }
    }

    /// The stabilization weights of a cell.
    fn weights(&self, cell: &CellGeometry<'_, D>, f: &Frame<D>) -> StabWeights {
        let sum_d2 = f.m.trace();
        match self.stabilization {
            Stabilization::Mrst => {
                StabWeights::Uniform(self.scale * cell.volume * self.mrst_num / (D as f64 * sum_d2))
            }
            Stabilization::Trace => StabWeights::Uniform(
                self.scale * cell.volume * self.trace / ((D + 1) as f64 * 0.5 * sum_d2),
            ),
            Stabilization::DRecipe => {
                let mut mean = 0.0;
                for i in 0..f.n {
                    for a in 0..D {
                        mean += self.consistency_diagonal(cell, f, i, a);
                    }
                }
                mean /= (f.n * D) as f64;
                StabWeights::Diagonal {
                    floor: DRECIPE_FLOOR * mean,
                    scale: self.scale,
                }
            }
        }
    }

    /// `(A_c)_{(i,a),(i,a)} = (1/|K|) Σ_{c,d} N_ic C_acad N_id`.
    #[inline]
    fn consistency_diagonal(
        &self,
        cell: &CellGeometry<'_, D>,
        f: &Frame<D>,
        i: usize,
        a: usize,
    ) -> f64 {
        let n = &cell.node_normals[i];
        let mut s = 0.0;
        for c in 0..D {
            for d in 0..D {
                s += n[c] * self.c[ci(a, c, a, d)] * n[d];
            }
        }
        s * f.inv_vol
    }

    /// The diagonal of `S` at node `i` (one entry per component).
    #[inline]
    fn node_weights(
        &self,
        w: StabWeights,
        cell: &CellGeometry<'_, D>,
        f: &Frame<D>,
        i: usize,
    ) -> Point<D> {
        match w {
            StabWeights::Uniform(a) => Point::<D>::repeat(a),
            StabWeights::Diagonal { floor, scale } => Point::<D>::from_fn(|a, _| {
                scale * self.consistency_diagonal(cell, f, i, a).max(floor)
            }),
        }
    }

    /// The stabilization diagonal `S` for every dof of the cell, written to `out`
    /// (length `D·n`; constant `α_K` for the uniform stabilizations).
    pub fn stabilization_diagonal(&self, cell: &CellGeometry<'_, D>, out: &mut [f64]) {
        let f = Frame::new(cell);
        let w = self.weights(cell, &f);
        for i in 0..f.n {
            let s = self.node_weights(w, cell, &f, i);
            out[D * i..D * i + D].copy_from_slice(s.as_slice());
        }
    }

    /// The local stiffness `A_K` (independent of the displacements), written to `out`
    /// (resized to `D·n × D·n`, reusing its buffer). Uses `scratch.vecs[0]` (and, for
    /// [`Stabilization::DRecipe`], `scratch.vecs[1]` and `scratch.mats[0]`).
    pub fn local_stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        out: &mut DMatrix<f64>,
        scratch: &mut Scratch,
    ) {
        if let (true, Some((lam, mu))) = (cell.coords.len() == D + 1, self.lame) {
            isotropic_simplex(cell, lam, mu, out);
            return;
        }
        let f = Frame::<D>::new(cell);
        let n = f.n;
        let nd = D * n;
        zero_matrix(out, nd, nd);
        let normals = cell.node_normals;

        // Per-node data (stride `2D + T`): d_j, M N_j / |K|², and for general materials
        // T_j[a][b][d] = (1/|K|) Σ_c N_jc C_acbd, so (A_c)_{(j,a),(k,b)} = Σ_d T_j[a][b][d] N_kd.
        // Isotropic materials skip T: (A_c)_jk = (λ N_j N_kᵀ + μ N_k N_jᵀ + μ (N_j·N_k) I)/|K|.
        let d3 = if self.lame.is_some() { 0 } else { D * D * D };
        let stride = 2 * D + d3;
        // On a simplex `P = I` (module docs): no stabilization term, and its per-node
        // data are not needed.
        let simplex = n == D + 1;
        let buf = &mut scratch.vecs[0];
        buf.clear();
        buf.resize(n * stride, 0.0);
        let inv_vol2 = f.inv_vol * f.inv_vol;
        for j in 0..n {
            let sj = &mut buf[j * stride..(j + 1) * stride];
            let nj = &normals[j];
            if !simplex {
                let dj = f.d(&cell.coords[j]);
                let mn = f.m * nj * inv_vol2;
                for a in 0..D {
                    sj[a] = dj[a];
                    sj[D + a] = mn[a];
                }
            }
            if d3 > 0 {
                let t = &mut sj[2 * D..];
                for a in 0..D {
                    for b in 0..D {
                        for d in 0..D {
                            let mut v = 0.0;
                            for c in 0..D {
                                v += nj[c] * self.c[ci(a, c, b, d)];
                            }
                            t[(a * D + b) * D + d] = v * f.inv_vol;
                        }
                    }
                }
            }
        }
        let w = if simplex {
            StabWeights::Uniform(0.0)
        } else {
            self.weights(cell, &f)
        };
        let alpha = match w {
            StabWeights::Uniform(a) => a,
            StabWeights::Diagonal { .. } => 0.0,
        };
        let inv_n = 1.0 / n as f64;
        let (lam, mu) = self
            .lame
            .map_or((0.0, 0.0), |(l, m)| (l * f.inv_vol, m * f.inv_vol));
        let o = out.as_mut_slice();
        for j in 0..n {
            let sj = &buf[j * stride..(j + 1) * stride];
            let nj = &normals[j];
            for k in j..n {
                let sk = &buf[k * stride..(k + 1) * stride];
                let nk = &normals[k];
                // Uniform stabilization: α s_jk on the diagonal of the block,
                // s_jk = δ_jk − 1/n − (d_j·N_k + d_k·N_j)/|K| + N_jᵀ M N_k/|K|².
                let stab = if simplex {
                    0.0
                } else {
                    let (mut djnk, mut dknj, mut mnk) = (0.0, 0.0, 0.0);
                    for c in 0..D {
                        djnk += sj[c] * nk[c];
                        dknj += sk[c] * nj[c];
                        mnk += sj[D + c] * nk[c];
                    }
                    let delta = if j == k { 1.0 } else { 0.0 };
                    alpha * (delta - inv_n - (djnk + dknj) * f.inv_vol + mnk)
                };
                let mut block = Tensor::<D>::zeros();
                if d3 == 0 {
                    block = isotropic_block(nj, nk, lam, mu, mu * nj.dot(nk) + stab);
                } else {
                    let t = &sj[2 * D..];
                    for b in 0..D {
                        for a in 0..D {
                            let mut v = 0.0;
                            for d in 0..D {
                                v += t[(a * D + b) * D + d] * nk[d];
                            }
                            block[(a, b)] = v;
                        }
                        block[(b, b)] += stab;
                    }
                }
                put_block(o, nd, j, k, &block);
            }
        }
        if let StabWeights::Diagonal { .. } = w {
            // (I − P)ᵀ S (I − P) per component a: Σ_i q_ij S_ia q_ik, q = I − p.
            let q = &mut scratch.mats[0];
            zero_matrix(q, n, n);
            for i in 0..n {
                let di = f.d(&cell.coords[i]);
                for j in 0..n {
                    let delta = if i == j { 1.0 } else { 0.0 };
                    q[(i, j)] = delta - inv_n - di.dot(&normals[j]) * f.inv_vol;
                }
            }
            let s = &mut scratch.vecs[1];
            s.clear();
            s.resize(nd, 0.0);
            for i in 0..n {
                let si = self.node_weights(w, cell, &f, i);
                s[D * i..D * i + D].copy_from_slice(si.as_slice());
            }
            for j in 0..n {
                for k in j..n {
                    for a in 0..D {
                        let mut v = 0.0;
                        for i in 0..n {
                            v += q[(i, j)] * s[D * i + a] * q[(i, k)];
                        }
                        out[(D * j + a, D * k + a)] += v;
                        if k != j {
                            out[(D * k + a, D * j + a)] += v;
                        }
                    }
                }
            }
        }
    }

    /// Mean displacement `ū` and average gradient `G = (1/|K|) Σ_j u_j ⊗ N_j`.
    #[inline]
    fn kinematics(cell: &CellGeometry<'_, D>, f: &Frame<D>, u: &[f64]) -> (Point<D>, Tensor<D>) {
        let mut ubar = Point::<D>::zeros();
        let mut g = Tensor::<D>::zeros();
        for (j, nj) in cell.node_normals.iter().enumerate() {
            let uj = node_vec::<D>(u, j);
            ubar += uj;
            g += uj * nj.transpose();
        }
        (ubar / f.n as f64, g * f.inv_vol)
    }
}

/// The displacement of node `i` from a flat node-major slice.
#[inline(always)]
fn node_vec<const D: usize>(u: &[f64], i: usize) -> Point<D> {
    Point::<D>::from_fn(|a, _| u[D * i + a])
}

impl<const D: usize> CellLaw<D> for VemLaw<D> {
    fn name(&self) -> &str {
        "vem"
    }

    fn energy(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _scratch: &mut Scratch,
    ) -> Result<f64, LawError> {
        cell.check()?;
        cell.check_len("displacements", u.len())?;
        let f = Frame::new(cell);
        let (ubar, g) = Self::kinematics(cell, &f, u);
        let eps = to_kelvin::<D>(&g);
        let mut e = 0.5 * cell.volume * eps.dot(&self.material.stress_kelvin(&eps));
        let w = self.weights(cell, &f);
        let mut stab = 0.0;
        for (i, x) in cell.coords.iter().enumerate() {
            let r = node_vec::<D>(u, i) - ubar - g * f.d(x);
            stab += r.dot(&self.node_weights(w, cell, &f, i).component_mul(&r));
        }
        e += 0.5 * stab;
        Ok(e)
    }

    fn forces(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        out: &mut [f64],
        _scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        cell.check()?;
        cell.check_len("displacements", u.len())?;
        cell.check_len("forces", out.len())?;
        let f = Frame::new(cell);
        let (ubar, g) = Self::kinematics(cell, &f, u);
        let sigma = from_kelvin::<D>(&self.material.stress_kelvin(&to_kelvin::<D>(&g)));
        let w = self.weights(cell, &f);
        // t_i = S_i r_i; need t̄ and Σ_i t_i ⊗ d_i.
        let mut tbar = Point::<D>::zeros();
        let mut td = Tensor::<D>::zeros();
        for (i, x) in cell.coords.iter().enumerate() {
            let d = f.d(x);
            let r = node_vec::<D>(u, i) - ubar - g * d;
            let t = self.node_weights(w, cell, &f, i).component_mul(&r);
            tbar += t;
            td += t * d.transpose();
        }
        tbar /= f.n as f64;
        td *= f.inv_vol;
        for (i, x) in cell.coords.iter().enumerate() {
            let nj = &cell.node_normals[i];
            let d = f.d(x);
            let r = node_vec::<D>(u, i) - ubar - g * d;
            let t = self.node_weights(w, cell, &f, i).component_mul(&r);
            let fi = -(sigma * nj) - (t - tbar - td * nj);
            out[D * i..D * i + D].copy_from_slice(fi.as_slice());
        }
        Ok(())
    }

    fn stiffness(
        &self,
        cell: &CellGeometry<'_, D>,
        _u: &[f64],
        out: &mut DMatrix<f64>,
        scratch: &mut Scratch,
    ) -> Result<(), LawError> {
        cell.check()?;
        self.local_stiffness(cell, out, scratch);
        Ok(())
    }

    fn stress(
        &self,
        cell: &CellGeometry<'_, D>,
        u: &[f64],
        _scratch: &mut Scratch,
    ) -> Result<Tensor<D>, LawError> {
        cell.check()?;
        cell.check_len("displacements", u.len())?;
        // G = (1/|K|) Σ_j u_j ⊗ N_j, as in `kinematics` (no frame needed).
        let mut g = Tensor::<D>::zeros();
        for (j, nj) in cell.node_normals.iter().enumerate() {
            g += node_vec::<D>(u, j) * nj.transpose();
        }
        let g = g * (1.0 / cell.volume);
        if let Some((lam, mu)) = self.lame {
            // Isotropic: σ = λ tr(ε) I + 2μ ε, ε = sym G.
            let eps = (g + g.transpose()) * 0.5;
            return Ok(Tensor::<D>::identity() * (lam * eps.trace()) + eps * (2.0 * mu));
        }
        Ok(from_kelvin::<D>(
            &self.material.stress_kelvin(&to_kelvin::<D>(&g)),
        ))
    }
}

/// The local stiffness of an isotropic material on a simplex, where `P = I` leaves only
/// the consistency part (the P1 element): blocks
/// `(λ N_j N_kᵀ + μ N_k N_jᵀ + μ (N_j·N_k) I)/|K|`, each entry written once per pair
/// `j ≤ k` and mirrored (the matrix is symmetric bit for bit).
fn isotropic_simplex<const D: usize>(
    cell: &CellGeometry<'_, D>,
    lam: f64,
    mu: f64,
    out: &mut DMatrix<f64>,
) {
    let n = cell.coords.len();
    let nd = D * n;
    if out.nrows() != nd || out.ncols() != nd {
        zero_matrix(out, nd, nd);
    }
    let inv_vol = 1.0 / cell.volume;
    let (lam, mu) = (lam * inv_vol, mu * inv_vol);
    let normals = cell.node_normals;
    let o = out.as_mut_slice();
    for j in 0..n {
        let nj = &normals[j];
        for k in j..n {
            let nk = &normals[k];
            let block = isotropic_block(nj, nk, lam, mu, mu * nj.dot(nk));
            put_block(o, nd, j, k, &block);
        }
    }
}

/// The isotropic consistency block of nodes `j`, `k` with `λ`, `μ` already divided by
/// `|K|`: `λ N_j N_kᵀ + μ N_k N_jᵀ` plus `diag` on the diagonal.
#[inline]
fn isotropic_block<const D: usize>(
    nj: &Point<D>,
    nk: &Point<D>,
    lam: f64,
    mu: f64,
    diag: f64,
) -> Tensor<D> {
    let mut block = Tensor::<D>::zeros();
    for b in 0..D {
        for a in 0..D {
            block[(a, b)] = lam * nj[a] * nk[b] + mu * nk[a] * nj[b];
        }
        block[(b, b)] += diag;
    }
    block
}

/// Write block `(j, k)` of an `nd × nd` column-major matrix `o` and its transpose at
/// `(k, j)` (the same values, so the matrix is symmetric bit for bit).
#[inline]
fn put_block<const D: usize>(o: &mut [f64], nd: usize, j: usize, k: usize, block: &Tensor<D>) {
    for b in 0..D {
        for a in 0..D {
            let v = block[(a, b)];
            o[(D * k + b) * nd + D * j + a] = v;
            o[(D * j + a) * nd + D * k + b] = v;
        }
    }
}

/// The average displacement gradient `G(u) = (1/|K|) Σ_i u_i ⊗ N_i`, exact for linear
/// fields; the projection is `Π u = ū + G (x − x̄)`.
pub fn projected_gradient<const D: usize>(cell: &CellGeometry<'_, D>, u: &[f64]) -> Tensor<D> {
    let mut g = Tensor::<D>::zeros();
    for (j, nj) in cell.node_normals.iter().enumerate() {
        g += node_vec::<D>(u, j) * nj.transpose();
    }
    g / cell.volume
}

/// The constant strain of the projection, `ε(Π u) = sym G(u)`, in Kelvin form.
pub fn projected_strain<const D: usize>(cell: &CellGeometry<'_, D>, u: &[f64]) -> Kelvin {
    to_kelvin::<D>(&projected_gradient(cell, u))
}

/// The volumetric strain of the projection, `tr ε(Π u) = (1/|K|) Σ_i N_i · u_i`: the
/// exact relative volume change of the cell (Biot's `div_d` per unit volume).
pub fn volumetric_strain<const D: usize>(cell: &CellGeometry<'_, D>, u: &[f64]) -> f64 {
    let mut s = 0.0;
    for (j, nj) in cell.node_normals.iter().enumerate() {
        s += nj.dot(&node_vec::<D>(u, j));
    }
    s / cell.volume
}

/// The weights of [`volumetric_strain`]: `out[D·i + a] = N_ia / |K|` (length `D·n`), so
/// `volumetric_strain = out · u`. Multiply by `|K|` for the volume change.
pub fn volumetric_strain_weights<const D: usize>(cell: &CellGeometry<'_, D>, out: &mut [f64]) {
    let inv = 1.0 / cell.volume;
    for (j, nj) in cell.node_normals.iter().enumerate() {
        for a in 0..D {
            out[D * j + a] = nj[a] * inv;
        }
    }
}

/// The projection `P = P_R + P_C` as a `D·n × D·n` matrix (`P = p ⊗ I_D`,
/// `p_ij = 1/n + (x_i − x̄) · N_j / |K|`), written to `out`. For diagnostics and tests;
/// the law itself never forms it.
pub fn projection_matrix<const D: usize>(cell: &CellGeometry<'_, D>, out: &mut DMatrix<f64>) {
    let f = Frame::new(cell);
    zero_matrix(out, D * f.n, D * f.n);
    for i in 0..f.n {
        let di = f.d(&cell.coords[i]);
        for j in 0..f.n {
            let p = 1.0 / f.n as f64 + di.dot(&cell.node_normals[j]) * f.inv_vol;
            for a in 0..D {
                out[(D * i + a, D * j + a)] = p;
            }
        }
    }
}

/// The Kelvin strain-to-dof matrix `W_c` (`D·n × K`): `(W_c)_{(i,a),k} = (B_k N_i)_a / |K|`,
/// so `ε_K = W_cᵀ u` and the consistency part is `|K| W_c D W_cᵀ`. For diagnostics and
/// tests. Written to `out`.
pub fn strain_matrix<const D: usize>(cell: &CellGeometry<'_, D>, out: &mut DMatrix<f64>) {
    let n = cell.coords.len();
    let k = kelvin_len(D);
    zero_matrix(out, D * n, k);
    for (i, ni) in cell.node_normals.iter().enumerate() {
        for kk in 0..k {
            let Some((a, b)) = kelvin_pair(D, kk) else {
                continue;
            };
            if a == b {
                out[(D * i + a, kk)] = ni[a] / cell.volume;
            } else {
                let s = std::f64::consts::FRAC_1_SQRT_2 / cell.volume;
                out[(D * i + a, kk)] = s * ni[b];
                out[(D * i + b, kk)] = s * ni[a];
            }
        }
    }
}
