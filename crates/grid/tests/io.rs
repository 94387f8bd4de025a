//! Mesh import/export: exact round trips, Gmsh fixtures, and errors that name the file and
//! the line (or the cell).

use std::path::{Path, PathBuf};

use porofrac_grid::generate::{cartesian, simplices};
use porofrac_grid::io::{
    Encoding, Field, PvdWriter, parse_msh, read_msh, read_vtu, write_vtu, write_vtu_with,
};
use porofrac_grid::{Grid, GridError, Point};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn tmp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("io_{name}"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// 1-based number of the first line whose trimmed text is `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.trim() == needle)
        .unwrap_or_else(|| panic!("`{needle}` not in fixture"))
        + 1
}

fn parse_line<T: std::fmt::Debug>(r: Result<T, GridError>, file: &str) -> (usize, String) {
    match r {
        Err(e @ GridError::Parse { .. }) => {
            let msg = e.to_string();
            let GridError::Parse { path, line, .. } = e else {
                unreachable!()
            };
            assert_eq!(path, Path::new(file));
            assert!(msg.starts_with(&format!("{file}:{line}:")), "{msg}");
            eprintln!("MSG {msg}");
            (line, msg)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

fn in_file_cell<T: std::fmt::Debug>(r: Result<T, GridError>, file: &str) -> (usize, String) {
    match r {
        Err(e @ GridError::InFile { .. }) => {
            let msg = e.to_string();
            let GridError::InFile { path, source } = e else {
                unreachable!()
            };
            assert_eq!(path, Path::new(file));
            assert!(msg.starts_with(file), "{msg}");
            match *source {
                GridError::Cell { cell, .. } => {
                    eprintln!("MSG {msg}");
                    (cell, msg)
                }
                other => panic!("expected a cell error, got {other:?}"),
            }
        }
        other => panic!("expected an in-file error, got {other:?}"),
    }
}

fn total_volume<const D: usize>(g: &Grid<D>) -> f64 {
    g.cell_volumes().iter().sum()
}

fn tag_area<const D: usize>(g: &Grid<D>, name: &str) -> f64 {
    g.face_tags()[name].iter().map(|&f| g.face_area(f)).sum()
}

/// Two overlapping cell tags, a boundary face tag and an interior face tag.
fn tagged<const D: usize>(mut g: Grid<D>) -> Grid<D> {
    let nc = g.num_cells();
    g.set_cell_tag("even", (0..nc).step_by(2).collect())
        .unwrap();
    g.set_cell_tag("first_half", (0..nc / 2).collect()).unwrap();
    g.set_cell_tag("empty", vec![]).unwrap();
    let xmin = g.boundary("xmin").unwrap();
    g.set_face_tag("left side", xmin).unwrap();
    let interior: Vec<usize> = (0..g.num_faces())
        .filter(|&f| !g.is_boundary_face(f))
        .step_by(3)
        .collect();
    g.set_face_tag("fault<&>", interior).unwrap();
    g
}

fn round_trip<const D: usize>(g: &Grid<D>, name: &str) {
    let dir = tmp_dir("roundtrip");
    for enc in [Encoding::Ascii, Encoding::Base64, Encoding::Appended] {
        let path = dir.join(format!("{name}_{enc:?}.vtu"));
        write_vtu_with(&path, g, &[], &[], enc).unwrap();
        let back: Grid<D> = read_vtu(&path).unwrap();
        assert!(back == *g, "{name} {enc:?}: read(write(g)) != g");
    }
}

#[test]
fn vtu_round_trip_is_exact() {
    // Irrational spacings so that coordinates use all 53 bits.
    let lo2 = Point::<2>::new(-0.3, 1.0 / 3.0);
    let hi2 = Point::<2>::new(std::f64::consts::PI, 2.0_f64.sqrt());
    let lo3 = Point::<3>::new(0.1, -1.0 / 7.0, 1e-3);
    let hi3 = Point::<3>::new(1.7, 0.9, std::f64::consts::E);
    round_trip(&tagged(cartesian::<2>(lo2, hi2, [4, 3]).unwrap()), "cart2");
    round_trip(&tagged(simplices::<2>(lo2, hi2, [3, 2]).unwrap()), "simp2");
    round_trip(
        &tagged(cartesian::<3>(lo3, hi3, [3, 2, 2]).unwrap()),
        "cart3",
    );
    round_trip(
        &tagged(simplices::<3>(lo3, hi3, [2, 2, 2]).unwrap()),
        "simp3",
    );
    // Mixed hexahedra, prisms, a pyramid and tetrahedra with Gmsh tags.
    round_trip(&read_msh::<3>(data("mixed.msh")).unwrap(), "mixed3");
    round_trip(&read_msh::<2>(data("tri_quad.msh")).unwrap(), "triquad2");
}

#[test]
fn msh_2d_triangles_and_quads() {
    let g: Grid<2> = read_msh(data("tri_quad.msh")).unwrap();
    // Node 7 (a geometry point) is used by no cell and dropped.
    assert_eq!(g.num_nodes(), 6);
    assert_eq!(g.num_cells(), 3);
    // 3 + 3 + 4 edge occurrences, 2 shared.
    assert_eq!(g.num_faces(), 8);
    assert_eq!(total_volume(&g), 2.0);
    assert_eq!(g.cell_volumes(), &[0.5, 0.5, 1.0]);
    assert_eq!(g.cell_tags()["rock"], vec![0, 1]);
    assert_eq!(g.cell_tags()["reservoir"], vec![2]);
    assert_eq!(g.cell_tags().len(), 2);
    assert_eq!(g.face_tags()["bottom"].len(), 2);
    assert_eq!(tag_area(&g, "bottom"), 2.0);
    assert_eq!(tag_area(&g, "left"), 1.0);
    let iface = &g.face_tags()["interface"];
    assert_eq!(iface.len(), 1);
    assert!(!g.is_boundary_face(iface[0]));
    // The tagged bottom faces are exactly the generic `ymin` side.
    assert_eq!(g.face_tags()["bottom"], g.boundary("ymin").unwrap());
}

#[test]
fn msh_3d_mixed_elements() {
    let g: Grid<3> = read_msh(data("mixed.msh")).unwrap();
    assert_eq!(g.num_nodes(), 15);
    assert_eq!(g.num_cells(), 6);
    // 6 + 5 + 5 + 5 + 4 + 4 = 29 face occurrences, 5 shared.
    assert_eq!(g.num_faces(), 24);
    // hex 1, prisms 1/2 each, pyramid 1/6, tetrahedra 1/24 each.
    let exact = [1.0, 0.5, 0.5, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 24.0];
    for (c, (&v, e)) in g.cell_volumes().iter().zip(exact).enumerate() {
        assert!((v - e).abs() <= 1e-15 * e, "cell {c}: {v} vs {e}");
    }
    // Exact total 9/4, up to the rounding of the non-dyadic cell volumes (measured: 2 ulp).
    assert!(
        (total_volume(&g) - 2.25).abs() <= 1e-15 * 2.25,
        "{}",
        total_volume(&g)
    );
    assert_eq!(g.cell_tags()["matrix"], vec![0, 1, 2]);
    assert_eq!(g.cell_tags()["physical_2"], vec![3, 4, 5]);
    assert_eq!(g.cell_tags().len(), 2);
    // The physical curve (dimension 1) is ignored in 3D.
    assert_eq!(g.face_tags().len(), 3);
    assert_eq!(g.face_tags()["bottom"].len(), 3);
    assert_eq!(tag_area(&g, "bottom"), 2.0);
    assert_eq!(g.face_tags()["bottom"], g.boundary("zmin").unwrap());
    let iface = &g.face_tags()["interface"];
    assert_eq!(iface.len(), 1);
    assert!(!g.is_boundary_face(iface[0]));
    assert_eq!(g.face_area(iface[0]), 1.0);
    assert_eq!(g.face_tags()["physical_12"], g.boundary("xmax").unwrap());
}

#[test]
fn vtu_standard_cell_types_match_gmsh() {
    let v: Grid<3> = read_vtu(data("mixed.vtu")).unwrap();
    let m: Grid<3> = read_msh(data("mixed.msh")).unwrap();
    assert_eq!(v.num_cells(), 6);
    assert_eq!(v.num_nodes(), 15);
    assert_eq!(v.num_faces(), 24);
    assert_eq!(v.nodes(), m.nodes());
    for c in 0..6 {
        let (a, b) = (v.cell_volume(c), m.cell_volume(c));
        assert!((a - b).abs() <= 1e-15 * b, "cell {c}: {a} vs {b}");
        assert!((v.cell_centroid(c) - m.cell_centroid(c)).norm() <= 1e-15);
    }
    assert!(
        (total_volume(&v) - 2.25).abs() <= 1e-15 * 2.25,
        "{}",
        total_volume(&v)
    );
    assert_eq!(v.cell_tags()["tag_3"], vec![0, 1, 2]);
    assert_eq!(v.cell_tags()["tag_5"], vec![3, 4, 5]);
}

// ------------------------------------------------------------------ Gmsh errors

const F2: &str = "bad.msh";

fn fixture2() -> String {
    std::fs::read_to_string(data("tri_quad.msh")).unwrap()
}

#[test]
fn msh_truncated_file() {
    let text = fixture2();
    let cut: String = text
        .lines()
        .take(line_of(&text, "11 1 5 6"))
        .map(|l| format!("{l}\n"))
        .collect();
    let (line, msg) = parse_line(parse_msh::<2>(&cut, F2), F2);
    assert_eq!(line, cut.lines().count(), "{msg}");
}

#[test]
fn msh_wrong_node_count() {
    // The block of entity (2, 2) declares 3 nodes but holds 2: the third "tag" is the first
    // coordinate line.
    let text = fixture2()
        .replace("3 7 1 7\n", "3 8 1 7\n")
        .replace("2 2 0 2\n", "2 2 0 3\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "2 0 0"), "{msg}");
    // Header total disagreeing with the blocks.
    let text = fixture2().replace("3 7 1 7\n", "3 8 1 7\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "3 8 1 7"), "{msg}");
    // More elements than declared in a block.
    let text = fixture2().replace("2 2 3 1\n", "2 2 3 2\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "2 2 3 2"), "{msg}");
}

#[test]
fn msh_bad_number_and_nan() {
    let text = fixture2().replace("\n1 1 0\n", "\n1 1x 0\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "1 1x 0"), "{msg}");
    assert!(msg.contains("1x"));
    let text = fixture2().replace("\n1 1 0\n", "\n1 NaN 0\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "1 NaN 0"), "{msg}");
}

#[test]
fn msh_missing_nodes_section() {
    let text = fixture2();
    let a = text.find("$Nodes").unwrap();
    let b = text.find("$EndNodes\n").unwrap() + "$EndNodes\n".len();
    let text = format!("{}{}", &text[..a], &text[b..]);
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "$Elements"), "{msg}");
    // Missing $Elements: reported at the end of the file.
    let text = fixture2();
    let text = &text[..text.find("$Elements").unwrap()];
    let (line, msg) = parse_line(parse_msh::<2>(text, F2), F2);
    assert_eq!(line, text.lines().count(), "{msg}");
}

#[test]
fn msh_unknown_node_in_element() {
    let text = fixture2().replace("11 1 5 6\n", "11 1 5 99\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "11 1 5 99"), "{msg}");
    assert!(msg.contains("99"));
}

#[test]
fn msh_version_binary_and_element_type() {
    let text = fixture2().replace("4.1 0 8", "2.2 0 8");
    assert_eq!(parse_line(parse_msh::<2>(&text, F2), F2).0, 2);
    let text = fixture2().replace("4.1 0 8", "4.1 1 8");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, 2);
    assert!(msg.contains("binary"));
    // A second-order triangle block.
    let text = fixture2().replace("2 1 2 2\n", "2 1 9 2\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "2 1 9 2"), "{msg}");
    assert!(msg.contains("type 9"));
    // A 2D mesh must be planar.
    let text = fixture2().replace("2 1 0\n", "2 1 0.5\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "2 1 0.5"), "{msg}");
    // Reading the 3D fixture as 2D fails at the first node off the plane of the first.
    let text3 = std::fs::read_to_string(data("mixed.msh")).unwrap();
    let (line, msg) = parse_line(parse_msh::<2>(&text3, F2), F2);
    assert_eq!(line, line_of(&text3, "0 0 0"), "{msg}");
    // A 3D element block in a 2D read.
    let text = fixture2().replace("2 2 3 1\n", "3 2 4 1\n");
    let (line, msg) = parse_line(parse_msh::<2>(&text, F2), F2);
    assert_eq!(line, line_of(&text, "3 2 4 1"), "{msg}");
    assert!(msg.contains("3D elements"), "{msg}");
}

#[test]
fn msh_degenerate_and_inverted_elements() {
    // Zero area: node 6 moved onto the line through nodes 1 and 5 (the diagonal).
    let text = fixture2().replace("0 1 0\n", "0.5 0.5 0\n");
    let (cell, msg) = in_file_cell(parse_msh::<2>(&text, F2), F2);
    assert_eq!(cell, 1, "{msg}");
    assert!(msg.contains("Gmsh element 11"), "{msg}");
    // Inverted (clockwise) triangle: element 10 is cell 0.
    let text = fixture2().replace("10 1 2 5\n", "10 2 1 5\n");
    let (cell, msg) = in_file_cell(parse_msh::<2>(&text, F2), F2);
    assert_eq!(cell, 0, "{msg}");
    assert!(
        msg.contains("inverted") && msg.contains("Gmsh element 10"),
        "{msg}"
    );
    assert!(
        msg.contains(&format!("line {}", line_of(&text, "10 2 1 5"))),
        "{msg}"
    );
    // Inverted tetrahedron in 3D (two nodes swapped): cell 4.
    let text3 = std::fs::read_to_string(data("mixed.msh"))
        .unwrap()
        .replace("5 5 13 8 14\n", "5 13 5 8 14\n");
    let (cell, msg) = in_file_cell(parse_msh::<3>(&text3, F2), F2);
    assert_eq!(cell, 4, "{msg}");
    assert!(msg.contains("inverted"), "{msg}");
}

#[test]
fn missing_file_is_io_error() {
    let p = data("does_not_exist.msh");
    match read_msh::<2>(&p) {
        Err(GridError::Io { path, .. }) => assert_eq!(path, p),
        other => panic!("{other:?}"),
    }
    match read_vtu::<3>(&p) {
        Err(GridError::Io { path, .. }) => assert_eq!(path, p),
        other => panic!("{other:?}"),
    }
}

// ------------------------------------------------------------------ VTU errors

fn vtu_variant(name: &str, from: &str, to: &str) -> (PathBuf, String) {
    let text = std::fs::read_to_string(data("mixed.vtu")).unwrap();
    assert!(text.contains(from), "{from}");
    let text = text.replacen(from, to, 1);
    let p = tmp_dir("vtu_bad").join(name);
    std::fs::write(&p, &text).unwrap();
    (p, text)
}

#[test]
fn vtu_bad_inputs() {
    let check = |name: &str, from: &str, to: &str, needle: &str| {
        let (p, text) = vtu_variant(name, from, to);
        let ps = p.to_str().unwrap().to_string();
        let (line, msg) = parse_line(read_vtu::<3>(&p), &ps);
        assert_eq!(line, line_of(&text, needle), "{msg}");
        msg
    };
    let m = check("num.vtu", "1 8 9 5 10 11", "1 8 9 5 1O 11", "1 8 9 5 1O 11");
    assert!(m.contains("1O"));
    let m = check(
        "appended.vtu",
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">",
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"0\">",
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"0\">",
    );
    assert!(m.contains("appended"));
    // zlib applies to binary arrays only: the ASCII arrays of this file still read.
    let (p, _) = vtu_variant(
        "zlib.vtu",
        "byte_order=\"LittleEndian\">",
        "byte_order=\"LittleEndian\" compressor=\"vtkZLibDataCompressor\">",
    );
    assert_eq!(read_vtu::<3>(&p).unwrap().num_cells(), 6);
    let m = check(
        "lz4.vtu",
        "byte_order=\"LittleEndian\">",
        "byte_order=\"LittleEndian\" compressor=\"vtkLZ4DataCompressor\">",
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" compressor=\"vtkLZ4DataCompressor\">",
    );
    assert!(m.contains("vtkLZ4DataCompressor"), "{m}");
    let m = check(
        "type.vtu",
        "12 13 13 14 10 10",
        "12 13 13 14 10 24",
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">",
    );
    assert!(m.contains("type 24"));
    check(
        "count.vtu",
        "NumberOfCells=\"6\"",
        "NumberOfCells=\"7\"",
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">",
    );
    check("xml.vtu", "</Cells>", "</Cell>", "</Cell>");
    // A wedge with the mirrored node order is inverted (VTK's own quality filter also
    // reports a negative volume for it): cell 1.
    let (p, _) = vtu_variant("wedge.vtu", "1 8 9 5 10 11", "1 9 8 5 11 10");
    let (cell, msg) = in_file_cell(read_vtu::<3>(&p), p.to_str().unwrap());
    assert_eq!(cell, 1, "{msg}");
    assert!(msg.contains("VTK cell 1"), "{msg}");
}

// ------------------------------------------------------------------ PVD, examples

#[test]
fn pvd_rewritten_after_every_add() {
    let dir = tmp_dir("pvd");
    let p = dir.join("run.pvd");
    let mut w = PvdWriter::create(&p).unwrap();
    let empty = std::fs::read_to_string(&p).unwrap();
    assert!(empty.contains("<Collection>") && !empty.contains("DataSet"));
    w.add(0.0, "run/step_0000.vtu").unwrap();
    w.add(0.1, Path::new("run").join("step_0001.vtu")).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    assert_eq!(text.matches("<DataSet ").count(), 2);
    assert!(text.contains("timestep=\"0.1\" group=\"\" part=\"0\" file=\"run/step_0001.vtu\""));
    assert!(w.add(f64::NAN, "x.vtu").is_err());
    assert_eq!(w.entries().len(), 2);
    // No temporary files are left behind.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("run.pvd")]);
}

/// Writes `target/tmp/meshio/grid2d.vtu` and `grid3d.vtu` (with a `displacement` point
/// array) for `python3 scripts/check_meshio.py`, and checks that they read back.
#[test]
fn meshio_example_files() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("meshio");
    std::fs::create_dir_all(&dir).unwrap();
    fn one<const D: usize>(g: Grid<D>, path: &Path) {
        let g = tagged(g);
        let u: Vec<Point<D>> = g.nodes().iter().map(|x| x * 1e-3).collect();
        let p: Vec<f64> = g.cell_centroids().iter().map(|x| x[0]).collect();
        let s: Vec<[f64; 6]> = (0..g.num_cells())
            .map(|c| [c as f64, 1.0, 2.0, 0.5, 0.0, 0.25])
            .collect();
        write_vtu(
            path,
            &g,
            &[("displacement", Field::Vectors(&u))],
            &[
                ("pressure", Field::Scalars(&p)),
                ("stress", Field::SymTensors(&s)),
            ],
        )
        .unwrap();
        let back: Grid<D> = read_vtu(path).unwrap();
        assert!(back == g);
    }
    one(
        simplices::<2>(Point::<2>::zeros(), Point::<2>::new(2.0, 1.0), [4, 2]).unwrap(),
        &dir.join("grid2d.vtu"),
    );
    one(
        cartesian::<3>(
            Point::<3>::zeros(),
            Point::<3>::new(1.0, 1.0, 2.0),
            [2, 2, 3],
        )
        .unwrap(),
        &dir.join("grid3d.vtu"),
    );
}

/// Meshes written by Gmsh 4.15 itself (`tests/data/gmsh_generate.py`, via the `gmsh`
/// Python package): counts as reported by meshio, measures in closed form.
#[test]
fn msh_written_by_gmsh() {
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    // 2D: [0,1]² in triangles, [1,2.5]×[0,1] in recombined quadrangles.
    let g: Grid<2> = read_msh(data("gmsh_tri_quad.msh")).unwrap();
    assert_eq!(g.num_cells(), 73 + 56);
    assert_eq!(g.num_nodes(), 112);
    assert!(rel(total_volume(&g), 2.5) <= 1e-14, "{}", total_volume(&g));
    let tri: f64 = g.cell_tags()["tri"].iter().map(|&c| g.cell_volume(c)).sum();
    assert!(rel(tri, 1.0) <= 1e-14);
    assert_eq!(g.cell_tags()["tri"].len(), 73);
    assert_eq!(g.cell_tags()["quad"].len(), 56);
    assert!(rel(tag_area(&g, "left"), 1.0) <= 1e-14);
    assert_eq!(g.face_tags()["left"], g.boundary("xmin").unwrap());
    // 3D: unit cube in tetrahedra.
    let g: Grid<3> = read_msh(data("gmsh_tets.msh")).unwrap();
    assert_eq!(g.num_cells(), 1140);
    assert!(rel(total_volume(&g), 1.0) <= 1e-14, "{}", total_volume(&g));
    assert_eq!(g.cell_tags()["box"].len(), 1140);
    assert!(rel(tag_area(&g, "bottom"), 1.0) <= 1e-14);
    assert_eq!(g.face_tags()["bottom"], g.boundary("zmin").unwrap());
    // 3D: [0,2]×[0,1]×[0,0.5] extruded in two layers of prisms.
    let g: Grid<3> = read_msh(data("gmsh_prisms.msh")).unwrap();
    assert_eq!(g.num_cells(), 136);
    assert!(rel(total_volume(&g), 1.0) <= 1e-14, "{}", total_volume(&g));
    assert!(rel(tag_area(&g, "base"), 2.0) <= 1e-14);
    assert_eq!(g.face_tags()["base"], g.boundary("zmin").unwrap());
    // And they survive a .vtu round trip exactly.
    round_trip(&g, "gmsh_prisms");
}

/// Every line-prefix of a fixture is an error at a line inside the prefix, and random byte
/// edits never panic (a small deterministic fuzz).
#[test]
fn truncations_and_mutations_never_panic() {
    for name in ["tri_quad.msh", "mixed.msh"] {
        let text = std::fs::read_to_string(data(name)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for k in 0..lines.len() {
            let prefix = lines[..k].join("\n");
            match parse_msh::<3>(&prefix, F2).and_then(|_| parse_msh::<2>(&prefix, F2)) {
                Err(GridError::Parse { line, .. }) => assert!(line >= 1 && line <= k.max(1)),
                other => panic!("{name} cut at {k} lines: {other:?}"),
            }
        }
    }
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let alphabet = b" \n0123456789-.e$\"<>/=abcdefghijklmnopqrstuvwxyzNT";
    let dir = tmp_dir("fuzz");
    for (name, n) in [
        ("tri_quad.msh", 1500),
        ("mixed.msh", 1500),
        ("mixed.vtu", 300),
    ] {
        let bytes = std::fs::read(data(name)).unwrap();
        for i in 0..n {
            let mut b = bytes.clone();
            for _ in 0..1 + next() % 3 {
                let at = (next() % b.len() as u64) as usize;
                match next() % 3 {
                    0 => b[at] = alphabet[(next() % alphabet.len() as u64) as usize],
                    1 => {
                        b.remove(at);
                    }
                    _ => b.insert(at, alphabet[(next() % alphabet.len() as u64) as usize]),
                }
            }
            let text = String::from_utf8_lossy(&b);
            if name.ends_with(".msh") {
                let _ = parse_msh::<2>(&text, F2);
                let _ = parse_msh::<3>(&text, F2);
            } else {
                let p = dir.join(format!("m{i}.vtu"));
                std::fs::write(&p, &b).unwrap();
                let _ = read_vtu::<3>(&p);
                let _ = read_vtu::<2>(&p);
            }
        }
    }
}
