//! Checks of a `model = "cosserat"` scene (docs/models/cosserat.md), and the
//! refusal of the Cosserat keys in continuum scenes. Every problem names its key.

use crate::common::bounds::{modulus, point_inside};
use crate::common::loaded::{LoadedScene, SceneError, expr_ok, k, ki};
use crate::common::sections::{
    DiagonalsChoice, GridKind, KeyPart, LinearChoice, NumOrExpr, Select,
};

use super::fields::Field;
use crate::common::rotation_keys::PerRotation;

/// The only law of the model.
pub const LAW: &str = "cosserat-dem";

fn other_model(ls: &LoadedScene, path: &[KeyPart], model: &str) -> SceneError {
    ls.error(
        path,
        format!(
            "belongs to another model than \"{}\" (the key is not used by model \"{}\")",
            ls.model(),
            model
        ),
    )
}

fn positive(ls: &LoadedScene, path: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v > 0.0) {
        return Err(ls.error(path, format!("= {v} must be > 0")));
    }
    Ok(())
}

fn non_negative(ls: &LoadedScene, path: &[KeyPart], v: f64) -> Result<(), SceneError> {
    if !(v.is_finite() && v >= 0.0) {
        return Err(ls.error(path, format!("= {v} must be ≥ 0")));
    }
    Ok(())
}

fn len_is(ls: &LoadedScene, path: &[KeyPart], got: usize, want: usize) -> Result<(), SceneError> {
    if got != want {
        return Err(ls.error(
            path,
            format!("has {got} components, want {want} in this scene"),
        ));
    }
    Ok(())
}

fn per_rotation(
    ls: &LoadedScene,
    path: &[KeyPart],
    v: &PerRotation,
    d: usize,
    allow_free: bool,
) -> Result<(), SceneError> {
    let r = porofrac_cosserat::rotations(d);
    match (v, d) {
        (PerRotation::One(_), 3) => {
            return Err(ls.error(path, "needs three values in 3D (one per axis)"));
        }
        (PerRotation::Many(m), 2) if m.len() != 1 => {
            return Err(ls.error(path, "is one value in 2D (the rotation about z)"));
        }
        (PerRotation::Many(m), _) => len_is(ls, path, m.len(), r)?,
        _ => {}
    }
    for x in v.values() {
        expr_ok(ls, path, x, allow_free)?;
    }
    Ok(())
}

