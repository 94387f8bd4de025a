//! Gmsh 4.1 `.msh` reader, ASCII and binary: what is read and the binary layout are in
//! "Reading Gmsh files" of the [`crate::io`] module docs.
//!
//! One parser serves both formats: `Records` reads a section's records as lines of
//! whitespace-separated numbers in text, or as fixed-size values in binary data, behind
//! the same calls (`begin`, `int`, `size`, `float`, `end`), and each section is parsed
//! once on top of it.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::io::{Origin, RawMesh, Shape, read_file};
use crate::point::{Point, assert_dim};

/// Read a Gmsh 4.1 mesh file, ASCII or binary, as a `D`-dimensional grid (see the
/// [`io`](crate::io) module docs).
pub fn read_msh<const D: usize>(path: impl AsRef<Path>) -> Result<Grid<D>> {
    let path = path.as_ref();
    let bytes = read_file(path)?;
    parse_msh_bytes::<D>(&bytes, path)
}

/// Parse the text of a Gmsh 4.1 ASCII mesh; `path` is only used in error messages.
pub fn parse_msh<const D: usize>(text: &str, path: impl AsRef<Path>) -> Result<Grid<D>> {
    parse_msh_bytes::<D>(text.as_bytes(), path)
}

/// Parse a Gmsh 4.1 mesh, ASCII or binary, from its bytes; `path` is only used in error
/// messages.
pub fn parse_msh_bytes<const D: usize>(bytes: &[u8], path: impl AsRef<Path>) -> Result<Grid<D>> {
    const { assert_dim::<D>() };
    let path = path.as_ref();
    Parser::<D>::new(bytes, path).run()
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

/// How the numbers of the current section are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Data {
    Text,
    Binary { big_endian: bool },
}

/// A position for error messages: a line in text, a byte offset in binary data.
#[derive(Clone, Copy, Debug)]
struct Mark(usize);

/// The file as records, read the same way whether they are text or binary.
///
/// Section headers, `$PhysicalNames` and every section of an ASCII file are lines; in a
/// binary file the data of `$Entities`, `$Nodes` and `$Elements` are fixed-size values.
/// A record is opened with [`Records::begin`] (the next non-blank line in text, nothing in
/// binary), its values are taken with [`Records::int`] (`int`: 4 bytes in binary),
/// [`Records::size`] (`size_t`: 8 bytes) and [`Records::float`] (`double`: 8 bytes),
/// and it is closed with [`Records::end`] (in text: no value may be left on the line).
/// Each section is therefore parsed by one function for both formats.
struct Records<'a> {
    bytes: &'a [u8],
    path: &'a Path,
    /// Byte cursor.
    pos: usize,
    /// Lines counted up to `line_pos` (newlines inside binary data included).
    line: usize,
    line_pos: usize,
    /// Number of lines of the file, as `str::lines` counts them (for end-of-file errors).
    last_line: usize,
    /// Format of the data sections (from `$MeshFormat`) and of the current section.
    file_data: Data,
    data: Data,
    /// Current section and the line of its header.
    section: &'a str,
    section_line: usize,
    /// Current record: where it starts, and in text its fields.
    mark: Mark,
    fields: Vec<&'a str>,
    next: usize,
}

impl<'a> Records<'a> {
    fn new(bytes: &'a [u8], path: &'a Path) -> Self {
        let newlines = memchr::memchr_iter(b'\n', bytes).count();
        let last_line = newlines + usize::from(bytes.last().is_some_and(|&b| b != b'\n'));
        Self {
            bytes,
            path,
            pos: 0,
            line: 0,
            line_pos: 0,
            last_line: last_line.max(1),
            file_data: Data::Text,
            data: Data::Text,
            section: "",
            section_line: 0,
            mark: Mark(0),
            fields: Vec::new(),
            next: 0,
        }
    }

    fn err_line(&self, line: usize, what: impl Into<String>) -> GridError {
        GridError::Parse {
            path: self.path.to_path_buf(),
            line,
            what: what.into(),
        }
    }

    /// An error at `m` in the current section.
    fn err_at(&self, m: Mark, what: impl std::fmt::Display) -> GridError {
        match self.data {
            Data::Text => self.err_line(m.0, what.to_string()),
            Data::Binary { .. } => self.err_line(
                self.section_line,
                format!("${} (binary data, byte {}): {what}", self.section, m.0),
            ),
        }
    }

    /// An error in the current record.
    fn err(&self, what: impl std::fmt::Display) -> GridError {
        self.err_at(self.mark, what)
    }

