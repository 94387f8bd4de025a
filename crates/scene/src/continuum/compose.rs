//! Composition of a continuum scene: the law and material of every cell (later regions
//! override earlier ones), the failure criteria, the boundary conditions and loads.
//!
//! Every stiffness of a material is built by [`material_stiffness`], so plane stress
//! (`λ* = 2λμ/(λ + 2μ)`) holds for the intact laws, the post-failure DEM law and the
//! drained bulk modulus of the fixed-stress split alike.

use porofrac_frac::{Combined, MohrCoulomb, Tensile, Toughness};
use porofrac_grid::Grid;
use porofrac_law::{CellLaw, Stiffness};
use porofrac_sim::{Displacement, Gravity, Loads, Platen, Traction};

use crate::common::laws::{LawRegistry, PostFailure};
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::RunError;
use crate::common::sections::{Material, Plane};

use crate::common::grid::{DeckCells, point, select_cells};

/// The stiffness of a material in the scene's setting (3D, 2D plane strain or plane
/// stress).
pub fn material_stiffness<const D: usize>(
    ls: &LoadedScene,
    name: &str,
    m: &Material,
) -> Result<Stiffness<D>, RunError> {
    let plane_stress = D == 2 && ls.scene.scene.plane == Some(Plane::Stress);
    let stiffness = if plane_stress {
        // λ* = 2λμ/(λ + 2μ), the same μ (Stiffness::<2>::isotropic_plane_stress).
        let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        Stiffness::<D>::from_lame(2.0 * lambda * mu / (lambda + 2.0 * mu), mu)
    } else {
        Stiffness::<D>::isotropic(m.youngs_modulus, m.poisson_ratio)
    };
    stiffness.map_err(|e| ls.error(&k(&["material", name]), e).into())
}

/// Cell law and material chosen by the regions.
pub struct Composition<const D: usize> {
    /// `(law name, material name)` of each law instance.
    pub keys: Vec<(String, String)>,
    /// The law instances.
    pub laws: Vec<Box<dyn CellLaw<D>>>,
    /// The intact law instance of every cell.
    pub law_of_cell: Vec<usize>,
    /// For each law instance: the instance a failed cell switches to
    /// ([`PostFailure`] of its law's registration).
    pub post_failure: Vec<usize>,
    /// For each law instance: the failure criterion of its material.
    pub criteria: Vec<Combined>,
}

impl<const D: usize> Composition<D> {
    /// Whether any material can fail.
    pub fn can_fail(&self) -> bool {
        self.criteria.iter().any(|c| !c.is_empty())
    }
    /// The material name of every cell.
    pub fn material_of_cell(&self) -> Vec<&str> {
        self.law_of_cell
            .iter()
            .map(|&l| self.keys[l].1.as_str())
            .collect()
    }
    /// The law instance of every cell for the failure flags `failed`.
    pub fn law_of_cell_after(&self, failed: &[bool]) -> Vec<usize> {
        self.law_of_cell
            .iter()
            .zip(failed)
            .map(|(&l, &f)| if f { self.post_failure[l] } else { l })
            .collect()
    }
}

