//! Running a scene: grid, composition per cell, conditions, solves, outputs.
//!
//! Mechanics-only scenes are solved statically at every time of the schedule (the
//! conditions may depend on time); the laws' stiffness is factorized once when all laws
//! are linear.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use porofrac_frac::recovery::{NodeCells, cell_average, recover_nodal};
use porofrac_frac::{
    Combined, CrackTracking, FailurePolicy, FailureState, MohrCoulomb, ResolveError, Tensile,
    resolve,
};
use porofrac_grid::generate::{
    CompositeSpec, cartesian, composite, extrude, perturb, simplices, voronoi,
};
use porofrac_grid::io::{Field, PvdWriter, read_msh, read_vtu, write_vtu};
use porofrac_grid::{Grid, GridError, Point};
use porofrac_law::{CellLaw, Stiffness, Tensor};
use porofrac_sim::{
    BiotState, Body, Displacement, DofMap, ExplicitOptions, ExplicitPressure, FixedStress,
    FractureFlow, FractureLaws, FractureSettings, FractureStep, Fracturing, Gravity, LawMap,
    LinearSolver, Loads, Monolithic, Pattern, Platen, ScalarField, Scheme, SimError, StaticOptions,
    StaticProblem, StaticSolver, StressMeasure, Traction, VectorField, cell_stresses,
    drained_bulk_modulus, solve_explicit, solve_static,
};

use crate::check::{LoadedScene, SceneError, k, ki};
use crate::expr::Expr;
use crate::output::{
    CsvTable, OutputError, SolverStats, Summary, WallSeconds, peak_memory_bytes, write_atomic,
};
use crate::sample::{Location, locate};
use crate::scene::{CellCount, NumOrExpr, Select};

/// Set by Ctrl-C: the run stops after the current step and keeps what it wrote.
pub static STOP: AtomicBool = AtomicBool::new(false);

