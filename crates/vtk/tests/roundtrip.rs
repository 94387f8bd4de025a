//! Round trips: every file kind is written in every encoding, read back with the small
//! reader below, and its arrays compared bit for bit.

use std::path::{Path, PathBuf};

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;
use porofrac_vtk::{
    Attributes, CellArray, CellType, DataArray, Encoding, ImageData, PolyData, Polyhedra,
    PvdWriter, UnstructuredGrid, VtkError, component_names, write_atomic,
};

const ENCODINGS: [Encoding; 3] = [Encoding::Ascii, Encoding::Base64, Encoding::Appended];

/// A data array as read back.
#[derive(Debug)]
struct Read {
    /// The section that holds it (`PointData`, `Cells`, …).
    section: String,
    name: String,
    ty: String,
    components: usize,
    tuples: Option<usize>,
    component_names: Vec<String>,
    /// Every value as the bits of an f64 (integers converted, exact below 2^53).
    values: Vec<u64>,
}

fn attr(tag: &str, key: &str) -> Option<String> {
    let pat = format!(" {key}=\"");
    let start = tag.find(&pat)? + pat.len();
    let end = start + tag[start..].find('"')?;
    Some(
        tag[start..end]
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&apos;", "'")
            .replace("&amp;", "&"),
    )
}

fn binary(ty: &str, data: &[u8]) -> (Vec<u64>, usize) {
    let n = u64::from_le_bytes(data[..8].try_into().unwrap()) as usize;
    let body = &data[8..8 + n];
    let v = match ty {
        "Float64" => body
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        "Int64" => body
            .chunks_exact(8)
            .map(|c| (i64::from_le_bytes(c.try_into().unwrap()) as f64).to_bits())
            .collect(),
        "Int32" => body
            .chunks_exact(4)
            .map(|c| (i32::from_le_bytes(c.try_into().unwrap()) as f64).to_bits())
            .collect(),
        "UInt8" => body.iter().map(|&b| (b as f64).to_bits()).collect(),
        other => panic!("type {other}"),
    };
    (v, 8 + n)
}

/// All data arrays of a file, and the root element's tag.
fn read(bytes: &[u8]) -> (String, Vec<Read>) {
    let split = bytes
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .unwrap_or(bytes.len());
    let text = std::str::from_utf8(&bytes[..split]).unwrap();
    let appended = (split < bytes.len()).then(|| {
        let tail = &bytes[split..];
        let us = tail.iter().position(|&b| b == b'_').unwrap();
        let data = &tail[us + 1..];
        assert!(tail.ends_with(b"\n  </AppendedData>\n</VTKFile>\n"));
        data
    });
    assert!(text.starts_with("<?xml version=\"1.0\"?>\n<VTKFile "));
    if appended.is_none() {
        assert!(text.ends_with("</VTKFile>\n"));
    }
    let root_end = text[22..].find('>').unwrap() + 22;
    let root = text[22..=root_end].to_string();
    let mut out = Vec::new();
    let mut pos = 0;
    while let Some(k) = text[pos..].find("<DataArray ") {
        let start = pos + k;
        let end = start + text[start..].find('>').unwrap();
        let tag = &text[start..=end];
        let section = [
            "FieldData",
            "PointData",
            "CellData",
            "Points",
            "Cells",
            "Verts",
            "Lines",
            "Polys",
        ]
        .iter()
        .filter_map(|s| {
            let a = text[..start].rfind(&format!("<{s}>"));
            let b = text[..start].rfind(&format!("<{s} "));
            a.max(b).map(|p| (p, s.to_string()))
        })
        .max()
        .unwrap()
        .1;
        let ty = attr(tag, "type").unwrap();
        let components = attr(tag, "NumberOfComponents").map_or(1, |c| c.parse().unwrap());
        let component_names = (0..)
            .map_while(|k| attr(tag, &format!("ComponentName{k}")))
            .collect();
        let format = attr(tag, "format").unwrap();
        let (values, next) = if format == "appended" {
            assert!(tag.ends_with("/>"));
            let off: usize = attr(tag, "offset").unwrap().parse().unwrap();
            (binary(&ty, &appended.unwrap()[off..]).0, end + 1)
        } else {
            let close = end + text[end..].find("</DataArray>").unwrap();
            let body = &text[end + 1..close];
            let v = if format == "ascii" {
                body.split_whitespace()
                    .map(|s| {
                        if ty == "Float64" {
                            s.parse::<f64>().unwrap().to_bits()
                        } else {
                            (s.parse::<i64>().unwrap() as f64).to_bits()
                        }
                    })
                    .collect()
            } else {
                assert_eq!(format, "binary");
                let raw = STANDARD.decode(body.trim()).unwrap();
                let (v, used) = binary(&ty, &raw);
                assert_eq!(used, raw.len(), "one base64 stream of header and data");
                v
            };
            (v, close)
        };
        out.push(Read {
            section,
            name: attr(tag, "Name").unwrap(),
            ty,
            components,
            tuples: attr(tag, "NumberOfTuples").map(|t| t.parse().unwrap()),
            component_names,
            values,
        });
        pos = next;
    }
    (root, out)
}

