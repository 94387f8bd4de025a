//! The flow model of a scene: rock properties per cell from the materials, the fluid,
//! pressure and flux conditions, sources and the initial pressure.

use porofrac_flow::{FlowModel, FlowProblem, Fluid, Permeability, Rock, SourceRate, Value};
use porofrac_grid::Grid;

use crate::check::{LoadedScene, k, ki};
use crate::expr::Expr;
use crate::run::{RunError, select_cells};
use crate::scene::{NumOrExpr, Permeability as ScenePerm};

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

fn value(v: &NumOrExpr) -> Value {
    match v {
        NumOrExpr::Num(x) => Value::Const(*x),
        NumOrExpr::Expr(s) => {
            let e = Expr::parse(s).expect("expression checked");
            match e.as_constant() {
                Some(c) => Value::Const(c),
                None => Value::func(move |x, t| e.eval(x, t)),
            }
        }
    }
}

/// Build the flow model. `material_of_cell[c]` names the material of cell `c`.
pub fn flow_setup<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
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
        porosity[c] = m
            .porosity
            .ok_or_else(|| ls.error(&k(&["material", name, "porosity"]), "is required by flow"))?;
        alpha[c] = m.biot_alpha.unwrap_or(1.0);
        diag[c] = match &m.permeability {
            Some(ScenePerm::Scalar(v)) => [*v; D],
            Some(ScenePerm::Diagonal(v)) => std::array::from_fn(|a| v[a]),
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
    for (i, bc) in s.bc.iter().enumerate() {
        if bc.pressure.is_none() && bc.flux.is_none() {
            continue;
        }
        let faces = grid.boundary(&bc.boundary).map_err(|e| {
            ls.error(
                &ki("bc", i, &["boundary"]),
                format!("= \"{}\": {e}", bc.boundary),
            )
        })?;
        if let Some(p) = &bc.pressure {
            problem = problem.pressure_bc(faces.clone(), value(p));
        }
        if let Some(q) = &bc.flux {
            problem = problem.flux_bc(faces, value(q));
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
        let cells = select_cells(ls, r, grid, &region.select)?;
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
    let p0: Vec<f64> = match s.initial.as_ref().and_then(|i| i.pressure.as_ref()) {
        Some(v) => {
            let f = value(v);
            grid.cell_centroids()
                .iter()
                .map(|x| f.eval(x.as_slice(), 0.0))
                .collect()
        }
        None => vec![0.0; n],
    };
    let model = FlowModel::new(grid, &problem).map_err(|e| RunError::Flow(e.to_string()))?;
    Ok(FlowSetup {
        model,
        p0,
        alpha,
        permeability,
        source_cells,
    })
}
