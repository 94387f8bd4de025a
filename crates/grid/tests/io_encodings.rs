//! Meshes written by VTK and Gmsh themselves in their binary encodings
//! (`tests/data/make_fixtures.py`): counts, measures and tags, the same grid bit for bit as
//! the ASCII file of the same mesh, and errors (never panics) for damaged files.
//!
//! `enc2d`: [0, 1]² in 31 triangles (Gmsh group 1 "tri") and [1, 2] × [0, 1] in 22
//! quadrangles (group 2 "quad"), left edge group 3 "left"; 49 nodes.
//! `enc3d`: the unit cube in 138 tetrahedra, 70 below z = 0.5 (group 1 "lower") and 68
//! above (group 2 "upper"), bottom face group 5 "bottom"; 52 nodes.

use std::path::{Path, PathBuf};

use porofrac_grid::io::{parse_msh_bytes, read_msh, read_vtu};
use porofrac_grid::{Grid, GridError};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("io_encodings");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The encodings of the `.vtu` fixtures besides `ascii`.
const VTU: [&str; 5] = [
    "appended_raw",
    "appended_zlib",
    "appended_base64",
    "binary_zlib",
    "appended_zlib_u32_be",
];

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn volume<const D: usize>(g: &Grid<D>, cells: &[usize]) -> f64 {
    cells.iter().map(|&c| g.cell_volume(c)).sum()
}

fn total<const D: usize>(g: &Grid<D>) -> f64 {
    g.cell_volumes().iter().sum()
}

fn face_area<const D: usize>(g: &Grid<D>, name: &str) -> f64 {
    g.face_tags()[name].iter().map(|&f| g.face_area(f)).sum()
}

/// The same grid, with node coordinates equal bit for bit.
fn assert_same<const D: usize>(a: &Grid<D>, b: &Grid<D>, what: &str) {
    assert_eq!(a.num_nodes(), b.num_nodes(), "{what}");
    for (k, (p, q)) in a.nodes().iter().zip(b.nodes()).enumerate() {
        for i in 0..D {
            assert_eq!(p[i].to_bits(), q[i].to_bits(), "{what}: node {k}");
        }
    }
    assert!(a == b, "{what}: not the same grid");
}

// ------------------------------------------------------------------ VTK

#[test]
fn vtu_2d_every_encoding_equals_ascii() {
    let ascii: Grid<2> = read_vtu(data("enc2d_ascii.vtu")).unwrap();
    assert_eq!(ascii.num_nodes(), 49);
    assert_eq!(ascii.num_cells(), 53);
    assert_eq!(ascii.cell_tags().len(), 2);
    let tri = &ascii.cell_tags()["tag_1"];
    let quad = &ascii.cell_tags()["tag_2"];
    assert_eq!((tri.len(), quad.len()), (31, 22));
    assert!(tri.iter().all(|&c| ascii.cell_nodes(c).len() == 3));
    assert!(quad.iter().all(|&c| ascii.cell_nodes(c).len() == 4));
    assert!(rel(total(&ascii), 2.0) <= 1e-12, "{}", total(&ascii));
    assert!(rel(volume(&ascii, tri), 1.0) <= 1e-12);
    assert!(rel(volume(&ascii, quad), 1.0) <= 1e-12);
    for enc in VTU {
        let g: Grid<2> = read_vtu(data(&format!("enc2d_{enc}.vtu"))).unwrap();
        assert_same(&g, &ascii, enc);
    }
}

#[test]
fn vtu_3d_every_encoding_equals_ascii() {
    let ascii: Grid<3> = read_vtu(data("enc3d_ascii.vtu")).unwrap();
    assert_eq!(ascii.num_nodes(), 52);
    assert_eq!(ascii.num_cells(), 138);
    let lower = &ascii.cell_tags()["tag_1"];
    let upper = &ascii.cell_tags()["tag_2"];
    assert_eq!((lower.len(), upper.len()), (70, 68));
    assert!(rel(total(&ascii), 1.0) <= 1e-12, "{}", total(&ascii));
    assert!(rel(volume(&ascii, lower), 0.5) <= 1e-12);
    assert!(rel(volume(&ascii, upper), 0.5) <= 1e-12);
    assert!(lower.iter().all(|&c| ascii.cell_centroid(c)[2] < 0.5));
    for enc in VTU {
        let g: Grid<3> = read_vtu(data(&format!("enc3d_{enc}.vtu"))).unwrap();
        assert_same(&g, &ascii, enc);
    }
}

