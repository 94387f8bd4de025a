//! Corner-point grids from Eclipse GRDECL decks.
//!
//! # Reading ([`read_deck`])
//!
//! Keywords, in any order and any case: `SPECGRID` or `DIMENS` (`nx ny nz`, before the
//! arrays), `COORD`, `ZCORN`, `ACTNUM`, `MAPAXES` (kept in [`Deck::mapaxes`], not
//! applied: the grid stays in the deck's coordinates), `GRIDUNIT`, the unit systems
//! `METRIC` (default), `FIELD` (feet) and `LAB` (centimetres), and the cell properties
//! `PORO`, `PERMX`, `PERMY`, `PERMZ` (millidarcy), `NTG`, `MULTPV`, and the faults:
//! `FAULTS` (named segments `'name' i1 i2 j1 j2 k1 k2 'face'`) with `MULTFLT`
//! (transmissibility multipliers by fault name; [`CornerPointGrid::fault_faces`] gives a
//! fault's faces). `INCLUDE` reads a file
//! relative to the including one (the name as written, then in upper and in lower case),
//! at most 16 deep, refusing cycles. Records end with `/`; `--` starts a comment; `n*v`
//! repeats `v` `n` times. Other keywords are skipped (listed in [`Deck::skipped`]): their
//! record up to `/`, or nothing when a known keyword follows first. Reading stops at the
//! first of the sections after `GRID` and `EDIT` (`PROPS`, `REGIONS`, `SOLUTION`,
//! `SUMMARY`, `SCHEDULE`), which hold no grid data, so that a whole simulation deck
//! (`.DATA`) can be read for its grid. Lengths are converted
//! to metres and permeabilities to m² ([`MILLIDARCY`]). [`check_cell_properties`]
//! checks the properties of the grid's cells for flow, naming keyword, file, line and
//! cell.
//!
//! **Units.** `GRIDUNIT` (`METRES`, `FEET` or `CM`, the first item; padded quoted names
//! such as `'METRES  '` as RMS and xtgeo write them), when given, is the unit of `COORD`
//! and `ZCORN` (the grid's own lengths); without it the unit system is
//! (`METRIC` metres, `FIELD` feet, `LAB` centimetres). The two never multiply: a cube of
//! 10 units under `FIELD` and `GRIDUNIT METRES` is 1000 m³.
//!
//! The file is read through a buffer, token by token, straight into the arrays: the text
//! is never held whole. A line may have at most [`MAX_LINE_BYTES`] (1 MiB), and so may a
//! token; a longer line (a file without newlines) is an error at that line. A path that
//! is not a regular file (a directory, a device such as `/dev/zero`, a FIFO) is refused
//! before it is opened, as the deck or as an `INCLUDE`. Errors name the file, the 1-based
//! line and the keyword; a wrong count says how many values the keyword needs and why
//! (`ZCORN has 7 values, needs 8 (8 × nx × ny × nz = 8 × 1 × 1 × 1, …)`); an `INCLUDE`
//! cycle is reported at the `INCLUDE` that closes it, with the chain of files. User text
//! repeated in a message is cut to its first 60 characters and its length. The size is
//! checked (at most 2³¹ cells) before anything is allocated for it, and no array grows
//! past its keyword's count (a repeat count `n*v` is checked against the values still
//! missing before any is pushed).
//!
//! # Processing ([`corner_point_grid`])
//!
//! The way reservoir codes process corner-point grids, into a [`Grid<3>`](crate::Grid):
//!
//! * **Pillars.** Every pillar is the line through its two `COORD` points; a corner at
//!   depth `z` is the point of its pillar at that depth. The corner depths of the active
//!   cells around a pillar, merged within the tolerance, are the pillar's nodes.
//! * **Cells.** Cells with `ACTNUM = 0` are left out, and so are cells whose thickness is
//!   within the tolerance at all four pillars (*pinched*). Cells are numbered in deck
//!   order (`i` fastest, then `j`, then `k`) and keep their `(i, j, k)`
//!   ([`CornerPointGrid::ijk`]). A cell whose bottom is above its top, or two cells of a
//!   column that overlap, is an error naming them in the deck's 1-based indices.
//! * **Faces between layers.** Each cell has its top and bottom faces; two cells of a
//!   column whose faces have the same corners share them — also across pinched layers,
//!   whose cells have vanished between them.
//! * **Faces between columns, and faults.** The side faces of two neighbouring columns lie
//!   on the surface between their two common pillars, parametrized by `s ∈ [0, 1]` from
//!   one pillar to the other and the depth `z`. There a cell's side is the quadrilateral
//!   between its top and bottom lines, linear in `s`. Each column's cells and the gaps
//!   between them (inactive cells, the space above and below) split the surface; the
//!   overlap of an element of one side with one of the other is a convex polygon in
//!   `(s, z)` (between `max` of the two tops and `min` of the two bottoms), found by a
//!   sweep down both columns. An overlap of two cells is a face they share; an overlap of
//!   a cell with a gap is a boundary face of the cell. Where the columns match, each
//!   overlap is the whole side face; across a fault (corners that differ) the side faces
//!   split into the overlapping sub-faces, whose corners inside the surface are new nodes
//!   at `(1 − s) P₀(z) + s P₁(z)`.
//! * **Closed cells.** A node lying on the edge of a face is a node of that face: the
//!   pillar nodes between two corners of a side face, and the nodes inside a pillar-pair
//!   surface on the top or bottom line of a cell. So every cell is a closed polyhedron and
//!   every sub-face has its two cells. Faces are polygons of any number of nodes, split
//!   into triangles about their vertex average like every grid face (non-planar faces as
//!   in reservoir codes). A face is oriented by how it was made (the corner order of a
//!   top or bottom, the `(s, z)` order of a sub-face) and by whether the deck's `i`, `j`
//!   and depth are right- or left-handed (`GDORIENT … RIGHT` or `LEFT`), never from its
//!   normal against the cell's centre, which a thin or partly pinched cell makes
//!   unreliable. A face whose loop passes twice through a node (corners of a pinched
//!   cell meeting) is split there into simple loops, and loops of fewer than three nodes
//!   are dropped. The grid is validated as every grid is; a cell it refuses is named by
//!   its `(i, j, k)`. A known limit: a cell millimetres thin at some corners and metres
//!   at others, with nodes of a fault on one face only, can have its triangulated top
//!   cross its bottom (the vertex averages differ): its volume is still that of its
//!   triangulated faces, and a cell whose crossing outweighs it is refused as inverted.
//! * **Outer faces** are tagged by the ijk side they face: `imin`, `imax`, `jmin`, `jmax`,
//!   `kmin` (top, Eclipse's convention of depth growing with `k`) and `kmax` (bottom),
//!   including faces towards inactive cells and across a fault's throw.
//!
//! Depths are kept as they are (`z` grows downwards, as in the deck). The tolerance is
//! [`RELATIVE_TOLERANCE`] times the largest depth of the deck (map coordinates, often in
//! the millions, do not count).

