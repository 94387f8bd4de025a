//! The continuum model on MPI ranks (`mpirun -n P porofrac run`, the `mpi` feature):
//! static linear elasticity — the standard problems E2 and E3 and scenes like them, with
//! no flow, no fracture, no platens, no schedule — solved by CG with the distributed
//! smoothed-aggregation AMG of `porofrac-dist`.
//!
//! # What each rank does
//!
//! 1. **The mesh is built whole on every rank**, with the laws, the conditions and the dof
//!    map, as a serial run builds them: simple and deterministic (every rank computes the
//!    same partition without communication), at the price of the whole grid's memory and
//!    build time on each rank (E2 n = 1000 on two ranks: 1.5 GB peak per rank, against
//!    1.6 GB for the threaded run on one process) — the part of the run that does not
//!    scale with the rank count.
//! 2. **Partition**: recursive coordinate bisection of the nodes into `P` parts balanced
//!    to one node ([`porofrac_dist::recursive_bisection`]); rank `r` owns the equations of
//!    the nodes of part `r`, numbered part by part (node order inside a part).
//! 3. **Assembly of the owned rows**: every cell with an owned node is evaluated once by
//!    its law (`K_K`), and the rows of its owned nodes are added into block rows (one
//!    `D × D` block per neighbouring node); the columns of prescribed dofs move to the
//!    right-hand side (`b = f − K_fp u_p`), as in the serial static solve. A cell on a
//!    partition border is evaluated by every rank that owns one of its nodes. The body
//!    loads are integrated over the same cells only
//!    ([`porofrac_sim::nodal_loads_of_cells`]: the owned nodes get the serial values).
//! 4. **Solve**: CG preconditioned by the distributed AMG (rigid-body modes of the owned
//!    equations; the options of the serial CG-AMG,
//!    [`porofrac_sim::elasticity_amg_options`]) to the scene's `[solver] tolerance`. The
//!    first level of at most `GATHER_BELOW` equations is gathered on every rank and
//!    handled by a serial hierarchy there.
//! 5. **Output**: the solution is gathered on every rank (the displacement of every node);
//!    each rank writes the cells whose first node it owns as its piece
//!    `vtk/step_0000_p<r>.vtu`, rank 0 writes `vtk/step_0000.pvtu` naming the pieces and
//!    `<name>.pvd`, and returns the summary with the error against
//!    `[output] exact_displacement` computed as the serial run computes it, the
//!    iterations, the times, and the `distributed` block (ranks, levels, setup time,
//!    time per CG iteration, the largest memory of a rank).

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use nalgebra::DMatrix;
use porofrac_dist::matrix::{all_gather_vec, max as global_max, sum_usize};
use porofrac_dist::{DistAmg, DistCsr, Layout, NearNullSpace, recursive_bisection};
use porofrac_grid::Grid;
use porofrac_law::{CellLaw, GeometryBuffer, Scratch};
use porofrac_sim::{DofMap, LawMap, elasticity_amg_options, nodal_loads_of_cells};
use porofrac_vtk::{
    Attributes, CellType, DataArray, Encoding, Polyhedra, PvdWriter, UnstructuredGrid,
};

use crate::common::distributed::agree;
use crate::common::driver::Observer;
use crate::common::grid::{AnyGrid, build_grid};
use crate::common::laws::LawRegistry;
use crate::common::loaded::{LoadedScene, k, ki};
use crate::common::model::RunError;
use crate::common::output::{SolverStats, Summary, WallSeconds, peak_memory_bytes};
use crate::common::sections::MechanicsSolver;

use super::compose::{compose, conditions};

/// A level of the distributed hierarchy with at most this many equations is gathered
/// on every rank and handled there by a serial hierarchy
/// ([`DistAmg::with_gathering`]): on E3 n = 40 (177 957 equations, level 1 of 3 072) two
/// ranks then exchange messages on the finest level only, on E2 n = 1000 on the finest
/// two (level 2 of 16 770 is gathered). A gathered level costs one gather of its
/// right-hand side per cycle and its serial V-cycle on every rank.
const GATHER_BELOW: usize = 20_000;

