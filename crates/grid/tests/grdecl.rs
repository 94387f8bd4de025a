//! Corner-point decks: reading (keywords, repeats, includes, units, errors) and
//! processing (regular blocks, faults with and without crossing layers, pinched layers)
//! against volumes and connections computed independently.

use std::path::PathBuf;

use porofrac_grid::io::grdecl::{Deck, IJK_SIDES, corner_point_grid, read_deck};
use porofrac_grid::io::read_grdecl;
use porofrac_grid::{Grid, GridError};

/// A deck of `nx × ny × nz` cells on vertical pillars at `x = i dx`, `y = j dy`, with the
/// top of cell `(i, j, k)` at corner `(x, y)` at depth `depth(i, x, y, k)` and the bottom at
/// `depth(i, x, y, k + 1)`, as GRDECL text followed by `extra`.
fn deck_text(
    dims: [usize; 3],
    dx: f64,
    dy: f64,
    depth: impl Fn(usize, f64, f64, usize) -> f64,
    extra: &str,
) -> String {
    let deck = Deck::on_vertical_pillars(dims, [dx, dy], |[i, _], x, y, k| depth(i, x, y, k));
    let mut out = b"-- a synthetic deck\n".to_vec();
    deck.write_text(&mut out).unwrap();
    String::from_utf8(out).unwrap() + extra
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("porofrac-grdecl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Every cell closed: the outward area vectors of its faces sum to zero.
fn assert_closed(grid: &Grid<3>) {
    for c in 0..grid.num_cells() {
        let mut sum = porofrac_grid::Point::<3>::zeros();
        for (&f, &out) in grid.cell_faces(c).iter().zip(grid.cell_face_outward(c)) {
            let a = grid.face_normal(f) * grid.face_area(f);
            sum += if out { a } else { -a };
        }
        let scale = grid.cell_volume(c).powf(2.0 / 3.0);
        assert!(
            sum.norm() < 1e-9 * scale,
            "cell {c}: area vectors sum to {sum:?}"
        );
    }
}

/// Interior faces as pairs of (i, j, k), sorted.
fn connections(cp: &porofrac_grid::io::grdecl::CornerPointGrid) -> Vec<([usize; 3], [usize; 3])> {
    let g = &cp.grid;
    let mut out: Vec<_> = (0..g.num_faces())
        .filter_map(|f| {
            let (a, b) = g.face_cells(f);
            b.map(|b| {
                let (x, y) = (cp.ijk[a], cp.ijk[b]);
                if x < y { (x, y) } else { (y, x) }
            })
        })
        .collect();
    out.sort();
    out
}

#[test]
fn a_regular_block_is_the_cartesian_grid() {
    let (dx, dy, dz) = (10.0, 20.0, 2.0);
    let text = deck_text(
        [3, 2, 2],
        dx,
        dy,
        |_, x, _, k| 1000.0 + k as f64 * dz + 0.1 * x,
        "",
    );
    let deck = read_deck(write("regular.grdecl", &text)).unwrap();
    let cp = corner_point_grid(&deck).unwrap();
    let g = &cp.grid;
    assert_eq!(g.num_cells(), 12);
    assert_eq!(g.num_nodes(), 4 * 3 * 3);
    // Faces of a 3 × 2 × 2 block of hexahedra: 4·2·2 + 3·3·2 + 3·2·3.
    assert_eq!(g.num_faces(), 16 + 18 + 18);
    for c in 0..12 {
        assert!((g.cell_volume(c) - dx * dy * dz).abs() < 1e-9 * dx * dy * dz);
    }
    assert_closed(g);
    // Outer faces by side: imin/imax 2·2 each, jmin/jmax 3·2, kmin/kmax 3·2.
    let counts: Vec<usize> = IJK_SIDES
        .iter()
        .map(|s| g.boundary(s).unwrap().len())
        .collect();
    assert_eq!(counts, [4, 4, 6, 6, 6, 6]);
    assert_eq!(cp.ijk[5], [2, 1, 0]);
}

#[test]
fn a_fault_with_half_a_layer_of_throw_splits_the_faces() {
    // Columns i = 2.. thrown down by dz / 2; the layers tilted by 0.1 in x.
    let (dx, dy, dz) = (10.0, 20.0, 2.0);
    let depth = |i: usize, x: f64, _y: f64, k: usize| {
        1000.0 + k as f64 * dz + 0.1 * x + if i >= 2 { dz / 2.0 } else { 0.0 }
    };
    let text = deck_text([3, 2, 3], dx, dy, depth, "");
    let (_, cp) = read_grdecl(write("fault.grdecl", &text)).unwrap();
    let g = &cp.grid;
    assert_eq!(g.num_cells(), 18);
    let total: f64 = g.cell_volumes().iter().sum();
    for c in 0..18 {
        assert!((g.cell_volume(c) - dx * dy * dz).abs() < 1e-9 * dx * dy * dz);
    }
    assert!((total - 18.0 * dx * dy * dz).abs() < 1e-9 * total);
    assert_closed(g);
    // Across the fault (i = 1 | i = 2), cell k meets k − 1 and k of the other side.
    let across: Vec<_> = connections(&cp)
        .into_iter()
        .filter(|(a, b)| a[0] == 1 && b[0] == 2)
        .collect();
    let mut expected = Vec::new();
    for j in 0..2 {
        for k in 0..3 {
            expected.push(([1, j, k], [2, j, k]));
            if k + 1 < 3 {
                expected.push(([1, j, k + 1], [2, j, k]));
            }
        }
    }
    expected.sort();
    assert_eq!(across, expected);
    // Each sub-face across the fault is half a side face.
    for f in 0..g.num_faces() {
        if let (a, Some(b)) = g.face_cells(f)
            && cp.ijk[a][0] != cp.ijk[b][0]
            && (cp.ijk[a][0] == 2 || cp.ijk[b][0] == 2)
        {
            let side = dy * dz;
            assert!(
                (g.face_area(f) - side / 2.0).abs() < 1e-9 * side,
                "face {f}"
            );
        }
    }
    // The uncovered halves on the fault are outer faces facing it.
    let imax_on_fault = g
        .boundary("imax")
        .unwrap()
        .into_iter()
        .filter(|&f| (g.face_centroid(f)[0] - 2.0 * dx).abs() < 1e-9)
        .count();
    let imin_on_fault = g
        .boundary("imin")
        .unwrap()
        .into_iter()
        .filter(|&f| (g.face_centroid(f)[0] - 2.0 * dx).abs() < 1e-9)
        .count();
    assert_eq!((imax_on_fault, imin_on_fault), (2, 2));
    // Bounding-box sides touch no face of the thrown top: a tag-free grid still works.
    assert!(!g.boundary("kmin").unwrap().is_empty());
}

#[test]
fn a_scissor_fault_whose_layers_cross_gets_nodes_inside_the_fault() {
    // The throw grows along the fault from 0 to 1.5 layers: layer lines cross inside.
    let (dx, dy, dz) = (10.0, 20.0, 2.0);
    let depth = |i: usize, x: f64, y: f64, k: usize| {
        500.0 + k as f64 * dz + 0.05 * x + if i >= 1 { 1.5 * dz * y / dy } else { 0.0 }
    };
    let text = deck_text([2, 1, 4], dx, dy, depth, "");
    let (_, cp) = read_grdecl(write("scissor.grdecl", &text)).unwrap();
    let g = &cp.grid;
    assert_eq!(g.num_cells(), 8);
    assert!(
        g.num_nodes() > 2 * 2 * 5 + 2 * 5,
        "nodes inside the fault surface"
    );
    for c in 0..8 {
        let v = g.cell_volume(c);
        assert!((v - dx * dy * dz).abs() < 1e-9 * v, "cell {c}: {v}");
    }
    assert_closed(g);
    // The fault face of each cell is covered: shared sub-faces plus outer ones add up to
    // the cell's side area.
    let mut covered = [0.0f64; 8];
    for f in 0..g.num_faces() {
        let x = g.face_centroid(f)[0];
        if (x - dx).abs() > 1e-9 {
            continue;
        }
        let (a, b) = g.face_cells(f);
        covered[a] += g.face_area(f);
        if let Some(b) = b {
            covered[b] += g.face_area(f);
        }
    }
    // A side face between vertical pillars dy apart with vertical sides dz long has area
    // dy dz, however the layer slopes.
    for (c, &a) in covered.iter().enumerate() {
        assert!(
            (a - dy * dz).abs() < 1e-9 * a,
            "cell {c}: fault faces cover {a}"
        );
    }
}

#[test]
fn pinched_layers_are_removed_and_the_layers_around_them_connected() {
    let tops = [0.0, 2.0, 2.0, 5.0];
    let text = deck_text([2, 1, 3], 10.0, 10.0, |_, _, _, k| 100.0 + tops[k], "");
    let deck = read_deck(write("pinch.grdecl", &text)).unwrap();
    let cp = corner_point_grid(&deck).unwrap();
    assert_eq!(cp.grid.num_cells(), 4);
    assert_eq!(cp.pinched, 2);
    let conn = connections(&cp);
    assert!(conn.contains(&([0, 0, 0], [0, 0, 2])));
    assert!(conn.contains(&([1, 0, 0], [1, 0, 2])));
    assert_eq!(conn.len(), 4);
}

#[test]
fn actnum_repeats_includes_and_units() {
    let (dx, dy, dz) = (10.0, 10.0, 1.0);
    let body = deck_text([2, 2, 2], dx, dy, |_, _, _, k| k as f64 * dz, "");
    // The arrays in an included file named in another case; ACTNUM with repeats.
    write("ARRAYS.INC", &body.replace("SPECGRID\n 2 2 2 1 F /", ""));
    let main = "FIELD\nSPECGRID\n2 2 2 1 F /\nMAPAXES\n 0 1 0 0 1 0 /\nECHO\n\
                UNKNOWN1\n 3*1 'x' /\ninclude\n 'arrays.inc' /\nACTNUM\n 4*1 3*0 1 /\n\
                PERMX\n 8*100 /\nPORO\n 8*0.2 /\n";
    let path = write("main.grdecl", main);
    let deck = read_deck(&path).unwrap();
    assert_eq!(deck.dims, [2, 2, 2]);
    assert_eq!(deck.mapaxes, Some([0.0, 1.0, 0.0, 0.0, 1.0, 0.0]));
    assert_eq!(deck.skipped, vec!["UNKNOWN1".to_string()]);
    let perm = deck.properties.perm[0].as_ref().unwrap();
    assert!((perm[0] - 100.0 * 9.869_233e-16).abs() < 1e-25);
    let cp = corner_point_grid(&deck).unwrap();
    assert_eq!(cp.grid.num_cells(), 5);
    assert_eq!(cp.inactive, 3);
    let ft: f64 = 0.3048;
    let v = dx * dy * dz * ft.powi(3);
    assert!(
        (cp.grid.cell_volume(0) - v).abs() < 1e-9 * v,
        "feet converted to metres"
    );
}

fn error_of(name: &str, text: &str) -> String {
    let path = write(name, text);
    match read_grdecl(&path) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("{name}: read without error"),
    }
}

#[test]
fn bad_decks_are_errors_naming_file_line_and_keyword() {
    let good = deck_text([1, 1, 1], 1.0, 1.0, |_, _, _, k| k as f64, "");
    let short = good.replacen(" 1.0 1.0 1.0 1.0\n/", " 1.0 1.0 1.0\n/", 1);
    let e = error_of("short.grdecl", &short);
    assert!(e.contains("ZCORN has 7 values, needs 8"), "{e}");
    assert!(e.contains("short.grdecl:"), "{e}");

    let e = error_of("noslash.grdecl", &good.replacen("/\nZCORN", "\nZCORN", 1));
    assert!(e.contains("COORD") && e.contains("missing"), "{e}");

    let e = error_of("first.grdecl", "COORD\n 1 2 3 /\n");
    assert!(e.contains("COORD before SPECGRID"), "{e}");

    let e = error_of("huge.grdecl", "DIMENS\n 100000 100000 100000 /\n");
    assert!(e.contains("more than"), "{e}");

    let e = error_of(
        "word.grdecl",
        &good.replacen(" 1.0 1.0 1.0 1.0\n/", " 1.0 1.0 1.0 zero\n/", 1),
    );
    assert!(
        e.contains("ZCORN") && e.contains("`zero` is not a number"),
        "{e}"
    );

    let e = error_of("inc.grdecl", "INCLUDE\n 'nowhere.inc' /\n");
    assert!(e.contains("nowhere.inc") && e.contains(":2:"), "{e}");

    let e = error_of("self.grdecl", "INCLUDE\n 'self.grdecl' /\n");
    assert!(e.contains("cycle"), "{e}");

    let upside = deck_text([1, 1, 1], 1.0, 1.0, |_, _, _, k| -(k as f64), "");
    let e = error_of("upside.grdecl", &upside);
    assert!(e.contains("bottom is above the top"), "{e}");

    let e = error_of("radial.grdecl", "SPECGRID\n 1 1 1 1 T /\n");
    assert!(e.contains("radial"), "{e}");

    let e = error_of(
        "default.grdecl",
        &good.replacen(" 1.0 1.0 1.0 1.0\n/", " 1.0 1.0 2*\n/", 1),
    );
    assert!(e.contains("`2*`") && e.contains("default"), "{e}");

    let e = error_of("quote.grdecl", "INCLUDE\n 'open.inc /\n");
    assert!(e.contains("not closed"), "{e}");

    let e = error_of(
        "faults.grdecl",
        &format!("{good}FAULTS\n 'F1' 1 2 1 1 1 1 'X' /\n/\n"),
    );
    assert!(e.contains("FAULTS: record `F1 1 2 1 1 1 1 X`"), "{e}");

    // Two cells of a column that overlap; a horizontal pillar.
    let two = deck_text([1, 1, 2], 1.0, 1.0, |_, _, _, k| k as f64, "");
    let mut deck = read_deck(write("two.grdecl", &two)).unwrap();
    deck.zcorn[8] = 0.5; // the top of cell k = 2 above the bottom of k = 1 at corner 1
    let e = corner_point_grid(&deck).unwrap_err().to_string();
    assert!(e.contains("overlap at corner 1"), "{e}");
    let mut flat = read_deck(write("flat.grdecl", &good)).unwrap();
    flat.coord[3] += 5.0;
    flat.coord[5] = flat.coord[2];
    let e = corner_point_grid(&flat).unwrap_err().to_string();
    assert!(e.contains("horizontal"), "{e}");

    let e = error_of("nozcorn.grdecl", "SPECGRID\n 1 1 1 /\nCOORD\n 24*0 /\n");
    assert!(matches!(
        read_deck(write("nz.grdecl", "SPECGRID\n 1 1 1 /\n")),
        Err(GridError::Parse { .. })
    ));
    assert!(e.contains("ZCORN"), "{e}");
}

/// A repeat count that wraps when added to the values already read is refused before
/// anything is pushed, naming the keyword, the file and the line.
#[test]
fn a_huge_repeat_count_is_an_error_not_an_allocation() {
    let good = deck_text([1, 1, 1], 1.0, 1.0, |_, _, _, k| k as f64, "");
    let at = good.find("ZCORN").unwrap();
    let bad = format!("{}ZCORN\n 0 18446744073709551615*1 /\n", &good[..at]);
    let line = bad.lines().count();
    let e = error_of("repeat.grdecl", &bad);
    assert!(
        e.contains(&format!("repeat.grdecl:{line}:"))
            && e.contains("ZCORN")
            && e.contains("more than the 8 values")
            && e.contains("(1 read before it)"),
        "{e}"
    );
}

/// Lines are read up to 1 MiB: a longer line (a file without newlines) is refused with
/// its line, and what is not a regular file (a device, a directory, a FIFO) is refused
/// before it is opened, also when an INCLUDE names it.
#[test]
fn long_lines_devices_directories_and_fifos_are_refused() {
    let long = format!("SPECGRID\n 1 1 1 /\n{}", " ".repeat(2 << 20));
    let e = error_of("long.grdecl", &long);
    assert!(
        e.contains("long.grdecl:3:") && e.contains("longer than 1048576 bytes"),
        "{e}"
    );
    let e = read_deck("/dev/zero").unwrap_err().to_string();
    assert!(
        e.contains("/dev/zero") && e.contains("not a regular file"),
        "{e}"
    );
    let e = error_of(
        "zero.grdecl",
        "SPECGRID\n 1 1 1 /\nINCLUDE\n '/dev/zero' /\n",
    );
    assert!(
        e.contains("zero.grdecl:4:") && e.contains("/dev/zero: is not a regular file"),
        "{e}"
    );
    let dir = write("dir.grdecl", "").parent().unwrap().join("a-folder");
    std::fs::create_dir_all(&dir).unwrap();
    let e = read_deck(&dir).unwrap_err().to_string();
    assert!(
        e.contains("a-folder") && e.contains("is a directory"),
        "{e}"
    );
    let e = error_of("incdir.grdecl", "INCLUDE\n 'a-folder' /\n");
    assert!(
        e.contains("incdir.grdecl:2:") && e.contains("is a directory"),
        "{e}"
    );
    let fifo = dir.join("pipe.grdecl");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", fifo.display());
    let e = read_deck(&fifo).unwrap_err().to_string();
    assert!(e.contains("pipe.grdecl") && e.contains("FIFO"), "{e}");
}

/// GRIDUNIT, when given, is the unit of COORD and ZCORN; without it the unit system
/// is: a cube of 10 deck units is (10 u)³ for the one unit u that applies, never the
/// product of two.
#[test]
fn grid_lengths_are_scaled_once_by_gridunit_or_else_the_unit_system() {
    let body = deck_text([1, 1, 1], 10.0, 10.0, |_, _, _, k| 10.0 * k as f64, "");
    let systems = [
        ("", 1.0),
        ("METRIC\n", 1.0),
        ("FIELD\n", 0.3048),
        ("LAB\n", 0.01),
    ];
    let gridunits = [
        ("", None),
        ("GRIDUNIT\n 'METRES  ' /\n", Some(1.0)),
        ("GRIDUNIT\n FEET /\n", Some(0.3048)),
        ("GRIDUNIT\n 'CM' '    ' /\n", Some(0.01)),
    ];
    for (system, unit) in systems {
        for (gridunit, grid_unit) in gridunits {
            let text = format!("{system}{gridunit}{body}");
            let (_, cp) = read_grdecl(write("units.grdecl", &text)).unwrap();
            let u = grid_unit.unwrap_or(unit);
            let want = (10.0f64 * u).powi(3);
            let got = cp.grid.cell_volume(0);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{system:?} {gridunit:?}: {got} m³, expected {want}"
            );
        }
    }
}