/// Compose the laws and criteria of every cell.
pub fn compose<const D: usize>(
    ls: &LoadedScene,
    registry: &LawRegistry,
    grid: &Grid<D>,
    deck: &DeckCells,
) -> Result<Composition<D>, RunError> {
    let s = &ls.scene;
    let n = grid.num_cells();
    let mut law_region: Vec<Option<usize>> = vec![None; n];
    let mut mat_region: Vec<Option<usize>> = vec![None; n];
    for (i, r) in s.region.iter().enumerate() {
        let cells = select_cells(ls, &ki("region", i, &["select"]), grid, deck, &r.select)?;
        for c in cells {
            if r.law.is_some() {
                law_region[c] = Some(i);
            }
            if r.material.is_some() {
                mat_region[c] = Some(i);
            }
        }
    }
    if let Some(c) = (0..n).find(|&c| law_region[c].is_none() || mat_region[c].is_none()) {
        let x = grid.cell_centroid(c);
        return Err(ls
            .error(
                &k(&["region"]),
                format!(
                    "leaves cell {c} (centroid {:?}) without a law or material: add a region \
                     that selects it",
                    x.as_slice()
                ),
            )
            .into());
    }
    let mut keys: Vec<(String, String)> = Vec::new();
    let mut key_region: Vec<usize> = Vec::new();
    let mut laws: Vec<Box<dyn CellLaw<D>>> = Vec::new();
    let mut law_of_cell = vec![0; n];
    // The law instance of each (law region, material region) pair, built on first use.
    let nr = s.region.len();
    let mut instance_of_pair: Vec<Option<usize>> = vec![None; nr * nr];
    for c in 0..n {
        let (lr, mr) = (law_region[c].unwrap_or(0), mat_region[c].unwrap_or(0));
        if let Some(i) = instance_of_pair[lr * nr + mr] {
            law_of_cell[c] = i;
            continue;
        }
        let key = (
            s.region[lr].law.clone().unwrap_or_default(),
            s.region[mr].material.clone().unwrap_or_default(),
        );
        let idx = match keys.iter().position(|k| *k == key) {
            Some(i) => i,
            None => {
                let stiffness = material_stiffness::<D>(ls, &key.1, &s.material[&key.1])?;
                let law = registry.build::<D>(&key.0, &stiffness).map_err(|e| {
                    ls.error(&ki("region", lr, &["law"]), format!("= \"{}\": {e}", key.0))
                })?;
                keys.push(key);
                key_region.push(lr);
                laws.push(law);
                keys.len() - 1
            }
        };
        instance_of_pair[lr * nr + mr] = Some(idx);
        law_of_cell[c] = idx;
    }
    let fracture = s.physics.fracture == Some(true);
    let mut criteria = Vec::new();
    for (_, mat) in &keys {
        let m = &s.material[mat];
        let mut c = Combined::default();
        if fracture {
            if let Some(t) = m.tensile_strength {
                c.tensile = Some(
                    Tensile::new(t)
                        .map_err(|e| ls.error(&k(&["material", mat, "tensile_strength"]), e))?,
                );
            }
            if let Some(kic) = m.fracture_toughness {
                c.toughness = Some(
                    Toughness::new(kic)
                        .map_err(|e| ls.error(&k(&["material", mat, "fracture_toughness"]), e))?,
                );
            }
            if let (Some(coh), Some(phi)) = (m.cohesion, m.friction_angle) {
                c.shear = Some(
                    MohrCoulomb::new(coh, phi)
                        .map_err(|e| ls.error(&k(&["material", mat, "cohesion"]), e))?,
                );
            }
        }
        criteria.push(c);
    }
    let mut post_failure: Vec<usize> = (0..keys.len()).collect();
    for i in 0..keys.len() {
        let switches = registry.post_failure(&keys[i].0) == Some(PostFailure::CompressionOnlyDem);
        if criteria[i].is_empty() || !switches {
            continue;
        }
        let mat = keys[i].1.clone();
        let stiffness = material_stiffness::<D>(ls, &mat, &s.material[&mat])?;
        let dem = porofrac_mdem::DemLaw::new(&stiffness, porofrac_mdem::DemMode::CompressionOnly)
            .and_then(|d| d.with_open_stiffness(s.physics.open_edge_stiffness.unwrap_or(1e-6)))
            .map_err(|e| {
                ls.error(
                    &ki("region", key_region[i], &["law"]),
                    format!("= \"{}\" after failure: {e}", keys[i].0),
                )
            })?;
        post_failure[i] = laws.len();
        keys.push(("dem-compression".into(), mat));
        laws.push(Box::new(dem));
        criteria.push(Combined::default());
        post_failure.push(laws.len() - 1);
    }
    Ok(Composition {
        keys,
        laws,
        law_of_cell,
        post_failure,
        criteria,
    })
}

/// Boundary conditions and loads of the scene.
pub struct Conditions<const D: usize> {
    /// Prescribed displacements.
    pub displacements: Vec<Displacement<D>>,
    /// Rigid platens.
    pub platens: Vec<Platen<D>>,
    /// Tractions, body force and gravity.
    pub loads: Loads<D>,
}