/// Refuse, by key, what the distributed path does not model.
fn refuse(ls: &LoadedScene) -> Result<(), RunError> {
    let s = &ls.scene;
    let not = |key: Vec<crate::common::sections::KeyPart>, what: &str| -> RunError {
        ls.error(
            &key,
            format!(
                "{what}: the distributed continuum solves static linear elasticity only \
                 (no flow, no fracture, one static solve); run this scene without mpirun"
            ),
        )
        .into()
    };
    if s.physics.flow == Some(true) {
        return Err(not(k(&["physics", "flow"]), "= true"));
    }
    if s.physics.fracture == Some(true) {
        return Err(not(k(&["physics", "fracture"]), "= true"));
    }
    for (name, m) in &s.material {
        for (key, set) in [
            ("tensile_strength", m.tensile_strength.is_some()),
            ("cohesion", m.cohesion.is_some()),
            ("fracture_toughness", m.fracture_toughness.is_some()),
        ] {
            if set {
                return Err(not(
                    k(&["material", name, key]),
                    "makes the material fail (a fracture model)",
                ));
            }
        }
    }
    if s.solver.mechanics == Some(MechanicsSolver::Explicit) {
        return Err(not(k(&["solver", "mechanics"]), "= \"explicit\""));
    }
    if s.schedule.is_some() {
        return Err(not(k(&["schedule"]), "a schedule of several solves"));
    }
    if let Some(i) = s.bc.iter().position(|b| b.platen.is_some()) {
        return Err(not(ki("bc", i, &["platen"]), "a rigid platen"));
    }
    if !s.output.probe.is_empty() {
        return Err(not(ki("output.probe", 0, &[]), "probes"));
    }
    if !s.output.line.is_empty() {
        return Err(not(ki("output.line", 0, &[]), "output lines"));
    }
    Ok(())
}

/// Run a continuum scene on the ranks of `world` (see the module docs). Collective.
pub(crate) fn run_distributed(
    ls: &LoadedScene,
    registry: &LawRegistry,
    out: &Path,
    world: &SimpleCommunicator,
    observer: &mut dyn Observer,
) -> Result<Summary, RunError> {
    let start = Instant::now();
    refuse(ls)?;
    let built = agree(world, build_grid(ls))?;
    let grid_seconds = start.elapsed().as_secs_f64();
    let stop = observer.stop_handle();
    match built.0 {
        AnyGrid::Two(g) => run_dim(
            ls,
            registry,
            &g,
            &built.1,
            out,
            world,
            start,
            grid_seconds,
            &stop,
        ),
        AnyGrid::Three(g) => run_dim(
            ls,
            registry,
            &g,
            &built.1,
            out,
            world,
            start,
            grid_seconds,
            &stop,
        ),
    }
}

/// Per owned node: its neighbour nodes (sorted) and one `D × D` block per neighbour.
struct BlockRows {
    ptr: Vec<usize>,
    nbr: Vec<usize>,
    val: Vec<f64>,
}

