//! A 2D grid with a round well: a Cartesian far field and a zone of graded triangles around
//! a circular well, joined by hanging nodes.
//!
//! ```text
//!   +-----+--*--*--+-----+      coarse cells of the far field: squares; a coarse cell
//!   |     | /\ /\ /|     |      next to the zone gets the zone's interface nodes (*) as
//!   |     *--\/--\/*     |      extra collinear vertices (hanging nodes)
//!   |     | \ ,--. |     |
//!   |     *--( () )*     |      the zone: whole coarse cells whose centroid lies in the
//!   |     | / `--' |     |      square |x − c|∞ ≤ zone_half_width, triangulated by a
//!   |     *--/\--/\*     |      constrained Delaunay triangulation with Ruppert
//!   +-----+--*--*--+-----+      refinement (the `spade` crate)
//! ```
//!
//! The zone boundary is split into `refine` equal segments per coarse cell edge (the
//! interface spacing `s = h / refine`); the well is the regular polygon of `n` nodes on the
//! circle `|x − c| = R`, `n` a multiple of 4 (nodes on the axes through `c`), with
//! `n = max(32, 4 ⌈2πR / (4 s_w)⌉)` for the edge length `s_w` on the wall (`well_size`,
//! default `s / 2`). Both loops are constraint edges that refinement never splits, so the
//! far field's hanging nodes and the polygon stay as built. Refinement inserts Steiner
//! points until every triangle has its smallest angle above [`MIN_ANGLE_DEG`] and its
//! area below the equilateral triangle of side `s`: the triangles grade from `s_w` on the
//! wall to `s` at the interface. The disc inside the polygon is triangulated the same way.
//!
//! Cells are numbered coarse first (x fastest, zone cells skipped), then the triangles by
//! their centroids row by row (y, then x); the Steiner points likewise (a banded
//! numbering, as on a lattice). Tags: the
//! triangles get [`REFINED_TAG`]; the triangles inside the well polygon get `well_tag`.

use spade::{ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};

use crate::error::{GridError, Result};
use crate::generate::composite::{CompositeSpec, REFINED_TAG, far_field_cells};
use crate::grid::Grid;
use crate::point::Point;

/// Smallest angle the refinement aims for, degrees (Ruppert's algorithm terminates for
/// limits up to about 30°).
pub const MIN_ANGLE_DEG: f64 = 28.0;

/// Fewest nodes on the well circumference.
pub const MIN_WELL_NODES: usize = 32;

/// The zone as inclusive coarse cell ranges `([i0, i1], [j0, j1])`.
pub type ZoneCells = ([usize; 2], [usize; 2]);

/// Parameters of [`round_well`] (scene-file keys in brackets).
#[derive(Clone, Debug, PartialEq)]
pub struct RoundWellSpec {
    /// Lower-left corner of the box (`extent[0]`), m.
    pub lo: Point<2>,
    /// Upper-right corner of the box (`extent[1]`), m.
    pub hi: Point<2>,
    /// Far-field cells per axis (`cells`).
    pub cells: [usize; 2],
    /// Centre of the zone and of the well (`center`), m.
    pub center: Point<2>,
    /// Half-width of the square zone, snapped to whole coarse cells (`zone_half_width`), m.
    pub zone_half_width: f64,
    /// Interface segments per coarse cell edge (`refine`, ≥ 1): the zone's coarsest
    /// triangle size is `h / refine`.
    pub refine: usize,
    /// Radius of the well (`well_radius`), m.
    pub well_radius: f64,
    /// Edge length on the well wall (`well_size`), m; `None`: half the interface spacing.
    pub well_size: Option<f64>,
    /// Name of the well cell tag (default `well`).
    pub well_tag: String,
}

impl RoundWellSpec {
    /// A spec with the required parameters; `well_size` by default, `well_tag = "well"`.
    pub fn new(
        lo: Point<2>,
        hi: Point<2>,
        cells: [usize; 2],
        center: Point<2>,
        zone_half_width: f64,
        refine: usize,
        well_radius: f64,
    ) -> Self {
        Self {
            lo,
            hi,
            cells,
            center,
            zone_half_width,
            refine,
            well_radius,
            well_size: None,
            well_tag: "well".into(),
        }
    }