/// Check a cosserat scene.
pub fn check(ls: &LoadedScene) -> Result<(), SceneError> {
    crate::common::lattice::check::refuse_obstacle_probes(ls, "cosserat")?;
    let s = &ls.scene;
    let d = s.scene.dim as usize;
    let model = "cosserat";
    // Keys of other models.
    if s.scene.plane.is_some() {
        return Err(other_model(ls, &k(&["scene", "plane"]), model));
    }
    if s.fluid.is_some() {
        return Err(other_model(ls, &k(&["fluid"]), model));
    }
    if !s.source.is_empty() {
        return Err(other_model(ls, &k(&["source"]), model));
    }
    if !s.well.is_empty() {
        return Err(other_model(ls, &k(&["well"]), model));
    }
    if s.initial.is_some() {
        return Err(other_model(ls, &k(&["initial"]), model));
    }
    let p = &s.physics;
    for (key, set) in [
        ("flow", p.flow.is_some()),
        ("coupling", p.coupling.is_some()),
        ("fracture", p.fracture.is_some()),
        ("failure_stress", p.failure_stress.is_some()),
        ("fracture_permeability", p.fracture_permeability.is_some()),
        (
            "fracture_transmissivity",
            p.fracture_transmissivity.is_some(),
        ),
        ("open_edge_stiffness", p.open_edge_stiffness.is_some()),
        ("crack_tracking", p.crack_tracking.is_some()),
        ("crack_exclusion", p.crack_exclusion.is_some()),
    ] {
        if set {
            return Err(other_model(ls, &k(&["physics", key]), model));
        }
    }
    if s.solver.mechanics.is_some() {
        return Err(other_model(ls, &k(&["solver", "mechanics"]), model));
    }
    if let Some(l @ (LinearChoice::Cholesky | LinearChoice::CgAmg)) = s.solver.linear {
        return Err(ls.error(
            &k(&["solver", "linear"]),
            format!(
                "= \"{}\" is a solver of model \"continuum\" (symmetric matrices); model \
                 \"cosserat\" takes \"auto\", \"lu\" or \"gmres-amg\"",
                if l == LinearChoice::Cholesky {
                    "cholesky"
                } else {
                    "cg-amg"
                }
            ),
        ));
    }
    if let Some(t) = s.solver.tolerance
        && !(t.is_finite() && t > 0.0 && t < 1.0)
    {
        return Err(ls.error(
            &k(&["solver", "tolerance"]),
            format!("= {t} must be in (0, 1) (GMRES's relative residual)"),
        ));
    }
    if s.output.exact_displacement.is_some() {
        return Err(other_model(
            ls,
            &k(&["output", "exact_displacement"]),
            model,
        ));
    }
    check_grid(ls, d)?;
    // Regions: one law, one material (the model is homogeneous).
    if s.region.is_empty() {
        return Err(ls.error(
            &k(&["region"]),
            "is missing: one [[region]] with law = \"cosserat-dem\" and a material",
        ));
    }
    let mut material: Option<&String> = None;
    for (i, r) in s.region.iter().enumerate() {
        if let Some(l) = &r.law
            && l != LAW
        {
            return Err(ls.error(
                &ki("region", i, &["law"]),
                format!("= \"{l}\": the cosserat model has the one law \"{LAW}\""),
            ));
        }
        if i == 0 && (r.law.is_none() || r.material.is_none()) {
            return Err(ls.error(
                &ki("region", 0, &[]),
                "the first region must give both a law and a material",
            ));
        }
        if let Some(m) = &r.material {
            if !s.material.contains_key(m) {
                return Err(ls.error(
                    &ki("region", i, &["material"]),
                    format!("= \"{m}\" is not a defined material"),
                ));
            }
            if material.is_some_and(|first| first != m) {
                return Err(ls.error(
                    &ki("region", i, &["material"]),
                    "= another material: the cosserat model is homogeneous (one material)",
                ));
            }
            material = Some(m);
        }
        if matches!(r.select, Select::All(false)) {
            return Err(ls.error(&ki("region", i, &["select"]), "selects nothing"));
        }
    }
    let name = material.expect("first region has a material");
    check_material(ls, name, d)?;
    // Boundary conditions.
    for (i, bc) in s.bc.iter().enumerate() {
        let key = |f: &str| ki("bc", i, &[f]);
        for (f, set) in [
            ("pressure", bc.pressure.is_some()),
            ("flux", bc.flux.is_some()),
            ("platen", bc.platen.is_some()),
        ] {
            if set {
                return Err(other_model(ls, &key(f), model));
            }
        }
        if let Some(u) = &bc.displacement {
            len_is(ls, &key("displacement"), u.len(), d)?;
            for c in u {
                expr_ok(ls, &key("displacement"), c, true)?;
            }
        }
        if let Some(t) = &bc.traction {
            len_is(ls, &key("traction"), t.len(), d)?;
            for c in t {
                expr_ok(ls, &key("traction"), c, false)?;
            }
            if let Some(u) = &bc.displacement
                && let Some(a) =
                    (0..d).find(|&a| !matches!(&u[a], NumOrExpr::Expr(s) if s == "free"))
            {
                return Err(ls.error(
                    &key("traction"),
                    format!(
                        "component {a} is also prescribed by displacement on this boundary \
                         (give \"free\" there)"
                    ),
                ));
            }
        }
        if let Some(r) = &bc.rotation {
            per_rotation(ls, &key("rotation"), r, d, true)?;
        }
        if let Some(m) = &bc.couple_traction {
            per_rotation(ls, &key("couple_traction"), m, d, false)?;
            if let Some(r) = &bc.rotation
                && r.values()
                    .iter()
                    .any(|v| !matches!(v, NumOrExpr::Expr(s) if s == "free"))
            {
                return Err(ls.error(
                    &key("couple_traction"),
                    "is given with a prescribed rotation on the same boundary (give \"free\" there)",
                ));
            }
        }
    }
    if let Some(l) = &s.loads {
        if l.gravity.is_some() {
            return Err(ls.error(
                &k(&["loads", "gravity"]),
                "is not used by model \"cosserat\": give body_force (N/m³)",
            ));
        }
        if let Some(b) = &l.body_force {
            len_is(ls, &k(&["loads", "body_force"]), b.len(), d)?;
            for v in b {
                expr_ok(ls, &k(&["loads", "body_force"]), v, false)?;
            }
        }
        if let Some(c) = &l.body_couple {
            per_rotation(ls, &k(&["loads", "body_couple"]), c, d, false)?;
        }
    }
    if let Some(eta) = s.solver.penalty {
        positive(ls, &k(&["solver", "penalty"]), eta)?;
    }
    if let Some(t) = s.solver.threads
        && !(0..=1024).contains(&t)
    {
        return Err(ls.error(
            &k(&["solver", "threads"]),
            format!("= {t} must be in 0..=1024"),
        ));
    }
    match &s.schedule {
        Some(sch) => {
            positive(ls, &k(&["schedule", "end_time"]), sch.end_time)?;
            match (sch.dt, sch.steps) {
                (Some(dt), None) => positive(ls, &k(&["schedule", "dt"]), dt)?,
                (None, Some(n)) if n >= 1 => {}
                (None, Some(n)) => {
                    return Err(ls.error(&k(&["schedule", "steps"]), format!("= {n} must be ≥ 1")));
                }
                _ => return Err(ls.error(&k(&["schedule"]), "needs exactly one of dt and steps")),
            }
            if crate::common::loaded::step_count_f64(sch) > crate::common::limits::MAX_STEPS as f64
            {
                return Err(ls.error(&k(&["schedule"]), "asks for too many steps"));
            }
            let m = &s.material[name];
            if m.density.is_none() {
                return Err(ls.error(
                    &k(&["material", name, "density"]),
                    "is required for dynamics (a [schedule])",
                ));
            }
            match m.micro_inertia {
                None => {
                    return Err(ls.error(
                        &k(&["material", name, "micro_inertia"]),
                        "is required for dynamics (a [schedule])",
                    ));
                }
                Some(j) => positive(ls, &k(&["material", name, "micro_inertia"]), j)?,
            }
        }
        None => {
            if s.solver.time_integration.is_some() {
                return Err(ls.error(
                    &k(&["solver", "time_integration"]),
                    "needs a [schedule] (without one the scene is a static solve)",
                ));
            }
        }
    }
    if s.output.every < 1 {
        return Err(ls.error(&k(&["output", "every"]), "must be ≥ 1"));
    }
    let extent = (s.grid.kind != GridKind::File)
        .then_some(s.grid.extent.as_ref())
        .flatten();
    let mut names = std::collections::BTreeSet::new();
    for (i, p) in s.output.probe.iter().enumerate() {
        Field::parse(&p.field, d).map_err(|e| ls.error(&ki("output.probe", i, &["field"]), e))?;
        len_is(ls, &ki("output.probe", i, &["at"]), p.at.len(), d)?;
        point_inside(ls, &ki("output.probe", i, &["at"]), &p.at, extent)?;
        if !names.insert(p.name.clone()) || p.name == "time" || p.name.contains(',') {
            return Err(ls.error(
                &ki("output.probe", i, &["name"]),
                format!("= \"{}\" is repeated, reserved or contains a comma", p.name),
            ));
        }
    }
    for (i, l) in s.output.line.iter().enumerate() {
        Field::parse(&l.field, d).map_err(|e| ls.error(&ki("output.line", i, &["field"]), e))?;
        len_is(ls, &ki("output.line", i, &["from"]), l.from.len(), d)?;
        len_is(ls, &ki("output.line", i, &["to"]), l.to.len(), d)?;
        point_inside(ls, &ki("output.line", i, &["from"]), &l.from, extent)?;
        point_inside(ls, &ki("output.line", i, &["to"]), &l.to, extent)?;
        crate::common::loaded::line_points_and_name(ls, i, l)?;
    }
    Ok(())
}