fn find<'r>(arrays: &'r [Read], section: &str, name: &str) -> &'r Read {
    arrays
        .iter()
        .find(|a| a.section == section && a.name == name)
        .unwrap_or_else(|| panic!("no {section}/{name}"))
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn ibits<T: Copy + Into<f64>>(v: &[T]) -> Vec<u64> {
    v.iter().map(|&x| x.into().to_bits()).collect()
}

fn i64bits(v: &[i64]) -> Vec<u64> {
    v.iter().map(|&x| (x as f64).to_bits()).collect()
}

/// Values that need all 64 bits to survive: subnormals, signed zero, extremes, NaN.
fn hard(n: usize) -> Vec<f64> {
    let special = [
        0.1,
        -0.0,
        5e-324,
        f64::MAX,
        -1.0 / 3.0,
        f64::NAN,
        f64::INFINITY,
        1e300,
        std::f64::consts::PI,
    ];
    (0..n)
        .map(|k| special[k % special.len()] * if k >= special.len() { 1.5 } else { 1.0 })
        .collect()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac_vtk_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn dir_names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A triangle, a quad, a pentagon, a tetrahedron and a polyhedron (a pyramid given by
/// its faces), with arrays of 1, 3, 4, 6 and 9 components and the usual names.
#[test]
fn unstructured_grid_round_trip() {
    let points: Vec<f64> = hard(3 * 10);
    let connectivity: Vec<i64> = vec![
        0, 1, 2, // triangle
        1, 3, 4, 2, // quad
        0, 1, 3, 4, 5, // pentagon
        5, 6, 7, 8, // tetrahedron
        4, 5, 6, 7, 9, // pyramid as polyhedron: its points
    ];
    let offsets = [3, 7, 12, 16, 21];
    let types = [
        CellType::Triangle,
        CellType::Quad,
        CellType::Polygon,
        CellType::Tetra,
        CellType::Polyhedron,
    ];
    let faces = [
        5, 4, 4, 7, 6, 5, 3, 4, 5, 9, 3, 5, 6, 9, 3, 6, 7, 9, 3, 7, 4, 9,
    ];
    let faceoffsets = [-1, -1, -1, -1, 22];
    let p1 = hard(10);
    let p3: Vec<f64> = hard(30).iter().map(|x| x * 2.0).collect();
    let ids: Vec<i32> = (0..10).map(|k| k * 1000 - 4000).collect();
    let s3 = hard(15);
    let s6 = hard(30);
    let t4 = hard(20);
    let t9 = hard(45);
    let tag: Vec<u8> = vec![0, 1, 255, 3, 4];
    let big: Vec<i64> = vec![-(1 << 40), 0, 1, i64::from(i32::MAX) + 1, 7];
    let point_arrays = [
        DataArray::new("pressure", 1, &p1[..]),
        DataArray::new("displacement", 3, &p3[..]).with_component_names(&component_names::VECTOR),
        DataArray::new("id & <name>", 1, &ids[..]),
    ];
    let cell_arrays = [
        DataArray::new("stress 2D", 3, &s3[..])
            .with_component_names(&component_names::SYMMETRIC_2D),
        DataArray::new("stress", 6, &s6[..]).with_component_names(&component_names::SYMMETRIC_3D),
        DataArray::new("gradient 2D", 4, &t4[..]).with_component_names(&component_names::TENSOR_2D),
        DataArray::new("couple_stress", 9, &t9[..]),
        DataArray::new("tag", 1, &tag[..]),
        DataArray::new("big", 1, &big[..]),
    ];
    let field = [DataArray::new("facetag:left", 1, &big[..3])];
    let g = UnstructuredGrid {
        points: &points,
        connectivity: &connectivity,
        offsets: &offsets,
        types: &types,
        polyhedra: Some(Polyhedra {
            faces: &faces,
            faceoffsets: &faceoffsets,
        }),
        field_data: &field,
        point_data: Attributes::new(&point_arrays).with_scalars("pressure"),
        cell_data: Attributes::new(&cell_arrays),
    };
    let dir = tmp("ugrid");
    for enc in ENCODINGS {
        let path = dir.join(format!("g_{enc:?}.vtu"));
        g.write(&path, enc).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes, g.to_bytes(enc).unwrap());
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains("<Piece NumberOfPoints=\"10\" NumberOfCells=\"5\">"));
        assert!(text.contains("<PointData Scalars=\"pressure\">"));
        let (root, arrays) = read(&bytes);
        assert!(root.contains("type=\"UnstructuredGrid\""), "{root}");
        assert!(root.contains("header_type=\"UInt64\""), "{root}");
        assert_eq!(arrays.len(), 3 + 6 + 1 + 1 + 5);
        let pts = find(&arrays, "Points", "Points");
        assert_eq!((pts.components, pts.tuples), (3, Some(10)));
        assert_eq!(pts.values, bits(&points));
        assert_eq!(
            find(&arrays, "Cells", "connectivity").values,
            i64bits(&connectivity)
        );
        assert_eq!(find(&arrays, "Cells", "offsets").values, i64bits(&offsets));
        let ty = find(&arrays, "Cells", "types");
        assert_eq!(ty.ty, "UInt8");
        assert_eq!(ty.values, ibits(&[5u8, 9, 7, 10, 42]));
        assert_eq!(find(&arrays, "Cells", "faces").values, i64bits(&faces));
        assert_eq!(
            find(&arrays, "Cells", "faceoffsets").values,
            i64bits(&faceoffsets)
        );
        let p = find(&arrays, "PointData", "pressure");
        assert_eq!(
            (p.components, p.tuples, p.values.clone()),
            (1, Some(10), bits(&p1))
        );
        let d = find(&arrays, "PointData", "displacement");
        assert_eq!(d.component_names, ["X", "Y", "Z"]);
        assert_eq!(d.values, bits(&p3));
        let i = find(&arrays, "PointData", "id & <name>");
        assert_eq!((i.ty.as_str(), i.values.clone()), ("Int32", ibits(&ids)));
        for (name, comps, v) in [
            ("stress 2D", 3, &s3),
            ("stress", 6, &s6),
            ("gradient 2D", 4, &t4),
            ("couple_stress", 9, &t9),
        ] {
            let a = find(&arrays, "CellData", name);
            assert_eq!((a.components, a.tuples), (comps, Some(5)), "{name}");
            assert_eq!(a.values, bits(v), "{name}");
        }
        assert_eq!(
            find(&arrays, "CellData", "stress").component_names,
            ["XX", "YY", "ZZ", "XY", "YZ", "XZ"]
        );
        assert_eq!(
            find(&arrays, "CellData", "gradient 2D").component_names,
            ["XX", "XY", "YX", "YY"]
        );
        assert!(
            find(&arrays, "CellData", "couple_stress")
                .component_names
                .is_empty()
        );
        assert_eq!(find(&arrays, "CellData", "tag").values, ibits(&tag));
        assert_eq!(find(&arrays, "CellData", "big").values, i64bits(&big));
        assert_eq!(
            find(&arrays, "FieldData", "facetag:left").values,
            i64bits(&big[..3])
        );
        // A scalar array has no NumberOfComponents attribute (meshio would read n × 1).
        assert!(!text.contains("NumberOfComponents=\"1\""));
    }
    assert_eq!(
        dir_names(&dir),
        ["g_Appended.vtu", "g_Ascii.vtu", "g_Base64.vtu"]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn poly_data_round_trip() {
    let n = 7;
    let points = hard(3 * n);
    let verts: Vec<i64> = (0..n as i64).collect();
    let vert_off: Vec<i64> = (1..=n as i64).collect();
    let lines = [0i64, 1, 2, 3, 3, 4, 5];
    let line_off = [2i64, 4, 7];
    let radius = hard(n);
    let force = hard(n + 3);
    let pd = [DataArray::new("radius", 1, &radius[..])];
    let cd = [DataArray::new("normal_force", 1, &force[..])];
    let p = PolyData {
        points: &points,
        verts: CellArray {
            connectivity: &verts,
            offsets: &vert_off,
        },
        lines: CellArray {
            connectivity: &lines,
            offsets: &line_off,
        },
        polys: CellArray::default(),
        field_data: &[],
        point_data: Attributes::new(&pd).with_scalars("radius"),
        cell_data: Attributes::new(&cd).with_scalars("normal_force"),
    };
    for enc in ENCODINGS {
        let bytes = p.to_bytes(enc).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(
            "<Piece NumberOfPoints=\"7\" NumberOfVerts=\"7\" NumberOfLines=\"3\" \
             NumberOfStrips=\"0\" NumberOfPolys=\"0\">"
        ));
        assert!(!text.contains("<Polys>"));
        let (root, arrays) = read(&bytes);
        assert!(root.contains("type=\"PolyData\""));
        assert_eq!(arrays.len(), 1 + 4 + 2);
        assert_eq!(find(&arrays, "Points", "Points").values, bits(&points));
        assert_eq!(
            find(&arrays, "Verts", "connectivity").values,
            i64bits(&verts)
        );
        assert_eq!(find(&arrays, "Verts", "offsets").values, i64bits(&vert_off));
        assert_eq!(
            find(&arrays, "Lines", "connectivity").values,
            i64bits(&lines)
        );
        assert_eq!(find(&arrays, "Lines", "offsets").values, i64bits(&line_off));
        assert_eq!(find(&arrays, "PointData", "radius").values, bits(&radius));
        assert_eq!(
            find(&arrays, "CellData", "normal_force").values,
            bits(&force)
        );
    }
    // An empty data set is valid.
    let empty = PolyData::default();
    for enc in ENCODINGS {
        let (_, arrays) = read(&empty.to_bytes(enc).unwrap());
        assert_eq!(arrays.len(), 1);
        assert!(find(&arrays, "Points", "Points").values.is_empty());
    }
}

#[test]
fn image_data_round_trip() {
    let (nx, ny) = (4, 3);
    let density = hard(nx * ny);
    let velocity = hard(2 * nx * ny);
    let cells = hard((nx - 1) * (ny - 1));
    let pd = [
        DataArray::new("density", 1, &density[..]),
        DataArray::new("velocity", 2, &velocity[..]),
    ];
    let cd = [DataArray::new("solid", 1, &cells[..])];
    let im = ImageData {
        size: [nx, ny, 1],
        origin: [-0.5, 0.25, 0.0],
        spacing: [1e-5, 1e-5, 1e-5],
        field_data: &[],
        point_data: Attributes::new(&pd),
        cell_data: Attributes::new(&cd),
    };
    for enc in ENCODINGS {
        let bytes = im.to_bytes(enc).unwrap();
        let (root, arrays) = read(&bytes);
        assert!(root.contains("type=\"ImageData\""));
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(
            "<ImageData WholeExtent=\"0 3 0 2 0 0\" Origin=\"-0.5 0.25 0.0\" \
             Spacing=\"1e-5 1e-5 1e-5\">"
        ));
        assert!(text.contains("<Piece Extent=\"0 3 0 2 0 0\">"));
        assert_eq!(arrays.len(), 3);
        assert_eq!(find(&arrays, "PointData", "density").values, bits(&density));
        let v = find(&arrays, "PointData", "velocity");
        assert_eq!((v.components, v.tuples), (2, Some(12)));
        assert_eq!(v.values, bits(&velocity));
        assert_eq!(find(&arrays, "CellData", "solid").values, bits(&cells));
    }
    // A flat axis keeps one layer of cells; a wrong length is an error.
    let bad = ImageData {
        cell_data: Attributes::new(&pd[..1]),
        ..im
    };
    let e = bad.to_bytes(Encoding::Base64).unwrap_err();
    assert_eq!(
        e.to_string(),
        "cell data array `density` has 12 values, expected 6 tuples of 1 components"
    );
    let empty_axis = ImageData {
        size: [4, 0, 1],
        ..im
    };
    assert!(empty_axis.to_bytes(Encoding::Ascii).is_err());
}