    /// The zone as inclusive coarse cell ranges and the number of well nodes, after
    /// checking the spec.
    pub fn layout(&self) -> Result<(ZoneCells, usize)> {
        let bad = |what: String| Err(GridError::Input(format!("round well grid: {what}")));
        let square = CompositeSpec::new(
            self.lo,
            self.hi,
            self.cells,
            self.center,
            self.zone_half_width,
            self.refine,
            self.well_radius,
        );
        let zone = square.zone_cells().map_err(|e| {
            GridError::Input(e.to_string().replace("composite grid", "round well grid"))
        })?;
        let s = self.interface_spacing();
        let sw = self.well_size.unwrap_or(0.5 * s);
        if !(sw.is_finite() && sw > 0.0) {
            return bad(format!("well_size must be > 0, got {sw}"));
        }
        let r = self.well_radius;
        // The polygon plus one interface spacing of triangles must fit inside the zone.
        let (z0, z1) = self.zone_box(zone);
        let room = (0..2)
            .map(|a| (self.center[a] - z0[a]).min(z1[a] - self.center[a]))
            .fold(f64::INFINITY, f64::min);
        if r + s > room {
            return bad(format!(
                "no room for the well: radius {r} plus the interface spacing {s} exceeds the \
                 distance {room} from the center to the zone boundary"
            ));
        }
        let quarter = (std::f64::consts::TAU * r / (4.0 * sw)).ceil() as usize;
        let n = (4 * quarter).max(MIN_WELL_NODES);
        if n > 1 << 20 {
            return bad(format!("well_size {sw} asks for {n} nodes on the well"));
        }
        Ok((zone, n))
    }

    fn spacing(&self) -> [f64; 2] {
        [
            (self.hi[0] - self.lo[0]) / self.cells[0] as f64,
            (self.hi[1] - self.lo[1]) / self.cells[1] as f64,
        ]
    }

    fn zone_box(&self, ([i0, i1], [j0, j1]): ZoneCells) -> (Point<2>, Point<2>) {
        let h = self.spacing();
        let at = |i: usize, a: usize| {
            if i == self.cells[a] {
                self.hi[a]
            } else {
                self.lo[a] + h[a] * i as f64
            }
        };
        (
            Point::<2>::new(at(i0, 0), at(j0, 1)),
            Point::<2>::new(at(i1 + 1, 0), at(j1 + 1, 1)),
        )
    }

    fn interface_spacing(&self) -> f64 {
        let h = self.spacing();
        h[0].max(h[1]) / self.refine as f64
    }
}