/// VTK's grid holds Gmsh's nodes and cells in Gmsh's order.
#[test]
fn vtu_and_msh_of_one_mesh_agree() {
    let v: Grid<2> = read_vtu(data("enc2d_appended_zlib.vtu")).unwrap();
    let m: Grid<2> = read_msh(data("enc2d_binary.msh")).unwrap();
    assert_eq!(v.nodes(), m.nodes());
    assert_eq!(v.cell_volumes(), m.cell_volumes());
    assert_eq!(v.cell_tags()["tag_1"], m.cell_tags()["tri"]);
    let v: Grid<3> = read_vtu(data("enc3d_appended_zlib.vtu")).unwrap();
    let m: Grid<3> = read_msh(data("enc3d_binary.msh")).unwrap();
    assert_eq!(v.nodes(), m.nodes());
    assert_eq!(v.cell_volumes(), m.cell_volumes());
    assert_eq!(v.cell_tags()["tag_2"], m.cell_tags()["upper"]);
}

/// Byte position of the first byte after the `_` marker of `<AppendedData>`.
fn appended_start(bytes: &[u8]) -> usize {
    let a = bytes
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap();
    a + bytes[a..].iter().position(|&b| b == b'_').unwrap() + 1
}

/// The `offset` attribute of the DataArray `name`.
fn offset_of(bytes: &[u8], name: &str) -> usize {
    let head = String::from_utf8_lossy(&bytes[..appended_start(bytes)]).into_owned();
    let at = head.find(&format!("Name=\"{name}\"")).unwrap();
    let o = at + head[at..].find("offset=\"").unwrap() + 8;
    head[o..o + head[o..].find('"').unwrap()].parse().unwrap()
}

/// A parse error naming `path`; returns the message.
fn parse_err<T>(r: Result<T, GridError>, path: &Path) -> String {
    match r {
        Err(e @ GridError::Parse { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.starts_with(&path.display().to_string()),
                "message does not name the file: {msg}"
            );
            eprintln!("MSG {msg}");
            msg
        }
        Err(e) => panic!("expected a parse error, got {e:?}"),
        Ok(_) => panic!("expected a parse error, got a grid"),
    }
}

/// Position of the first `needle` in `hay`.
fn find(hay: &[u8], needle: &str) -> usize {
    hay.windows(needle.len())
        .position(|w| w == needle.as_bytes())
        .unwrap_or_else(|| panic!("`{needle}` not found"))
}