/// The mechanical conditions and loads of the scene.
pub fn conditions<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    comp: &Composition<D>,
) -> Result<Conditions<D>, RunError> {
    let s = &ls.scene;
    let mut out = Conditions {
        displacements: Vec::new(),
        platens: Vec::new(),
        loads: Loads::default(),
    };
    for (i, bc) in s.bc.iter().enumerate() {
        let has_mechanics =
            bc.displacement.is_some() || bc.traction.is_some() || bc.platen.is_some();
        if !has_mechanics {
            continue;
        }
        let faces = boundary_faces(ls, grid, i)?;
        let name = format!("bc[{i}] {}", bc.boundary);
        if let Some(u) = &bc.displacement {
            out.displacements.push(Displacement {
                name: name.clone(),
                faces: faces.clone(),
                components: std::array::from_fn(|a| u[a].to_component()),
            });
        }
        if let Some(t) = &bc.traction {
            out.loads.tractions.push(Traction {
                name: name.clone(),
                faces: faces.clone(),
                traction: std::array::from_fn(|a| t[a].to_field()),
            });
        }
        if let Some(p) = &bc.platen {
            out.platens.push(Platen {
                name,
                faces,
                force: std::array::from_fn(|a| p.force[a].to_component()),
            });
        }
    }
    if let Some(l) = &s.loads {
        if let Some(b) = &l.body_force {
            out.loads.body_force = Some(crate::common::sections::vector_field::<D>(b));
        }
        if let Some(g) = &l.gravity {
            let mut density = vec![0.0; grid.num_cells()];
            for (c, mat) in comp.material_of_cell().into_iter().enumerate() {
                density[c] = s.material[mat].density.ok_or_else(|| {
                    ls.error(
                        &k(&["material", mat, "density"]),
                        "is required by loads.gravity",
                    )
                })?;
            }
            out.loads.gravity = Some(Gravity {
                g: point(g),
                density,
            });
        }
    }
    Ok(out)
}

/// The faces of `[[bc]]` number `i`; an error naming the key when there are none.
pub fn boundary_faces<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    i: usize,
) -> Result<Vec<usize>, RunError> {
    let bc = &ls.scene.bc[i];
    let faces = grid.boundary(&bc.boundary).map_err(|e| {
        ls.error(
            &ki("bc", i, &["boundary"]),
            format!("= \"{}\": {e}", bc.boundary),
        )
    })?;
    if faces.is_empty() {
        return Err(ls
            .error(
                &ki("bc", i, &["boundary"]),
                if porofrac_grid::SIDE_NAMES.contains(&bc.boundary.as_str())
                    && grid.face_tags().contains_key("imin")
                {
                    format!(
                        "= \"{}\" has no faces on this grid: it is a side of the bounding box, \
                     which the faces of a corner-point grid need not lie on; use the ijk \
                     sides imin, imax, jmin, jmax, kmin (top), kmax (bottom)",
                        bc.boundary
                    )
                } else {
                    format!("= \"{}\" has no faces on this grid", bc.boundary)
                },
            )
            .into());
    }
    Ok(faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(plane: &str) -> LoadedScene {
        let text = format!(
            "[scene]\nname = \"s\"\ndim = 2\nplane = \"{plane}\"\n[grid]\nkind = \"triangles\"\n\
             extent = [[0.0, 0.0], [1.0, 1.0]]\ncells = [2, 2]\n[[region]]\nname = \"a\"\n\
             select = {{ all = true }}\nlaw = \"mdem\"\nmaterial = \"m\"\n[material.m]\n\
             youngs_modulus = 1.0e9\npoisson_ratio = 0.3\n"
        );
        crate::common::loaded::parse(&text, std::path::Path::new("s.toml"), crate::MODELS).unwrap()
    }

    #[test]
    fn plane_stress_reaches_every_stiffness_of_a_material() {
        let (e, nu) = (1.0e9, 0.3);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        for (plane, want) in [
            ("strain", lambda),
            ("stress", 2.0 * lambda * mu / (lambda + 2.0 * mu)),
        ] {
            let ls = scene(plane);
            let m = &ls.scene.material["m"];
            let s = material_stiffness::<2>(&ls, "m", m).unwrap();
            let (l, g) = s.lame().unwrap();
            assert!((l - want).abs() <= 1e-12 * want, "{plane}: λ = {l}");
            assert!((g - mu).abs() <= 1e-12 * mu);
            // The drained bulk modulus of the fixed-stress split uses the same stiffness:
            // plane strain K = λ + μ, plane stress K = λ* + μ.
            let k_dr = porofrac_sim::drained_bulk_modulus(&s);
            assert!(
                (k_dr - (want + mu)).abs() <= 1e-9 * k_dr,
                "{plane}: K = {k_dr}"
            );
        }
    }
}
