//! VTK XML UnstructuredGrid (`.vtu`) reader (the writer is [`crate::io::write_vtu`]).
//!
//! # Reading
//!
//! `VTK_TRIANGLE` (5), `VTK_QUAD` (9), `VTK_POLYGON` (7) in 2D (all points at one `z`);
//! `VTK_TETRA` (10), `VTK_HEXAHEDRON` (12), `VTK_WEDGE` (13), `VTK_PYRAMID` (14),
//! `VTK_POLYHEDRON` (42) in 3D. Cell tags come from the `tag:<name>` arrays, or, if there
//! are none, from an integer `tag` array as `tag_<value>`; face tags from `facetag:<name>`
//! field data. One `<Piece>`.
//!
//! Data arrays may be ASCII, inline base64 or appended (raw or base64), uncompressed or
//! zlib-compressed: see "Reading VTK files" in the [`crate::io`] module docs.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Read as _;
use std::path::Path;

use flate2::read::ZlibDecoder;

use crate::builder::CellFaceLoops;
use crate::error::{GridError, Result};
use crate::grid::Grid;
use crate::io::xml::{self, Element, LineIndex};
use crate::io::{Origin, RawMesh, Shape, base64, read_file};
use crate::point::{Point, assert_dim};

/// Name of the 2D field-data array that keeps the order of each cell's faces.
pub(crate) const EDGE_ORDER: &str = "porofrac:edge_order";
/// Name of the 3D field-data array holding every cell's face stream (when standard cell
/// types are written, [`crate::io::write_vtu`]).
pub(crate) const FACES: &str = "porofrac:faces";
/// The end positions of each cell's part of [`FACES`].
pub(crate) const FACE_OFFSETS: &str = "porofrac:faceoffsets";

// ---------------------------------------------------------------------------- reading

/// Value types of VTK data arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    F32,
    F64,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "Float32" => Ty::F32,
            "Float64" => Ty::F64,
            "Int8" => Ty::I8,
            "UInt8" => Ty::U8,
            "Int16" => Ty::I16,
            "UInt16" => Ty::U16,
            "Int32" => Ty::I32,
            "UInt32" => Ty::U32,
            "Int64" => Ty::I64,
            "UInt64" => Ty::U64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::F32 | Ty::I32 | Ty::U32 => 4,
            Ty::F64 | Ty::I64 | Ty::U64 => 8,
        }
    }
    fn is_float(self) -> bool {
        matches!(self, Ty::F32 | Ty::F64)
    }
}

/// The bytes after the `_` marker of `<AppendedData>`.
struct Appended<'a> {
    data: &'a [u8],
    /// `encoding="base64"` (else `raw`).
    base64: bool,
    /// Whether `</AppendedData>` follows the data (else the file ends inside it).
    closed: bool,
    /// Sorted offsets of all appended arrays: a base64 array ends where the next begins.
    starts: Vec<usize>,
}

/// Largest ratio of inflated to deflated size that zlib can reach (a deflate block of
/// repeated bytes codes 258 bytes in 2 bits, i.e. at most 1032 : 1), with slack for the
/// stream header and checksum.
const ZLIB_MAX_RATIO: u64 = 1032;

struct Ctx<'a> {
    path: &'a Path,
    lines: LineIndex,
    big_endian: bool,
    header64: bool,
    /// `compressor="vtkZLibDataCompressor"`: binary arrays are zlib blocks.
    zlib: bool,
    appended: Option<Appended<'a>>,
}

/// Which array is being decoded, for error messages.
struct ArrayAt<'e> {
    name: &'e str,
    offset: usize,
    how: String,
}

