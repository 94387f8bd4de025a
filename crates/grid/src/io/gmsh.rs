//! Gmsh 4.1 ASCII `.msh` reader.
//!
//! Sections read: `$MeshFormat` (must be `4.1 0 …`, ASCII), `$PhysicalNames`,
//! `$Entities` (entity → physical groups), `$Nodes` and `$Elements` (entity blocks).
//! Other sections (`$Periodic`, `$NodeData`, …) are skipped; `$PartitionedEntities` is
//! refused.
//!
//! * Cells are the elements of dimension `D`: triangles (2) and quadrangles (3) in 2D;
//!   tetrahedra (4), hexahedra (5), prisms (6) and pyramids (7) in 3D, in file order.
//! * A physical group of dimension `D` becomes a cell tag, named by `$PhysicalNames` or
//!   `physical_<tag>`. A physical group of dimension `D − 1` (lines in 2D, triangles and
//!   quadrangles in 3D) becomes a face tag: each of its elements is matched to the grid
//!   face with the same node set.
//! * Points (15), and lines (1) in 3D, are accepted and ignored. Any other element type
//!   (second order, …) is an error naming the line and the type.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::io::{Origin, RawMesh, Shape, read_file};
use crate::point::{Point, assert_dim};

/// Read a Gmsh 4.1 ASCII mesh file as a `D`-dimensional grid (see the module docs).
pub fn read_msh<const D: usize>(path: impl AsRef<Path>) -> Result<Grid<D>> {
    let path = path.as_ref();
    let bytes = read_file(path)?;
    let text = String::from_utf8_lossy(&bytes);
    parse_msh::<D>(&text, path)
}

/// Parse the text of a Gmsh 4.1 ASCII mesh; `path` is only used in error messages.
pub fn parse_msh<const D: usize>(text: &str, path: impl AsRef<Path>) -> Result<Grid<D>> {
    const { assert_dim::<D>() };
    let path = path.as_ref();
    Parser::<D>::new(text, path).run()
}

/// Element type → (dimension, number of nodes, cell shape if a supported cell type).
fn element_type(t: i64) -> std::result::Result<(usize, usize, Option<Shape>), String> {
    Ok(match t {
        15 => (0, 1, None),
        1 => (1, 2, None),
        2 => (2, 3, Some(Shape::Triangle)),
        3 => (2, 4, Some(Shape::Quad)),
        4 => (3, 4, Some(Shape::Tetra)),
        5 => (3, 8, Some(Shape::Hexa)),
        6 => (3, 6, Some(Shape::Prism)),
        7 => (3, 5, Some(Shape::Pyramid)),
        _ => {
            let name = match t {
                8 => "second-order line (3 nodes)",
                9 => "second-order triangle (6 nodes)",
                10 => "second-order quadrangle (9 nodes)",
                11 => "second-order tetrahedron (10 nodes)",
                12 => "second-order hexahedron (27 nodes)",
                13 => "second-order prism (18 nodes)",
                14 => "second-order pyramid (14 nodes)",
                16 => "second-order quadrangle (8 nodes)",
                17 => "second-order hexahedron (20 nodes)",
                18 => "second-order prism (15 nodes)",
                19 => "second-order pyramid (13 nodes)",
                _ => "a higher-order or unknown element",
            };
            return Err(format!(
                "unsupported element type {t} ({name}); only first-order points, lines, \
                 triangles, quadrangles, tetrahedra, hexahedra, prisms and pyramids are read"
            ));
        }
    })
}

struct Parser<'a, const D: usize> {
    lines: Vec<&'a str>,
    pos: usize,
    path: &'a Path,
    fields: Vec<&'a str>,
    // $PhysicalNames: (dim, tag) → name
    names: HashMap<(usize, i64), String>,
    // $Entities: (dim, tag) → physical tags
    entities: Option<HashMap<(usize, i64), Vec<i64>>>,
    // $Nodes
    node_index: HashMap<u64, usize>,
    nodes: Vec<Point<D>>,
    node_label: Vec<(u64, usize)>,
    // cells
    loops: CellFaceLoops,
    origin: Vec<Origin>,
    cell_entity: Vec<i64>,
    // (D−1)-dimensional elements: nodes (file indices), line, tag, entity
    face_el_pos: Vec<usize>,
    face_el_nodes: Vec<usize>,
    face_el_info: Vec<(usize, u64, i64)>,
}

fn num<T: std::str::FromStr>(tok: &str) -> Option<T> {
    tok.parse().ok()
}

