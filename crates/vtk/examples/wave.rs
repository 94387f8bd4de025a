//! A time series of lattice fields for ParaView with `porofrac-vtk` alone: a travelling
//! wave `h(x, y, t) = sin(k x − ω t) cos(k y)` and its gradient on a 64 × 32 lattice,
//! written as ImageData files (`.vti`, raw binary appended data) and a `.pvd` collection
//! that ParaView opens as one animated data set.
//!
//! ```sh
//! cargo run --release -p porofrac-vtk --example wave -- out/wave
//! ```
//! then open `out/wave/wave.pvd` in ParaView.

use std::f64::consts::PI;
use std::path::PathBuf;

use porofrac_vtk::{Attributes, DataArray, Encoding, ImageData, PvdWriter, VtkError};

fn main() -> Result<(), VtkError> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "out/wave".into()));
    std::fs::create_dir_all(&dir).map_err(|source| VtkError::Io {
        path: dir.clone(),
        source,
    })?;
    let (nx, ny, h) = (64usize, 32usize, 0.1);
    let k = 2.0 * PI / (nx as f64 * h / 2.0);
    let omega = 2.0 * PI;
    let mut collection = PvdWriter::create(dir.join("wave.pvd"))?;
    for step in 0..10 {
        let t = 0.1 * step as f64;
        let mut height = Vec::with_capacity(nx * ny);
        let mut gradient = Vec::with_capacity(3 * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (i as f64 * h, j as f64 * h);
                height.push((k * x - omega * t).sin() * (k * y).cos());
                gradient.extend([
                    k * (k * x - omega * t).cos() * (k * y).cos(),
                    -k * (k * x - omega * t).sin() * (k * y).sin(),
                    0.0,
                ]);
            }
        }
        let arrays = [
            DataArray::new("height", 1, &height[..]),
            DataArray::new("gradient", 3, &gradient[..]),
        ];
        let name = format!("wave_{step:04}.vti");
        ImageData {
            size: [nx, ny, 1],
            origin: [0.0; 3],
            spacing: [h; 3],
            field_data: &[],
            point_data: Attributes::new(&arrays),
            cell_data: Attributes::default(),
        }
        .write(dir.join(&name), Encoding::Appended)?;
        collection.add(t, &name)?;
    }
    println!("wrote {} (10 steps)", dir.join("wave.pvd").display());
    Ok(())
}