impl Ctx<'_> {
    fn err(&self, offset: usize, what: impl Into<String>) -> GridError {
        GridError::Parse {
            path: self.path.to_path_buf(),
            line: self.lines.line(offset),
            what: what.into(),
        }
    }

    fn zlib_note(&self) -> &'static str {
        if self.zlib { ", zlib" } else { "" }
    }

    fn array_err(&self, at: &ArrayAt<'_>, what: impl std::fmt::Display) -> GridError {
        let cut = match &self.appended {
            Some(a) if !a.closed && at.how.starts_with("appended") => {
                "; the file ends inside <AppendedData> (no </AppendedData>): is it cut short?"
            }
            _ => "",
        };
        self.err(
            at.offset,
            format!("DataArray `{}` ({}): {what}{cut}", at.name, at.how),
        )
    }

    /// Decode a DataArray as f64 (`want_int`: refuse float types) with `ncomp`
    /// components and `tuples` tuples (if given).
    fn array(
        &self,
        el: &Element<'_>,
        ncomp: usize,
        tuples: Option<usize>,
        want_int: bool,
    ) -> Result<Vec<f64>> {
        let name = el.attr("Name").unwrap_or("(unnamed)");
        let ty_name = el
            .attr("type")
            .ok_or_else(|| self.err(el.offset, format!("DataArray `{name}` has no type")))?;
        let ty = Ty::parse(ty_name).ok_or_else(|| {
            self.err(
                el.offset,
                format!("DataArray `{name}`: unsupported type `{ty_name}`"),
            )
        })?;
        if want_int && ty.is_float() {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}` must be an integer array, found {ty_name}"),
            ));
        }
        let nc: usize = match el.attr("NumberOfComponents") {
            None => 1,
            Some(s) => s.trim().parse().map_err(|_| {
                self.err(
                    el.offset,
                    format!("DataArray `{name}`: bad NumberOfComponents `{s}`"),
                )
            })?,
        };
        if nc != ncomp {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}` has {nc} components, expected {ncomp}"),
            ));
        }
        // Expected size in bytes, when the number of tuples is known.
        let expected = match tuples {
            None => None,
            Some(t) => Some(
                t.checked_mul(ncomp)
                    .and_then(|n| n.checked_mul(ty.size()))
                    .ok_or_else(|| {
                        self.err(
                            el.offset,
                            format!(
                                "DataArray `{name}`: {t} tuples of {ncomp} {ty_name} values \
                                 do not fit in memory"
                            ),
                        )
                    })?,
            ),
        };
        let format = el.attr("format").unwrap_or("ascii");
        let values: Vec<f64> = match format {
            "ascii" => {
                let mut v = Vec::new();
                for tok in el.text.split_ascii_whitespace() {
                    let off = el.text_offset + (tok.as_ptr() as usize - el.text.as_ptr() as usize);
                    let x: f64 = if ty.is_float() {
                        tok.parse().ok()
                    } else {
                        tok.parse::<i64>().ok().map(|i| i as f64)
                    }
                    .ok_or_else(|| {
                        self.err(
                            off,
                            format!("DataArray `{name}`: bad {ty_name} value `{tok}`"),
                        )
                    })?;
                    v.push(x);
                }
                v
            }
            "binary" => {
                let at = ArrayAt {
                    name,
                    offset: el.offset,
                    how: format!("inline base64{}", self.zlib_note()),
                };
                let raw = base64::decode(el.text.as_bytes())
                    .map_err(|w| self.err(el.text_offset, format!("DataArray `{name}`: {w}")))?;
                let payload = self.unpack(&raw, &at, ty, expected)?;
                self.convert(&payload, ty)
            }
            "appended" => {
                let ap = self.appended.as_ref().ok_or_else(|| {
                    self.err(
                        el.offset,
                        format!(
                            "DataArray `{name}` has format=\"appended\" but the file has no \
                             <AppendedData> block"
                        ),
                    )
                })?;
                let off_text = el.attr("offset").unwrap_or("");
                let off: usize = off_text.trim().parse().map_err(|_| {
                    self.err(
                        el.offset,
                        format!("DataArray `{name}`: bad or missing appended offset `{off_text}`"),
                    )
                })?;
                let at = ArrayAt {
                    name,
                    offset: el.offset,
                    how: format!(
                        "appended {}, offset {off}{}",
                        if ap.base64 { "base64" } else { "raw" },
                        self.zlib_note()
                    ),
                };
                if off >= ap.data.len() {
                    return Err(self.array_err(
                        &at,
                        format!(
                            "the offset is past the end of the appended data ({} bytes)",
                            ap.data.len()
                        ),
                    ));
                }
                if ap.base64 {
                    let next = ap.starts.partition_point(|&s| s <= off);
                    let end = ap.starts.get(next).copied().unwrap_or(ap.data.len());
                    let raw = base64::decode(&ap.data[off..end.min(ap.data.len())])
                        .map_err(|w| self.array_err(&at, w))?;
                    let payload = self.unpack(&raw, &at, ty, expected)?;
                    self.convert(&payload, ty)
                } else {
                    let payload = self.unpack(&ap.data[off..], &at, ty, expected)?;
                    self.convert(&payload, ty)
                }
            }
            _ => {
                return Err(self.err(
                    el.offset,
                    format!("DataArray `{name}`: unknown format `{format}`"),
                ));
            }
        };
        if !values.len().is_multiple_of(ncomp) {
            return Err(self.err(
                el.offset,
                format!(
                    "DataArray `{name}`: {} values is not a multiple of {ncomp}",
                    values.len()
                ),
            ));
        }
        if let Some(t) = tuples
            && values.len() / ncomp != t
        {
            return Err(self.err(
                el.offset,
                format!(
                    "DataArray `{name}` has {} tuples, expected {t}",
                    values.len() / ncomp
                ),
            ));
        }
        if let Some(bad) = values.iter().position(|x| !x.is_finite()) {
            return Err(self.err(
                el.offset,
                format!("DataArray `{name}`: value {bad} is not finite"),
            ));
        }
        Ok(values)
    }

    /// The data bytes of a binary array that starts (with its header) at `src[0]`:
    /// uncompressed, one size word then the bytes; with zlib, VTK's block header then the
    /// compressed blocks (see the module docs). `expected` is the size in bytes if known.
    /// Every size is checked against the bytes present before anything is allocated.
    fn unpack<'s>(
        &self,
        src: &'s [u8],
        at: &ArrayAt<'_>,
        ty: Ty,
        expected: Option<usize>,
    ) -> Result<Cow<'s, [u8]>> {
        let hs = if self.header64 { 8 } else { 4 };
        let word = |k: usize| -> Option<u64> {
            let b = src.get(k * hs..(k + 1) * hs)?;
            Some(self.uint(b))
        };
        let size = ty.size() as u64;
        let check_total = |total: u64| -> Result<()> {
            if !total.is_multiple_of(size) {
                return Err(self.array_err(
                    at,
                    format!("{total} bytes is not a whole number of {size}-byte values"),
                ));
            }
            if let Some(e) = expected
                && total != e as u64
            {
                return Err(self.array_err(
                    at,
                    format!(
                        "the header gives {total} bytes ({} values), expected {e} bytes ({} values)",
                        total / size,
                        e as u64 / size
                    ),
                ));
            }
            Ok(())
        };
        if !self.zlib {
            let count = word(0).ok_or_else(|| {
                self.array_err(
                    at,
                    format!("no {hs}-byte size header ({} bytes present)", src.len()),
                )
            })?;
            let avail = (src.len() - hs) as u64;
            if count > avail {
                return Err(self.array_err(
                    at,
                    format!("the header gives {count} bytes, only {avail} follow"),
                ));
            }
            check_total(count)?;
            return Ok(Cow::Borrowed(&src[hs..hs + count as usize]));
        }
        let [Some(nb), Some(bs), Some(last)] = [word(0), word(1), word(2)] else {
            return Err(self.array_err(
                at,
                format!(
                    "no compression header (3 words of {hs} bytes; {} bytes present)",
                    src.len()
                ),
            ));
        };
        let room = (src.len() / hs - 3) as u64;
        if nb > room {
            return Err(self.array_err(
                at,
                format!(
                    "the compression header gives {nb} blocks, but the {} bytes present \
                     hold at most {room} block sizes",
                    src.len()
                ),
            ));
        }
        let nb = nb as usize;
        if nb > 0 && (bs == 0 || last > bs) {
            return Err(self.array_err(
                at,
                format!(
                    "bad compression header: block size {bs}, last block size {last} \
                     ({nb} blocks)"
                ),
            ));
        }
        // The last block is full when its size is given as 0.
        let block_size = |k: usize| if k + 1 < nb || last == 0 { bs } else { last };
        let total = match nb {
            0 => Some(0),
            _ => (nb as u64 - 1)
                .checked_mul(bs)
                .and_then(|t| t.checked_add(block_size(nb - 1))),
        }
        .ok_or_else(|| self.array_err(at, format!("{nb} blocks of {bs} bytes overflow")))?;
        check_total(total)?;
        let mut compressed = 0u64;
        for k in 0..nb {
            let cs = word(3 + k).unwrap_or(0);
            let us = block_size(k);
            if us > cs.saturating_mul(ZLIB_MAX_RATIO).saturating_add(64) {
                return Err(self.array_err(
                    at,
                    format!(
                        "block {k} of {nb}: {cs} compressed bytes cannot inflate to the \
                         {us} bytes the header gives"
                    ),
                ));
            }
            compressed = compressed.saturating_add(cs);
        }
        let header = (3 + nb) * hs;
        let avail = (src.len() - header) as u64;
        if compressed > avail {
            return Err(self.array_err(
                at,
                format!(
                    "the header gives {nb} compressed blocks of {compressed} bytes in all, \
                     only {avail} bytes follow"
                ),
            ));
        }
        // `total` is now bounded by the bytes present (ratio above).
        let mut out = Vec::with_capacity(total as usize);
        let mut pos = header;
        for k in 0..nb {
            let cs = word(3 + k).unwrap_or(0) as usize;
            let us = block_size(k);
            let block = &src[pos..pos + cs];
            let before = out.len();
            ZlibDecoder::new(block)
                .take(us + 1)
                .read_to_end(&mut out)
                .map_err(|e| {
                    self.array_err(at, format!("block {k} of {nb}: corrupt zlib data ({e})"))
                })?;
            let got = (out.len() - before) as u64;
            if got != us {
                return Err(self.array_err(
                    at,
                    format!("block {k} of {nb} inflates to {got} bytes, the header gives {us}"),
                ));
            }
            pos += cs;
        }
        Ok(Cow::Owned(out))
    }

    /// Binary values in the file's byte order as f64.
    fn convert(&self, b: &[u8], ty: Ty) -> Vec<f64> {
        macro_rules! conv {
            ($t:ty) => {{
                const N: usize = std::mem::size_of::<$t>();
                b.chunks_exact(N)
                    .map(|c| {
                        let a: [u8; N] = c.try_into().unwrap_or([0; N]);
                        let v = if self.big_endian {
                            <$t>::from_be_bytes(a)
                        } else {
                            <$t>::from_le_bytes(a)
                        };
                        v as f64
                    })
                    .collect()
            }};
        }
        match ty {
            Ty::F32 => conv!(f32),
            Ty::F64 => conv!(f64),
            Ty::I8 => conv!(i8),
            Ty::U8 => conv!(u8),
            Ty::I16 => conv!(i16),
            Ty::U16 => conv!(u16),
            Ty::I32 => conv!(i32),
            Ty::U32 => conv!(u32),
            Ty::I64 => conv!(i64),
            Ty::U64 => conv!(u64),
        }
    }

    fn uint(&self, b: &[u8]) -> u64 {
        let mut x = 0u64;
        for k in 0..b.len() {
            let byte = if self.big_endian {
                b[k]
            } else {
                b[b.len() - 1 - k]
            };
            x = (x << 8) | u64::from(byte);
        }
        x
    }

    fn ints(&self, el: &Element<'_>, tuples: Option<usize>) -> Result<Vec<i64>> {
        Ok(self
            .array(el, 1, tuples, true)?
            .into_iter()
            .map(|x| x as i64)
            .collect())
    }
}