impl<'a, const D: usize> Parser<'a, D> {
    fn new(text: &'a str, path: &'a Path) -> Self {
        Self {
            lines: text.lines().collect(),
            pos: 0,
            path,
            fields: Vec::new(),
            names: HashMap::new(),
            entities: None,
            node_index: HashMap::new(),
            nodes: Vec::new(),
            node_label: Vec::new(),
            loops: CellFaceLoops::new(),
            origin: Vec::new(),
            cell_entity: Vec::new(),
            face_el_pos: vec![0],
            face_el_nodes: Vec::new(),
            face_el_info: Vec::new(),
        }
    }

    fn err(&self, line: usize, what: impl Into<String>) -> GridError {
        GridError::Parse {
            path: self.path.to_path_buf(),
            line,
            what: what.into(),
        }
    }

    /// The next non-blank line: (line number, trimmed text), or `None` at the end.
    fn next_line(&mut self) -> Option<(usize, &'a str)> {
        while self.pos < self.lines.len() {
            let l = self.lines[self.pos].trim();
            self.pos += 1;
            if !l.is_empty() {
                return Some((self.pos, l));
            }
        }
        None
    }

    /// The next line split into whitespace-separated fields (in `self.fields`).
    fn record(&mut self, ctx: &str) -> Result<usize> {
        let Some((line, text)) = self.next_line() else {
            return Err(self.err(
                self.lines.len().max(1),
                format!("unexpected end of file in {ctx}"),
            ));
        };
        if text.starts_with('$') {
            return Err(self.err(
                line,
                format!("expected {ctx}, found `{text}` (fewer entries than declared?)"),
            ));
        }
        self.fields.clear();
        self.fields.extend(text.split_whitespace());
        Ok(line)
    }

    /// Parse field `k` of the current record.
    fn field<T: std::str::FromStr>(&self, line: usize, k: usize, what: &str) -> Result<T> {
        let tok = self.fields.get(k).copied().unwrap_or("");
        num(tok).ok_or_else(|| {
            if tok.is_empty() {
                self.err(line, format!("missing {what}"))
            } else {
                self.err(line, format!("bad {what} `{tok}`"))
            }
        })
    }

    fn expect_count(&self, line: usize, n: usize, what: &str) -> Result<()> {
        if self.fields.len() != n {
            return Err(self.err(
                line,
                format!(
                    "expected {n} value(s) ({what}), found {}",
                    self.fields.len()
                ),
            ));
        }
        Ok(())
    }

    fn expect_end(&mut self, section: &str) -> Result<()> {
        let end = format!("$End{section}");
        match self.next_line() {
            Some((_, l)) if l == end => Ok(()),
            Some((line, l)) => Err(self.err(
                line,
                format!("expected {end}, found `{l}` (more entries than declared?)"),
            )),
            None => Err(self.err(
                self.lines.len().max(1),
                format!("unexpected end of file: missing {end}"),
            )),
        }
    }

    fn run(mut self) -> Result<Grid<D>> {
        let mut seen_format = false;
        let mut seen: Vec<&str> = Vec::new();
        while let Some((line, l)) = self.next_line() {
            let Some(name) = l.strip_prefix('$') else {
                return Err(self.err(
                    line,
                    format!("expected a section header such as $Nodes, found `{l}`"),
                ));
            };
            if !seen_format && name != "MeshFormat" {
                return Err(self.err(line, "the file does not start with $MeshFormat"));
            }
            if seen.contains(&name) {
                return Err(self.err(line, format!("section ${name} appears twice")));
            }
            seen.push(name);
            match name {
                "MeshFormat" => {
                    self.mesh_format()?;
                    seen_format = true;
                }
                "PhysicalNames" => self.physical_names()?,
                "Entities" => self.entities_section()?,
                "Nodes" => self.nodes_section()?,
                "Elements" => {
                    if !seen.contains(&"Nodes") {
                        return Err(self.err(line, "$Elements without a preceding $Nodes section"));
                    }
                    self.elements_section()?;
                }
                "PartitionedEntities" | "Parametrizations" => {
                    return Err(self.err(
                        line,
                        format!("section ${name} is not supported (save an unpartitioned mesh)"),
                    ));
                }
                _ => {
                    let end = format!("$End{name}");
                    loop {
                        match self.next_line() {
                            Some((_, l)) if l == end => break,
                            Some(_) => {}
                            None => {
                                return Err(self
                                    .err(line, format!("section ${name} is not closed by {end}")));
                            }
                        }
                    }
                }
            }
        }
        let last = self.lines.len().max(1);
        if !seen_format {
            return Err(self.err(last, "not a Gmsh file: no $MeshFormat section"));
        }
        for s in ["Nodes", "Elements"] {
            if !seen.contains(&s) {
                return Err(self.err(last, format!("missing ${s} section")));
            }
        }
        self.finish()
    }