fn check_grid(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    match (g.kind, d) {
        (GridKind::Triangles, 2) | (GridKind::Tetrahedra, 3) | (GridKind::File, _) => {}
        (kind, _) => {
            return Err(ls.error(
                &key("kind"),
                format!(
                    "= \"{}\": model \"cosserat\" needs simplices ({})",
                    kind.as_str(),
                    if d == 2 {
                        "\"triangles\" or a \"file\" of triangles"
                    } else {
                        "\"tetrahedra\" or a \"file\" of tetrahedra"
                    }
                ),
            ));
        }
    }
    for (f, set) in [
        ("center", g.center.is_some()),
        ("zone_half_width", g.zone_half_width.is_some()),
        ("refine", g.refine.is_some()),
        ("well_radius", g.well_radius.is_some()),
        ("well_tag", g.well_tag.is_some()),
        ("lloyd", g.lloyd.is_some()),
    ] {
        if set {
            return Err(other_model(ls, &key(f), "cosserat"));
        }
    }
    if let Some(dg) = g.diagonals
        && (g.kind != GridKind::Triangles || dg == DiagonalsChoice::Alternating)
    {
        return Err(ls.error(
            &key("diagonals"),
            "applies to kind = \"triangles\" and is \"structured\" or \"crossed\"",
        ));
    }
    if g.kind == GridKind::File {
        if g.path.is_none() {
            return Err(ls.error(&key("path"), "is required for kind = \"file\""));
        }
        return Ok(());
    }
    let Some(ext) = &g.extent else {
        return Err(ls.error(&key("extent"), "is required"));
    };
    len_is(ls, &key("extent"), ext[0].len(), d)?;
    len_is(ls, &key("extent"), ext[1].len(), d)?;
    for a in 0..d {
        if !(ext[0][a].is_finite() && ext[1][a].is_finite() && ext[1][a] > ext[0][a]) {
            return Err(ls.error(&key("extent"), format!("needs min < max on axis {a}")));
        }
    }
    match &g.cells {
        Some(crate::common::sections::CellCount::PerAxis(v)) => {
            len_is(ls, &key("cells"), v.len(), d)?;
            if v.iter().any(|&n| n < 1) {
                return Err(ls.error(&key("cells"), format!("= {v:?} must all be ≥ 1")));
            }
            let total: f64 = v.iter().map(|&n| n as f64).product::<f64>() * 6.0;
            if total > 5e6 {
                return Err(ls.error(&key("cells"), format!("= {v:?} is too many cells")));
            }
        }
        _ => return Err(ls.error(&key("cells"), "is required: one count per axis")),
    }
    if let Some(p) = g.perturb
        && !(0.0..=porofrac_grid::generate::MAX_PERTURB).contains(&p)
    {
        return Err(ls.error(
            &key("perturb"),
            format!(
                "= {p} must be in [0, {}] (a fraction of the local cell size)",
                porofrac_grid::generate::MAX_PERTURB
            ),
        ));
    }
    Ok(())
}