/// `bytes` with the first `from` replaced by `to`.
fn replace(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let at = find(bytes, from);
    [&bytes[..at], to.as_bytes(), &bytes[at + from.len()..]].concat()
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let p = tmp(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn vtu_truncated_appended_data() {
    let bytes = std::fs::read(data("enc3d_appended_raw.vtu")).unwrap();
    let start = appended_start(&bytes);
    // The file ends inside the connectivity array.
    let cut = start + offset_of(&bytes, "connectivity") + 100;
    let p = write("cut.vtu", &bytes[..cut]);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(
        m.contains("`connectivity`") && m.contains("cut short"),
        "{m}"
    );
    // 40 bytes of the last array missing, the closing tags still there.
    let mut short = bytes.clone();
    let end = short.len() - b"\n  </AppendedData>\n</VTKFile>\n".len();
    short.drain(end - 40..end);
    let p = write("short.vtu", &short);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(m.contains("`types`") && m.contains("only"), "{m}");
    // Cut inside the base64 text.
    let bytes = std::fs::read(data("enc3d_appended_base64.vtu")).unwrap();
    let cut = appended_start(&bytes) + offset_of(&bytes, "offsets") + 10;
    let p = write("cut64.vtu", &bytes[..cut]);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(m.contains("`offsets`") && m.contains("cut short"), "{m}");
}

#[test]
fn vtu_bad_offset() {
    for name in ["enc3d_appended_raw.vtu", "enc3d_appended_zlib.vtu"] {
        let bytes = std::fs::read(data(name)).unwrap();
        let from = format!("offset=\"{}\"", offset_of(&bytes, "connectivity"));
        // Past the end of the data.
        let p = write("offset.vtu", &replace(&bytes, &from, "offset=\"99999999\""));
        let m = parse_err(read_vtu::<3>(&p), &p);
        assert!(
            m.contains("`connectivity`") && m.contains("past the end"),
            "{m}"
        );
        // Into the middle of another array.
        let p = write("offset.vtu", &replace(&bytes, &from, "offset=\"17\""));
        let m = parse_err(read_vtu::<3>(&p), &p);
        assert!(m.contains("`connectivity`"), "{m}");
        // Not a number.
        let p = write("offset.vtu", &replace(&bytes, &from, "offset=\"x\""));
        let m = parse_err(read_vtu::<3>(&p), &p);
        assert!(
            m.contains("`connectivity`") && m.contains("offset `x`"),
            "{m}"
        );
    }
}

#[test]
fn vtu_corrupt_zlib_stream() {
    let mut bytes = std::fs::read(data("enc3d_appended_zlib.vtu")).unwrap();
    // Overwrite compressed bytes of the connectivity (after its 4-word UInt64 header).
    let at = appended_start(&bytes) + offset_of(&bytes, "connectivity") + 4 * 8 + 3;
    for b in &mut bytes[at..at + 40] {
        *b ^= 0x5a;
    }
    let p = write("corrupt.vtu", &bytes);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(
        m.contains("`connectivity`") && m.contains("block 0 of 1"),
        "{m}"
    );
    // In an inline compressed file: a damaged character of the compressed Points.
    let mut b = std::fs::read(data("enc3d_binary_zlib.vtu")).unwrap();
    let at = find(&b, "Name=\"Points\"");
    // Past the end of the separately encoded block header.
    let text = at + find(&b[at..], ">");
    let at = text + find(&b[text..], "=") + 30;
    b[at] = if b[at] == b'A' { b'B' } else { b'A' };
    let p = write("corrupt64.vtu", &b);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(m.contains("`Points`"), "{m}");
}

#[test]
fn vtu_absurd_counts() {
    let bytes = std::fs::read(data("enc3d_appended_zlib.vtu")).unwrap();
    // A piece claiming 10^15 points.
    let b = replace(
        &bytes,
        "NumberOfPoints=\"52\"",
        "NumberOfPoints=\"1000000000000000\"",
    );
    let p = write("points.vtu", &b);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(m.contains("`Points`") && m.contains("expected"), "{m}");
    // A compression header claiming 10^15 blocks, and one claiming blocks of 10^15 bytes.
    let conn = appended_start(&bytes) + offset_of(&bytes, "connectivity");
    for (words, what) in [(0..1, "1000000000000000 blocks"), (1..3, "cannot inflate")] {
        let mut b = bytes.clone();
        for w in words {
            b[conn + 8 * w..conn + 8 * w + 8]
                .copy_from_slice(&1_000_000_000_000_000u64.to_le_bytes());
        }
        let p = write("blocks.vtu", &b);
        let m = parse_err(read_vtu::<3>(&p), &p);
        assert!(m.contains("`connectivity`") && m.contains(what), "{m}");
    }
    // An uncompressed size header claiming 10^15 bytes.
    let mut b = std::fs::read(data("enc3d_appended_raw.vtu")).unwrap();
    let conn = appended_start(&b) + offset_of(&b, "connectivity");
    b[conn..conn + 8].copy_from_slice(&1_000_000_000_000_000u64.to_le_bytes());
    let p = write("bytes.vtu", &b);
    let m = parse_err(read_vtu::<3>(&p), &p);
    assert!(
        m.contains("`connectivity`") && m.contains("1000000000000000 bytes"),
        "{m}"
    );
}

/// xorshift64 for reproducible damage.
fn rng(mut state: u64) -> impl FnMut() -> u64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    }
}

/// Random byte edits and truncations of the binary fixtures give errors or grids, never
/// panics.
#[test]
fn damaged_binary_files_never_panic() {
    let mut next = rng(0x9e37_79b9_7f4a_7c15);
    for name in ["enc2d_binary.msh", "enc3d_binary.msh"] {
        let bytes = std::fs::read(data(name)).unwrap();
        let data_start = section_data(&bytes, "Entities").start;
        for i in 0..400 {
            // Mostly in the binary data, sometimes anywhere.
            let start = if i % 4 == 0 { 0 } else { data_start };
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 4 {
                let at = start + (next() as usize) % (b.len() - start);
                b[at] = next() as u8;
            }
            let _ = parse_msh_bytes::<2>(&b, "fuzz.msh");
            let _ = parse_msh_bytes::<3>(&b, "fuzz.msh");
        }
    }
    for name in [
        "enc2d_appended_raw.vtu",
        "enc2d_appended_zlib.vtu",
        "enc2d_appended_zlib_u32_be.vtu",
        "enc2d_appended_base64.vtu",
        "enc2d_binary_zlib.vtu",
    ] {
        let bytes = std::fs::read(data(name)).unwrap();
        let data_start = appended_start_or_zero(&bytes);
        let p = tmp(&format!("fuzz_{name}"));
        for i in 0..200 {
            let start = if i % 8 == 1 { 0 } else { data_start };
            let mut b = bytes.clone();
            if i % 4 == 0 {
                b.truncate(start + (next() as usize) % (b.len() - start));
            } else {
                for _ in 0..1 + next() % 4 {
                    let at = start + (next() as usize) % (b.len() - start);
                    b[at] = next() as u8;
                }
            }
            std::fs::write(&p, &b).unwrap();
            let _ = read_vtu::<2>(&p);
            let _ = read_vtu::<3>(&p);
        }
    }
}