    fn mesh_format(&mut self) -> Result<()> {
        let line = self.record("the mesh format `4.1 0 8`")?;
        self.expect_count(line, 3, "version, file type, data size")?;
        let version = self.fields[0];
        if version != "4.1" {
            return Err(self.err(
                line,
                format!(
                    "Gmsh format version {version} is not supported; save the mesh as \
                     version 4.1 ASCII (gmsh -format msh41)"
                ),
            ));
        }
        let kind: i64 = self.field(line, 1, "file type")?;
        if kind != 0 {
            return Err(self.err(
                line,
                "binary .msh files are not supported; save the mesh as ASCII",
            ));
        }
        let size: i64 = self.field(line, 2, "data size")?;
        if size != 8 {
            return Err(self.err(line, format!("data size {size} is not supported (8)")));
        }
        self.expect_end("MeshFormat")
    }

    fn physical_names(&mut self) -> Result<()> {
        let line = self.record("the number of physical names")?;
        self.expect_count(line, 1, "number of physical names")?;
        let n: usize = self.field(line, 0, "number of physical names")?;
        for _ in 0..n {
            let Some((line, l)) = self.next_line() else {
                return Err(self.err(
                    self.lines.len().max(1),
                    "unexpected end of file in $PhysicalNames",
                ));
            };
            let (head, rest) = l.split_at(l.find('"').unwrap_or(l.len()));
            let mut it = head.split_whitespace();
            let dim: Option<usize> = it.next().and_then(num);
            let tag: Option<i64> = it.next().and_then(num);
            let name = rest
                .trim_end()
                .strip_prefix('"')
                .and_then(|r| r.strip_suffix('"'))
                .filter(|_| it.next().is_none());
            match (dim, tag, name) {
                (Some(dim), Some(tag), Some(name)) if dim <= 3 => {
                    self.names.insert((dim, tag), name.to_string());
                }
                _ => {
                    return Err(self.err(
                        line,
                        format!("expected `dimension tag \"name\"`, found `{l}`"),
                    ));
                }
            }
        }
        self.expect_end("PhysicalNames")
    }