#[allow(clippy::too_many_arguments)]
fn run_dim<const D: usize>(
    ls: &LoadedScene,
    registry: &LawRegistry,
    grid: &Grid<D>,
    deck: &crate::common::grid::DeckCells,
    out: &Path,
    world: &SimpleCommunicator,
    start: Instant,
    grid_seconds: f64,
    stop: &crate::common::driver::Stop,
) -> Result<Summary, RunError> {
    let s = &ls.scene;
    let rank = world.rank() as usize;
    let size = world.size() as usize;
    let t_asm = Instant::now();
    let comp = compose(ls, registry, grid, deck)?;
    let cond = conditions(ls, grid, &comp)?;
    let law_refs: Vec<&dyn CellLaw<D>> = comp.laws.iter().map(|l| l.as_ref()).collect();
    let laws = LawMap::new(grid, law_refs, comp.law_of_cell.clone())?;
    let dofs = DofMap::new(grid, &cond.displacements, &cond.platens)
        .map_err(|e| super::explain::conditions(ls, e))?;
    dofs.check_rigid_modes(grid)?;
    let t = 0.0;
    let nn = grid.num_nodes();
    let mut u = vec![0.0; dofs.num_dofs()];
    dofs.set_prescribed(grid, t, &mut u);

    // Partition and numbering.
    let coords: Vec<f64> = grid
        .nodes()
        .iter()
        .flat_map(|p| p.iter().copied())
        .collect();
    let part = recursive_bisection(&coords, D, size);
    // The loads of the owned nodes, from the cells that touch them (the values of the
    // serial run's, bit for bit).
    let mut f = vec![0.0; D * nn];
    let touches = |c: usize| grid.cell_nodes(c).iter().any(|&v| part[v] == rank);
    nodal_loads_of_cells(grid, &cond.loads, t, &touches, &mut f)?;
    const NONE: usize = usize::MAX;
    let mut eq = vec![NONE; D * nn];
    let mut counts = vec![0usize; size + 1];
    let mut order: Vec<usize> = (0..nn).collect();
    order.sort_by_key(|&v| (part[v], v));
    let mut next = 0usize;
    for &v in &order {
        for a in 0..D {
            if dofs.equation(v, a).is_some() {
                eq[D * v + a] = next;
                next += 1;
                counts[part[v] + 1] += 1;
            }
        }
    }
    let owned_nodes: Vec<usize> = order.iter().copied().filter(|&v| part[v] == rank).collect();
    let mut local_of = vec![NONE; nn];
    for (l, &v) in owned_nodes.iter().enumerate() {
        local_of[v] = l;
    }

    // Block-row pattern of the owned nodes.
    let mut node_cells: Vec<Vec<usize>> = vec![Vec::new(); owned_nodes.len()];
    let mut cells_touching = Vec::new();
    for c in 0..grid.num_cells() {
        let mut touches = false;
        for &v in grid.cell_nodes(c) {
            if local_of[v] != NONE {
                node_cells[local_of[v]].push(c);
                touches = true;
            }
        }
        if touches {
            cells_touching.push(c);
        }
    }
    let mut rows = BlockRows {
        ptr: vec![0],
        nbr: Vec::new(),
        val: Vec::new(),
    };
    let mut nb = Vec::new();
    for cells in &node_cells {
        nb.clear();
        for &c in cells {
            nb.extend_from_slice(grid.cell_nodes(c));
        }
        nb.sort_unstable();
        nb.dedup();
        rows.nbr.extend_from_slice(&nb);
        rows.ptr.push(rows.nbr.len());
    }
    drop(node_cells);
    rows.val = vec![0.0; rows.nbr.len() * D * D];
    let mut geom = GeometryBuffer::<D>::default();
    let mut scratch = Scratch::default();
    let mut kmat = DMatrix::<f64>::zeros(0, 0);
    let mut zero = Vec::new();
    for &c in &cells_touching {
        let nodes = grid.cell_nodes(c);
        zero.clear();
        zero.resize(D * nodes.len(), 0.0);
        let g = geom.load(grid, c);
        laws.law(c)
            .stiffness(&g, &zero, &mut kmat, &mut scratch)
            .map_err(|e| {
                RunError::from(porofrac_sim::SimError::Input(format!(
                    "cell {c}: the law cannot evaluate its stiffness: {e}"
                )))
            })?;
        for (la, &va) in nodes.iter().enumerate() {
            let l = local_of[va];
            if l == NONE {
                continue;
            }
            let range = rows.ptr[l]..rows.ptr[l + 1];
            for (lb, &vb) in nodes.iter().enumerate() {
                let pos = range.start + rows.nbr[range.clone()].binary_search(&vb).unwrap_or(0);
                for i in 0..D {
                    for j in 0..D {
                        rows.val[pos * D * D + i * D + j] += kmat[(D * la + i, D * lb + j)];
                    }
                }
            }
        }
    }
    // Owned equation rows with the prescribed columns moved to the right-hand side.
    let (mut ptr, mut col, mut val) = (vec![0usize], Vec::new(), Vec::new());
    let mut b = Vec::new();
    let mut eq_dofs = Vec::new();
    for (l, &v) in owned_nodes.iter().enumerate() {
        for i in 0..D {
            if eq[D * v + i] == NONE {
                continue;
            }
            let mut rhs = f[D * v + i];
            for p in rows.ptr[l]..rows.ptr[l + 1] {
                let w = rows.nbr[p];
                for j in 0..D {
                    let a = rows.val[p * D * D + i * D + j];
                    match eq[D * w + j] {
                        NONE => rhs -= a * u[D * w + j],
                        e => {
                            col.push(e);
                            val.push(a);
                        }
                    }
                }
            }
            b.push(rhs);
            ptr.push(col.len());
            eq_dofs.push((v, i));
        }
    }
    drop(rows);
    let layout = Layout::from_local(world, eq_dofs.len());
    let a = DistCsr::from_rows(world, layout.clone(), layout.clone(), &ptr, &col, &val)
        .map_err(dist_error)?;
    drop((ptr, col, val));
    let assembly = global_max(world, t_asm.elapsed().as_secs_f64());

    // Solve.
    if crate::common::distributed::any(world, stop.requested()) {
        return Err(RunError::Interrupted);
    }
    let t_solve = Instant::now();
    let options = elasticity_amg_options(D);
    let null = if eq_dofs.is_empty() {
        NearNullSpace::constant(1).map_err(|e| dist_error(e.into()))?
    } else {
        NearNullSpace::rigid_body_modes(&coords, D, &eq_dofs).map_err(|e| dist_error(e.into()))?
    };
    let nodes_of: Vec<usize> = eq_dofs.iter().map(|d| d.0).collect();
    let amg = agree(
        world,
        DistAmg::with_gathering(world, a, &nodes_of, &null, &options, GATHER_BELOW)
            .map_err(dist_error),
    )?;
    let setup = global_max(world, t_solve.elapsed().as_secs_f64());
    let tolerance = s.solver.tolerance.unwrap_or(1e-8);
    let mut x = vec![0.0; eq_dofs.len()];
    let stats = agree(
        world,
        amg.solve(
            world,
            &mut x,
            &b,
            tolerance,
            porofrac_sim::linear::DEFAULT_MAX_ITERATIONS,
        )
        .map_err(dist_error),
    )?;
    let solve = global_max(world, t_solve.elapsed().as_secs_f64());
    let cg_seconds = global_max(world, stats.seconds);
    let levels = amg.level_info(world);
    let gathered = amg.gathered_levels();
    let amg_bytes = amg.bytes();
    drop(amg);

    // The displacement of every node on every rank.
    let all = all_gather_vec(world, &x);
    for (v, a) in (0..nn).flat_map(|v| (0..D).map(move |a| (v, a))) {
        if let Some(&e) = eq.get(D * v + a)
            && e != NONE
        {
            u[D * v + a] = all[e];
        }
    }
    drop(all);

    // Output.
    let t_out = Instant::now();
    let vtk = if s.output.vtk {
        agree(
            world,
            write_pieces(grid, &u, &part, rank, size, out, &s.scene.name),
        )
    } else {
        Ok(())
    };
    vtk?;
    let output = global_max(world, t_out.elapsed().as_secs_f64());

    let mut errors = BTreeMap::new();
    if let Some(exact) = &s.output.exact_displacement {
        let exact = crate::common::sections::vector_field::<D>(exact);
        let l2 = porofrac_sim::norms::l2_error_p1_field(grid, &u, &exact, t).ok_or_else(|| {
            ls.error(
                &k(&["output", "exact_displacement"]),
                "needs a grid of triangles or tetrahedra (the error is that of the P1 \
                 interpolant of the nodal displacement)",
            )
        })?;
        errors.insert("l2_displacement".to_string(), l2);
    }
    let mut extrema = BTreeMap::new();
    for (a, name) in ["ux", "uy", "uz"].iter().enumerate().take(D) {
        let (lo, hi) = (0..nn).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(u[D * v + a]), hi.max(u[D * v + a]))
        });
        extrema.insert((*name).to_string(), [lo, hi]);
    }
    let peak = peak_memory_bytes();
    let peak_all = all_gather_vec(world, &[peak]);
    let neq = sum_usize(world, eq_dofs.len());
    let iterations = stats.iterations;
    let mut extra = serde_json::Map::new();
    extra.insert(
        "distributed".into(),
        serde_json::json!({
            "ranks": size,
            "partition": "recursive coordinate bisection of the nodes",
            "equations_per_rank": counts.windows(2).map(|w| w[1]).collect::<Vec<_>>(),
            "levels": levels.iter().map(|l| serde_json::json!({"rows": l.rows, "nnz": l.nnz})).collect::<Vec<_>>(),
            "gathered_levels": gathered.iter().map(|l| serde_json::json!({"rows": l.rows, "nnz": l.nnz})).collect::<Vec<_>>(),
            "amg_setup_seconds": setup,
            "cg_seconds": cg_seconds,
            "seconds_per_iteration": if iterations > 0 { cg_seconds / iterations as f64 } else { 0.0 },
            "peak_memory_bytes_per_rank": peak_all,
            "amg_bytes_rank0": amg_bytes,
        }),
    );
    Ok(Summary {
        scene: s.scene.name.clone(),
        model: ls.model().to_string(),
        dim: D,
        cells: Some(grid.num_cells()),
        nodes: Some(nn),
        dofs: Some(neq),
        sizes_text: format!(
            "{} cells, {nn} nodes, {neq} unknowns on {size} ranks",
            grid.num_cells()
        ),
        steps: 0,
        status: "ok".into(),
        interrupted_at: None,
        fractured_cells: Some(0),
        wall_seconds: WallSeconds {
            total: start.elapsed().as_secs_f64(),
            grid: grid_seconds,
            assembly,
            solve,
            output,
            ..WallSeconds::default()
        },
        peak_memory_bytes: peak_all.iter().copied().max().unwrap_or(peak),
        solver: SolverStats {
            linear: format!("cg-amg (distributed, {size} ranks)"),
            factorizations: 0,
            symbolic_factorizations: 0,
            factor_nnz: 0,
            low_rank_updates: 0,
            iterations,
            max_relative_residual: stats.relative_residual,
        },
        field_extrema: extrema,
        errors,
        version: env!("CARGO_PKG_VERSION").into(),
        overrides: ls.overrides(),
        extra,
    })
}