fn appended_start_or_zero(bytes: &[u8]) -> usize {
    if bytes.windows(13).any(|w| w == b"<AppendedData") {
        appended_start(bytes)
    } else {
        0
    }
}

// ------------------------------------------------------------------ Gmsh

#[test]
fn msh_2d_binary_equals_ascii() {
    let ascii: Grid<2> = read_msh(data("enc2d_ascii.msh")).unwrap();
    let binary: Grid<2> = read_msh(data("enc2d_binary.msh")).unwrap();
    assert_same(&binary, &ascii, "enc2d_binary.msh");
    let g = &binary;
    assert_eq!(g.num_nodes(), 49);
    assert_eq!(g.num_cells(), 53);
    assert_eq!(g.cell_tags().len(), 2);
    assert_eq!(g.cell_tags()["tri"].len(), 31);
    assert_eq!(g.cell_tags()["quad"].len(), 22);
    assert!(rel(total(g), 2.0) <= 1e-12, "{}", total(g));
    assert!(rel(volume(g, &g.cell_tags()["tri"]), 1.0) <= 1e-12);
    assert!(rel(volume(g, &g.cell_tags()["quad"]), 1.0) <= 1e-12);
    assert_eq!(g.face_tags().len(), 1);
    assert_eq!(g.face_tags()["left"].len(), 3);
    assert!(rel(face_area(g, "left"), 1.0) <= 1e-12);
    assert_eq!(g.face_tags()["left"], g.boundary("xmin").unwrap());
}

#[test]
fn msh_3d_binary_equals_ascii() {
    let ascii: Grid<3> = read_msh(data("enc3d_ascii.msh")).unwrap();
    let binary: Grid<3> = read_msh(data("enc3d_binary.msh")).unwrap();
    assert_same(&binary, &ascii, "enc3d_binary.msh");
    let g = &binary;
    assert_eq!(g.num_nodes(), 52);
    assert_eq!(g.num_cells(), 138);
    assert_eq!(g.cell_tags().len(), 2);
    assert_eq!(g.cell_tags()["lower"].len(), 70);
    assert_eq!(g.cell_tags()["upper"].len(), 68);
    assert!(rel(total(g), 1.0) <= 1e-12, "{}", total(g));
    assert!(rel(volume(g, &g.cell_tags()["lower"]), 0.5) <= 1e-12);
    assert!(rel(volume(g, &g.cell_tags()["upper"]), 0.5) <= 1e-12);
    assert_eq!(g.face_tags().len(), 1);
    assert_eq!(g.face_tags()["bottom"].len(), 14);
    assert!(rel(face_area(g, "bottom"), 1.0) <= 1e-12);
    assert_eq!(g.face_tags()["bottom"], g.boundary("zmin").unwrap());
}