    fn entities_section(&mut self) -> Result<()> {
        let line = self.record("the entity counts")?;
        self.expect_count(line, 4, "numbers of points, curves, surfaces, volumes")?;
        let mut counts = [0usize; 4];
        for (k, c) in counts.iter_mut().enumerate() {
            *c = self.field(line, k, "entity count")?;
        }
        let mut map = HashMap::new();
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let line = self.record(&format!("a {dim}D entity"))?;
                let tag: i64 = self.field(line, 0, "entity tag")?;
                let first = if dim == 0 { 4 } else { 7 };
                for k in 1..first {
                    let x: f64 = self.field(line, k, "coordinate")?;
                    let _ = x;
                }
                let np: usize = self.field(line, first, "number of physical tags")?;
                let mut phys = Vec::new();
                for k in 0..np {
                    phys.push(self.field::<i64>(line, first + 1 + k, "physical tag")?);
                }
                let mut expected = first + 1 + np;
                if dim > 0 {
                    let nb: usize = self.field(line, expected, "number of bounding entities")?;
                    for k in 0..nb {
                        self.field::<i64>(line, expected + 1 + k, "bounding entity tag")?;
                    }
                    expected += 1 + nb;
                }
                self.expect_count(line, expected, &format!("{dim}D entity record"))?;
                if map.insert((dim, tag), phys).is_some() {
                    return Err(self.err(line, format!("{dim}D entity {tag} defined twice")));
                }
            }
        }
        self.entities = Some(map);
        self.expect_end("Entities")
    }

    fn nodes_section(&mut self) -> Result<()> {
        let header = self.record("the $Nodes header")?;
        self.expect_count(header, 4, "numEntityBlocks numNodes minNodeTag maxNodeTag")?;
        let blocks: usize = self.field(header, 0, "number of entity blocks")?;
        let total: usize = self.field(header, 1, "number of nodes")?;
        let mut z0: Option<(f64, usize)> = None;
        let mut tags = Vec::new();
        for _ in 0..blocks {
            let bl = self.record("a node block header")?;
            self.expect_count(bl, 4, "entityDim entityTag parametric numNodesInBlock")?;
            let edim: usize = self.field(bl, 0, "entity dimension")?;
            let parametric: u8 = self.field(bl, 2, "parametric flag")?;
            let n: usize = self.field(bl, 3, "number of nodes in the block")?;
            if edim > 3 || parametric > 1 {
                return Err(self.err(bl, "bad node block header"));
            }
            if self.nodes.len().saturating_add(n) > total {
                return Err(self.err(
                    bl,
                    format!("node blocks hold more nodes than the {total} declared in the header"),
                ));
            }
            tags.clear();
            for _ in 0..n {
                let line = self.record("a node tag")?;
                self.expect_count(line, 1, "node tag")?;
                let t: u64 = self.field(line, 0, "node tag")?;
                tags.push((t, line));
            }
            let ncoord = 3 + if parametric == 1 { edim } else { 0 };
            for &(t, tag_line) in &tags {
                let line = self.record("node coordinates `x y z`")?;
                self.expect_count(line, ncoord, "node coordinates")?;
                let mut x = [0.0f64; 3];
                for (k, xk) in x.iter_mut().enumerate() {
                    *xk = self.field(line, k, "coordinate")?;
                    if !xk.is_finite() {
                        return Err(
                            self.err(line, format!("non-finite coordinate `{}`", self.fields[k]))
                        );
                    }
                }
                if D == 2 {
                    match z0 {
                        None => z0 = Some((x[2], line)),
                        Some((z, l0)) if z != x[2] => {
                            return Err(self.err(
                                line,
                                format!(
                                    "z = {} differs from z = {z} on line {l0}: a 2D mesh must \
                                     lie in a plane z = const",
                                    x[2]
                                ),
                            ));
                        }
                        _ => {}
                    }
                }
                if self.node_index.insert(t, self.nodes.len()).is_some() {
                    return Err(self.err(tag_line, format!("node tag {t} defined twice")));
                }
                self.nodes.push(Point::<D>::from_fn(|a, _| x[a]));
                self.node_label.push((t, line));
            }
        }
        if self.nodes.len() != total {
            return Err(self.err(
                header,
                format!(
                    "the header declares {total} nodes but the blocks hold {}",
                    self.nodes.len()
                ),
            ));
        }
        self.expect_end("Nodes")
    }

    fn elements_section(&mut self) -> Result<()> {
        let header = self.record("the $Elements header")?;
        self.expect_count(
            header,
            4,
            "numEntityBlocks numElements minElementTag maxElementTag",
        )?;
        let blocks: usize = self.field(header, 0, "number of entity blocks")?;
        let total: usize = self.field(header, 1, "number of elements")?;
        let mut count = 0usize;
        let mut v = Vec::with_capacity(8);
        for _ in 0..blocks {
            let bl = self.record("an element block header")?;
            self.expect_count(bl, 4, "entityDim entityTag elementType numElementsInBlock")?;
            let edim: usize = self.field(bl, 0, "entity dimension")?;
            let etag: i64 = self.field(bl, 1, "entity tag")?;
            let etype: i64 = self.field(bl, 2, "element type")?;
            let n: usize = self.field(bl, 3, "number of elements in the block")?;
            let (tdim, nn, shape) = element_type(etype).map_err(|w| self.err(bl, w))?;
            if tdim != edim {
                return Err(self.err(
                    bl,
                    format!("element type {etype} has dimension {tdim}, but the block's entity has dimension {edim}"),
                ));
            }
            if tdim > D {
                return Err(self.err(
                    bl,
                    format!("{tdim}D elements (type {etype}) in a mesh read as {D}D"),
                ));
            }
            count = count.saturating_add(n);
            if count > total {
                return Err(self.err(
                    bl,
                    format!(
                        "element blocks hold more elements than the {total} declared in the header"
                    ),
                ));
            }
            if let (Some(map), true) = (&self.entities, tdim + 1 >= D)
                && !map.contains_key(&(edim, etag))
            {
                return Err(self.err(
                    bl,
                    format!("entity ({edim}D, tag {etag}) is not listed in $Entities"),
                ));
            }
            for _ in 0..n {
                let line = self.record(&format!("an element line `tag` + {nn} node tags"))?;
                self.expect_count(line, 1 + nn, &format!("element tag and {nn} node tags"))?;
                let tag: u64 = self.field(line, 0, "element tag")?;
                v.clear();
                for k in 0..nn {
                    let t: u64 = self.field(line, 1 + k, "node tag")?;
                    let Some(&i) = self.node_index.get(&t) else {
                        return Err(self.err(
                            line,
                            format!("element {tag}: node tag {t} is not defined in $Nodes"),
                        ));
                    };
                    if v.contains(&i) {
                        return Err(
                            self.err(line, format!("element {tag}: node tag {t} appears twice"))
                        );
                    }
                    v.push(i);
                }
                if tdim == D {
                    // Only supported cell types reach here (element_type checked).
                    if let Some(shape) = shape {
                        shape.push(&mut self.loops, &v);
                        self.origin.push(Origin {
                            line,
                            tag,
                            standard: true,
                        });
                        self.cell_entity.push(etag);
                    }
                } else if tdim + 1 == D {
                    self.face_el_nodes.extend_from_slice(&v);
                    self.face_el_pos.push(self.face_el_nodes.len());
                    self.face_el_info.push((line, tag, etag));
                }
            }
        }
        if count != total {
            return Err(self.err(
                header,
                format!("the header declares {total} elements but the blocks hold {count}"),
            ));
        }
        self.expect_end("Elements")
    }

    fn group_name(&self, dim: usize, tag: i64) -> String {
        self.names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical_{tag}"))
    }

    fn finish(mut self) -> Result<Grid<D>> {
        let raw = RawMesh::<D> {
            nodes: std::mem::take(&mut self.nodes),
            node_label: self.node_label.clone(),
            loops: std::mem::take(&mut self.loops),
            origin: std::mem::take(&mut self.origin),
            what_cell: "Gmsh element",
            what_node: "Gmsh node",
        };
        let built = raw.build(self.path)?;
        let mut grid = built.grid;
        let empty = HashMap::new();
        let entities = self.entities.as_ref().unwrap_or(&empty);
        // Named groups of the two relevant dimensions exist even when empty.
        let mut cell_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        let mut face_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for &(dim, tag) in self.names.keys() {
            if dim == D {
                cell_tags.entry(self.group_name(dim, tag)).or_default();
            } else if dim + 1 == D {
                face_tags.entry(self.group_name(dim, tag)).or_default();
            }
        }
        for (c, e) in self.cell_entity.iter().enumerate() {
            for &p in entities.get(&(D, *e)).map(Vec::as_slice).unwrap_or(&[]) {
                cell_tags.entry(self.group_name(D, p)).or_default().push(c);
            }
        }
        // Faces: node → faces incidence, then match node sets.
        let nf = grid.num_faces();
        let mut node_face_pos = vec![0usize; grid.num_nodes() + 1];
        for f in 0..nf {
            for &n in grid.face_nodes(f) {
                node_face_pos[n + 1] += 1;
            }
        }
        for n in 0..grid.num_nodes() {
            node_face_pos[n + 1] += node_face_pos[n];
        }
        let mut fill = node_face_pos.clone();
        let mut node_faces = vec![0usize; node_face_pos[grid.num_nodes()]];
        for f in 0..nf {
            for &n in grid.face_nodes(f) {
                node_faces[fill[n]] = f;
                fill[n] += 1;
            }
        }
        let mut mapped = Vec::with_capacity(4);
        for (k, &(line, tag, etag)) in self.face_el_info.iter().enumerate() {
            let phys = entities
                .get(&(D - 1, etag))
                .map(Vec::as_slice)
                .unwrap_or(&[]);
            if phys.is_empty() {
                continue;
            }
            mapped.clear();
            for &i in &self.face_el_nodes[self.face_el_pos[k]..self.face_el_pos[k + 1]] {
                let m = built.node_map[i];
                if m == usize::MAX {
                    return Err(self.err(
                        line,
                        format!(
                            "element {tag} (physical group `{}`) uses node tag {}, which belongs to no cell",
                            self.group_name(D - 1, phys[0]),
                            self.node_label[i].0
                        ),
                    ));
                }
                mapped.push(m);
            }
            let n0 = mapped[0];
            let face = node_faces[node_face_pos[n0]..node_face_pos[n0 + 1]]
                .iter()
                .copied()
                .find(|&f| {
                    let fnodes = grid.face_nodes(f);
                    fnodes.len() == mapped.len() && mapped.iter().all(|n| fnodes.contains(n))
                });
            let Some(face) = face else {
                return Err(self.err(
                    line,
                    format!(
                        "element {tag} (physical group `{}`) does not match a face of the grid",
                        self.group_name(D - 1, phys[0])
                    ),
                ));
            };
            for &p in phys {
                face_tags
                    .entry(self.group_name(D - 1, p))
                    .or_default()
                    .push(face);
            }
        }
        let in_file = |e: GridError| GridError::InFile {
            path: self.path.to_path_buf(),
            source: Box::new(e),
        };
        for (name, cells) in cell_tags {
            grid.set_cell_tag(name, cells).map_err(in_file)?;
        }
        for (name, faces) in face_tags {
            grid.set_face_tag(name, faces).map_err(in_file)?;
        }
        Ok(grid)
    }
}