/// The appended section holds the blocks back to back in array order.
#[test]
fn appended_layout() {
    let a = [1.5f64, -2.0];
    let b = [7i32];
    let pd = [
        DataArray::new("a", 1, &a[..]),
        DataArray::new("b", 1, &b[..]),
    ];
    let im = ImageData {
        size: [2, 1, 1],
        origin: [0.0; 3],
        spacing: [1.0; 3],
        field_data: &[],
        point_data: Attributes::new(&pd[..1]),
        cell_data: Attributes::new(&pd[1..]),
    };
    let bytes = im.to_bytes(Encoding::Appended).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("Name=\"a\" NumberOfTuples=\"2\" format=\"appended\" offset=\"0\"/>"));
    assert!(text.contains("Name=\"b\" NumberOfTuples=\"1\" format=\"appended\" offset=\"24\"/>"));
    let mut tail = b"  <AppendedData encoding=\"raw\">\n   _".to_vec();
    tail.extend_from_slice(&16u64.to_le_bytes());
    tail.extend_from_slice(&1.5f64.to_le_bytes());
    tail.extend_from_slice(&(-2.0f64).to_le_bytes());
    tail.extend_from_slice(&4u64.to_le_bytes());
    tail.extend_from_slice(&7i32.to_le_bytes());
    tail.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    assert!(bytes.ends_with(&tail));
}