    fn eof(&self, what: impl std::fmt::Display) -> GridError {
        self.err_line(self.last_line, what.to_string())
    }

    /// The line of `m` for node and element labels: 0 in binary data.
    fn line_of(&self, m: Mark) -> usize {
        match self.data {
            Data::Text => m.0,
            Data::Binary { .. } => 0,
        }
    }

    /// Where the current record starts.
    fn mark(&self) -> Mark {
        self.mark
    }

    /// Enter section `name` (header on `line`); `binary_data`: its data are binary in a
    /// binary file.
    fn enter(&mut self, name: &'a str, line: usize, binary_data: bool) {
        self.section = name;
        self.section_line = line;
        self.data = if binary_data {
            self.file_data
        } else {
            Data::Text
        };
    }

    /// The next non-blank line, trimmed, with its 1-based number; `None` at the end.
    fn next_line(&mut self) -> Option<(usize, &'a [u8])> {
        if self.line_pos < self.pos {
            // Binary data were read since the last line.
            self.line += memchr::memchr_iter(b'\n', &self.bytes[self.line_pos..self.pos]).count();
        }
        while self.pos < self.bytes.len() {
            let rest = &self.bytes[self.pos..];
            let n = memchr::memchr(b'\n', rest).unwrap_or(rest.len());
            self.pos = (self.pos + n + 1).min(self.bytes.len());
            self.line += 1;
            let l = rest[..n].trim_ascii();
            if !l.is_empty() {
                self.line_pos = self.pos;
                return Some((self.line, l));
            }
        }
        self.line_pos = self.pos;
        None
    }

    /// `l` (line `line`) as text.
    fn text(&self, line: usize, l: &'a [u8]) -> Result<&'a str> {
        std::str::from_utf8(l).map_err(|_| {
            self.err_line(
                line,
                "expected text, found binary bytes (a binary file saved without \
                 `4.1 1 8` in $MeshFormat?)",
            )
        })
    }

    /// Open the next record; `ctx` says what is expected, for errors.
    fn begin(&mut self, ctx: &str) -> Result<()> {
        if let Data::Binary { .. } = self.data {
            self.mark = Mark(self.pos);
            return Ok(());
        }
        let Some((line, l)) = self.next_line() else {
            return Err(self.eof(format!("unexpected end of file in {ctx}")));
        };
        self.mark = Mark(line);
        let l = self.text(line, l)?;
        if l.starts_with('$') {
            return Err(self.err(format!(
                "expected {ctx}, found `{l}` (fewer entries than declared?)"
            )));
        }
        self.fields.clear();
        self.fields.extend(l.split_ascii_whitespace());
        self.next = 0;
        Ok(())
    }

    /// The next text field of the record.
    fn token(&mut self, what: &str) -> Result<&'a str> {
        let tok = self.fields.get(self.next).copied();
        self.next += 1;
        tok.ok_or_else(|| self.err(format!("missing {what}")))
    }