fn named<'e, 'a>(parent: &'e Element<'a>, name: &str) -> Option<&'e Element<'a>> {
    parent
        .children_named("DataArray")
        .find(|d| d.attr("Name") == Some(name))
}

/// Read a `.vtu` file as a `D`-dimensional grid: any cell types, tags and data encodings
/// listed in the [`io`](crate::io) module docs (ASCII, inline base64, appended raw or
/// base64, with or without zlib compression).
pub fn read_vtu<const D: usize>(path: impl AsRef<Path>) -> Result<Grid<D>> {
    const { assert_dim::<D>() };
    let path = path.as_ref();
    let bytes = read_file(path)?;
    let (text, appended) = split_appended(&bytes, path)?;
    parse_vtu(&text, appended, path)
}

/// The appended data of a `.vtu` file: `(data, closed)`, the bytes after the `_` marker
/// up to `</AppendedData>` (or to the end of the file, `closed == false`).
type AppendedBytes<'b> = Option<(&'b [u8], bool)>;

/// Split a `.vtu` file into its XML text and its appended data. The XML text is the file
/// with the bytes from the `_` marker to `</AppendedData>` cut out (byte offsets before
/// the marker are unchanged, so line numbers of errors are exact); a file that ends inside
/// the appended data gets the closing tags added.
fn split_appended<'b>(bytes: &'b [u8], path: &Path) -> Result<(Cow<'b, str>, AppendedBytes<'b>)> {
    let err = |at: usize, what: String| GridError::Parse {
        path: path.to_path_buf(),
        line: memchr::memchr_iter(b'\n', &bytes[..at.min(bytes.len())]).count() + 1,
        what,
    };
    let text = |from: usize, to: usize| -> Result<&'b str> {
        std::str::from_utf8(&bytes[from..to]).map_err(|e| {
            err(
                from + e.valid_up_to(),
                "not UTF-8 text (outside of <AppendedData>)".into(),
            )
        })
    };
    let Some(start) = memchr::memmem::find(bytes, b"<AppendedData") else {
        return Ok((Cow::Borrowed(text(0, bytes.len())?), None));
    };
    let Some(gt) = memchr::memchr(b'>', &bytes[start..]).map(|p| start + p) else {
        return Err(err(start, "unterminated <AppendedData> start tag".into()));
    };
    if bytes[gt - 1] == b'/' {
        // `<AppendedData/>`: no data.
        return Ok((Cow::Borrowed(text(0, bytes.len())?), None));
    }
    let marker = gt
        + 1
        + bytes[gt + 1..]
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .unwrap_or(bytes.len() - gt - 1);
    if bytes.get(marker) != Some(&b'_') {
        return Err(err(
            marker,
            "<AppendedData> must begin with the `_` marker".into(),
        ));
    }
    let data = marker + 1;
    let end = memchr::memmem::rfind(&bytes[data..], b"</AppendedData>").map(|p| data + p);
    let mut xml = String::with_capacity(marker + 64);
    xml.push_str(text(0, marker)?);
    match end {
        Some(e) => xml.push_str(text(e, bytes.len())?),
        None => xml.push_str("</AppendedData></VTKFile>"),
    }
    let slice = &bytes[data..end.unwrap_or(bytes.len())];
    Ok((Cow::Owned(xml), Some((slice, end.is_some()))))
}