fn check_material(ls: &LoadedScene, name: &str, d: usize) -> Result<(), SceneError> {
    let m = &ls.scene.material[name];
    let key = |f: &str| k(&["material", name, f]);
    for (f, set) in [
        ("biot_alpha", m.biot_alpha.is_some()),
        ("porosity", m.porosity.is_some()),
        ("permeability", m.permeability.is_some()),
        ("solid_bulk_modulus", m.solid_bulk_modulus.is_some()),
        ("tensile_strength", m.tensile_strength.is_some()),
        ("fracture_toughness", m.fracture_toughness.is_some()),
        ("cohesion", m.cohesion.is_some()),
        ("friction_angle", m.friction_angle.is_some()),
    ] {
        if set {
            return Err(other_model(ls, &key(f), "cosserat"));
        }
    }
    let nu = m.poisson_ratio;
    if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
        return Err(ls.error(
            &key("poisson_ratio"),
            format!("= {nu} must be in (-1, 0.5)"),
        ));
    }
    match (m.shear_modulus, m.youngs_modulus.is_nan()) {
        (Some(g), true) => modulus(ls, &key("shear_modulus"), g, false)?,
        (None, false) => modulus(ls, &key("youngs_modulus"), m.youngs_modulus, false)?,
        (Some(_), false) => {
            return Err(ls.error(
                &key("shear_modulus"),
                "and youngs_modulus are both given: give one",
            ));
        }
        (None, true) => {
            return Err(ls.error(&key("shear_modulus"), "is missing (or give youngs_modulus)"));
        }
    }
    match m.cosserat_shear_modulus {
        Some(gc) => modulus(ls, &key("cosserat_shear_modulus"), gc, true)?,
        None => return Err(ls.error(&key("cosserat_shear_modulus"), "is missing")),
    }
    match (m.characteristic_length, &m.couple_moduli, d) {
        (Some(l), None, _) => positive(ls, &key("characteristic_length"), l)?,
        (None, Some(c), 3) => {
            len_is(ls, &key("couple_moduli"), c.len(), 3)?;
            non_negative(ls, &key("couple_moduli"), c[0])?;
            positive(ls, &key("couple_moduli"), c[1])?;
            non_negative(ls, &key("couple_moduli"), c[2])?;
        }
        (None, Some(_), _) => {
            return Err(ls.error(
                &key("couple_moduli"),
                "is for 3D scenes; give characteristic_length in 2D",
            ));
        }
        (Some(_), Some(_), _) => {
            return Err(ls.error(
                &key("couple_moduli"),
                "and characteristic_length are both given: give one",
            ));
        }
        (None, None, _) => {
            return Err(ls.error(
                &key("characteristic_length"),
                "is missing: the length scale ℓ of the couple stresses (in 3D or couple_moduli)",
            ));
        }
    }
    if let Some(rho) = m.density {
        positive(ls, &key("density"), rho)?;
    }
    if let Some(j) = m.micro_inertia {
        positive(ls, &key("micro_inertia"), j)?;
    }
    Ok(())
}
