//! Extent of the crack connected to a borehole wall against the hole pressure, one line
//! per run, from the `crack.csv` files of lattice solid scenes (`time,i,j,pressure,extent`):
//!
//! ```text
//! cargo run --release -p porofrac-lsm --example crack_extent_plot -- \
//!     OUT.png TITLE HOLE_RADIUS LABEL:RUN_DIR:P_B [LABEL:RUN_DIR:P_B ...]
//! ```
//!
//! The pressure is shown over `p_b` (Pa, given per run: each packing has its own
//! calibrated σ_t), the extent in hole radii from the centre; the dashed line is the
//! breakdown extent `2a`. Used by `scripts/lsm_breakdown.sh`.

use plotters::prelude::*;

fn read(dir: &str) -> Result<Vec<(f64, f64)>, String> {
    let path = format!("{dir}/crack.csv");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?;
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |k: usize| {
            f.get(k)
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or_else(|| format!("{path}:{}: bad row {line}", n + 1))
        };
        rows.push((num(3)?, num(4)?));
    }
    Ok(rows)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: OUT.png TITLE HOLE_RADIUS LABEL:RUN_DIR:P_B...".into());
    }
    let a: f64 = args[2].parse().map_err(|_| "HOLE_RADIUS: not a number")?;
    let mut runs = Vec::new();
    for spec in &args[3..] {
        let parts: Vec<&str> = spec.rsplitn(2, ':').collect();
        let (pb, rest) = (parts[0], parts.get(1).ok_or("LABEL:RUN_DIR:P_B expected")?);
        let (label, dir) = rest.split_once(':').ok_or("LABEL:RUN_DIR:P_B expected")?;
        let pb: f64 = pb
            .parse()
            .map_err(|_| format!("{spec}: P_B is not a number"))?;
        runs.push((label.to_string(), read(dir)?, pb));
    }
    let xmax = runs
        .iter()
        .flat_map(|r| r.1.iter().map(move |p| p.0 / r.2))
        .fold(1.5f64, f64::max);
    let ymax = runs
        .iter()
        .flat_map(|r| r.1.iter().map(|p| p.1 / a))
        .fold(2.5f64, f64::max);
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        include_bytes!("../../scene/assets/DejaVuSans.ttf"),
    )
    .map_err(|_| "font")?;
    let root = BitMapBackend::new(&args[0], (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&args[1], ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..xmax * 1.02, 0.0..ymax * 1.05)?;
    chart
        .configure_mesh()
        .x_desc("hole pressure / p_b")
        .y_desc("extent of the wall crack / a")
        .draw()?;
    for (k, (label, rows, pb)) in runs.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        // a step line: the extent holds until the next broken bond
        let mut pts = vec![(0.0, 1.0)];
        let mut last = 1.0;
        for &(p, e) in rows {
            let y = (e / a).max(1.0);
            pts.push((p / pb, last));
            pts.push((p / pb, y));
            last = y;
        }
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))?
            .label(label.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    let dash = (0..60).map(|i| i as f64 * xmax * 1.02 / 60.0);
    chart.draw_series(dash.clone().step_by(2).map(|x| {
        PathElement::new(
            vec![(x, 2.0), (x + xmax * 1.02 / 60.0, 2.0)],
            BLACK.stroke_width(1),
        )
    }))?;
    chart.draw_series(std::iter::once(PathElement::new(
        vec![(1.0, 0.0), (1.0, ymax * 1.05)],
        BLACK.mix(0.4).stroke_width(1),
    )))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