fn parse_vtu<const D: usize>(
    text: &str,
    appended: AppendedBytes<'_>,
    path: &Path,
) -> Result<Grid<D>> {
    let mut cx = Ctx {
        path,
        lines: LineIndex::new(text),
        big_endian: false,
        header64: false,
        zlib: false,
        appended: None,
    };
    let root = xml::parse(text).map_err(|e| cx.err(e.offset, format!("XML: {}", e.what)))?;
    if root.name != "VTKFile" || root.attr("type") != Some("UnstructuredGrid") {
        return Err(cx.err(
            root.offset,
            "not a VTK UnstructuredGrid file (<VTKFile type=\"UnstructuredGrid\">)",
        ));
    }
    cx.zlib = match root.attr("compressor").unwrap_or("") {
        "" => false,
        "vtkZLibDataCompressor" => true,
        c => {
            return Err(cx.err(
                root.offset,
                format!(
                    "compressor `{c}` is not supported (only vtkZLibDataCompressor; save \
                     with zlib or without compression)"
                ),
            ));
        }
    };
    cx.big_endian = match root.attr("byte_order").unwrap_or("LittleEndian") {
        "LittleEndian" => false,
        "BigEndian" => true,
        o => return Err(cx.err(root.offset, format!("unknown byte_order `{o}`"))),
    };
    cx.header64 = match root.attr("header_type").unwrap_or("UInt32") {
        "UInt32" => false,
        "UInt64" => true,
        o => return Err(cx.err(root.offset, format!("unsupported header_type `{o}`"))),
    };
    if let Some((data, closed)) = appended {
        let a = root
            .child("AppendedData")
            .ok_or_else(|| cx.err(root.offset, "<AppendedData> is not a child of <VTKFile>"))?;
        let base64 = match a.attr("encoding").unwrap_or("") {
            "raw" => false,
            "base64" => true,
            e => {
                return Err(cx.err(
                    a.offset,
                    format!("<AppendedData> encoding `{e}` (expected raw or base64)"),
                ));
            }
        };
        let mut starts = Vec::new();
        root.walk(&mut |el| {
            if el.name == "DataArray"
                && el.attr("format") == Some("appended")
                && let Some(o) = el.attr("offset").and_then(|s| s.trim().parse().ok())
            {
                starts.push(o);
            }
        });
        starts.sort_unstable();
        starts.dedup();
        cx.appended = Some(Appended {
            data,
            base64,
            closed,
            starts,
        });
    }
    let ug = root
        .child("UnstructuredGrid")
        .ok_or_else(|| cx.err(root.offset, "no <UnstructuredGrid> element"))?;
    let mut pieces = ug.children_named("Piece");
    let piece = pieces
        .next()
        .ok_or_else(|| cx.err(ug.offset, "no <Piece> element"))?;
    if let Some(p) = pieces.next() {
        return Err(cx.err(p.offset, "more than one <Piece> is not supported"));
    }
    let count = |attr: &str| -> Result<usize> {
        piece
            .attr(attr)
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| cx.err(piece.offset, format!("<Piece> needs a valid {attr}")))
    };
    let np = count("NumberOfPoints")?;
    let nc = count("NumberOfCells")?;

    // Points.
    let pts_el = piece
        .child("Points")
        .and_then(|p| p.child("DataArray"))
        .ok_or_else(|| cx.err(piece.offset, "no <Points><DataArray>"))?;
    let xyz = cx.array(pts_el, 3, Some(np), false)?;
    if D == 2
        && let Some(k) = (1..np).find(|&k| xyz[3 * k + 2] != xyz[2])
    {
        return Err(cx.err(
            pts_el.offset,
            format!(
                "point {k} has z = {} but point 0 has z = {}: a 2D grid must lie in a plane z = const",
                xyz[3 * k + 2],
                xyz[2]
            ),
        ));
    }
    let nodes: Vec<Point<D>> = (0..np)
        .map(|k| Point::<D>::from_fn(|a, _| xyz[3 * k + a]))
        .collect();
    drop(xyz);

    // Cells.
    let cells_el = piece
        .child("Cells")
        .ok_or_else(|| cx.err(piece.offset, "no <Cells> element"))?;
    let get = |name: &str| {
        named(cells_el, name)
            .ok_or_else(|| cx.err(cells_el.offset, format!("<Cells> has no `{name}` array")))
    };
    let conn_el = get("connectivity")?;
    let types_el = get("types")?;
    let offs_el = get("offsets")?;
    let conn = cx.ints(conn_el, None)?;
    let offsets = cx.ints(offs_el, Some(nc))?;
    let types = cx.ints(types_el, Some(nc))?;
    // porofrac's own face stream of every cell (written beside tetrahedra and hexahedra)
    // rebuilds the exact face numbering; else the `<Cells>` faces of the polyhedra.
    let field_faces = if D == 3 {
        let fds: Vec<_> = [ug.child("FieldData"), piece.child("FieldData")]
            .into_iter()
            .flatten()
            .collect();
        let fe = fds.iter().find_map(|fd| named(fd, FACES));
        let fo = fds.iter().find_map(|fd| named(fd, FACE_OFFSETS));
        match (fe, fo) {
            (Some(fe), Some(fo)) => Some((cx.ints(fe, None)?, cx.ints(fo, Some(nc))?, fe.offset)),
            _ => None,
        }
    } else {
        None
    };
    let own_faces = field_faces.is_some();
    let poly = if field_faces.is_some() {
        field_faces
    } else if types.contains(&42) {
        let fe = get("faces")?;
        let fo = get("faceoffsets")?;
        Some((cx.ints(fe, None)?, cx.ints(fo, Some(nc))?, fe.offset))
    } else {
        None
    };
    // Optional 2D face order (see `edge_order`).
    let mut order: Option<(Vec<i64>, usize)> = None;
    if D == 2
        && let Some(el) = [ug.child("FieldData"), piece.child("FieldData")]
            .into_iter()
            .flatten()
            .find_map(|fd| named(fd, EDGE_ORDER))
    {
        order = Some((cx.ints(el, None)?, el.offset));
    }
    let mut order_pos = 0usize;
    let mut loops = CellFaceLoops::new();
    let mut origin = Vec::with_capacity(nc);
    let mut start = 0usize;
    let mut face_start = 0usize;
    let mut v: Vec<usize> = Vec::with_capacity(8);
    let point = |id: i64, c: usize, off: usize| -> Result<usize> {
        if id < 0 || id as usize >= np {
            Err(cx.err(
                off,
                format!("cell {c}: point {id} does not exist ({np} points)"),
            ))
        } else {
            Ok(id as usize)
        }
    };
    for c in 0..nc {
        let end = offsets[c];
        if end < start as i64 || end as usize > conn.len() {
            return Err(cx.err(
                offs_el.offset,
                format!(
                    "cell {c}: offset {end} is out of order or past the connectivity ({} ids)",
                    conn.len()
                ),
            ));
        }
        let end = end as usize;
        v.clear();
        for &id in &conn[start..end] {
            v.push(point(id, c, conn_el.offset)?);
        }
        start = end;
        let t = types[c];
        let shape = match (D, t) {
            // Triangles and quadrilaterals go the polygon's way (with the edge order).
            (2, 5 | 9) => {
                let want = if t == 5 { 3 } else { 4 };
                if v.len() != want {
                    return Err(cx.err(
                        conn_el.offset,
                        format!(
                            "cell {c}: a {} needs {want} points, got {}",
                            if t == 5 { "triangle" } else { "quadrilateral" },
                            v.len()
                        ),
                    ));
                }
                None
            }
            (2, 7) => None,
            (3, 10 | 12 | 13 | 14) if own_faces => None,
            (3, 10) => Some(Shape::Tetra),
            (3, 12) => Some(Shape::Hexa),
            (3, 13) => Some(Shape::Prism),
            (3, 14) => Some(Shape::Pyramid),
            (3, 42) => None,
            _ => {
                return Err(cx.err(
                    types_el.offset,
                    format!("cell {c}: VTK cell type {t} is not supported in a {D}D grid"),
                ));
            }
        };
        if let Some(s) = shape {
            if v.len() != s.num_nodes() {
                return Err(cx.err(
                    conn_el.offset,
                    format!(
                        "cell {c}: a {} needs {} points, got {}",
                        s.name(),
                        s.num_nodes(),
                        v.len()
                    ),
                ));
            }
            s.push(&mut loops, &v);
        } else if D == 2 {
            if v.len() < 3 {
                return Err(cx.err(
                    conn_el.offset,
                    format!("cell {c}: a polygon needs at least 3 points"),
                ));
            }
            match &order {
                None => loops.push_polygon(&v),
                Some((ord, off)) => {
                    let m = v.len();
                    let chunk = ord.get(order_pos..order_pos + m).ok_or_else(|| {
                        cx.err(*off, format!("{EDGE_ORDER}: too short for cell {c}"))
                    })?;
                    let mut hit = [false; 64];
                    for &p in chunk {
                        let ok = p >= 0 && (p as usize) < m && (m > 64 || !hit[p as usize]);
                        if !ok {
                            return Err(cx.err(
                                *off,
                                format!(
                                    "{EDGE_ORDER}: cell {c} is not a permutation of its {m} edges"
                                ),
                            ));
                        }
                        if m <= 64 {
                            hit[p as usize] = true;
                        }
                        let p = p as usize;
                        loops.push_face(&[v[p], v[(p + 1) % m]]);
                    }
                    loops.finish_cell();
                    order_pos += m;
                }
            }
        } else {
            let Some((faces, fo, foff)) = &poly else {
                return Err(cx.err(cells_el.offset, "polyhedra without a faces array"));
            };
            let fend = fo[c];
            let bad = |w: String| cx.err(*foff, format!("cell {c}: {w}"));
            if fend < face_start as i64 || fend as usize > faces.len() {
                return Err(bad(format!(
                    "faceoffset {fend} is out of order or past the faces array"
                )));
            }
            let fend = fend as usize;
            let stream = &faces[face_start..fend];
            let nfaces = *stream
                .first()
                .ok_or_else(|| bad("empty face list".into()))?;
            let mut k = 1usize;
            for _ in 0..nfaces.max(0) {
                let m = *stream
                    .get(k)
                    .ok_or_else(|| bad("face list shorter than declared".into()))?;
                if m < 3 || m as usize > stream.len() - k - 1 {
                    return Err(bad(format!("bad face size {m}")));
                }
                v.clear();
                for &id in &stream[k + 1..k + 1 + m as usize] {
                    v.push(point(id, c, *foff)?);
                }
                loops.push_face(&v);
                k += 1 + m as usize;
            }
            if k != stream.len() {
                return Err(bad(format!(
                    "face list has {} extra values",
                    stream.len() - k
                )));
            }
            loops.finish_cell();
            face_start = fend;
        }
        if !own_faces
            && poly.is_some()
            && shape.is_some()
            && poly.as_ref().is_some_and(|p| p.1[c] >= 0)
        {
            return Err(cx.err(
                cells_el.offset,
                format!("cell {c}: faceoffset must be -1 for a non-polyhedral cell"),
            ));
        }
        origin.push(Origin {
            line: cx.lines.line(types_el.offset),
            tag: c as u64,
            standard: shape.is_some() || D == 2,
        });
    }
    if let Some((ord, off)) = &order
        && order_pos != ord.len()
    {
        return Err(cx.err(
            *off,
            format!(
                "{EDGE_ORDER} has {} values, the polygons have {order_pos} edges",
                ord.len()
            ),
        ));
    }
    let raw = RawMesh::<D> {
        nodes,
        node_label: (0..np)
            .map(|k| (k as u64, cx.lines.line(pts_el.offset)))
            .collect(),
        loops,
        origin,
        what_cell: "VTK cell",
        what_node: "VTK point",
    };
    let built = raw.build(path)?;
    let mut grid = built.grid;
    let in_file = |e: GridError| GridError::InFile {
        path: path.to_path_buf(),
        source: Box::new(e),
    };

    // Tags.
    let mut cell_tags: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    if let Some(cd) = piece.child("CellData") {
        let mut have_named = false;
        for el in cd.children_named("DataArray") {
            if let Some(name) = el.attr("Name").and_then(|n| n.strip_prefix("tag:")) {
                have_named = true;
                let vals = cx.ints(el, Some(nc))?;
                let cells = (0..nc).filter(|&c| vals[c] != 0).collect();
                cell_tags.insert(name.to_string(), cells);
            }
        }
        if !have_named && let Some(el) = named(cd, "tag") {
            let vals = cx.ints(el, Some(nc))?;
            for (c, &t) in vals.iter().enumerate() {
                cell_tags.entry(format!("tag_{t}")).or_default().push(c);
            }
        }
    }
    for (name, cells) in cell_tags {
        grid.set_cell_tag(name, cells).map_err(in_file)?;
    }
    for fd in [ug.child("FieldData"), piece.child("FieldData")]
        .into_iter()
        .flatten()
    {
        for el in fd.children_named("DataArray") {
            if let Some(name) = el.attr("Name").and_then(|n| n.strip_prefix("facetag:")) {
                let vals = cx.ints(el, None)?;
                if let Some(&f) = vals
                    .iter()
                    .find(|&&f| f < 0 || f as usize >= grid.num_faces())
                {
                    return Err(cx.err(
                        el.offset,
                        format!(
                            "face tag `{name}` lists face {f}; the grid has {} faces",
                            grid.num_faces()
                        ),
                    ));
                }
                grid.set_face_tag(name, vals.iter().map(|&f| f as usize).collect())
                    .map_err(in_file)?;
            }
        }
    }
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::cartesian;
    use crate::io::vtu_write::{Encoding, Field, vtu_bytes};

    /// The VTK cell types of a written grid, and the grid read back.
    fn written_types<const D: usize>(g: &Grid<D>) -> Vec<i64> {
        let mut types = Vec::new();
        for enc in [Encoding::Ascii, Encoding::Base64, Encoding::Appended] {
            let bytes = vtu_bytes(g, &[], &[], enc).unwrap();
            let text = String::from_utf8_lossy(&bytes).into_owned();
            if enc != Encoding::Appended {
                let cx = Ctx {
                    path: Path::new("x.vtu"),
                    lines: LineIndex::new(&text),
                    big_endian: false,
                    header64: true,
                    zlib: false,
                    appended: None,
                };
                let root = xml::parse(&text).ok().unwrap();
                let cells = root
                    .child("UnstructuredGrid")
                    .and_then(|u| u.child("Piece"))
                    .and_then(|p| p.child("Cells"))
                    .unwrap();
                let t = cx
                    .ints(named(cells, "types").unwrap(), Some(g.num_cells()))
                    .unwrap();
                if !types.is_empty() {
                    assert_eq!(t, types, "{enc:?}");
                }
                types = t;
            }
            let path = std::env::temp_dir().join(format!(
                "porofrac_vtu_types_{}_{D}_{}_{enc:?}.vtu",
                std::process::id(),
                g.num_cells()
            ));
            std::fs::write(&path, &bytes).unwrap();
            let back: Grid<D> = read_vtu(&path).unwrap();
            std::fs::remove_file(&path).unwrap();
            assert!(back == *g, "{enc:?}: read(write(g)) != g");
        }
        types
    }

    /// Triangles (5), quadrilaterals (9), tetrahedra (10) and hexahedra (12) are written
    /// with their own VTK types, other cells as polygons (7) and polyhedra (42); every
    /// grid reads back identical.
    #[test]
    fn standard_cell_types() {
        use crate::generate::simplices;
        let lo2 = Point::<2>::new(0.0, 0.0);
        let hi2 = Point::<2>::new(2.0, 1.0);
        let tri = simplices::<2>(lo2, hi2, [2, 1]).unwrap();
        assert_eq!(written_types(&tri), vec![5; tri.num_cells()]);
        let quads = cartesian::<2>(lo2, hi2, [2, 1]).unwrap();
        assert_eq!(written_types(&quads), vec![9, 9]);
        // A quadrilateral, a pentagon (hanging node 5 on its bottom edge) and a triangle.
        let nodes = vec![
            Point::<2>::new(0.0, 0.0),
            Point::<2>::new(1.0, 0.0),
            Point::<2>::new(2.0, 0.0),
            Point::<2>::new(0.0, 1.0),
            Point::<2>::new(1.0, 1.0),
            Point::<2>::new(1.5, 0.0),
            Point::<2>::new(2.0, 1.0),
            Point::<2>::new(1.0, 2.0),
        ];
        let mut loops = CellFaceLoops::new();
        loops.push_polygon(&[0, 1, 4, 3]);
        loops.push_polygon(&[1, 5, 2, 6, 4]);
        loops.push_polygon(&[4, 6, 7]);
        let mixed = Grid::<2>::from_cell_faces(nodes, &loops).unwrap();
        assert_eq!(written_types(&mixed), vec![9, 7, 5]);
        let lo3 = Point::<3>::new(0.0, 0.0, 0.0);
        let hi3 = Point::<3>::new(1.0, 2.0, 3.0);
        let tets = simplices::<3>(lo3, hi3, [2, 1, 1]).unwrap();
        assert_eq!(written_types(&tets), vec![10; tets.num_cells()]);
        let hexes = cartesian::<3>(lo3, hi3, [2, 1, 1]).unwrap();
        assert_eq!(written_types(&hexes), vec![12, 12]);
        // Hexahedra and tetrahedra with prisms and a pyramid, which stay polyhedra.
        let mixed3: Grid<3> = crate::io::read_msh(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mixed.msh"),
        )
        .unwrap();
        assert_eq!(written_types(&mixed3), vec![12, 42, 42, 42, 10, 10]);
    }

    /// Field arrays are written with the right layout in both encodings.
    #[test]
    fn field_layout() {
        let g =
            cartesian::<2>(Point::<2>::new(0.0, 0.0), Point::<2>::new(2.0, 1.0), [2, 1]).unwrap();
        let s = [0.1, -2.5e-300];
        let vecs = [Point::<2>::new(1.0, 2.0), Point::<2>::new(3.0, 4.0)];
        let t = [[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]; 2];
        let ints = [7, -8];
        let full: Vec<f64> = (0..18).map(|k| k as f64 - 0.5).collect();
        let cd = [
            ("s", Field::Scalars(&s)),
            ("v", Field::Vectors(&vecs)),
            ("t", Field::SymTensors(&t)),
            ("i", Field::Ints(&ints)),
            (
                "f",
                Field::Components {
                    components: 9,
                    values: &full,
                },
            ),
        ];
        for enc in [Encoding::Ascii, Encoding::Base64] {
            let text = String::from_utf8(vtu_bytes(&g, &[], &cd, enc).unwrap()).unwrap();
            let cx = Ctx {
                path: Path::new("x.vtu"),
                lines: LineIndex::new(&text),
                big_endian: false,
                header64: true,
                zlib: false,
                appended: None,
            };
            let root = xml::parse(&text).ok().unwrap();
            let cdel = root
                .child("UnstructuredGrid")
                .and_then(|u| u.child("Piece"))
                .and_then(|p| p.child("CellData"))
                .unwrap();
            let get = |n: &str, nc: usize| {
                cx.array(named(cdel, n).unwrap(), nc, Some(2), false)
                    .unwrap()
            };
            assert_eq!(get("s", 1), s.to_vec());
            assert_eq!(get("v", 3), vec![1.0, 2.0, 0.0, 3.0, 4.0, 0.0]);
            // xx yy zz xy yz xz → row-major [xx xy xz; xy yy yz; xz yz zz]
            assert_eq!(
                &get("t", 9)[..9],
                &[1.0, 4.0, 6.0, 4.0, 2.0, 5.0, 6.0, 5.0, 3.0]
            );
            assert_eq!(get("i", 1), vec![7.0, -8.0]);
            assert_eq!(get("f", 9), full);
        }
        // A component count that does not divide the values is an error.
        let odd: [(&str, Field<'_, 2>); 1] = [(
            "f",
            Field::Components {
                components: 4,
                values: &full,
            },
        )];
        let e = vtu_bytes(&g, &[], &odd, Encoding::Ascii)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a multiple of its 4 components"), "{e}");
        // Bad lengths and reserved names are errors.
        assert!(vtu_bytes(&g, &[("p", Field::Scalars(&s))], &[], Encoding::Ascii).is_err());
        assert!(vtu_bytes(&g, &[], &[("tag", Field::Ints(&ints))], Encoding::Ascii).is_err());
    }

    /// VTK's own variant: a UInt32 header encoded as a separate base64 stream, big-endian.
    #[test]
    fn separate_header_big_endian() {
        let vals = [1.5f64, -2.0, 3.25e-7];
        let mut data = Vec::new();
        for v in vals {
            data.extend_from_slice(&v.to_be_bytes());
        }
        let mut text = String::new();
        base64::encode_into(&(data.len() as u32).to_be_bytes(), &mut text);
        text.push('\n');
        base64::encode_into(&data, &mut text);
        let doc =
            format!("<DataArray type=\"Float64\" Name=\"x\" format=\"binary\">{text}</DataArray>");
        let el = xml::parse(&doc).ok().unwrap();
        let cx = Ctx {
            path: Path::new("x.vtu"),
            lines: LineIndex::new(&doc),
            big_endian: true,
            header64: false,
            zlib: false,
            appended: None,
        };
        assert_eq!(cx.array(&el, 1, Some(3), false).unwrap(), vals.to_vec());
        // A header claiming more bytes than present is an error.
        let mut h = String::new();
        base64::encode_into(&99u32.to_be_bytes(), &mut h);
        let doc = doc.replacen(&text[..8], &h, 1);
        let el = xml::parse(&doc).ok().unwrap();
        assert!(cx.array(&el, 1, None, false).is_err());
    }

    fn ctx(big_endian: bool, header64: bool, zlib: bool) -> Ctx<'static> {
        Ctx {
            path: Path::new("x.vtu"),
            lines: LineIndex::new(""),
            big_endian,
            header64,
            zlib,
            appended: None,
        }
    }

    fn word(v: u64, cx: &Ctx<'_>, out: &mut Vec<u8>) {
        match (cx.header64, cx.big_endian) {
            (true, true) => out.extend_from_slice(&v.to_be_bytes()),
            (true, false) => out.extend_from_slice(&v.to_le_bytes()),
            (false, true) => out.extend_from_slice(&(v as u32).to_be_bytes()),
            (false, false) => out.extend_from_slice(&(v as u32).to_le_bytes()),
        }
    }

    /// VTK's zlib layout: header, then one zlib stream per block.
    fn zlib_block(cx: &Ctx<'_>, data: &[u8], bs: usize) -> Vec<u8> {
        use std::io::Write as _;
        let blocks: Vec<Vec<u8>> = data
            .chunks(bs)
            .map(|c| {
                let mut e =
                    flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                e.write_all(c).unwrap();
                e.finish().unwrap()
            })
            .collect();
        let mut out = Vec::new();
        word(blocks.len() as u64, cx, &mut out);
        word(bs as u64, cx, &mut out);
        word((data.len() % bs) as u64, cx, &mut out);
        for b in &blocks {
            word(b.len() as u64, cx, &mut out);
        }
        for b in &blocks {
            out.extend_from_slice(b);
        }
        out
    }

    fn at() -> ArrayAt<'static> {
        ArrayAt {
            name: "x",
            offset: 0,
            how: "inline binary".into(),
        }
    }

    fn unpack_err(cx: &Ctx<'_>, src: &[u8], expected: Option<usize>) -> String {
        match cx.unpack(src, &at(), Ty::F64, expected) {
            Err(e) => e.to_string(),
            Ok(v) => panic!("expected an error, got {} bytes", v.len()),
        }
    }

    /// zlib blocks in both byte orders and header types, with a partial last block, a
    /// full last block (size 0 in the header) and no block at all.
    #[test]
    fn zlib_blocks() {
        for (be, h64) in [(false, false), (false, true), (true, false), (true, true)] {
            let cx = ctx(be, h64, true);
            for n in [1000usize, 512, 0] {
                let vals: Vec<f64> = (0..n).map(|k| (k as f64).sqrt() - 7.25).collect();
                let mut bytes = Vec::new();
                for v in &vals {
                    bytes.extend_from_slice(&if be { v.to_be_bytes() } else { v.to_le_bytes() });
                }
                let src = zlib_block(&cx, &bytes, 1024);
                let out = cx.unpack(&src, &at(), Ty::F64, Some(8 * n)).unwrap();
                assert_eq!(cx.convert(&out, Ty::F64), vals);
            }
        }
    }

    #[test]
    fn zlib_errors_before_allocation() {
        let cx = ctx(false, true, true);
        let bytes: Vec<u8> = (0..4000u32)
            .flat_map(|k| (k as f64).to_le_bytes())
            .collect();
        let good = zlib_block(&cx, &bytes, 4096);
        assert!(cx.unpack(&good, &at(), Ty::F64, Some(32000)).is_ok());
        // A header claiming 10^15 blocks.
        let mut bad = good.clone();
        bad[..8].copy_from_slice(&1_000_000_000_000_000u64.to_le_bytes());
        let m = unpack_err(&cx, &bad, None);
        assert!(m.contains("1000000000000000 blocks"), "{m}");
        // A block claiming 10^15 bytes from a few compressed ones.
        let mut bad = good.clone();
        bad[8..16].copy_from_slice(&1_000_000_000_000_000u64.to_le_bytes());
        let m = unpack_err(&cx, &bad, None);
        assert!(m.contains("cannot inflate"), "{m}");
        // Compressed sizes past the end (the data cut short).
        let m = unpack_err(&cx, &good[..good.len() - 10], None);
        assert!(m.contains("only"), "{m}");
        // Fewer bytes than the header itself.
        let m = unpack_err(&cx, &good[..20], None);
        assert!(m.contains("no compression header"), "{m}");
        // A corrupt stream: bytes of the first block overwritten.
        let mut bad = good.clone();
        let h = 8 * (3 + 8);
        for b in &mut bad[h + 2..h + 40] {
            *b = 0xa5;
        }
        let m = unpack_err(&cx, &bad, None);
        assert!(m.contains("block 0 of 8"), "{m}");
        // The expected size disagrees with the header.
        let m = unpack_err(&cx, &good, Some(8 * 3999));
        assert!(m.contains("expected 31992 bytes"), "{m}");
        // Uncompressed: a size header past the data.
        let cx = ctx(false, false, false);
        let mut raw = 800u32.to_le_bytes().to_vec();
        raw.extend_from_slice(&[0; 16]);
        let m = unpack_err(&cx, &raw, None);
        assert!(m.contains("800 bytes, only 16 follow"), "{m}");
        let m = unpack_err(&cx, &raw[..3], None);
        assert!(m.contains("no 4-byte size header"), "{m}");
    }
}
