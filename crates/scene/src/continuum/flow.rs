//! The flow model of a scene: rock properties per cell from the materials, the fluid,
//! pressure and flux conditions, sources, Peaceman wells and the initial pressure.

use porofrac_flow::{
    FlowModel, FlowProblem, Fluid, Permeability, Rock, SourceRate, Well, WellControl,
};
use porofrac_grid::Grid;

use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::RunError;
use crate::common::sample::locate;
use crate::common::sections::Permeability as ScenePerm;

use super::compose::boundary_faces;
use crate::common::grid::{DeckCells, point, select_cells};

/// Flow model, initial pressure per cell and Biot coefficient per cell.
pub struct FlowSetup<const D: usize> {
    /// The TPFA model.
    pub model: FlowModel<D>,
    /// Initial pressure per cell (Pa).
    pub p0: Vec<f64>,
    /// Biot coefficient per cell.
    pub alpha: Vec<f64>,
    /// Permeability per cell as given (m²), before any fracture update.
    pub permeability: Permeability<D>,
    /// Cells of a fluid source (injection or production region).
    pub source_cells: Vec<bool>,
}

/// Build the flow model. `material_of_cell[c]` names the material of cell `c`.
pub fn flow_setup<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    deck: &DeckCells,
    material_of_cell: &[&str],
) -> Result<FlowSetup<D>, RunError> {
    let s = &ls.scene;
    let fluid = s
        .fluid
        .as_ref()
        .ok_or_else(|| ls.error(&k(&["physics", "flow"]), "= true needs a [fluid] section"))?;
    let n = grid.num_cells();
    let mut porosity = vec![0.0; n];
    let mut alpha = vec![1.0; n];
    let mut diag = vec![[0.0; D]; n];
    let mut ks: Option<f64> = None;
    for c in 0..n {
        let name = material_of_cell[c];
        let m = &s.material[name];
        // The material's value, else the deck's (PORO × NTG × MULTPV).
        porosity[c] = match (m.porosity, &deck.porosity) {
            (Some(v), _) => v,
            (None, Some(p)) => p[c],
            (None, None) => {
                return Err(ls
                    .error(&k(&["material", name, "porosity"]), "is required by flow")
                    .into());
            }
        };
        alpha[c] = m.biot_alpha.unwrap_or(1.0);
        diag[c] = match &m.permeability {
            Some(ScenePerm::Scalar(v)) => [*v; D],
            Some(ScenePerm::Diagonal(v)) => std::array::from_fn(|a| v[a]),
            None if deck.permeability.is_some() => {
                let k = deck.permeability.as_ref().expect("checked")[c];
                std::array::from_fn(|a| k[a])
            }
            None => {
                return Err(ls
                    .error(
                        &k(&["material", name, "permeability"]),
                        "is required by flow",
                    )
                    .into());
            }
        };
        if let Some(v) = m.solid_bulk_modulus {
            if ks.is_some_and(|k0| k0 != v) {
                return Err(ls
                    .error(
                        &k(&["material", name, "solid_bulk_modulus"]),
                        "must be the same for all materials of a flow scene",
                    )
                    .into());
            }
            ks = Some(v);
        }
    }
    let permeability =
        Permeability::from_diagonals(&diag).map_err(|e| RunError::Flow(e.to_string()))?;
    let mut rock = Rock::new(porosity, permeability.clone());
    rock.biot_alpha = alpha.clone();
    rock.solid_bulk_modulus = ks.unwrap_or(f64::INFINITY);
    let mut problem = FlowProblem::new(
        rock,
        Fluid {
            viscosity: fluid.viscosity,
            compressibility: fluid.compressibility,
        },
    );
    for (faces, m) in &deck.fault_multipliers {
        problem = problem.transmissibility_multiplier(faces.clone(), *m);
    }
    for (i, bc) in s.bc.iter().enumerate() {
        if bc.pressure.is_none() && bc.flux.is_none() {
            continue;
        }
        let faces = boundary_faces(ls, grid, i)?;
        if let Some(p) = &bc.pressure {
            problem = problem.pressure_bc(faces.clone(), p.to_field());
        }
        if let Some(q) = &bc.flux {
            problem = problem.flux_bc(faces, q.to_field());
        }
    }
    let mut source_cells = vec![false; n];
    for (i, src) in s.source.iter().enumerate() {
        let (r, region) = s
            .region
            .iter()
            .enumerate()
            .find(|(_, r)| r.name == src.region)
            .expect("source regions checked");
        let cells = select_cells(
            ls,
            &ki("region", r, &["select"]),
            grid,
            deck,
            &region.select,
        )?;
        let rate = match (src.rate, src.pore_volumes_per_hour) {
            (Some(q), _) => SourceRate::Total(q),
            (None, Some(v)) => SourceRate::PoreVolumesPerHour(v),
            _ => {
                return Err(ls
                    .error(&ki("source", i, &[]), "needs rate or pore_volumes_per_hour")
                    .into());
            }
        };
        for &c in &cells {
            source_cells[c] = true;
        }
        problem = problem.source(src.region.clone(), cells, rate);
    }
    for (i, w) in s.well.iter().enumerate() {
        let cell = match (&w.at, w.cell) {
            (Some(at), _) => locate(grid, &point(at)).map(|l| l.cell).ok_or_else(|| {
                ls.error(
                    &ki("well", i, &["at"]),
                    format!("= {at:?} is outside the grid"),
                )
            })?,
            (None, Some(c)) if (0..grid.num_cells() as i64).contains(&c) => c as usize,
            (None, c) => {
                return Err(ls
                    .error(
                        &ki("well", i, &["cell"]),
                        format!(
                            "= {c:?} is not a cell of the grid (0 to {})",
                            grid.num_cells() - 1
                        ),
                    )
                    .into());
            }
        };
        let control = match (w.rate, w.bottom_hole_pressure) {
            (Some(q), None) => WellControl::Rate(q),
            (None, Some(p)) => WellControl::Bhp(p),
            _ => {
                return Err(ls
                    .error(
                        &ki("well", i, &[]),
                        "needs exactly one of rate and bottom_hole_pressure",
                    )
                    .into());
            }
        };
        let mut well = Well::new(w.name.clone(), cell, w.radius, control);
        well.skin = w.skin.unwrap_or(0.0);
        problem = problem.well(well);
    }
    let p0: Vec<f64> = match s.initial.as_ref().and_then(|i| i.pressure.as_ref()) {
        Some(v) => {
            let f = v.to_field();
            grid.cell_centroids()
                .iter()
                .map(|x| f.eval(x.as_slice(), 0.0))
                .collect()
        }
        None => vec![0.0; n],
    };
    let model = FlowModel::new(grid, &problem).map_err(|e| {
        // Well errors (no positive well index, ...) name the well.
        let text = e.to_string();
        match s.well.iter().position(|w| text.contains(&w.name)) {
            Some(i) => RunError::from(ls.error(&ki("well", i, &[]), text)),
            None => RunError::Flow(text),
        }
    })?;
    Ok(FlowSetup {
        model,
        p0,
        alpha,
        permeability,
        source_cells,
    })
}