/// Every message names a file and a 1-based line: an INCLUDE cycle at the INCLUDE that
/// closes it, a deck without SPECGRID at its end.
#[test]
fn include_cycles_and_a_missing_size_name_file_and_line() {
    write("cycle-b.inc", "-- b\nINCLUDE\n 'cycle-a.inc' /\n");
    write("cycle-a.inc", "-- a\n\nINCLUDE\n 'cycle-b.inc' /\n");
    let e = error_of("cycle.grdecl", "INCLUDE\n 'cycle-a.inc' /\n");
    assert!(
        e.contains("cycle-b.inc:3:")
            && e.contains("cycle of includes (cycle-a.inc → cycle-b.inc → cycle-a.inc)"),
        "{e}"
    );
    let e = error_of("nosize.grdecl", "-- nothing\nPORO_X\n/\n\n");
    assert!(
        e.contains("nosize.grdecl:4:") && e.contains("no SPECGRID or DIMENS"),
        "{e}"
    );
    let e = error_of("empty.grdecl", "");
    assert!(e.contains("empty.grdecl:1:"), "{e}");
}

/// User text in a message is cut to 60 characters and its length.
#[test]
fn long_user_text_is_not_echoed_whole() {
    let token = "X".repeat(500_000);
    let e = error_of("token.grdecl", &format!("SPECGRID\n 1 1 1 /\n{token}\n"));
    assert!(
        e.len() < 300 && e.contains(&format!("{}… (500000 characters)", &token[..60])),
        "{}",
        &e[..e.len().min(400)]
    );
    let e = error_of("quoted.grdecl", &format!("'{token}'\n"));
    assert!(
        e.len() < 300 && e.contains("(500000 characters)"),
        "{}",
        &e[..e.len().min(400)]
    );
    let good = deck_text([1, 1, 1], 1.0, 1.0, |_, _, _, k| k as f64, "");
    let e = error_of(
        "number.grdecl",
        &good.replacen(
            " 1.0 1.0 1.0 1.0\n/",
            &format!(" 1.0 1.0 1.0 {token}\n/"),
            1,
        ),
    );
    assert!(
        e.len() < 300 && e.contains("(500000 characters)"),
        "{}",
        &e[..e.len().min(400)]
    );
}

