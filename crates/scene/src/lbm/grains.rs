//! `[grains]`: a digitised rock as the lattice's solid map (Mora et al. (2015), Fig. 10:
//! fluid and heat through a 2D sandstone). The grains of a grey-level image (PGM or PNG,
//! [`porofrac_lbm::image`]) are sampled at the lattice nodes and enter the lattice as fixed
//! rectangles of nodes with halfway bounce-back; with `[thermal]` they start at their own
//! temperature and either cool by conduction (conjugate: the solid diffusivity of
//! `thermal.solid_diffusivity`) or are held at it (`held = true`, a Dirichlet condition on
//! the solid). `thermal.books = true` writes the heat books of every lattice step
//! (`heat_books.csv`, summary `heat_books`).

use std::path::PathBuf;

use porofrac_lbm::image::{GreyImage, Polarity, rectangles};
use porofrac_lbm::{HeatBooks, Lattice, Obstacle, Shape, Thermal, Units};

use crate::common::loaded::{LoadedScene, SceneError, k};
use crate::common::model::RunError;

/// `[grains]` (model `lbm`).
#[derive(Clone, Debug, serde::Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GrainsSection {
    /// Grey-level image of the rock (PGM `P2`/`P5` or PNG; colour is turned to grey),
    /// relative to the scene file. Row 0 of the file is the top of the picture.
    pub image: String,
    /// Grey level that separates grains from pores, as a fraction of white (0–1; default
    /// 0.5).
    pub threshold: Option<f64>,
    /// Which pixels are grains: `"above"` the threshold (bright grains, default) or
    /// `"below"` it.
    #[serde(default)]
    pub solid: GrainSide,
    /// Size of a pixel (m): the picture spans `width × pixel_size` by `height ×
    /// pixel_size`. A lattice node is a grain node when the pixel under its centre is a
    /// grain pixel.
    #[schemars(extend("unit" = "m"))]
    pub pixel_size: f64,
    /// Lower-left corner of the picture (m; default the lower-left corner of
    /// `lbm.extent`).
    #[schemars(extend("unit" = "m"))]
    pub origin: Option<Vec<f64>>,
    /// Initial temperature of the grains (needs `[thermal]`; default `thermal.initial` at
    /// each node).
    #[schemars(extend("unit" = "°C"))]
    pub temperature: Option<f64>,
    /// Hold the grains at `temperature` (a Dirichlet condition on the solid: a reservoir
    /// keeps them hot) instead of letting them cool by conduction with
    /// `thermal.solid_diffusivity` (conjugate heat transfer, default).
    #[serde(default)]
    pub held: bool,
}

/// `[grains] solid`.
#[derive(Clone, Copy, Debug, Default, serde::Deserialize, schemars::JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum GrainSide {
    /// Grey level at or above the threshold.
    #[default]
    Above,
    /// Grey level below the threshold.
    Below,
}

fn key(f: &str) -> Vec<crate::common::sections::KeyPart> {
    k(&["grains", f])
}

/// The image of a checked or unchecked `[grains]`, read from its file.
fn read(ls: &LoadedScene, g: &GrainsSection) -> Result<GreyImage, SceneError> {
    let path: PathBuf = ls.resolve(&g.image);
    GreyImage::read(&path).map_err(|e| {
        ls.error(
            &key("image"),
            format!("= \"{}\" ({}): {e}", g.image, path.display()),
        )
    })
}

/// Most rectangles of grain nodes a scene may have (each is an obstacle of the lattice,
/// and adding one costs a pass over those before it).
pub const MAX_RECTANGLES: usize = 20_000;

/// Most lattice steps whose books a run keeps (one row of `heat_books.csv` each).
pub const MAX_BOOK_STEPS: f64 = 1e6;

/// Check `[grains]` and the heat keys of `[thermal]` of a scene of model `lbm`.
pub(crate) fn check_keys(ls: &LoadedScene, units: &Units) -> Result<(), SceneError> {
    if let Some(t) = &ls.scene.thermal {
        if let Some(c) = t.heat_capacity
            && !(c.is_finite() && c > 0.0)
        {
            return Err(ls.error(
                &k(&["thermal", "heat_capacity"]),
                format!("= {c} must be a positive number (J/(m³·K))"),
            ));
        }
        if t.books == Some(true)
            && let Some(sch) = &ls.scene.schedule
        {
            let steps = (sch.end_time / units.dt).round();
            if steps > MAX_BOOK_STEPS {
                return Err(ls.error(
                    &k(&["thermal", "books"]),
                    format!(
                        "keeps one row per lattice step: {steps:e} steps (schedule.end_time / \
                         Δt = {:e} s) is above {MAX_BOOK_STEPS:e}",
                        units.dt
                    ),
                ));
            }
        }
    }
    match &super::own(ls).grains {
        Some(g) => check(ls, g),
        None => Ok(()),
    }
}

