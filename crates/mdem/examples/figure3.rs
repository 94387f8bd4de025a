//! Nilsen et al. (2017) §3, Figure 3: the stiffness lost by the central-force DEM model of
//! a triangle, `T = C − 𝒦(diag 𝒦⁻¹(C))`, as the apex of the triangle moves.
//!
//! The triangle has its base from (−½, 0) to (½, 0) and its apex at (x, y); at
//! (0, √3/2) it is equilateral and, for E = 1, ν = 1/4 in plane strain, `𝐊` is
//! diagonal so `T = 0`. The six independent Kelvin components `T₁₁, T₂₂, T₃₃, T₁₂,
//! T₁₃, T₂₃` are drawn as heat maps over the apex position (panels left to right, top
//! to bottom), each on its own symmetric blue–white–red scale (red positive, the scale
//! is the 90th percentile of |T| over the panel, larger values saturate); the
//! reference triangle is drawn in yellow. The image has no text (no fonts are needed);
//! the scale of each panel is printed, and the data are written as CSV beside the PNG.
//!
//! Run: `cargo run -p porofrac-mdem --example figure3 -- [out.png]`
//! (default `figure3.png`).

use std::error::Error;
use std::io::Write;

use plotters::prelude::*;
use porofrac_grid::Point;
use porofrac_law::Stiffness;
use porofrac_mdem::dem_stiffness_loss;

const X_RANGE: (f64, f64) = (-0.8, 0.8);
const Y_RANGE: (f64, f64) = (0.25, 1.5);
const NX: usize = 192;
const NY: usize = 150;
const PANEL: (u32, u32) = (2 * NX as u32, 2 * NY as u32);
const COMPONENTS: [(usize, usize, &str); 6] = [
    (0, 0, "T11"),
    (1, 1, "T22"),
    (2, 2, "T33"),
    (0, 1, "T12"),
    (0, 2, "T13"),
    (1, 2, "T23"),
];

fn colour(v: f64, vmax: f64) -> RGBColor {
    let s = if vmax > 0.0 {
        (v / vmax).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let fade = |c: f64| (255.0 * (1.0 - s.abs()) + c * s.abs()) as u8;
    if s >= 0.0 {
        RGBColor(fade(200.0), fade(30.0), fade(30.0))
    } else {
        RGBColor(fade(30.0), fade(60.0), fade(200.0))
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "figure3.png".into());
    let c = Stiffness::<2>::isotropic(1.0, 0.25)?.to_dmatrix();

    // T over the grid of apex positions (cell centres).
    let xs: Vec<f64> = (0..NX)
        .map(|i| X_RANGE.0 + (i as f64 + 0.5) * (X_RANGE.1 - X_RANGE.0) / NX as f64)
        .collect();
    let ys: Vec<f64> = (0..NY)
        .map(|j| Y_RANGE.0 + (j as f64 + 0.5) * (Y_RANGE.1 - Y_RANGE.0) / NY as f64)
        .collect();
    let mut data = vec![[0.0; 6]; NX * NY];
    let mut csv = std::fs::File::create(format!("{out}.csv"))?;
    writeln!(csv, "x,y,T11,T22,T33,T12,T13,T23")?;
    for (j, &y) in ys.iter().enumerate() {
        for (i, &x) in xs.iter().enumerate() {
            let tri = [
                Point::<2>::new(-0.5, 0.0),
                Point::<2>::new(0.5, 0.0),
                Point::<2>::new(x, y),
            ];
            let t = dem_stiffness_loss(&tri, &c)?;
            let v = COMPONENTS.map(|(a, b, _)| t[(a, b)]);
            writeln!(
                csv,
                "{x},{y},{},{},{},{},{},{}",
                v[0], v[1], v[2], v[3], v[4], v[5]
            )?;
            data[j * NX + i] = v;
        }
    }

    let root = BitMapBackend::new(&out, (3 * PANEL.0 + 40, 2 * PANEL.1 + 30)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.margin(10, 10, 10, 10).split_evenly((2, 3));
    let to_px = |x: f64, y: f64| -> (i32, i32) {
        let px = (x - X_RANGE.0) / (X_RANGE.1 - X_RANGE.0) * PANEL.0 as f64;
        let py = (Y_RANGE.1 - y) / (Y_RANGE.1 - Y_RANGE.0) * PANEL.1 as f64;
        (px.round() as i32, py.round() as i32)
    };
    for (p, (panel, &(_, _, name))) in panels.iter().zip(COMPONENTS.iter()).enumerate() {
        // Colour scale: the 90th percentile of |T| (near-flat triangles at the bottom
        // corners dominate the maximum), values beyond it saturate.
        let mut mags: Vec<f64> = data.iter().map(|v| v[p].abs()).collect();
        mags.sort_by(f64::total_cmp);
        let vmax = mags[mags.len() * 9 / 10];
        let (vmin_s, vmax_s) = data
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v[p]), b.max(v[p]))
            });
        println!(
            "{name}: range [{vmin_s:.4}, {vmax_s:.4}], colour scale ±{vmax:.4} (90th percentile of |T|)"
        );
        let sx = PANEL.0 as i32 / NX as i32;
        let sy = PANEL.1 as i32 / NY as i32;
        for j in 0..NY {
            for i in 0..NX {
                let x0 = i as i32 * sx;
                let y0 = (NY - 1 - j) as i32 * sy;
                panel.draw(&Rectangle::new(
                    [(x0, y0), (x0 + sx, y0 + sy)],
                    colour(data[j * NX + i][p], vmax).filled(),
                ))?;
            }
        }
        // Reference (equilateral) triangle's apex region outline and apex, in yellow.
        let h = 3f64.sqrt() / 2.0;
        let yellow = RGBColor(230, 200, 0);
        let tri = [
            (-0.5, Y_RANGE.0.max(0.0)),
            (0.0, h),
            (0.5, Y_RANGE.0.max(0.0)),
        ];
        panel.draw(&PathElement::new(
            tri.iter().map(|&(x, y)| to_px(x, y)).collect::<Vec<_>>(),
            yellow.stroke_width(2),
        ))?;
        panel.draw(&Circle::new(to_px(0.0, h), 4, yellow.filled()))?;
        panel.draw(&Rectangle::new(
            [(0, 0), (PANEL.0 as i32, PANEL.1 as i32)],
            BLACK.stroke_width(1),
        ))?;
    }
    root.present()?;
    println!("wrote {out} and {out}.csv");
    Ok(())
}