/// Byte range of the binary data of section `name` (after its header line, before the
/// newline that precedes `$End…`).
fn section_data(bytes: &[u8], name: &str) -> std::ops::Range<usize> {
    let start = find(bytes, &format!("${name}\n")) + name.len() + 2;
    let end = start + find(&bytes[start..], &format!("\n$End{name}\n"));
    start..end
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    i32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

/// Every cut of a binary file is a parse error naming the file; cuts inside the binary
/// data of a section name that section.
#[test]
fn msh_binary_cut_short() {
    const FILE: &str = "cut.msh";
    for name in ["enc2d_binary.msh", "enc3d_binary.msh"] {
        let bytes = std::fs::read(data(name)).unwrap();
        let sections: Vec<_> = ["Entities", "Nodes", "Elements"]
            .iter()
            .map(|s| (*s, section_data(&bytes, s)))
            .collect();
        // The final newline is not needed.
        for k in 0..bytes.len() - 1 {
            let r = if name.starts_with("enc2d") {
                parse_msh_bytes::<2>(&bytes[..k], FILE).map(|_| ())
            } else {
                parse_msh_bytes::<3>(&bytes[..k], FILE).map(|_| ())
            };
            let m = match r {
                Err(e @ GridError::Parse { .. }) => e.to_string(),
                Err(e) => panic!("{name} cut at {k}: {e}"),
                Ok(_) => panic!("{name} cut at {k}: read"),
            };
            assert!(m.starts_with(FILE), "{m}");
            for (s, r) in &sections {
                if r.start < k && k < r.end {
                    assert!(m.contains(&format!("${s} (binary data, byte")), "{k}: {m}");
                }
            }
        }
    }
    // One message in full.
    let bytes = std::fs::read(data("enc2d_binary.msh")).unwrap();
    let r = section_data(&bytes, "Elements");
    let p = write("cut.msh", &bytes[..r.start + 100]);
    let m = parse_err(read_msh::<2>(&p), &p);
    assert!(m.contains("$Elements") && m.contains("cut short"), "{m}");
}

#[test]
fn msh_binary_absurd_counts() {
    const HUGE: u64 = 1_000_000_000_000_000;
    let bytes = std::fs::read(data("enc3d_binary.msh")).unwrap();
    let nodes = section_data(&bytes, "Nodes").start;
    let elements = section_data(&bytes, "Elements").start;
    let entities = section_data(&bytes, "Entities").start;
    let cases = [
        (nodes + 8, "1000000000000000 nodes cannot fit"),
        (nodes, "1000000000000000 node blocks cannot fit"),
        // The number of nodes of the first block.
        (nodes + 32 + 12, "more nodes than the 52 declared"),
        (elements + 8, "1000000000000000 elements cannot fit"),
        (elements + 32 + 12, "more elements than the"),
        (entities, "entities cannot fit"),
    ];
    for (at, what) in cases {
        let mut b = bytes.clone();
        b[at..at + 8].copy_from_slice(&HUGE.to_le_bytes());
        let p = write("counts.msh", &b);
        let m = parse_err(read_msh::<3>(&p), &p);
        assert!(m.contains(what), "{m}");
        let section = if at >= elements {
            "$Elements"
        } else if at >= nodes {
            "$Nodes"
        } else {
            "$Entities"
        };
        assert!(m.contains(section), "{m}");
    }
    // The number of elements in a block, once the header total is large enough.
    let mut b = bytes.clone();
    b[elements + 8..elements + 16].copy_from_slice(&HUGE.to_le_bytes());
    b[elements + 32 + 12..elements + 32 + 20].copy_from_slice(&HUGE.to_le_bytes());
    let p = write("counts.msh", &b);
    let m = parse_err(read_msh::<3>(&p), &p);
    assert!(m.contains("$Elements") && m.contains("cannot fit"), "{m}");
}

#[test]
fn msh_binary_byte_order_check() {
    let bytes = std::fs::read(data("enc2d_binary.msh")).unwrap();
    let b = replace(
        &bytes,
        "4.1 1 8\n\x01\x00\x00\x00",
        "4.1 1 8\n\x02\x00\x00\x00",
    );
    let p = write("order.msh", &b);
    let m = parse_err(read_msh::<2>(&p), &p);
    assert!(m.contains(":2:") && m.contains("byte order"), "{m}");
    // An ASCII file declared binary.
    let text = std::fs::read(data("enc2d_ascii.msh")).unwrap();
    let p = write("declared.msh", &replace(&text, "4.1 0 8", "4.1 1 8"));
    let m = parse_err(read_msh::<2>(&p), &p);
    assert!(m.contains(":2:") && m.contains("binary"), "{m}");
}

/// Binary elements are named by tag (no line); the first triangle turned over is an
/// inverted cell.
#[test]
fn msh_binary_inverted_element() {
    let mut b = std::fs::read(data("enc2d_binary.msh")).unwrap();
    let mut at = section_data(&b, "Elements").start;
    let blocks = u64_at(&b, at);
    at += 32;
    for _ in 0..blocks {
        let etype = i32_at(&b, at + 8);
        let n = u64_at(&b, at + 12) as usize;
        at += 20;
        let nn = match etype {
            1 => 2,
            2 => 3,
            3 => 4,
            t => panic!("type {t}"),
        };
        if etype == 2 {
            // Swap the second and third node tags of the first triangle.
            let (n1, n2) = (at + 16, at + 24);
            let t = b[n1..n1 + 8].to_vec();
            b.copy_within(n2..n2 + 8, n1);
            b[n2..n2 + 8].copy_from_slice(&t);
            let tag = u64_at(&b, at);
            let p = write("inverted.msh", &b);
            match read_msh::<2>(&p) {
                Err(e @ GridError::InFile { .. }) => {
                    let m = e.to_string();
                    assert!(m.contains("inverted"), "{m}");
                    assert!(m.contains(&format!("Gmsh element {tag})")), "{m}");
                }
                other => panic!("{:?}", other.map(|g| g.num_cells())),
            }
            return;
        }
        at += n * (1 + nn) * 8;
    }
    panic!("no triangle block");
}