mod deck;
mod process;

pub use deck::{
    CellProperties, Deck, DeckLimit, FaultFace, FaultSegment, MAX_DECK_CELLS, MAX_LINE_BYTES,
    MILLIDARCY, Units, read_deck, read_deck_with,
};
pub use process::{CornerPointGrid, IJK_SIDES, RELATIVE_TOLERANCE, corner_point_grid, fault_faces};

use std::path::Path;

use crate::error::{GridError, Result};

/// Read a deck and process it into a grid; grid errors name the file.
pub fn read_grdecl(path: impl AsRef<Path>) -> Result<(Deck, CornerPointGrid)> {
    read_grdecl_with(path, &DeckLimit::default())
}

/// [`read_grdecl`] with a bound on the deck's size.
pub fn read_grdecl_with(
    path: impl AsRef<Path>,
    limit: &DeckLimit,
) -> Result<(Deck, CornerPointGrid)> {
    let path = path.as_ref();
    let deck = read_deck_with(path, limit)?;
    let grid = corner_point_grid(&deck).map_err(|e| GridError::InFile {
        path: path.to_path_buf(),
        source: Box::new(e),
    })?;
    Ok((deck, grid))
}

/// Check the cell properties of the deck's cells in the grid (active, not pinched: the
/// values of other cells are never used) as flow uses them: `PORO` in (0, 1], `PERMX`,
/// `PERMY`, `PERMZ` finite and ≥ 0, `NTG` in [0, 1], `MULTPV` finite and ≥ 0, and the
/// pore fraction `PORO × NTG × MULTPV` in (0, 1]. The first bad value, in deck order, is
/// an error naming the keyword, the file and line it was read at, and the cell's 1-based
/// `(i, j, k)`.
pub fn check_cell_properties(deck: &Deck, cp: &CornerPointGrid) -> Result<()> {
    let p = &deck.properties;
    let at = |word: &str, what: String| {
        let (path, line) = deck
            .keyword_lines
            .iter()
            .rev()
            .find(|(w, _, _)| w == word)
            .map_or((Default::default(), 0), |(_, f, l)| (f.clone(), *l));
        GridError::Parse { path, line, what }
    };
    let cell = |c: usize| {
        let [i, j, k] = cp.ijk[c];
        format!("cell (i, j, k) = ({}, {}, {})", i + 1, j + 1, k + 1)
    };
    let value = |v: &Option<Vec<f64>>, d: usize| v.as_ref().map(|v| v[d]);
    for (c, &d) in cp.deck_cell.iter().enumerate() {
        let poro = value(&p.poro, d);
        if let Some(v) = poro.filter(|v| !(*v > 0.0 && *v <= 1.0)) {
            return Err(at(
                "PORO",
                format!("PORO of {} is {v}; porosity must be in (0, 1]", cell(c)),
            ));
        }
        for (word, perm) in ["PERMX", "PERMY", "PERMZ"].iter().zip(&p.perm) {
            if let Some(v) = value(perm, d).filter(|v| !(v.is_finite() && *v >= 0.0)) {
                let md = (v / MILLIDARCY * 1e9).round() / 1e9;
                return Err(at(
                    word,
                    format!(
                        "{word} of {} is {md} mD; permeability must be finite and ≥ 0",
                        cell(c)
                    ),
                ));
            }
        }
        let ntg = value(&p.ntg, d);
        if let Some(v) = ntg.filter(|v| !(0.0..=1.0).contains(v)) {
            return Err(at(
                "NTG",
                format!("NTG of {} is {v}; net-to-gross must be in [0, 1]", cell(c)),
            ));
        }
        let multpv = value(&p.multpv, d);
        if let Some(v) = multpv.filter(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(at(
                "MULTPV",
                format!(
                    "MULTPV of {} is {v}; a pore-volume multiplier must be finite and ≥ 0",
                    cell(c)
                ),
            ));
        }
        if let Some(poro) = poro {
            let (n, m) = (ntg.unwrap_or(1.0), multpv.unwrap_or(1.0));
            let phi = poro * n * m;
            if !(phi > 0.0 && phi <= 1.0) {
                let word = if n == 0.0 || m == 0.0 || multpv.is_none() {
                    "NTG"
                } else {
                    "MULTPV"
                };
                return Err(at(
                    word,
                    format!(
                        "PORO × NTG × MULTPV of {} is {poro} × {n} × {m} = {phi}; the pore \
                         fraction must be in (0, 1]",
                        cell(c)
                    ),
                ));
            }
        }
    }
    Ok(())
}