/// Check `[grains]`: the keys, the image file, and that some lattice node is a grain node.
fn check(ls: &LoadedScene, g: &GrainsSection) -> Result<(), SceneError> {
    let t = g.threshold.unwrap_or(0.5);
    if !(0.0..=1.0).contains(&t) {
        return Err(ls.error(
            &key("threshold"),
            format!("= {t} must lie in 0–1 (a fraction of white)"),
        ));
    }
    if !(g.pixel_size.is_finite() && g.pixel_size > 0.0) {
        return Err(ls.error(
            &key("pixel_size"),
            format!("= {} must be a positive length (m)", g.pixel_size),
        ));
    }
    if let Some(o) = &g.origin
        && (o.len() != 2 || !o.iter().all(|v| v.is_finite()))
    {
        return Err(ls.error(&key("origin"), "must be two finite numbers [x, y] (m)"));
    }
    match (g.temperature, ls.scene.thermal.is_some()) {
        (Some(v), _) if !v.is_finite() => {
            return Err(ls.error(&key("temperature"), format!("= {v} is not a finite number")));
        }
        (Some(_), false) => {
            return Err(ls.error(&key("temperature"), "needs [thermal]"));
        }
        (None, _) if g.held => {
            return Err(ls.error(
                &key("held"),
                "needs grains.temperature: what they are held at",
            ));
        }
        _ => {}
    }
    let img = read(ls, g)?;
    let l = ls.scene.lbm.as_ref().expect("checked");
    let (nx, ny) = crate::common::lattice::nodes(l);
    let (nx, ny) = (nx as usize, ny as usize);
    let solid = solid_map(ls, g, &img, nx, ny);
    let pieces = rectangles(&solid, nx, ny).len();
    if pieces > MAX_RECTANGLES {
        return Err(ls.error(
            &key("image"),
            format!(
                "= \"{}\": its grains cut into {pieces} rectangles of lattice nodes (at most \
                 {MAX_RECTANGLES}; each is an obstacle of the lattice): a noisy image — \
                 smooth it, or segment it into grains and pores first",
                g.image
            ),
        ));
    }
    if solid.iter().all(|s| !s) {
        return Err(ls.error(
            &key("image"),
            format!(
                "= \"{}\": no lattice node falls on a grain pixel ({} × {} pixels of {} m from \
                 the origin, threshold {t}, grains {}): check pixel_size, origin, threshold and \
                 solid",
                g.image,
                img.width,
                img.height,
                g.pixel_size,
                match g.solid {
                    GrainSide::Above => "above",
                    GrainSide::Below => "below",
                }
            ),
        ));
    }
    Ok(())
}

/// The grain nodes of the whole lattice (`nx × ny`, x fastest), less those a declared
/// obstacle covers (the obstacle keeps them).
fn solid_map(
    ls: &LoadedScene,
    g: &GrainsSection,
    img: &GreyImage,
    nx: usize,
    ny: usize,
) -> Vec<bool> {
    let l = ls.scene.lbm.as_ref().expect("checked");
    let dx = l.spacing;
    let corner = [l.extent[0][0], l.extent[0][1]];
    let o = g.origin.as_deref().unwrap_or(&corner);
    let mut solid = img.solid_map(
        nx,
        ny,
        [(o[0] - corner[0]) / dx, (o[1] - corner[1]) / dx],
        g.pixel_size / dx,
        g.threshold.unwrap_or(0.5),
        match g.solid {
            GrainSide::Above => Polarity::Above,
            GrainSide::Below => Polarity::Below,
        },
    );
    // the declared obstacles keep their nodes (lattice units from the corner; only the
    // spacing of the units enters a shape)
    let units = Units {
        dx,
        dt: 1.0,
        density: l.density,
        tau: l.tau,
    };
    let shapes: Vec<Shape> = super::own(ls)
        .obstacle
        .iter()
        .map(|o| super::shape_of(o, &units, corner))
        .collect();
    if !shapes.is_empty() {
        for j in 0..ny {
            for i in 0..nx {
                let p = [i as f64 + 0.5, j as f64 + 0.5];
                if solid[j * nx + i] && shapes.iter().any(|s| s.contains(p)) {
                    solid[j * nx + i] = false;
                }
            }
        }
    }
    solid
}

/// The grains on a built lattice: rectangles of nodes added as fixed obstacles after the
/// declared ones. Returns the grain nodes of `lat` (local columns of a window).
pub(crate) fn add(
    ls: &LoadedScene,
    g: &GrainsSection,
    lat: &mut Lattice,
) -> Result<Vec<(usize, usize)>, RunError> {
    let img = read(ls, g)?;
    let (bx, by) = lat.box_size();
    let solid = solid_map(ls, g, &img, bx, by);
    for r in rectangles(&solid, bx, by) {
        lat.add_obstacle(Obstacle {
            shape: Shape::aligned_box(
                [r[0] as f64, r[1] as f64],
                [r[2] as f64 + 1.0, r[3] as f64 + 1.0],
            ),
            velocity: [0.0, 0.0],
            angular_velocity: 0.0,
        })
        .map_err(|e| ls.error(&key("image"), e))?;
    }
    let (x0, (nx, _)) = (lat.origin(), lat.size());
    Ok((0..bx * by)
        .filter(|&n| solid[n] && (x0..x0 + nx).contains(&(n % bx)))
        .map(|n| (n % bx - x0, n / bx))
        .collect())
}

/// Give the grain nodes their temperature, or hold them at it.
pub(crate) fn heat(g: &GrainsSection, th: &mut Thermal, nodes: &[(usize, usize)]) {
    let Some(t) = g.temperature else {
        return;
    };
    if g.held {
        th.hold(nodes.iter().copied(), t);
    } else {
        for &(i, j) in nodes {
            th.set_temperature(i, j, t);
        }
    }
}

/// One row of `heat_books.csv`: lattice step and the books in J per metre of depth.
pub(crate) fn row(step: u64, b: &HeatBooks, joules: f64) -> [f64; 9] {
    [
        step as f64,
        b.stored_before * joules,
        b.stored_after * joules,
        b.conduction_in * joules,
        b.advection_in * joules,
        b.advection_out * joules,
        b.solids * joules,
        b.defect() * joules,
        if b.stored_before != 0.0 {
            b.defect() / b.stored_before.abs()
        } else {
            b.defect().abs()
        },
    ]
}

/// The header of `heat_books.csv`.
pub(crate) const HEADER: &str = "step,stored_before [J/m],stored_after [J/m],conduction_in [J/m],\
advection_in [J/m],advection_out [J/m],solids [J/m],defect [J/m],relative_defect";