#[test]
fn input_errors() {
    let points = [0.0; 9];
    let one = [1.0];
    let g = UnstructuredGrid {
        points: &points,
        connectivity: &[0, 1, 2],
        offsets: &[3],
        types: &[CellType::Triangle],
        polyhedra: None,
        field_data: &[],
        point_data: Attributes::default(),
        cell_data: Attributes::default(),
    };
    assert!(g.to_bytes(Encoding::Base64).is_ok());
    let msg = |g: UnstructuredGrid<'_>| g.to_bytes(Encoding::Ascii).unwrap_err().to_string();
    assert_eq!(
        msg(UnstructuredGrid {
            points: &points[..8],
            ..g
        }),
        "points: 8 coordinates are not 3 per point"
    );
    assert_eq!(
        msg(UnstructuredGrid { offsets: &[2], ..g }),
        "cells: the offsets end at 2, the connectivity has 3 entries"
    );
    assert_eq!(
        msg(UnstructuredGrid {
            connectivity: &[0, 1, 3],
            ..g
        }),
        "cells: point 3 of 3 points"
    );
    assert_eq!(
        msg(UnstructuredGrid {
            types: &[CellType::Polyhedron],
            ..g
        }),
        "polyhedra: cells of type 42 without faces"
    );
    let arrays = [DataArray::new("p", 1, &one[..])];
    assert_eq!(
        msg(UnstructuredGrid {
            point_data: Attributes::new(&arrays),
            ..g
        }),
        "point data array `p` has 1 values, expected 3 tuples of 1 components"
    );
    let twice = [
        DataArray::new("p", 1, &one[..]),
        DataArray::new("p", 1, &one[..]),
    ];
    assert_eq!(
        msg(UnstructuredGrid {
            cell_data: Attributes::new(&twice),
            ..g
        }),
        "cell data array `p` given twice"
    );
    let named = [DataArray::new("p", 1, &one[..]).with_component_names(&["A", "B"])];
    assert_eq!(
        msg(UnstructuredGrid {
            cell_data: Attributes::new(&named),
            ..g
        }),
        "cell data array `p` has 2 component names for 1 components"
    );
    // Nothing is written for bad input.
    let dir = tmp("errors");
    let bad = UnstructuredGrid { offsets: &[2], ..g };
    assert!(matches!(
        bad.write(dir.join("x.vtu"), Encoding::Base64),
        Err(VtkError::Input(_))
    ));
    assert!(dir_names(&dir).is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pvd_collection() {
    let dir = tmp("pvd");
    let p = dir.join("run.pvd");
    let mut w = PvdWriter::create(&p).unwrap();
    assert_eq!(
        std::fs::read_to_string(&p).unwrap(),
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n  </Collection>\n</VTKFile>\n"
    );
    w.add(0.0, "run/step_0000.vtu").unwrap();
    w.add(0.1, Path::new("run").join("a&b.vtu")).unwrap();
    assert_eq!(
        std::fs::read_to_string(&p).unwrap(),
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n    \
         <DataSet timestep=\"0.0\" group=\"\" part=\"0\" file=\"run/step_0000.vtu\"/>\n    \
         <DataSet timestep=\"0.1\" group=\"\" part=\"0\" file=\"run/a&amp;b.vtu\"/>\n  \
         </Collection>\n</VTKFile>\n"
    );
    assert_eq!(
        w.add(f64::INFINITY, "x.vtu").unwrap_err().to_string(),
        "pvd: time inf is not finite"
    );
    assert!(w.add(1.0, dir.join("abs.vtu")).is_err());
    assert_eq!(w.entries().len(), 2);
    assert_eq!(w.path(), p);
    assert_eq!(dir_names(&dir), ["run.pvd"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A written file replaces the old one whole and leaves nothing else in the directory.
#[test]
fn files_replace_whole() {
    let dir = tmp("replace");
    let path = dir.join("p.vtp");
    write_atomic(&path, &vec![b'#'; 1 << 20]).unwrap();
    let p = PolyData::default();
    p.write(&path, Encoding::Base64).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        p.to_bytes(Encoding::Base64).unwrap()
    );
    assert_eq!(dir_names(&dir), ["p.vtp"]);
    std::fs::remove_dir_all(&dir).unwrap();
}
