//! The plot of the section "Cosserat DEM against a Python port and a P2–P1 FEM" of
//! `docs/BENCHMARKS.md`: relative SCF error against wall time (assembly + solve) for the
//! plate with a hole, porofrac's DEM, the same DEM in Python/scipy and a P2–P1 FEM in FEniCSx.
//!
//! `cargo run --release -p porofrac-cosserat --example speed_error_plot -- CSV PNG`, with the
//! CSV of `scripts/cosserat_table.py` (`code,level,cells,dofs,t_assemble,t_solve,t_total,
//! scf,err_rel`), e.g. `docs/data/cosserat_rounds.csv` → `docs/speed_error_cosserat.png`.

use plotters::prelude::*;
use plotters::style::FontStyle;

type BoxError = Box<dyn std::error::Error>;

/// Series: CSV code, legend, colour, hollow marker.
const SERIES: &[(&str, &str, RGBColor, bool)] = &[
    (
        "porofrac",
        "porofrac DEM (library, LDLᵀ + Schur / GMRES-AMG)",
        RGBColor(31, 119, 180),
        false,
    ),
    (
        "porofrac-command",
        "porofrac DEM (porofrac run, scene)",
        RGBColor(44, 160, 44),
        true,
    ),
    (
        "python-dem",
        "same DEM in numpy/scipy (spsolve)",
        RGBColor(255, 127, 14),
        false,
    ),
    (
        "porofrac-first-interpolating",
        "porofrac DEM, the seed's stencil rule (earlier round)",
        RGBColor(31, 119, 180),
        true,
    ),
    (
        "python-dem-smallest-weight",
        "DEM in numpy/scipy, the paper's wider stencils",
        RGBColor(214, 39, 40),
        true,
    ),
    (
        "fenicsx-p2p1",
        "FEniCSx P2–P1 FEM (MUMPS)",
        RGBColor(127, 127, 127),
        true,
    ),
];

fn main() -> Result<(), BoxError> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        return Err("usage: speed_error_plot CSV PNG".into());
    }
    let text = std::fs::read_to_string(&args[1])?;
    let mut pts: Vec<Vec<(f64, f64)>> = vec![Vec::new(); SERIES.len()];
    for (i, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 9 {
            return Err(format!("{}:{}: want 9 fields, got {}", args[1], i + 1, f.len()).into());
        }
        let Some(s) = SERIES.iter().position(|s| s.0 == f[0]) else {
            continue;
        };
        let t: f64 = f[6].parse()?;
        let e: f64 = f[8].parse::<f64>()?.abs();
        if t > 0.0 && e > 0.0 {
            pts[s].push((t, e));
        }
    }
    let all = || pts.iter().flatten();
    if all().next().is_none() {
        return Err(format!("{}: no points", args[1]).into());
    }
    let dec_lo = |v: f64| 10f64.powf(v.log10().floor());
    let dec_hi = |v: f64| 10f64.powf(v.log10().ceil());
    let x0 = dec_lo(all().map(|p| p.0).fold(f64::INFINITY, f64::min));
    let x1 = dec_hi(all().map(|p| p.0).fold(0.0, f64::max) * 1.05);
    let y0 = dec_lo(all().map(|p| p.1).fold(f64::INFINITY, f64::min));
    let y1 = dec_hi(all().map(|p| p.1).fold(0.0, f64::max));
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        include_bytes!("../../scene/assets/DejaVuSans.ttf"),
    );
    let root = BitMapBackend::new(&args[2], (1000, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Cosserat plate with a hole (r/ℓ = 1.063, N = 0.5): SCF error against time",
            ("sans-serif", 20),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("wall time, assembly + solve [s]")
        .y_desc("|SCF − SCF_Mindlin| / SCF_Mindlin")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()?;
    for (s, p) in SERIES.iter().zip(&mut pts) {
        if p.is_empty() {
            continue;
        }
        p.sort_by(|a, b| a.0.total_cmp(&b.0));
        let line = s.2.stroke_width(2);
        let dot = if s.3 {
            s.2.stroke_width(2)
        } else {
            s.2.filled()
        };
        chart.draw_series(LineSeries::new(p.clone(), line))?;
        chart
            .draw_series(
                p.iter()
                    .map(|&q| EmptyElement::at(q) + Circle::new((0, 0), 5, dot)),
            )?
            .label(s.1)
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(-12, 0), (12, 0)], line)
                    + Circle::new((0, 0), 5, dot)
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 15))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    println!("{}", args[2]);
    Ok(())
}