/// Build the round-well grid of `spec` (see the module docs).
///
/// Errors: a bad spec (non-positive sizes, zone not inside the box or holding no coarse
/// cell, `refine = 0`, `well_radius ≤ 0`, a well with no room in the zone, `well_size ≤ 0`)
/// or a triangulation failure.
pub fn round_well(spec: &RoundWellSpec) -> Result<Grid<2>> {
    let (zone, n_well) = spec.layout()?;
    let ([i0, i1], [j0, j1]) = zone;
    let [nx, ny] = spec.cells;
    let r = spec.refine;
    let h = spec.spacing();
    let (lo, hi) = (spec.lo, spec.hi);
    let coarse_x = |i: usize, a: usize, n: usize| {
        if i == n {
            hi[a]
        } else {
            lo[a] + h[a] * i as f64
        }
    };
    let in_zone = |i: usize, j: usize| (i0..=i1).contains(&i) && (j0..=j1).contains(&j);
    let strictly_inside = |i: usize, j: usize| i > i0 && i <= i1 && j > j0 && j <= j1;

    let mut nodes: Vec<Point<2>> = Vec::new();
    let mut coarse_id = vec![usize::MAX; (nx + 1) * (ny + 1)];
    for j in 0..=ny {
        for i in 0..=nx {
            if !strictly_inside(i, j) {
                coarse_id[j * (nx + 1) + i] = nodes.len();
                nodes.push(Point::<2>::new(coarse_x(i, 0, nx), coarse_x(j, 1, ny)));
            }
        }
    }
    // The interface ring: fine lattice points on the zone boundary, counter-clockwise from
    // the lower-left corner; `ring_id` maps a fine lattice index to its node.
    let (fx, fy) = ((i1 - i0 + 1) * r, (j1 - j0 + 1) * r);
    let (z0, z1) = spec.zone_box(zone);
    let mut ring: Vec<usize> = Vec::with_capacity(2 * (fx + fy));
    let mut ring_id = vec![usize::MAX; (fx + 1) * (fy + 1)];
    let walk = (0..fx)
        .map(|ii| (ii, 0))
        .chain((0..fy).map(|jj| (fx, jj)))
        .chain((1..=fx).rev().map(|ii| (ii, fy)))
        .chain((1..=fy).rev().map(|jj| (0, jj)));
    for (ii, jj) in walk {
        let id = if ii % r == 0 && jj % r == 0 {
            coarse_id[(j0 + jj / r) * (nx + 1) + i0 + ii / r]
        } else {
            let x = match ii {
                0 => z0[0],
                _ if ii == fx => z1[0],
                _ => z0[0] + (z1[0] - z0[0]) * ii as f64 / fx as f64,
            };
            let y = match jj {
                0 => z0[1],
                _ if jj == fy => z1[1],
                _ => z0[1] + (z1[1] - z0[1]) * jj as f64 / fy as f64,
            };
            nodes.push(Point::<2>::new(x, y));
            nodes.len() - 1
        };
        ring_id[jj * (fx + 1) + ii] = id;
        ring.push(id);
    }
    let (mut pos, mut cell_nodes) = far_field_cells(
        [nx, ny],
        [i0, j0],
        r,
        in_zone,
        |i, j| coarse_id[j * (nx + 1) + i],
        |ii, jj| ring_id[jj * (fx + 1) + ii],
    );
    let num_coarse = pos.len() - 1;

    // The zone: constrained Delaunay triangulation of the ring and the well polygon.
    let tri_err = |e: spade::InsertionError| {
        GridError::Input(format!("round well grid: triangulation failed: {e}"))
    };
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    // node id of each triangulation vertex (by vertex index); usize::MAX: not yet a node.
    let mut node_of: Vec<usize> = Vec::new();
    let insert = |cdt: &mut ConstrainedDelaunayTriangulation<Point2<f64>>,
                  node_of: &mut Vec<usize>,
                  p: Point<2>,
                  id: usize| {
        let v = cdt.insert(Point2::new(p[0], p[1])).map_err(tri_err)?;
        if node_of.len() <= v.index() {
            node_of.resize(v.index() + 1, usize::MAX);
        }
        node_of[v.index()] = id;
        Ok::<_, GridError>(v)
    };
    let ring_v = ring
        .iter()
        .map(|&id| insert(&mut cdt, &mut node_of, nodes[id], id))
        .collect::<Result<Vec<_>>>()?;
    let (c, rw) = (spec.center, spec.well_radius);
    let mut well_v = Vec::with_capacity(n_well);
    for k in 0..n_well {
        let t = std::f64::consts::TAU * k as f64 / n_well as f64;
        let p = Point::<2>::new(c[0] + rw * t.cos(), c[1] + rw * t.sin());
        nodes.push(p);
        well_v.push(insert(&mut cdt, &mut node_of, p, nodes.len() - 1)?);
    }
    for lp in [&ring_v, &well_v] {
        for k in 0..lp.len() {
            cdt.add_constraint(lp[k], lp[(k + 1) % lp.len()]);
        }
    }
    let s = spec.interface_spacing();
    let result = cdt.refine(
        RefinementParameters::<f64>::new()
            .with_angle_limit(spade::AngleLimit::from_deg(MIN_ANGLE_DEG))
            .with_max_allowed_area(0.25 * 3f64.sqrt() * s * s)
            .keep_constraint_edges()
            .with_max_additional_vertices(1 << 22),
    );
    if !result.refinement_complete {
        return Err(GridError::Input(
            "round well grid: the refinement did not complete".into(),
        ));
    }
    // The Steiner points and then the triangles are numbered row by row (y, then x), as
    // on a lattice: a banded numbering keeps the fill of the factorizations low.
    node_of.resize(cdt.num_vertices(), usize::MAX);
    let mut steiner: Vec<(usize, Point<2>)> = cdt
        .vertices()
        .filter(|v| node_of[v.fix().index()] == usize::MAX)
        .map(|v| {
            (
                v.fix().index(),
                Point::<2>::new(v.position().x, v.position().y),
            )
        })
        .collect();
    let row_order = |a: &Point<2>, b: &Point<2>| a[1].total_cmp(&b[1]).then(a[0].total_cmp(&b[0]));
    steiner.sort_by(|a, b| row_order(&a.1, &b.1));
    for (i, p) in steiner {
        node_of[i] = nodes.len();
        nodes.push(p);
    }
    // Inside the regular polygon: the centroid's projection on its sector's mid-direction
    // is below the apothem.
    let apothem = rw * (std::f64::consts::PI / n_well as f64).cos();
    let sector = std::f64::consts::TAU / n_well as f64;
    let in_well = |p: Point<2>| {
        let d = p - c;
        let phi = d[1].atan2(d[0]).rem_euclid(std::f64::consts::TAU);
        let mid = ((phi / sector).floor() + 0.5) * sector;
        d[0] * mid.cos() + d[1] * mid.sin() < apothem
    };
    let mut triangles: Vec<([usize; 3], Point<2>)> = cdt
        .inner_faces()
        .map(|f| {
            let t = f.vertices().map(|v| node_of[v.fix().index()]);
            (t, (nodes[t[0]] + nodes[t[1]] + nodes[t[2]]) / 3.0)
        })
        .collect();
    triangles.sort_by(|a, b| row_order(&a.1, &b.1));
    let mut well = Vec::new();
    for ([a, b, cc], centroid) in triangles {
        if in_well(centroid) {
            well.push(pos.len() - 1);
        }
        cell_nodes.extend_from_slice(&[a, b, cc]);
        pos.push(cell_nodes.len());
    }
    let mut grid = Grid::from_polygons(nodes, &pos, &cell_nodes)?;
    let num_cells = grid.num_cells();
    grid.set_cell_tag(REFINED_TAG, (num_coarse..num_cells).collect())?;
    grid.set_cell_tag(spec.well_tag.clone(), well)?;
    Ok(grid)
}