    fn parse<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        let tok = self.token(what)?;
        tok.parse()
            .map_err(|_| self.err(format!("bad {what} `{tok}`")))
    }

    /// The next `N` bytes of binary data.
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N]> {
        let Some(b) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(self.err_at(
                Mark(self.pos),
                format!(
                    "the file ends inside the data ({what}: {N} bytes needed, {} left); is \
                     it cut short?",
                    self.bytes.len() - self.pos
                ),
            ));
        };
        self.pos += N;
        Ok(b.try_into().unwrap_or([0; N]))
    }

    /// An `int` (4 bytes in binary).
    fn int(&mut self, what: &str) -> Result<i64> {
        match self.data {
            Data::Text => self.parse(what),
            Data::Binary { big_endian } => {
                let b = self.take::<4>(what)?;
                Ok(i64::from(if big_endian {
                    i32::from_be_bytes(b)
                } else {
                    i32::from_le_bytes(b)
                }))
            }
        }
    }

    /// A `size_t` (8 bytes in binary).
    fn size(&mut self, what: &str) -> Result<u64> {
        match self.data {
            Data::Text => self.parse(what),
            Data::Binary { big_endian } => {
                let b = self.take::<8>(what)?;
                Ok(if big_endian {
                    u64::from_be_bytes(b)
                } else {
                    u64::from_le_bytes(b)
                })
            }
        }
    }

    /// A `double` (8 bytes in binary).
    fn float(&mut self, what: &str) -> Result<f64> {
        match self.data {
            Data::Text => self.parse(what),
            Data::Binary { big_endian } => {
                let b = self.take::<8>(what)?;
                Ok(if big_endian {
                    f64::from_be_bytes(b)
                } else {
                    f64::from_le_bytes(b)
                })
            }
        }
    }

    /// Close the record: in text, no value may be left on the line.
    fn end(&mut self, what: &str) -> Result<()> {
        if self.data == Data::Text && self.fields.len() > self.next {
            return Err(self.err(format!(
                "expected {} value(s) ({what}), found {}",
                self.next,
                self.fields.len()
            )));
        }
        Ok(())
    }

    /// Check that `count` items fit in the rest of the file before anything is allocated
    /// for them: each takes at least `text_min` bytes in text, `binary` bytes in binary.
    fn room(&self, count: u64, text_min: u64, binary: u64, what: &str) -> Result<usize> {
        let per = match self.data {
            Data::Text => text_min,
            Data::Binary { .. } => binary,
        };
        let left = (self.bytes.len() - self.pos) as u64;
        if count > left / per.max(1) {
            return Err(self.err(format!(
                "{count} {what} cannot fit in the {left} bytes left in the file ({per} bytes \
                 or more each): a wrong count, or the file is cut short"
            )));
        }
        Ok(count as usize)
    }

    /// The `$End…` line of the current section.
    fn expect_end(&mut self) -> Result<()> {
        let section = self.section;
        self.data = Data::Text;
        match self.next_line() {
            Some((_, l)) if l.strip_prefix(b"$End") == Some(section.as_bytes()) => Ok(()),
            Some((line, l)) => Err(self.err_line(
                line,
                format!(
                    "expected $End{section}, found `{}` (more entries than declared?)",
                    String::from_utf8_lossy(&l[..l.len().min(40)])
                ),
            )),
            None => Err(self.eof(format!("unexpected end of file: missing $End{section}"))),
        }
    }
}

struct Parser<'a, const D: usize> {
    src: Records<'a>,
    path: &'a Path,
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