/// Bad cell properties of the grid's cells name the keyword, the file and line it was
/// read at, and the cell's 1-based (i, j, k); inactive cells are not checked.
#[test]
fn bad_cell_properties_name_keyword_file_line_and_cell() {
    use porofrac_grid::io::grdecl::check_cell_properties;
    let body = deck_text([3, 1, 2], 1.0, 1.0, |_, _, _, k| k as f64, "");
    let check = |name: &str, props: &str| {
        let text = format!("{body}{props}");
        let (deck, cp) = read_grdecl(write(name, &text)).unwrap();
        check_cell_properties(&deck, &cp).map_err(|e| e.to_string())
    };
    // Cell (3, 1, 2) is the sixth of the deck; (1, 1, 1) inactive with PORO 0.
    let props = "ACTNUM\n 0 5*1 /\nPORO\n 0 0.2 0.2 0.2 0.2 -0.45 /\n";
    let line = body.lines().count() + 3;
    let e = check("poro.grdecl", props).unwrap_err();
    assert_eq!(
        e,
        format!(
            "{}:{line}: PORO of cell (i, j, k) = (3, 1, 2) is -0.45; porosity must be in (0, 1]",
            write("poro.grdecl", "").display()
        )
    );
    assert!(check("ok.grdecl", "ACTNUM\n 0 5*1 /\nPORO\n 0 5*0.2 /\n").is_ok());
    let e = check(
        "permy.grdecl",
        "PORO\n 6*0.2 /\nPERMX\n 6*100 /\nPERMY\n 100 -5 4*100 /\n",
    )
    .unwrap_err();
    assert!(
        e.contains("PERMY of cell (i, j, k) = (2, 1, 1) is -5 mD") && e.contains("permy.grdecl:"),
        "{e}"
    );
    let e = check("ntg.grdecl", "PORO\n 6*0.2 /\nNTG\n 5*1 1.5 /\n").unwrap_err();
    assert!(
        e.contains("NTG of cell (i, j, k) = (3, 1, 2) is 1.5"),
        "{e}"
    );
    let e = check("multpv.grdecl", "PORO\n 6*0.5 /\nMULTPV\n 1 3 4*1 /\n").unwrap_err();
    assert!(
        e.contains("MULTPV") && e.contains("(2, 1, 1) is 0.5 × 1 × 3 = 1.5"),
        "{e}"
    );
}

/// A whole simulation deck is read for its grid: reading stops at the first section
/// after GRID (here SUMMARY, whose records this reader does not parse); a block-centred
/// deck (DX, DY, DZ, TOPS) is refused as such.
#[test]
fn a_simulation_deck_is_read_up_to_its_grid_and_block_grids_are_named() {
    let body = deck_text([1, 1, 1], 2.0, 2.0, |_, _, _, k| 100.0 + k as f64, "");
    let text = format!("RUNSPEC\nDIMENS\n 1 1 1 /\nGRID\n{body}PROPS\nSUMMARY\nBPR\n1 1 1 /\n/\n");
    let (_, cp) = read_grdecl(write("case.DATA", &text)).unwrap();
    assert!((cp.grid.cell_volume(0) - 4.0).abs() < 1e-12);
    let e = error_of(
        "blocks.DATA",
        "DIMENS\n 2 1 1 /\nGRID\nDX\n 2*10 /\nDY\n 2*10 /\nDZ\n 2*5 /\nTOPS\n 2*100 /\nPROPS\n",
    );
    assert!(
        e.contains("blocks.DATA:1:") && e.contains("no COORD") && e.contains("DX DY DZ TOPS"),
        "{e}"
    );
}