/// Anything that ends a run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A problem in the scene file.
    #[error("{0}")]
    Scene(#[from] SceneError),
    /// The grid could not be built or read.
    #[error("grid: {0}")]
    Grid(#[from] GridError),
    /// The mechanics failed (singular system, bad law composition, ...).
    #[error("{0}")]
    Sim(#[from] SimError),
    /// Writing output failed.
    #[error("output: {0}")]
    Output(#[from] OutputError),
    /// Failures did not settle within a step.
    #[error("fracture: {0}")]
    Fracture(String),
    /// The flow model could not be built or solved.
    #[error("flow: {0}")]
    Flow(String),
    /// The poroelastic coupling failed.
    #[error("coupling: {0}")]
    Biot(#[from] porofrac_sim::BiotError),
    /// A plot could not be drawn.
    #[error("plot: {0}")]
    Plot(#[from] crate::plots::PlotError),
    /// The coupled fracturing step failed.
    #[error("{0}")]
    Coupled(#[from] porofrac_sim::FractureError),
}

/// A grid of either dimension.
pub enum AnyGrid {
    /// 2D.
    Two(Grid<2>),
    /// 3D.
    Three(Grid<3>),
}

fn point<const D: usize>(v: &[f64]) -> Point<D> {
    Point::<D>::from_fn(|i, _| v[i])
}

/// Build (or read) the grid of a checked scene.
pub fn build_grid(ls: &LoadedScene) -> Result<AnyGrid, RunError> {
    let g = &ls.scene.grid;
    let d = ls.scene.scene.dim as usize;
    let seed = g.seed.unwrap_or(0);
    let per_axis = || match &g.cells {
        Some(CellCount::PerAxis(v)) => v.iter().map(|&n| n as usize).collect::<Vec<_>>(),
        _ => vec![],
    };
    let ext = g
        .extent
        .clone()
        .unwrap_or_else(|| [vec![0.0; d], vec![1.0; d]]);
    let at_grid = |e: GridError| {
        RunError::Scene(ls.error(&k(&["grid", "kind"]), format!("= \"{}\": {e}", g.kind)))
    };
    let grid = match (d, g.kind.as_str()) {
        (2, "cartesian") => {
            let n = per_axis();
            AnyGrid::Two(cartesian(point(&ext[0]), point(&ext[1]), [n[0], n[1]]).map_err(at_grid)?)
        }
        (3, "cartesian") => {
            let n = per_axis();
            AnyGrid::Three(
                cartesian(point(&ext[0]), point(&ext[1]), [n[0], n[1], n[2]]).map_err(at_grid)?,
            )
        }
        (2, "triangles") => {
            let n = per_axis();
            AnyGrid::Two(simplices(point(&ext[0]), point(&ext[1]), [n[0], n[1]]).map_err(at_grid)?)
        }
        (3, "tetrahedra") => {
            let n = per_axis();
            AnyGrid::Three(
                simplices(point(&ext[0]), point(&ext[1]), [n[0], n[1], n[2]]).map_err(at_grid)?,
            )
        }
        (2, "voronoi") => {
            let n = match &g.cells {
                Some(CellCount::One(n)) => *n as usize,
                _ => 0,
            };
            let lloyd = g.lloyd.map_or(porofrac_grid::generate::DEFAULT_LLOYD, |l| {
                l.max(0) as usize
            });
            AnyGrid::Two(voronoi(point(&ext[0]), point(&ext[1]), n, seed, lloyd).map_err(at_grid)?)
        }
        (_, "composite") => {
            // 2D: the composite grid; 3D: the same in x, y, extruded over cells[2] layers
            // (tetrahedra from the triangles, polygonal prisms from the far field).
            let n = per_axis();
            let c = g.center.clone().unwrap_or_default();
            if c.len() != 2 {
                return Err(ls
                    .error(&k(&["grid", "center"]), "must have 2 components")
                    .into());
            }
            let mut spec = CompositeSpec::new(
                point(&ext[0][..2]),
                point(&ext[1][..2]),
                [n[0], n[1]],
                point(&c),
                g.zone_half_width.unwrap_or(0.0),
                g.refine.unwrap_or(0).max(0) as usize,
                g.well_radius.unwrap_or(0.0),
            );
            if let Some(t) = &g.well_tag {
                spec.well_tag = t.clone();
            }
            if g.diagonals.as_deref() == Some("alternating") {
                spec.diagonals = porofrac_grid::generate::Diagonals::Alternating;
            }
            spec.perturb = g.perturb.unwrap_or(0.0);
            spec.seed = seed;
            // The jitter applies to the refined zone only; see docs/grid.md.
            let g2 = composite(&spec).map_err(at_grid)?;
            if d == 2 {
                return Ok(AnyGrid::Two(g2));
            }
            let (z0, z1, nz) = (ext[0][2], ext[1][2], n[2]);
            let levels: Vec<f64> = (0..=nz)
                .map(|i| {
                    if i == nz {
                        z1
                    } else {
                        z0 + (z1 - z0) * i as f64 / nz as f64
                    }
                })
                .collect();
            return Ok(AnyGrid::Three(extrude(&g2, &levels).map_err(at_grid)?));
        }
        (_, "file") => {
            let path = ls.resolve(g.path.as_deref().unwrap_or(""));
            let is_vtu = path.extension().is_some_and(|e| e == "vtu");
            let at_path = |e: GridError| {
                RunError::Scene(ls.error(
                    &k(&["grid", "path"]),
                    format!("= \"{}\": {e}", path.display()),
                ))
            };
            return Ok(match (d, is_vtu) {
                (2, true) => AnyGrid::Two(read_vtu(&path).map_err(at_path)?),
                (2, false) => AnyGrid::Two(read_msh(&path).map_err(at_path)?),
                (_, true) => AnyGrid::Three(read_vtu(&path).map_err(at_path)?),
                (_, false) => AnyGrid::Three(read_msh(&path).map_err(at_path)?),
            });
        }
        (_, kind) => {
            return Err(ls
                .error(
                    &k(&["grid", "kind"]),
                    format!("= \"{kind}\" is not available in {d}D"),
                )
                .into());
        }
    };
    let amp = g.perturb.unwrap_or(0.0);
    if amp > 0.0 {
        let at_perturb = |e: GridError| {
            RunError::Scene(ls.error(&k(&["grid", "perturb"]), format!("= {amp}: {e}")))
        };
        return Ok(match grid {
            AnyGrid::Two(gr) => AnyGrid::Two(perturb(&gr, amp, seed).map_err(at_perturb)?),
            AnyGrid::Three(gr) => AnyGrid::Three(perturb(&gr, amp, seed).map_err(at_perturb)?),
        });
    }
    Ok(grid)
}

fn field(ls: &LoadedScene, v: &NumOrExpr) -> ScalarField {
    match v {
        NumOrExpr::Num(x) => ScalarField::Const(*x),
        NumOrExpr::Expr(s) => {
            // Checked before: the expression parses.
            let e = Expr::parse(s).expect("expression checked");
            match e.as_constant() {
                Some(c) => ScalarField::Const(c),
                None => {
                    let _ = ls;
                    ScalarField::from_fn(move |x, t| e.eval(x, t))
                }
            }
        }
    }
}

fn component(ls: &LoadedScene, v: &NumOrExpr) -> Option<ScalarField> {
    match v {
        NumOrExpr::Expr(s) if s == "free" => None,
        v => Some(field(ls, v)),
    }
}

/// Which cells a selection picks (by centroid).
pub(crate) fn select_cells<const D: usize>(
    ls: &LoadedScene,
    i: usize,
    grid: &Grid<D>,
    sel: &Select,
) -> Result<Vec<usize>, RunError> {
    let centroids = grid.cell_centroids();
    let pick = |f: &dyn Fn(&Point<D>) -> bool| -> Vec<usize> {
        (0..grid.num_cells())
            .filter(|&c| f(&centroids[c]))
            .collect()
    };
    let cells = match sel {
        Select::All(_) => (0..grid.num_cells()).collect(),
        Select::Box(b) => pick(&|x| (0..D).all(|a| x[a] >= b[0][a] && x[a] <= b[1][a])),
        Select::Circle(ball) | Select::Sphere(ball) => {
            let c: Point<D> = point(&ball.center);
            pick(&|x| (x - c).norm() <= ball.radius)
        }
        Select::Tag(name) => {
            match grid.cell_tags().get(name) {
                Some(v) => v.clone(),
                None => {
                    let known: Vec<_> = grid.cell_tags().keys().cloned().collect();
                    return Err(ls
                    .error(&ki("region", i, &["select"]), format!("= {{ tag = \"{name}\" }}: the grid has no such cell tag (known: {})", if known.is_empty() { "none".into() } else { known.join(", ") }))
                    .into());
                }
            }
        }
    };
    if cells.is_empty() {
        return Err(ls
            .error(
                &ki("region", i, &["select"]),
                "selects no cell (cells are selected by their centroid)",
            )
            .into());
    }
    Ok(cells)
}

/// Run a checked scene and write its outputs into `out`.
pub fn run(ls: &LoadedScene, out: &Path) -> Result<Summary, RunError> {
    // `[solver] threads`: 0 (default) keeps rayon's pool (one thread per core); n > 0 runs
    // the scene in a pool of n threads (the parallel assembly, AMG and flow kernels).
    match ls.scene.solver.threads {
        Some(n) if n > 0 => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .build()
                .map_err(|e| ls.error(&k(&["solver", "threads"]), format!("= {n}: {e}")))?;
            pool.install(|| run_in_pool(ls, out))
        }
        _ => run_in_pool(ls, out),
    }
}

fn run_in_pool(ls: &LoadedScene, out: &Path) -> Result<Summary, RunError> {
    let start = Instant::now();
    check_supported(ls)?;
    let grid = build_grid(ls)?;
    let grid_time = start.elapsed().as_secs_f64();
    let mut summary = match grid {
        AnyGrid::Two(g) => run_dim::<2>(ls, &g, out, start)?,
        AnyGrid::Three(g) => run_dim::<3>(ls, &g, out, start)?,
    };
    summary.wall_seconds.grid = grid_time;
    summary.wall_seconds.total = start.elapsed().as_secs_f64();
    summary.peak_memory_bytes = peak_memory_bytes();
    summary.write(out)?;
    Ok(summary)
}

/// Physics this version does not model yet is an error, not silently ignored.
fn check_supported(ls: &LoadedScene) -> Result<(), RunError> {
    let s = &ls.scene;
    let unsupported = |path: Vec<crate::scene::KeyPart>, what: &str| -> RunError {
        ls.error(
            &path,
            format!("{what} is not available in this version of porofrac"),
        )
        .into()
    };
    let flow = s.physics.flow == Some(true);
    // CG-AMG solves the static mechanics (SPD); the Biot system is indefinite.
    if s.solver.linear.as_deref() == Some("cg-amg") {
        let coupled = flow && s.physics.coupling.as_deref() != Some("none");
        let explicit = s.solver.mechanics.as_deref() == Some("explicit");
        if coupled || explicit {
            return Err(ls
                .error(
                    &k(&["solver", "linear"]),
                    "= \"cg-amg\" solves static mechanics only; coupled flow (an indefinite \
                     Biot system) and explicit mechanics need \"cholesky\" or \"auto\"",
                )
                .into());
        }
    }
    for (i, bc) in s.bc.iter().enumerate() {
        if !flow && (bc.pressure.is_some() || bc.flux.is_some()) {
            return Err(ls
                .error(
                    &ki("bc", i, &["pressure"]),
                    "is a flow condition: set [physics] flow = true",
                )
                .into());
        }
    }
    if !flow && !s.source.is_empty() {
        return Err(ls
            .error(&ki("source", 0, &[]), "needs [physics] flow = true")
            .into());
    }
    let coupling = s.physics.coupling.as_deref().unwrap_or("monolithic");
    if flow && coupling != "none" && s.solver.mechanics.as_deref() == Some("explicit") {
        return Err(unsupported(
            k(&["solver", "mechanics"]),
            "= \"explicit\" with coupled flow",
        ));
    }
    Ok(())
}

/// Cell law and material chosen by the regions (later regions override earlier ones).
struct Composition<const D: usize> {
    /// `(law name, material name)` of each law instance.
    keys: Vec<(String, String)>,
    laws: Vec<Box<dyn CellLaw<D>>>,
    law_of_cell: Vec<usize>,
    /// For each law instance: the instance a failed cell switches to (MDEM and DEM cells
    /// become compression-only DEM, seed eqs. 32–33; VEM cells keep their law).
    post_failure: Vec<usize>,
    /// For each law instance: the failure criterion of its material.
    criteria: Vec<Combined>,
}

fn compose<const D: usize>(ls: &LoadedScene, grid: &Grid<D>) -> Result<Composition<D>, RunError> {
    let s = &ls.scene;
    let n = grid.num_cells();
    let mut law_name: Vec<Option<usize>> = vec![None; n];
    let mut mat_name: Vec<Option<usize>> = vec![None; n];
    for (i, r) in s.region.iter().enumerate() {
        let cells = select_cells(ls, i, grid, &r.select)?;
        for c in cells {
            if r.law.is_some() {
                law_name[c] = Some(i);
            }
            if r.material.is_some() {
                mat_name[c] = Some(i);
            }
        }
    }
    if let Some(c) = (0..n).find(|&c| law_name[c].is_none() || mat_name[c].is_none()) {
        let x = grid.cell_centroid(c);
        return Err(ls
            .error(&k(&["region"]), format!("leaves cell {c} (centroid {:?}) without a law or material: add a region that selects it", x.as_slice()))
            .into());
    }
    let mut keys: Vec<(String, String)> = Vec::new();
    let mut laws: Vec<Box<dyn CellLaw<D>>> = Vec::new();
    let mut law_of_cell = vec![0; n];
    let plane_stress = s.scene.plane.as_deref() == Some("stress");
    for c in 0..n {
        let (lr, mr) = (law_name[c].unwrap_or(0), mat_name[c].unwrap_or(0));
        let key = (
            s.region[lr].law.clone().unwrap_or_default(),
            s.region[mr].material.clone().unwrap_or_default(),
        );
        let idx = match keys.iter().position(|k| *k == key) {
            Some(i) => i,
            None => {
                let m = &s.material[&key.1];
                let stiffness = if plane_stress {
                    // Plane stress: λ* = 2λμ/(λ + 2μ) (scene.plane is 2D only).
                    let (e, nu) = (m.youngs_modulus, m.poisson_ratio);
                    let (lambda, mu) = (
                        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
                        e / (2.0 * (1.0 + nu)),
                    );
                    Stiffness::<D>::from_lame(2.0 * lambda * mu / (lambda + 2.0 * mu), mu)
                } else {
                    Stiffness::<D>::isotropic(m.youngs_modulus, m.poisson_ratio)
                }
                .map_err(|e| ls.error(&k(&["material", &key.1]), e))?;
                let law_err = |e: porofrac_mdem::MdemError| {
                    ls.error(&ki("region", lr, &["law"]), format!("= \"{}\": {e}", key.0))
                };
                let law: Box<dyn CellLaw<D>> = match key.0.as_str() {
                    "vem" => Box::new(porofrac_vem::VemLaw::new(stiffness)),
                    "mdem" => Box::new(porofrac_mdem::MdemLaw::new(&stiffness).map_err(law_err)?),
                    "dem" => Box::new(
                        porofrac_mdem::DemLaw::new(&stiffness, porofrac_mdem::DemMode::Elastic)
                            .map_err(law_err)?,
                    ),
                    other => {
                        return Err(ls
                            .error(
                                &ki("region", lr, &["law"]),
                                format!("= \"{other}\" is not available"),
                            )
                            .into());
                    }
                };
                keys.push(key);
                laws.push(law);
                keys.len() - 1
            }
        };
        law_of_cell[c] = idx;
    }
    let fracture = s.physics.fracture == Some(true);
    let mut criteria = Vec::new();
    for (law, mat) in &keys {
        let m = &s.material[mat];
        let mut c = Combined::default();
        if fracture {
            if let Some(t) = m.tensile_strength {
                c.tensile = Some(
                    Tensile::new(t)
                        .map_err(|e| ls.error(&k(&["material", mat, "tensile_strength"]), e))?,
                );
            }
            if let (Some(coh), Some(phi)) = (m.cohesion, m.friction_angle) {
                c.shear = Some(
                    MohrCoulomb::new(coh, phi)
                        .map_err(|e| ls.error(&k(&["material", mat, "cohesion"]), e))?,
                );
            }
        }
        let _ = law;
        criteria.push(c);
    }
    let mut post_failure: Vec<usize> = (0..keys.len()).collect();
    for i in 0..keys.len() {
        if criteria[i].is_empty() || (keys[i].0 != "mdem" && keys[i].0 != "dem") {
            continue;
        }
        let m = &s.material[&keys[i].1];
        let stiffness = Stiffness::<D>::isotropic(m.youngs_modulus, m.poisson_ratio)
            .map_err(|e| ls.error(&k(&["material", &keys[i].1]), e))?;
        let dem = porofrac_mdem::DemLaw::new(&stiffness, porofrac_mdem::DemMode::CompressionOnly)
            .and_then(|d| d.with_open_stiffness(s.physics.open_edge_stiffness.unwrap_or(1e-6)))
            .map_err(|e| ls.error(&k(&["material", &keys[i].1]), e))?;
        post_failure[i] = laws.len();
        keys.push(("dem-compression".into(), keys[i].1.clone()));
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

/// The coupled flow–mechanics run of a scene ([`Fracturing`]: with failure criteria when
/// a material has a strength, without them it is plain poroelasticity).
fn coupled_setup<'a, const D: usize>(
    ls: &LoadedScene,
    grid: &'a Grid<D>,
    comp: &Composition<D>,
    law_refs: &[&'a dyn CellLaw<D>],
    f: crate::flowsetup::FlowSetup<D>,
    dofs: &'a DofMap<D>,
    pattern: &'a Pattern,
    cond: &'a Conditions<D>,
    recovered: bool,
) -> Result<Fracturing<'a, D>, RunError> {
    let s = &ls.scene;
    let coupling = s.physics.coupling.as_deref().unwrap_or("monolithic");
    let fracture_on = comp.criteria.iter().any(|c| !c.is_empty());
    let body = Body {
        grid,
        dofs,
        pattern,
        loads: &cond.loads,
    };
    let laws = FractureLaws {
        laws: law_refs.to_vec(),
        law_of_cell: comp.law_of_cell.clone(),
        post_failure: comp.post_failure.clone(),
    };
    let mut settings = FractureSettings::new(comp.criteria.clone(), comp.law_of_cell.clone());
    if recovered {
        settings.stress = StressMeasure::Recovered;
    }
    settings.tracking_angle = s.physics.crack_tracking;
    let source_cells = f.source_cells.clone();
    let flow = FractureFlow {
        model: f.model,
        permeability: f.permeability,
        fracture_permeability: fracture_on
            .then(|| s.physics.fracture_permeability.unwrap_or(1e-12)),
        alpha: f.alpha,
        p0: f.p0,
    };
    let mut k_dr = Vec::new();
    if coupling == "fixed-stress" {
        for &l in &comp.law_of_cell {
            let m = &s.material[&comp.keys[l].1];
            let st = Stiffness::<D>::isotropic(m.youngs_modulus, m.poisson_ratio)
                .map_err(|e| ls.error(&k(&["material", &comp.keys[l].1]), e))?;
            k_dr.push(drained_bulk_modulus(&st));
        }
    }
    let tolerance = s.solver.tolerance.unwrap_or(1e-10);
    Ok(Fracturing::new(body, laws, settings, flow, |sys| {
        let sys: &porofrac_sim::BiotSystem<'_, D> = sys;
        Ok(match coupling {
            "fixed-stress" => Scheme::FixedStress(FixedStress::new(tolerance, 500), k_dr),
            "explicit-pressure" => {
                Scheme::ExplicitPressure(ExplicitPressure::new(source_cells.clone()), source_cells)
            }
            _ => Scheme::Monolithic(Monolithic::new(sys, None)?),
        })
    })?)
}

/// Boundary conditions and loads of the scene.
struct Conditions<const D: usize> {
    displacements: Vec<Displacement<D>>,
    platens: Vec<Platen<D>>,
    loads: Loads<D>,
}

fn conditions<const D: usize>(
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
                    format!("= \"{}\" has no faces on this grid", bc.boundary),
                )
                .into());
        }
        if let Some(u) = &bc.displacement {
            let components: [Option<ScalarField>; D] =
                std::array::from_fn(|a| component(ls, &u[a]));
            out.displacements.push(Displacement {
                name: format!("bc[{i}] {}", bc.boundary),
                faces: faces.clone(),
                components,
            });
        }
        if let Some(t) = &bc.traction {
            let traction: [ScalarField; D] = std::array::from_fn(|a| field(ls, &t[a]));
            out.loads.tractions.push(Traction {
                name: format!("bc[{i}] {}", bc.boundary),
                faces: faces.clone(),
                traction,
            });
        }
        if let Some(p) = &bc.platen {
            let force: [Option<ScalarField>; D] =
                std::array::from_fn(|a| component(ls, &p.force[a]));
            out.platens.push(Platen {
                name: format!("bc[{i}] {}", bc.boundary),
                faces,
                force,
            });
        }
    }
    if let Some(l) = &s.loads {
        if let Some(b) = &l.body_force {
            out.loads.body_force = Some(VectorField::Components(std::array::from_fn(|a| {
                field(ls, &b[a])
            })));
        }
        if let Some(g) = &l.gravity {
            let mut density = vec![0.0; grid.num_cells()];
            for c in 0..grid.num_cells() {
                let mat = &comp.keys[comp.law_of_cell[c]].1;
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

/// The output times: 0, then every step of the schedule.
fn times(ls: &LoadedScene) -> Vec<f64> {
    let mut t = vec![0.0];
    if let Some(sch) = &ls.scene.schedule {
        let n = match (sch.dt, sch.steps) {
            (Some(dt), _) => (sch.end_time / dt - 1e-9).ceil().max(1.0) as usize,
            (None, Some(n)) => n as usize,
            _ => 1,
        };
        let dt = sch.dt.unwrap_or(sch.end_time / n as f64);
        for k in 1..=n {
            t.push((k as f64 * dt).min(sch.end_time));
        }
    }
    t
}

/// Nodal displacements and cell stresses.
type State<const D: usize> = (Vec<f64>, Vec<Tensor<D>>);

/// Principal stresses (largest, smallest) of a symmetric tensor.
fn principal<const D: usize>(s: &Tensor<D>) -> (f64, f64) {
    let m = nalgebra::DMatrix::from_fn(D, D, |i, j| s[(i, j)]);
    let e = m.symmetric_eigenvalues();
    (e.max(), e.min())
}

/// The value of a named field at a located point.
fn sample<const D: usize>(
    field: &str,
    loc: &Location,
    u: &[f64],
    stress: &[Tensor<D>],
    failed: &[bool],
    pressure: Option<&[f64]>,
) -> f64 {
    let s = &stress[loc.cell];
    let comp = |a: usize, b: usize| if a < D && b < D { s[(a, b)] } else { 0.0 };
    match field {
        "ux" => loc.nodal(u, D, 0),
        "uy" => loc.nodal(u, D, 1),
        "uz" if D == 3 => loc.nodal(u, D, 2),
        "sxx" => comp(0, 0),
        "syy" => comp(1, 1),
        "szz" => comp(2, 2),
        "sxy" => comp(0, 1),
        "syz" => comp(1, 2),
        "sxz" => comp(0, 2),
        "smax" => principal(s).0,
        "smin" => principal(s).1,
        "pressure" => pressure.map_or(f64::NAN, |p| p[loc.cell]),
        _ => f64::from(u8::from(failed[loc.cell])), // "fractured"
    }
}

fn run_dim<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    out: &Path,
    start: Instant,
) -> Result<Summary, RunError> {
    let s = &ls.scene;
    let mut wall = WallSeconds::default();
    let comp = compose(ls, grid)?;
    let cond = conditions(ls, grid, &comp)?;
    let law_refs: Vec<&dyn CellLaw<D>> = comp.laws.iter().map(|l| l.as_ref()).collect();
    // Checks every cell against its law once (e.g. MDEM on a polygon is an error).
    LawMap::new(grid, law_refs.clone(), comp.law_of_cell.clone())?;
    let law_of = |flags: &[bool]| -> Vec<usize> {
        comp.law_of_cell
            .iter()
            .zip(flags)
            .map(|(&l, &f)| if f { comp.post_failure[l] } else { l })
            .collect()
    };
    let fracture_on = comp.criteria.iter().any(|c| !c.is_empty());
    let recovered = s.physics.failure_stress.as_deref() == Some("recovered");
    let adjacency = (fracture_on && recovered).then(|| NodeCells::new(grid));
    let mut tracking = match (fracture_on, s.physics.crack_tracking) {
        (true, Some(a)) => Some(
            CrackTracking::new(grid, a)
                .map_err(|e| ls.error(&k(&["physics", "crack_tracking"]), e))?,
        ),
        _ => None,
    };
    let mut failures = FailureState::new(grid.num_cells());
    // Explicit mechanics: density per cell (scaled for quasi-static relaxation).
    let explicit: Option<Vec<f64>> = if s.solver.mechanics.as_deref() == Some("explicit") {
        let mut density = Vec::with_capacity(grid.num_cells());
        for &l in &comp.law_of_cell {
            let mat = &comp.keys[l].1;
            density.push(s.material[mat].density.ok_or_else(|| {
                ls.error(
                    &k(&["material", mat, "density"]),
                    "is required by solver.mechanics = \"explicit\"",
                )
            })?);
        }
        Some(density)
    } else {
        None
    };
    let mut previous_u: Option<Vec<f64>> = None;
    let flow_on = s.physics.flow == Some(true);
    let material_of_cell: Vec<&str> = comp
        .law_of_cell
        .iter()
        .map(|&l| comp.keys[l].1.as_str())
        .collect();
    let mut flow = if flow_on {
        let t_flow = Instant::now();
        let f = crate::flowsetup::flow_setup(ls, grid, &material_of_cell)?;
        wall.flow += t_flow.elapsed().as_secs_f64();
        Some(f)
    } else {
        None
    };
    let mut pressure: Option<Vec<f64>> = flow.as_ref().map(|f| f.p0.clone());
    let coupling = s
        .physics
        .coupling
        .clone()
        .unwrap_or_else(|| "monolithic".into());
    let coupled_flow = if flow_on && coupling != "none" {
        flow.take()
    } else {
        None
    };
    // Flow on a fixed skeleton: `linear = "cg-amg"` solves the pressure systems with
    // CG-AMG too ("auto" keeps Cholesky for them).
    if let (Some(f), Some("cg-amg")) = (flow.as_mut(), s.solver.linear.as_deref()) {
        f.model
            .set_linear_solver(porofrac_flow::FlowLinearSolver::CgAmg {
                tolerance: s.solver.tolerance.unwrap_or(1e-8),
            })
            .map_err(|e| ls.error(&k(&["solver", "tolerance"]), e.to_string()))?;
    }
    let t_asm = Instant::now();
    let dofs = DofMap::new(grid, &cond.displacements, &cond.platens)?;
    let pattern = Pattern::new(grid, &dofs)?;
    // Cholesky with nested dissection in 3D (2.9x faster than AMD on E3 n = 40, see
    // docs/BENCHMARKS.md) and AMD in 2D, or CG-AMG; "auto" picks by size.
    let cg = LinearSolver::CgAmg {
        tolerance: s.solver.tolerance.unwrap_or(1e-8),
    };
    let linear = match s.solver.linear.as_deref() {
        Some("cholesky") => LinearSolver::Cholesky,
        Some("cg-amg") => cg,
        _ => match LinearSolver::Auto.resolve(D, dofs.num_equations()) {
            LinearSolver::CgAmg { .. } => cg,
            other => other,
        },
    };
    let mut solver = StaticSolver::new(grid, &dofs, &pattern, linear)?;
    // Coupled poroelasticity, with fracturing when a material has a strength.
    let mut coupled = match coupled_flow {
        Some(f) => Some(coupled_setup(
            ls,
            grid,
            &comp,
            &law_refs,
            f,
            &dofs,
            &pattern,
            &cond,
            adjacency.is_some(),
        )?),
        None => None,
    };
    let mut biot_state: Option<BiotState> = None;
    wall.assembly += t_asm.elapsed().as_secs_f64();
    let options = StaticOptions {
        tolerance: s.solver.tolerance.unwrap_or(1e-10),
        ..StaticOptions::default()
    };

    // Probes and lines are located once.
    let (probe_locs, line_locs) = locate_outputs(ls, grid, flow_on)?;

    let mut header = vec!["time".to_string()];
    header.extend(s.output.probe.iter().map(|p| p.name.clone()));
    let mut probes = CsvTable::new(out.join("probes.csv"), &header);
    let axes = ["x", "y", "z"];
    let mut line_header = vec!["time".to_string(), "s".to_string()];
    line_header.extend(axes[..D].iter().map(|a| a.to_string()));
    line_header.push("value".into());
    let mut lines: Vec<CsvTable> = s
        .output
        .line
        .iter()
        .map(|l| {
            CsvTable::new(
                out.join("lines").join(format!("{}.csv", l.name)),
                &line_header,
            )
        })
        .collect();
    let mut fracture_header = vec!["cell".to_string()];
    fracture_header.extend(axes[..D].iter().map(|a| a.to_string()));
    fracture_header.extend(["time".to_string(), "mode".to_string()]);
    let mut fracture_csv = CsvTable::new(out.join("fracture.csv"), &fracture_header);
    fracture_csv.flush()?;
    let mut logged = 0;
    if s.output.vtk {
        std::fs::create_dir_all(out.join("vtk")).map_err(|source| OutputError {
            path: out.join("vtk"),
            source,
        })?;
    }
    let mut pvd = if s.output.vtk {
        Some(PvdWriter::create(
            out.join(format!("{}.pvd", s.scene.name)),
        )?)
    } else {
        None
    };

    let law_ids: Vec<i32> = comp.law_of_cell.iter().map(|&l| l as i32).collect();
    let mut series: Vec<Vec<f64>> = vec![Vec::new(); s.output.probe.len()];
    let mut written_times = Vec::new();
    let mut stats = SolverStats {
        linear: if explicit.is_some() {
            "explicit"
        } else if coupled.is_some() {
            "cholesky"
        } else {
            solver.name()
        }
        .into(),
        ..SolverStats::default()
    };
    let all_times = times(ls);
    let mut progress = Progress::new(all_times.len());
    let zero_start = s.initial.as_ref().and_then(|i| i.mechanics.as_deref()) == Some("zero");
    let mut last: Option<(Vec<f64>, Vec<Tensor<D>>)> = None;
    let mut steps = 0;
    for (step, &t) in all_times.iter().enumerate() {
        let (u, stress) = if let Some(frac) = coupled.as_mut() {
            let t_solve = Instant::now();
            let next = match &biot_state {
                None if zero_start => FractureStep {
                    state: BiotState {
                        displacement: vec![0.0; D * grid.num_nodes()],
                        pressure: frac.initial_pressure().to_vec(),
                    },
                    stress: vec![Tensor::<D>::zeros(); grid.num_cells()],
                    new_failures: 0,
                    rounds: 1,
                    solves: 0,
                    residual: 0.0,
                },
                None => frac.initial_state(t)?,
                Some(st) => {
                    let t_prev = all_times[step - 1];
                    frac.step(st, t_prev, t - t_prev)?
                }
            };
            stats.iterations += next.solves;
            stats.max_relative_residual = stats.max_relative_residual.max(next.residual);
            wall.solve += t_solve.elapsed().as_secs_f64();
            failures = frac.failures().clone();
            pressure = Some(next.state.pressure.clone());
            let u = next.state.displacement.clone();
            biot_state = Some(next.state);
            (u, next.stress)
        } else if step == 0 && zero_start {
            (
                vec![0.0; D * grid.num_nodes()],
                vec![Tensor::<D>::zeros(); grid.num_cells()],
            )
        } else {
            let solve = |flags: &FailureState| -> Result<(State<D>, Vec<Tensor<D>>), RunError> {
                let laws = LawMap::new(grid, law_refs.clone(), law_of(flags.flags()))?;
                let problem = StaticProblem {
                    grid,
                    laws: &laws,
                    dofs: &dofs,
                    pattern: &pattern,
                    loads: &cond.loads,
                };
                let t_solve = Instant::now();
                let sol = match &explicit {
                    None => {
                        let sol = solve_static(&problem, &mut solver, t, &options)?;
                        stats.max_relative_residual = stats.max_relative_residual.max(sol.residual);
                        stats.iterations += sol.linear_iterations;
                        sol.displacement
                    }
                    Some(density) => {
                        // Damped dynamic relaxation from the previous state.
                        let opts = ExplicitOptions {
                            tolerance: s.solver.tolerance.unwrap_or(1e-8),
                            density_scaling: Some(1.0),
                            ..ExplicitOptions::default()
                        };
                        let sol =
                            solve_explicit(&problem, density, t, &opts, previous_u.as_deref())?;
                        stats.iterations += sol.steps;
                        stats.max_relative_residual =
                            stats.max_relative_residual.max(sol.unbalanced_ratio);
                        sol.displacement
                    }
                };
                wall.solve += t_solve.elapsed().as_secs_f64();
                let t_asm = Instant::now();
                let stress = cell_stresses(grid, &laws, &sol)?;
                let measure = match &adjacency {
                    Some(adj) => cell_average(grid, &recover_nodal(grid, adj, &stress)),
                    None => stress.clone(),
                };
                wall.assembly += t_asm.elapsed().as_secs_f64();
                Ok(((sol, stress), measure))
            };
            let class: Vec<usize> = comp.law_of_cell.clone();
            let (solution, _, _, _) = resolve(
                &mut failures,
                t,
                &comp.criteria,
                &class,
                FailurePolicy::default(),
                tracking.as_mut(),
                if fracture_on { 200 } else { 1 },
                solve,
            )
            .map_err(|e| match e {
                ResolveError::Solve(e) => e,
                other => RunError::Fracture(other.to_string()),
            })?;
            solution
        };
        for f in &failures.log()[logged..] {
            let x = grid.cell_centroid(f.cell);
            let mut row = vec![f.cell.to_string()];
            row.extend(x.iter().map(|v| v.to_string()));
            row.push(f.time.to_string());
            row.push(f.mode.as_str().to_string());
            fracture_csv.push_text(&row)?;
        }
        logged = failures.count();
        let fractured: Vec<i32> = failures.flags().iter().map(|&f| f as i32).collect();
        if let (Some(f), Some(p), true) = (flow.as_mut(), pressure.as_mut(), step > 0) {
            let t_flow = Instant::now();
            let t_prev = all_times[step - 1];
            let res = f
                .model
                .step(p, t - t_prev, t_prev)
                .map_err(|e| RunError::Flow(e.to_string()))?;
            *p = res.pressure;
            wall.flow += t_flow.elapsed().as_secs_f64();
        }
        let write = step == 0 || step % s.output.every as usize == 0 || step + 1 == all_times.len();
        if write {
            let t_out = Instant::now();
            let mut row = vec![t];
            for (j, (p, loc)) in s.output.probe.iter().zip(&probe_locs).enumerate() {
                let v = sample(
                    &p.field,
                    loc,
                    &u,
                    &stress,
                    failures.flags(),
                    pressure.as_deref(),
                );
                series[j].push(v);
                row.push(v);
            }
            probes.push(&row)?;
            for ((l, pts), table) in s.output.line.iter().zip(&line_locs).zip(lines.iter_mut()) {
                for (dist, x, loc) in pts {
                    let mut r = vec![t, *dist];
                    r.extend(x.iter().copied());
                    r.push(sample(
                        &l.field,
                        loc,
                        &u,
                        &stress,
                        failures.flags(),
                        pressure.as_deref(),
                    ));
                    table.push(&r)?;
                }
            }
            if let Some(pvd) = pvd.as_mut() {
                let name = format!("step_{:04}.vtu", written_times.len());
                let disp: Vec<Point<D>> = (0..grid.num_nodes())
                    .map(|n| Point::<D>::from_column_slice(&u[D * n..D * n + D]))
                    .collect();
                let sym: Vec<[f64; 6]> = stress.iter().map(vtk_sym).collect();
                let mut cell_data = vec![
                    ("stress", Field::SymTensors(&sym)),
                    ("law", Field::Ints(&law_ids)),
                    ("fractured", Field::Ints(&fractured)),
                ];
                if let Some(p) = pressure.as_deref() {
                    cell_data.push(("pressure", Field::Scalars(p)));
                }
                write_vtu(
                    out.join("vtk").join(&name),
                    grid,
                    &[("displacement", Field::Vectors(&disp))],
                    &cell_data,
                )?;
                pvd.add(t, format!("vtk/{name}"))?;
            }
            written_times.push(t);
            wall.output += t_out.elapsed().as_secs_f64();
        }
        if step > 0 {
            steps += 1;
        }
        if explicit.is_some() {
            previous_u = Some(u.clone());
        }
        last = Some((u, stress));
        progress.step(step, t, stats.iterations, failures.count());
        if STOP.load(Ordering::Relaxed) {
            break;
        }
    }
    stats.factorizations = solver.numeric_factorizations();
    stats.symbolic_factorizations = solver.symbolic_factorizations();
    stats.factor_nnz = solver.factor_nnz();

    let t_out = Instant::now();
    if s.output.plots {
        let plotted = PlotInputs {
            series,
            written_times: &written_times,
            last: last.as_ref(),
            failures: &failures,
            pressure: pressure.as_deref(),
        };
        write_plots(ls, out, grid, plotted)?;
    }
    wall.output += t_out.elapsed().as_secs_f64();
    let _ = start;
    Ok(Summary {
        scene: s.scene.name.clone(),
        dim: D,
        cells: grid.num_cells(),
        nodes: grid.num_nodes(),
        dofs: dofs.num_equations(),
        steps,
        status: "ok".into(),
        fractured_cells: failures.count(),
        wall_seconds: wall,
        peak_memory_bytes: 0,
        solver: stats,
        version: env!("CARGO_PKG_VERSION").into(),
    })
}

/// Sample points along an output line: arc length from its start, position, location.
type LinePoints<const D: usize> = Vec<(f64, Point<D>, Location)>;

/// The cells holding the probes and the points of the output lines; errors name the
/// probe or line that lies outside the grid or asks for pressure without flow.
fn locate_outputs<const D: usize>(
    ls: &LoadedScene,
    grid: &Grid<D>,
    flow_on: bool,
) -> Result<(Vec<Location>, Vec<LinePoints<D>>), RunError> {
    let s = &ls.scene;
    let mut probe_locs = Vec::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        if p.field == "pressure" && !flow_on {
            return Err(ls
                .error(
                    &ki("output.probe", i, &["field"]),
                    "= \"pressure\" needs [physics] flow = true",
                )
                .into());
        }
        let loc = locate(grid, &point(&p.at)).ok_or_else(|| {
            ls.error(
                &ki("output.probe", i, &["at"]),
                format!("= {:?} is outside the grid", p.at),
            )
        })?;
        probe_locs.push(loc);
    }
    let mut line_locs: Vec<LinePoints<D>> = Vec::new();
    for (i, l) in s.output.line.iter().enumerate() {
        if l.field == "pressure" && !flow_on {
            return Err(ls
                .error(
                    &ki("output.line", i, &["field"]),
                    "= \"pressure\" needs [physics] flow = true",
                )
                .into());
        }
        let (a, b): (Point<D>, Point<D>) = (point(&l.from), point(&l.to));
        let mut pts = Vec::new();
        for j in 0..l.points as usize {
            let f = j as f64 / (l.points as f64 - 1.0);
            let x = a + (b - a) * f;
            let loc = locate(grid, &x).ok_or_else(|| {
                ls.error(
                    &ki("output.line", i, &["from"]),
                    format!("point {:?} of the line is outside the grid", x.as_slice()),
                )
            })?;
            pts.push(((b - a).norm() * f, x, loc));
        }
        line_locs.push(pts);
    }
    Ok((probe_locs, line_locs))
}

/// What the end-of-run plots show: the probe series at the written times, the last
/// displacement and cell stresses, the failures and the pressure.
struct PlotInputs<'a, const D: usize> {
    series: Vec<Vec<f64>>,
    written_times: &'a [f64],
    last: Option<&'a (Vec<f64>, Vec<Tensor<D>>)>,
    failures: &'a FailureState,
    pressure: Option<&'a [f64]>,
}

/// `plots/`: the probe time series, the last state's fields (2D: the grid; 3D: the
/// mid-height section) and, after fracturing in 2D, the seed's Figs. 4 and 5.
fn write_plots<const D: usize>(
    ls: &LoadedScene,
    out: &Path,
    grid: &Grid<D>,
    inputs: PlotInputs<'_, D>,
) -> Result<(), RunError> {
    let s = &ls.scene;
    let PlotInputs {
        series,
        written_times,
        last,
        failures,
        pressure,
    } = inputs;
    let columns: Vec<(String, Vec<f64>)> = s
        .output
        .probe
        .iter()
        .map(|p| p.name.clone())
        .zip(series)
        .collect();
    if !columns.is_empty() {
        crate::plots::time_series(
            &out.join("plots").join("probes.png"),
            written_times,
            &columns,
            &format!("{}: probes", s.scene.name),
        )?;
    }
    if let Some((u, stress)) = &last {
        // 2D: the grid; 3D: its cross-section at mid-height (shifted off a layer of
        // nodes by 1e-4 of the height, so extruded grids are cut inside a layer).
        let (canvas, where_) = match (as_2d(grid), as_3d(grid)) {
            (Some(g2), _) => (crate::plots::Canvas::of_grid(g2), String::new()),
            (_, Some(g3)) => {
                let (lo, hi) = g3.bounding_box();
                let z = lo[2] + (0.5 + 1e-4) * (hi[2] - lo[2]);
                (
                    crate::plots::Canvas::z_slice(g3, z),
                    format!(" on z = {:.4}", 0.5 * (lo[2] + hi[2])),
                )
            }
            _ => unreachable!("grids are 2D or 3D"),
        };
        let marked = failures.flags().to_vec();
        let cell_mean = |a: usize| -> Vec<f64> {
            (0..grid.num_cells())
                .map(|c| {
                    let nodes = grid.cell_nodes(c);
                    nodes.iter().map(|&p| u[D * p + a]).sum::<f64>() / nodes.len() as f64
                })
                .collect()
        };
        let comp = |i: usize, j: usize| -> Vec<f64> { stress.iter().map(|s| s[(i, j)]).collect() };
        let (smax, smin): (Vec<f64>, Vec<f64>) = stress.iter().map(principal).unzip();
        let mut plots: Vec<(&str, Vec<f64>)> = vec![("ux", cell_mean(0)), ("uy", cell_mean(1))];
        if D == 3 {
            plots.push(("uz", cell_mean(2)));
        }
        plots.extend([("sxx", comp(0, 0)), ("syy", comp(1, 1))]);
        if D == 3 {
            plots.push(("szz", comp(2, 2)));
        }
        plots.extend([
            ("sxy", comp(0, 1)),
            ("smax", smax),
            ("smin", smin),
            ("divergence", cell_divergence(grid, u)),
        ]);
        if let Some(p) = &pressure {
            plots.push(("pressure", p.to_vec()));
        }
        let t_last = written_times.last().copied().unwrap_or(0.0);
        for (name, vals) in &plots {
            let title = format!("{name} at t = {t_last} s{where_}");
            crate::plots::field(
                &out.join("plots").join(format!("{name}.png")),
                &crate::plots::FieldPlot::new(&canvas, &title, &marked),
                crate::plots::Values::Cell(vals),
            )?;
        }
        if let (Some(g2), true) = (as_2d(grid), failures.count() > 0) {
            // The seed's Figs. 4 and 5.
            let stress2: Vec<Tensor<2>> = stress
                .iter()
                .map(|s| Tensor::<2>::from_fn(|i, j| s[(i, j)]))
                .collect();
            fracture_plots(
                &out.join("plots"),
                g2,
                &canvas,
                &plots,
                &stress2,
                &marked,
                failures.log().iter().map(|f| f.cell),
                t_last,
            )?;
        }
    }
    Ok(())
}

/// Cell divergence of the displacement, `div u = Σ_i N_i · u_i / |K|`
/// ([`porofrac_vem::volumetric_strain`]: the exact volume change of the VEM projection per
/// unit volume; seed Fig. 4, upper right).
fn cell_divergence<const D: usize>(grid: &Grid<D>, u: &[f64]) -> Vec<f64> {
    let mut geometry = porofrac_law::GeometryBuffer::<D>::default();
    let mut local = Vec::new();
    (0..grid.num_cells())
        .map(|c| {
            local.clear();
            for &n in grid.cell_nodes(c) {
                local.extend_from_slice(&u[D * n..D * n + D]);
            }
            porofrac_vem::volumetric_strain(&geometry.load(grid, c), &local)
        })
        .collect()
}

/// Principal directions (unit, of the largest and the smallest principal stress).
fn principal_directions(s: &Tensor<2>) -> ([f64; 2], [f64; 2]) {
    let theta = 0.5 * (2.0 * s[(0, 1)]).atan2(s[(0, 0)] - s[(1, 1)]);
    let (c, si) = (theta.cos(), theta.sin());
    ([c, si], [-si, c])
}

/// A square window around the points, padded by 30 % and half a metre, inside the grid.
fn window_around(grid: &Grid<2>, pts: &[Point<2>], pad: f64) -> ([f64; 2], [f64; 2]) {
    let (glo, ghi) = grid.bounding_box();
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let half = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) * 1.3 + pad;
    let mut w = ([0.0; 2], [0.0; 2]);
    for a in 0..2 {
        let m = 0.5 * (lo[a] + hi[a]);
        w.0[a] = (m - half).max(glo[a]);
        w.1[a] = (m + half).min(ghi[a]);
    }
    w
}

/// Plots of a fractured 2D scene, like the seed's Figs. 4 and 5, in `plots/fracture/`:
/// the fields of `plots` zoomed on the fractured cells (principal directions on `smax` and
/// `smin`), and near the crack tip (the last cell to fail) the largest principal stress of
/// the cells next to the Zienkiewicz–Zhu recovered one (Fig. 5).
#[allow(clippy::too_many_arguments)]
fn fracture_plots(
    dir: &Path,
    grid: &Grid<2>,
    canvas: &crate::plots::Canvas,
    plots: &[(&str, Vec<f64>)],
    stress: &[Tensor<2>],
    marked: &[bool],
    failed_in_order: impl Iterator<Item = usize>,
    t: f64,
) -> Result<(), RunError> {
    let dir = dir.join("fracture");
    let order: Vec<usize> = failed_in_order.collect();
    let centroids: Vec<Point<2>> = order.iter().map(|&c| *grid.cell_centroid(c)).collect();
    let window = window_around(grid, &centroids, 0.5);
    let (dmax, dmin): (Vec<[f64; 2]>, Vec<[f64; 2]>) =
        stress.iter().map(principal_directions).unzip();
    for (name, vals) in plots {
        let title = format!("{name} at t = {t} s, near the fracture");
        let mut plot = crate::plots::FieldPlot::new(canvas, &title, marked);
        plot.window = Some(window);
        plot.directions = match *name {
            "smax" => Some(&dmax),
            "smin" => Some(&dmin),
            _ => None,
        };
        crate::plots::field(
            &dir.join(format!("{name}.png")),
            &plot,
            crate::plots::Values::Cell(vals),
        )?;
    }
    // Fig. 5: cell stress against recovered stress at the tip.
    let Some(&tip) = order.last() else {
        return Ok(());
    };
    let h = grid.cell_volume(tip).sqrt();
    let tip_window = window_around(grid, &[*grid.cell_centroid(tip)], 6.0 * h);
    let nodal = recover_nodal(grid, &NodeCells::new(grid), stress);
    let smax_cell: Vec<f64> = stress.iter().map(|s| principal(s).0).collect();
    let smax_nodal: Vec<f64> = nodal.iter().map(|s| principal(s).0).collect();
    for (file, title, values) in [
        (
            "tip_smax_cell.png",
            format!("smax of the cells near the tip, t = {t} s"),
            crate::plots::Values::Cell(&smax_cell),
        ),
        (
            "tip_smax_recovered.png",
            format!("smax recovered (ZZ patch) near the tip, t = {t} s"),
            crate::plots::Values::Nodal(&smax_nodal),
        ),
    ] {
        let mut plot = crate::plots::FieldPlot::new(canvas, &title, marked);
        plot.window = Some(tip_window);
        crate::plots::field(&dir.join(file), &plot, values)?;
    }
    Ok(())
}

/// Plain symmetric components `[xx, yy, zz, xy, yz, xz]` for VTK.
fn vtk_sym<const D: usize>(s: &Tensor<D>) -> [f64; 6] {
    let c = |a: usize, b: usize| if a < D && b < D { s[(a, b)] } else { 0.0 };
    [c(0, 0), c(1, 1), c(2, 2), c(0, 1), c(1, 2), c(0, 2)]
}

/// The grid as a 2D grid, if it is one (plots are 2D only).
fn as_2d<const D: usize>(grid: &Grid<D>) -> Option<&Grid<2>> {
    (grid as &dyn std::any::Any).downcast_ref::<Grid<2>>()
}

/// The grid as a 3D grid, if it is one.
fn as_3d<const D: usize>(grid: &Grid<D>) -> Option<&Grid<3>> {
    (grid as &dyn std::any::Any).downcast_ref::<Grid<3>>()
}

/// Default output directory of a scene: `out/<name>`.
pub fn default_out(ls: &LoadedScene) -> PathBuf {
    PathBuf::from("out").join(&ls.scene.scene.name)
}

/// Write an error status into `summary.json` of a failed run (best effort).
pub fn write_failed_summary(ls: &LoadedScene, out: &Path, error: &str, start: Instant) {
    let summary = Summary {
        scene: ls.scene.scene.name.clone(),
        dim: ls.scene.scene.dim as usize,
        cells: 0,
        nodes: 0,
        dofs: 0,
        steps: 0,
        status: error.to_string(),
        fractured_cells: 0,
        wall_seconds: WallSeconds {
            total: start.elapsed().as_secs_f64(),
            ..WallSeconds::default()
        },
        peak_memory_bytes: peak_memory_bytes(),
        solver: SolverStats::default(),
        version: env!("CARGO_PKG_VERSION").into(),
    };
    let _ = std::fs::create_dir_all(out);
    let _ = write_atomic(
        &out.join("summary.json"),
        serde_json::to_string_pretty(&summary)
            .unwrap_or_default()
            .as_bytes(),
    );
}

/// Progress of a run: an indicatif bar when stderr is a terminal, plain lines otherwise.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    total: usize,
    /// Solver iterations reported so far (the lines show those of each step).
    iterations: usize,
}

impl Progress {
    fn new(total: usize) -> Self {
        use std::io::IsTerminal;
        let bar = (std::io::stderr().is_terminal() && total > 1).then(|| {
            let bar = indicatif::ProgressBar::new(total as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{bar:30} step {pos}/{len}  {msg}  ETA {eta}",
            ) {
                bar.set_style(style);
            }
            bar
        });
        Self {
            bar,
            total,
            iterations: 0,
        }
    }

    /// Report step `step` at time `t`; `iterations` is the running total of solver
    /// iterations (coupled solves, active-set and failure rounds, CG iterations).
    fn step(&mut self, step: usize, t: f64, iterations: usize, fractured: usize) {
        let this_step = iterations.saturating_sub(self.iterations);
        self.iterations = iterations;
        let msg = format!(
            "t = {t:.4e} s, solver iterations {this_step} (total {iterations}), fractured {fractured}"
        );
        match &self.bar {
            Some(bar) => {
                bar.set_position(step as u64 + 1);
                bar.set_message(msg);
                if step + 1 == self.total {
                    bar.finish_and_clear();
                }
            }
            None if self.total > 1 => eprintln!("step {}/{}: {msg}", step + 1, self.total),
            None => {}
        }
    }
}