impl<'a, const D: usize> Parser<'a, D> {
    fn new(bytes: &'a [u8], path: &'a Path) -> Self {
        Self {
            src: Records::new(bytes, path),
            path,
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

    fn run(mut self) -> Result<Grid<D>> {
        let mut seen_format = false;
        let mut seen: Vec<&str> = Vec::new();
        while let Some((line, l)) = self.src.next_line() {
            let l = self.src.text(line, l)?;
            let Some(name) = l.strip_prefix('$') else {
                return Err(self.src.err_line(
                    line,
                    format!("expected a section header such as $Nodes, found `{l}`"),
                ));
            };
            if !seen_format && name != "MeshFormat" {
                return Err(self
                    .src
                    .err_line(line, "the file does not start with $MeshFormat"));
            }
            if seen.contains(&name) {
                return Err(self
                    .src
                    .err_line(line, format!("section ${name} appears twice")));
            }
            seen.push(name);
            let binary_data = matches!(name, "Entities" | "Nodes" | "Elements");
            self.src.enter(name, line, binary_data);
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
                        return Err(self
                            .src
                            .err_line(line, "$Elements without a preceding $Nodes section"));
                    }
                    self.elements_section()?;
                }
                "PartitionedEntities" | "Parametrizations" => {
                    return Err(self.src.err_line(
                        line,
                        format!("section ${name} is not supported (save an unpartitioned mesh)"),
                    ));
                }
                _ => loop {
                    match self.src.next_line() {
                        Some((_, l)) if l.strip_prefix(b"$End") == Some(name.as_bytes()) => {
                            break;
                        }
                        Some(_) => {}
                        None => {
                            return Err(self.src.err_line(
                                line,
                                format!("section ${name} is not closed by $End{name}"),
                            ));
                        }
                    }
                },
            }
        }
        let last = self.src.last_line;
        if !seen_format {
            return Err(self
                .src
                .err_line(last, "not a Gmsh file: no $MeshFormat section"));
        }
        for s in ["Nodes", "Elements"] {
            if !seen.contains(&s) {
                return Err(self.src.err_line(last, format!("missing ${s} section")));
            }
        }
        self.finish()
    }

    fn mesh_format(&mut self) -> Result<()> {
        let src = &mut self.src;
        src.begin("the mesh format `4.1 0 8` or `4.1 1 8`")?;
        let version = src.token("version")?;
        if version != "4.1" {
            return Err(src.err(format!(
                "Gmsh format version {version} is not supported; save the mesh as \
                 version 4.1 (gmsh -format msh41)"
            )));
        }
        let kind = src.int("file type")?;
        let size = src.int("data size")?;
        src.end("version, file type, data size")?;
        match kind {
            0 => src.file_data = Data::Text,
            1 => {
                // The integer 1 in binary, written in the machine's byte order.
                let b = src.bytes.get(src.pos..src.pos + 4).unwrap_or_default();
                src.file_data = match b {
                    [1, 0, 0, 0] => Data::Binary { big_endian: false },
                    [0, 0, 0, 1] => Data::Binary { big_endian: true },
                    _ => {
                        return Err(src.err(format!(
                            "binary mesh (file type 1): the 4 bytes after this line must be \
                             the integer 1 (the byte order check), found {b:02x?}"
                        )));
                    }
                };
                src.pos += 4;
            }
            _ => {
                return Err(src.err(format!("file type {kind}: must be 0 (ASCII) or 1 (binary)")));
            }
        }
        if size != 8 {
            return Err(src.err(format!(
                "data size {size} is not supported (8: 64-bit size_t)"
            )));
        }
        src.expect_end()
    }

    fn physical_names(&mut self) -> Result<()> {
        self.src.begin("the number of physical names")?;
        let n = self.src.size("number of physical names")?;
        self.src.end("number of physical names")?;
        // `1 1 "a"` takes 8 bytes or more.
        let n = self.src.room(n, 8, 8, "physical names")?;
        for _ in 0..n {
            let Some((line, l)) = self.src.next_line() else {
                return Err(self.src.eof("unexpected end of file in $PhysicalNames"));
            };
            let l = self.src.text(line, l)?;
            let (head, rest) = l.split_at(l.find('"').unwrap_or(l.len()));
            let mut it = head.split_whitespace();
            let dim: Option<usize> = it.next().and_then(|t| t.parse().ok());
            let tag: Option<i64> = it.next().and_then(|t| t.parse().ok());
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
                    return Err(self.src.err_line(
                        line,
                        format!("expected `dimension tag \"name\"`, found `{l}`"),
                    ));
                }
            }
        }
        self.src.expect_end()
    }

    fn entities_section(&mut self) -> Result<()> {
        let src = &mut self.src;
        src.begin("the entity counts")?;
        let mut counts = [0u64; 4];
        for c in &mut counts {
            *c = src.size("entity count")?;
        }
        src.end("numbers of points, curves, surfaces, volumes")?;
        let all = counts.iter().fold(0u64, |a, &c| a.saturating_add(c));
        // A point entity is `tag x y z 0`: 10 bytes or more in text, 36 in binary.
        let all = src.room(all, 10, 36, "entities")?;
        let mut map = HashMap::with_capacity(all);
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                src.begin(&format!("a {dim}D entity"))?;
                let tag = src.int("entity tag")?;
                for _ in 0..if dim == 0 { 3 } else { 6 } {
                    src.float("coordinate")?;
                }
                let np = src.size("number of physical tags")?;
                let np = src.room(np, 2, 4, "physical tags")?;
                let mut phys = Vec::with_capacity(np);
                for _ in 0..np {
                    phys.push(src.int("physical tag")?);
                }
                if dim > 0 {
                    let nb = src.size("number of bounding entities")?;
                    for _ in 0..src.room(nb, 2, 4, "bounding entities")? {
                        src.int("bounding entity tag")?;
                    }
                }
                src.end(&format!("{dim}D entity record"))?;
                if map.insert((dim, tag), phys).is_some() {
                    return Err(src.err(format!("{dim}D entity {tag} defined twice")));
                }
            }
        }
        self.entities = Some(map);
        src.expect_end()
    }

    fn nodes_section(&mut self) -> Result<()> {
        let src = &mut self.src;
        src.begin("the $Nodes header")?;
        let header = src.mark();
        let blocks = src.size("number of entity blocks")?;
        let total = src.size("number of nodes")?;
        src.size("minimum node tag")?;
        src.size("maximum node tag")?;
        src.end("numEntityBlocks numNodes minNodeTag maxNodeTag")?;
        // A node is a tag and 3 coordinates: `1` and `0 0 0` (8 bytes) or 32 bytes.
        let total = src.room(total, 8, 32, "nodes")?;
        // A block header: `0 1 0 1` or 3 ints and a size_t.
        let blocks = src.room(blocks, 8, 20, "node blocks")?;
        self.nodes.reserve(total);
        self.node_label.reserve(total);
        self.node_index.reserve(total);
        let mut z0: Option<(f64, u64)> = None;
        let mut tags = Vec::new();
        for _ in 0..blocks {
            src.begin("a node block header")?;
            let edim = src.int("entity dimension")?;
            src.int("entity tag")?;
            let parametric = src.int("parametric flag")?;
            let n = src.size("number of nodes in the block")?;
            src.end("entityDim entityTag parametric numNodesInBlock")?;
            if !(0..=3).contains(&edim) || !(0..=1).contains(&parametric) {
                return Err(src.err(format!(
                    "bad node block header (entity dimension {edim}, parametric {parametric})"
                )));
            }
            if n > (total - self.nodes.len()) as u64 {
                return Err(src.err(format!(
                    "node blocks hold more nodes than the {total} declared in the header"
                )));
            }
            tags.clear();
            for _ in 0..n {
                src.begin("a node tag")?;
                let m = src.mark();
                let t = src.size("node tag")?;
                src.end("node tag")?;
                tags.push((t, m));
            }
            let extra = if parametric == 1 { edim } else { 0 };
            for &(t, tag_mark) in &tags {
                src.begin("node coordinates `x y z`")?;
                let m = src.mark();
                let mut x = [0.0f64; 3];
                for xk in &mut x {
                    *xk = src.float("coordinate")?;
                    if !xk.is_finite() {
                        return Err(src.err(format!("node {t}: non-finite coordinate {xk}")));
                    }
                }
                for _ in 0..extra {
                    src.float("parametric coordinate")?;
                }
                src.end("node coordinates")?;
                if D == 2 {
                    match z0 {
                        None => z0 = Some((x[2], t)),
                        Some((z, t0)) if z != x[2] => {
                            return Err(src.err(format!(
                                "node {t}: z = {} differs from z = {z} of node {t0}: a 2D \
                                 mesh must lie in a plane z = const",
                                x[2]
                            )));
                        }
                        _ => {}
                    }
                }
                if self.node_index.insert(t, self.nodes.len()).is_some() {
                    return Err(src.err_at(tag_mark, format!("node tag {t} defined twice")));
                }
                self.nodes.push(Point::<D>::from_fn(|a, _| x[a]));
                self.node_label.push((t, src.line_of(m)));
            }
        }
        if self.nodes.len() != total {
            return Err(src.err_at(
                header,
                format!(
                    "the header declares {total} nodes but the blocks hold {}",
                    self.nodes.len()
                ),
            ));
        }
        src.expect_end()
    }

    fn elements_section(&mut self) -> Result<()> {
        let src = &mut self.src;
        src.begin("the $Elements header")?;
        let header = src.mark();
        let blocks = src.size("number of entity blocks")?;
        let total = src.size("number of elements")?;
        src.size("minimum element tag")?;
        src.size("maximum element tag")?;
        src.end("numEntityBlocks numElements minElementTag maxElementTag")?;
        // An element is a tag and one node tag or more: `1 1` (4 bytes) or 16 bytes.
        let total = src.room(total, 4, 16, "elements")?;
        let blocks = src.room(blocks, 8, 20, "element blocks")?;
        let mut count = 0usize;
        let mut v = Vec::with_capacity(8);
        for _ in 0..blocks {
            src.begin("an element block header")?;
            let edim = src.int("entity dimension")?;
            let etag = src.int("entity tag")?;
            let etype = src.int("element type")?;
            let n = src.size("number of elements in the block")?;
            src.end("entityDim entityTag elementType numElementsInBlock")?;
            let (tdim, nn, shape) = element_type(etype).map_err(|w| src.err(w))?;
            if tdim as i64 != edim {
                return Err(src.err(format!(
                    "element type {etype} has dimension {tdim}, but the block's entity has \
                     dimension {edim}"
                )));
            }
            if tdim > D {
                return Err(src.err(format!(
                    "{tdim}D elements (type {etype}) in a mesh read as {D}D"
                )));
            }
            if n > (total - count) as u64 {
                return Err(src.err(format!(
                    "element blocks hold more elements than the {total} declared in the header"
                )));
            }
            if let (Some(map), true) = (&self.entities, tdim + 1 >= D)
                && !map.contains_key(&(tdim, etag))
            {
                return Err(src.err(format!(
                    "entity ({edim}D, tag {etag}) is not listed in $Entities"
                )));
            }
            let per = 1 + nn as u64;
            let n = src.room(n, 2 * per, 8 * per, "elements")?;
            count += n;
            if tdim == D {
                self.origin.reserve(n);
                self.cell_entity.reserve(n);
            }
            for _ in 0..n {
                src.begin(&format!("an element line `tag` + {nn} node tags"))?;
                let m = src.mark();
                let tag = src.size("element tag")?;
                v.clear();
                for _ in 0..nn {
                    let t = src.size("node tag")?;
                    let Some(&i) = self.node_index.get(&t) else {
                        return Err(src.err(format!(
                            "element {tag}: node tag {t} is not defined in $Nodes"
                        )));
                    };
                    if v.contains(&i) {
                        return Err(src.err(format!("element {tag}: node tag {t} appears twice")));
                    }
                    v.push(i);
                }
                src.end(&format!("element tag and {nn} node tags"))?;
                if tdim == D {
                    // Only supported cell types reach here (element_type checked).
                    if let Some(shape) = shape {
                        shape.push(&mut self.loops, &v);
                        self.origin.push(Origin {
                            line: src.line_of(m),
                            tag,
                            standard: true,
                        });
                        self.cell_entity.push(etag);
                    }
                } else if tdim + 1 == D {
                    self.face_el_nodes.extend_from_slice(&v);
                    self.face_el_pos.push(self.face_el_nodes.len());
                    // Binary elements are reported at the $Elements line.
                    let line = match src.data {
                        Data::Text => m.0,
                        Data::Binary { .. } => src.section_line,
                    };
                    self.face_el_info.push((line, tag, etag));
                }
            }
        }
        if count != total {
            return Err(src.err_at(
                header,
                format!("the header declares {total} elements but the blocks hold {count}"),
            ));
        }
        src.expect_end()
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
                    return Err(self.src.err_line(
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
                return Err(self.src.err_line(
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles on the unit square in group 7 "rock", as Gmsh lays out a binary file,
    /// in either byte order.
    fn binary_square(big_endian: bool) -> Vec<u8> {
        let mut b = Vec::new();
        let int = |b: &mut Vec<u8>, v: i32| {
            b.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let size = |b: &mut Vec<u8>, v: u64| {
            b.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let float = |b: &mut Vec<u8>, v: f64| {
            b.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        b.extend_from_slice(b"$MeshFormat\n4.1 1 8\n");
        int(&mut b, 1);
        b.extend_from_slice(b"\n$EndMeshFormat\n$PhysicalNames\n1\n2 7 \"rock\"\n");
        b.extend_from_slice(b"$EndPhysicalNames\n$Entities\n");
        for c in [0, 0, 1, 0] {
            size(&mut b, c);
        }
        int(&mut b, 1);
        for x in [0.0, 0.0, 0.0, 1.0, 1.0, 0.0] {
            float(&mut b, x);
        }
        size(&mut b, 1);
        int(&mut b, 7);
        size(&mut b, 0);
        b.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
        for v in [1, 4, 1, 4] {
            size(&mut b, v);
        }
        int(&mut b, 2);
        int(&mut b, 1);
        int(&mut b, 0);
        size(&mut b, 4);
        for t in 1..=4 {
            size(&mut b, t);
        }
        for x in [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0] {
            float(&mut b, x);
        }
        b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        for v in [1, 2, 1, 2] {
            size(&mut b, v);
        }
        int(&mut b, 2);
        int(&mut b, 1);
        int(&mut b, 2);
        size(&mut b, 2);
        for v in [1, 1, 2, 3, 2, 1, 3, 4] {
            size(&mut b, v);
        }
        b.extend_from_slice(b"\n$EndElements\n");
        b
    }

    #[test]
    fn binary_both_byte_orders_match_ascii() {
        let ascii = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 7 \"rock\"\n\
                     $EndPhysicalNames\n$Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 7 0\n$EndEntities\n\
                     $Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n\
                     $Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 1 3 4\n$EndElements\n";
        let a: Grid<2> = parse_msh(ascii, "a.msh").unwrap();
        assert_eq!(a.cell_tags()["rock"], vec![0, 1]);
        for be in [false, true] {
            let g: Grid<2> = parse_msh_bytes(&binary_square(be), "b.msh").unwrap();
            assert!(g == a, "big endian: {be}");
        }
        // An integer that is 1 in neither byte order.
        let mut b = binary_square(true);
        let at = b"$MeshFormat\n4.1 1 8\n".len();
        b[at..at + 4].copy_from_slice(&[0, 0, 1, 0]);
        let e = parse_msh_bytes::<2>(&b, "b.msh").unwrap_err().to_string();
        assert!(e.starts_with("b.msh:2:") && e.contains("byte order"), "{e}");
    }
}