fn dist_error(e: porofrac_dist::DistError) -> RunError {
    RunError::Distributed(format!("distributed solve: {e}"))
}

/// Write this rank's piece (the cells whose first node it owns) and, on rank 0, the
/// `.pvtu` header and the `.pvd` series.
fn write_pieces<const D: usize>(
    grid: &Grid<D>,
    u: &[f64],
    part: &[usize],
    rank: usize,
    size: usize,
    out: &Path,
    name: &str,
) -> Result<(), RunError> {
    let dir = out.join("vtk");
    std::fs::create_dir_all(&dir).map_err(|source| crate::common::output::OutputError {
        path: dir.clone(),
        source,
    })?;
    let cells: Vec<usize> = (0..grid.num_cells())
        .filter(|&c| grid.cell_nodes(c).first().is_some_and(|&v| part[v] == rank))
        .collect();
    const NONE: usize = usize::MAX;
    let mut local = vec![NONE; grid.num_nodes()];
    let mut pts = Vec::new();
    let mut disp = Vec::new();
    let mut point = |v: usize, pts: &mut Vec<f64>, disp: &mut Vec<f64>| -> i64 {
        if local[v] == NONE {
            local[v] = pts.len() / 3;
            let p = grid.node(v);
            pts.extend((0..3).map(|a| if a < D { p[a] } else { 0.0 }));
            disp.extend((0..3).map(|a| if a < D { u[D * v + a] } else { 0.0 }));
        }
        local[v] as i64
    };
    let (mut conn, mut offsets, mut types) = (Vec::new(), Vec::new(), Vec::new());
    let (mut faces, mut faceoffsets) = (Vec::new(), Vec::new());
    let mut any_poly = false;
    for &c in &cells {
        let nodes = grid.cell_nodes(c);
        for &v in nodes {
            conn.push(point(v, &mut pts, &mut disp));
        }
        offsets.push(conn.len() as i64);
        if D == 2 {
            types.push(match nodes.len() {
                3 => CellType::Triangle,
                4 => CellType::Quad,
                _ => CellType::Polygon,
            });
            faceoffsets.push(-1);
        } else if nodes.len() == 4 {
            types.push(CellType::Tetra);
            faceoffsets.push(-1);
        } else {
            any_poly = true;
            types.push(CellType::Polyhedron);
            let fs = grid.cell_faces(c);
            faces.push(fs.len() as i64);
            for &fc in fs {
                let fnodes = grid.face_nodes(fc);
                faces.push(fnodes.len() as i64);
                for &v in fnodes {
                    faces.push(point(v, &mut pts, &mut disp));
                }
            }
            faceoffsets.push(faces.len() as i64);
        }
    }
    let ranks = vec![rank as i32; cells.len()];
    let pd = [DataArray::new("displacement", 3, &disp[..])];
    let cd = [DataArray::new("rank", 1, &ranks[..])];
    let ug = UnstructuredGrid {
        points: &pts,
        connectivity: &conn,
        offsets: &offsets,
        types: &types,
        polyhedra: any_poly.then_some(Polyhedra {
            faces: &faces,
            faceoffsets: &faceoffsets,
        }),
        field_data: &[],
        point_data: Attributes::new(&pd),
        cell_data: Attributes::new(&cd),
    };
    let vtk_err = |e: porofrac_vtk::VtkError| RunError::Distributed(format!("VTK output: {e}"));
    ug.write(dir.join(format!("step_0000_p{rank}.vtu")), Encoding::Base64)
        .map_err(vtk_err)?;
    if rank == 0 {
        let sources: Vec<String> = (0..size).map(|r| format!("step_0000_p{r}.vtu")).collect();
        porofrac_vtk::write_pvtu(dir.join("step_0000.pvtu"), &sources, &pd, &cd)
            .map_err(vtk_err)?;
        let mut pvd = PvdWriter::create(out.join(format!("{name}.pvd"))).map_err(vtk_err)?;
        pvd.add(0.0, "vtk/step_0000.pvtu").map_err(vtk_err)?;
    }
    Ok(())
}
