//! Checks of a continuum scene (docs/SCENE.md): the grid, materials, regions, boundary
//! conditions, loads, sources, wells, schedule, physics, solver and outputs, and the
//! sizes a scene asks for. Every problem is a [`SceneError`] naming its key and line.

use crate::common::bounds::{modulus, point_inside};
use crate::common::laws::LawRegistry;
use crate::common::loaded::{
    LoadedScene, SceneError, expr_ok, k, ki, len_is, line_points_and_name, positive, step_count_f64,
};
use crate::common::sections::{
    Bc, CellCount, Component, CrackFlow, DiagonalsChoice, GridKind, KeyPart, LinearChoice,
    Permeability, Select,
};
use porofrac_grid::Point;
use porofrac_grid::generate::RoundWellSpec;

/// Check a scene with `[scene] model = "continuum"` (the default), after the checks every
/// model shares.
pub fn check(ls: &LoadedScene, laws: &LawRegistry) -> Result<(), SceneError> {
    let s = &ls.scene;
    let d = s.scene.dim as usize;
    crate::common::lattice::check::refuse_obstacle_probes(ls, "continuum")?;
    refuse_cosserat_keys(ls)?;
    if !ls.has_section("grid") {
        return Err(ls.error(
            &k(&["grid"]),
            "is missing: a continuum scene needs a [grid]",
        ));
    }
    check_grid(ls, d)?;
    // Materials.
    for (name, m) in &s.material {
        let key = |f: &str| k(&["material", name, f]);
        modulus(ls, &key("youngs_modulus"), m.youngs_modulus, false)?;
        let nu = m.poisson_ratio;
        if !nu.is_finite() || nu >= 0.5 {
            return Err(ls.error(&key("poisson_ratio"), format!("= {nu} must be < 0.5")));
        }
        if nu <= -1.0 {
            return Err(ls.error(&key("poisson_ratio"), format!("= {nu} must be > -1")));
        }
        if let Some(v) = m.solid_bulk_modulus {
            modulus(ls, &key("solid_bulk_modulus"), v, false)?;
        }
        for (f, v) in [
            ("density", m.density),
            ("tensile_strength", m.tensile_strength),
            ("fracture_toughness", m.fracture_toughness),
        ] {
            if let Some(v) = v {
                positive(ls, &key(f), v)?;
            }
        }
        if m.fracture_toughness.is_some() && m.tensile_strength.is_none() {
            return Err(ls.error(
                &key("fracture_toughness"),
                "needs tensile_strength (the toughness only holds crack tips that the strength \
                 would fail)",
            ));
        }
        if let Some(c) = m.cohesion {
            if !(c.is_finite() && c >= 0.0) {
                return Err(ls.error(&key("cohesion"), format!("= {c} must be ≥ 0")));
            }
            if m.friction_angle.is_none() {
                return Err(ls.error(&key("cohesion"), "needs friction_angle (Mohr–Coulomb)"));
            }
        }
        if let Some(a) = m.friction_angle
            && !(0.0..90.0).contains(&a)
        {
            return Err(ls.error(
                &key("friction_angle"),
                format!("= {a} must be in [0, 90) degrees"),
            ));
        }
        if let Some(a) = m.biot_alpha
            && !(0.0..=1.0).contains(&a)
        {
            return Err(ls.error(&key("biot_alpha"), format!("= {a} must be in [0, 1]")));
        }
        if let Some(phi) = m.porosity
            && !(phi > 0.0 && phi <= 1.0)
        {
            return Err(ls.error(&key("porosity"), format!("= {phi} must be in (0, 1]")));
        }
        match &m.permeability {
            Some(Permeability::Scalar(v)) => positive(ls, &key("permeability"), *v)?,
            Some(Permeability::Diagonal(v)) => {
                len_is(ls, &key("permeability"), v.len(), d)?;
                for &x in v {
                    positive(ls, &key("permeability"), x)?;
                }
            }
            None => {}
        }
    }
    // Regions.
    if s.region.is_empty() {
        return Err(ls.error(&k(&["region"]), "is missing: at least one [[region]] must select cells and give them a law and a material"));
    }
    for (i, r) in s.region.iter().enumerate() {
        if let Some(m) = &r.material
            && !s.material.contains_key(m)
        {
            let known: Vec<_> = s.material.keys().cloned().collect();
            return Err(ls.error(
                &ki("region", i, &["material"]),
                format!(
                    "= \"{m}\" is not a defined material (known: {})",
                    known.join(", ")
                ),
            ));
        }
        if let Some(l) = &r.law
            && !laws.contains(l)
        {
            return Err(ls.error(
                &ki("region", i, &["law"]),
                format!(
                    "= \"{l}\" is not a known law (known: {})",
                    laws.names().join(", ")
                ),
            ));
        }
        match &r.select {
            Select::All(false) => {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    "= { all = false } selects nothing",
                ));
            }
            Select::Box(b) => {
                len_is(ls, &ki("region", i, &["select"]), b[0].len(), d)?;
                len_is(ls, &ki("region", i, &["select"]), b[1].len(), d)?;
            }
            Select::Around(pb)
                if pb.path.is_empty()
                    || pb.path.iter().any(|p| p.len() != d)
                    || pb.radius.is_nan()
                    || pb.radius <= 0.0 =>
            {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    format!(
                        "= {{ around = {{ path, radius }} }} needs points of {d} coordinates and \
                         a radius > 0"
                    ),
                ));
            }
            Select::Ijk(r) if d != 3 || r.iter().any(|a| a[0] < 1 || a[0] > a[1]) => {
                return Err(ls.error(
                    &ki("region", i, &["select"]),
                    "= { ijk = [[i0, i1], [j0, j1], [k0, k1]] } needs 1 ≤ lower ≤ upper on \
                     each axis (1-based, inclusive) in a 3D scene",
                ));
            }
            Select::Circle(b) | Select::Sphere(b) => {
                let want = if matches!(r.select, Select::Circle(_)) {
                    2
                } else {
                    3
                };
                if want != d {
                    return Err(ls.error(
                        &ki("region", i, &["select"]),
                        format!("uses a {}D shape in a {d}D scene", want),
                    ));
                }
                len_is(ls, &ki("region", i, &["select"]), b.center.len(), d)?;
                positive(ls, &ki("region", i, &["select"]), b.radius)?;
            }
            _ => {}
        }
    }
    if s.region
        .first()
        .is_some_and(|r| r.material.is_none() || r.law.is_none())
    {
        return Err(ls.error(
            &ki("region", 0, &[]),
            "the first region must give both a law and a material",
        ));
    }
    // Boundary conditions.
    for (i, bc) in s.bc.iter().enumerate() {
        check_bc(ls, i, bc, d)?;
    }
    if let Some(l) = &s.loads {
        if let Some(g) = &l.gravity {
            len_is(ls, &k(&["loads", "gravity"]), g.len(), d)?;
        }
        if let Some(b) = &l.body_force {
            len_is(ls, &k(&["loads", "body_force"]), b.len(), d)?;
            for v in b {
                expr_ok(ls, &k(&["loads", "body_force"]), v, false)?;
            }
        }
    }
    for (i, src) in s.source.iter().enumerate() {
        if !s.region.iter().any(|r| r.name == src.region) {
            return Err(ls.error(
                &ki("source", i, &["region"]),
                format!("= \"{}\" is not a defined region", src.region),
            ));
        }
        match (src.rate, src.pore_volumes_per_hour) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(ls.error(
                    &ki("source", i, &[]),
                    "needs exactly one of rate and pore_volumes_per_hour",
                ));
            }
            (Some(r), None) if !r.is_finite() => {
                return Err(ls.error(&ki("source", i, &["rate"]), "must be finite"));
            }
            _ => {}
        }
    }
    if let Some(sch) = &s.schedule {
        positive(ls, &k(&["schedule", "end_time"]), sch.end_time)?;
        match (sch.dt, sch.steps) {
            (Some(dt), None) => positive(ls, &k(&["schedule", "dt"]), dt)?,
            (None, Some(n)) if n >= 1 => {}
            (None, Some(n)) => {
                return Err(ls.error(&k(&["schedule", "steps"]), format!("= {n} must be ≥ 1")));
            }
            _ => return Err(ls.error(&k(&["schedule"]), "needs exactly one of dt and steps")),
        }
    }
    if let Some(init) = &s.initial
        && let Some(p) = &init.pressure
    {
        expr_ok(ls, &k(&["initial", "pressure"]), p, false)?;
    }
    if let Some(f) = &s.fluid {
        crate::common::bounds::fluid(ls, f)?;
    }
    if let Some(kf) = s.physics.fracture_permeability {
        positive(ls, &k(&["physics", "fracture_permeability"]), kf)?;
    }
    if let Some(r) = s.physics.tip_sample_distance {
        positive(ls, &k(&["physics", "tip_sample_distance"]), r)?;
        if s.physics.tip_rule != Some(crate::common::sections::TipRuleChoice::Opening) {
            return Err(ls.error(
                &k(&["physics", "tip_sample_distance"]),
                "applies with tip_rule = \"opening\" only",
            ));
        }
        if s.physics.crack_tracking.is_none() {
            return Err(ls.error(
                &k(&["physics", "tip_sample_distance"]),
                "needs crack_tracking (the rule reads every cell around a tip as ahead of \
                 it; tracking picks the one the crack enters)",
            ));
        }
    }
    if let Some(p) = s.physics.cavitation_pressure {
        if !p.is_finite() {
            return Err(ls.error(
                &k(&["physics", "cavitation_pressure"]),
                format!("= {p} must be a finite pressure (Pa)"),
            ));
        }
        if s.physics.flow != Some(true) {
            return Err(ls.error(&k(&["physics", "cavitation_pressure"]), "needs flow = true"));
        }
    }
    if s.physics.fluid_lag.is_some()
        && (s.physics.fracture != Some(true) || s.physics.flow != Some(true))
    {
        return Err(ls.error(
            &k(&["physics", "fluid_lag"]),
            "needs fracture = true and flow = true",
        ));
    }
    if let Some(cf) = s.physics.crack_flow {
        if s.physics.fracture != Some(true) || s.physics.flow != Some(true) {
            return Err(ls.error(
                &k(&["physics", "crack_flow"]),
                "needs fracture = true and flow = true",
            ));
        }
        if cf == CrackFlow::CubicLaw && s.physics.fracture_permeability.is_some() {
            return Err(ls.error(
                &k(&["physics", "fracture_permeability"]),
                "does not apply with crack_flow = \"cubic-law\" (the permeability follows \
                 the opening; fracture_transmissivity sets the floor of a closed crack)",
            ));
        }
    }
    if let Some(
        rule @ (crate::common::sections::TipRuleChoice::Opening
        | crate::common::sections::TipRuleChoice::Asymptote),
    ) = s.physics.tip_rule
    {
        let name = if rule == crate::common::sections::TipRuleChoice::Opening {
            "opening"
        } else {
            "asymptote"
        };
        if s.physics.fracture != Some(true) || s.physics.flow != Some(true) {
            return Err(ls.error(
                &k(&["physics", "tip_rule"]),
                "needs fracture = true and flow = true",
            ));
        }
        if s.physics.failure_stress == Some(crate::common::sections::FailureStress::Recovered) {
            return Err(ls.error(
                &k(&["physics", "tip_rule"]),
                format!(
                    "= \"{name}\" reads the cell stress away from tips: it cannot be combined \
                     with failure_stress = \"recovered\""
                ),
            ));
        }
        if !s.material.values().any(|m| m.fracture_toughness.is_some()) {
            return Err(ls.error(
                &k(&["physics", "tip_rule"]),
                format!("= \"{name}\" needs a material with a fracture_toughness"),
            ));
        }
    }
    if let Some(t) = s.physics.fracture_transmissivity {
        positive(ls, &k(&["physics", "fracture_transmissivity"]), t)?;
        if s.physics.fracture_permeability.is_some() {
            return Err(ls.error(
                &k(&["physics", "fracture_transmissivity"]),
                "and fracture_permeability both set: give one of them",
            ));
        }
    }
    if let Some(a) = s.physics.crack_tracking
        && !(a.is_finite() && a > 0.0 && a <= 90.0)
    {
        return Err(ls.error(
            &k(&["physics", "crack_tracking"]),
            format!("= {a} must be an angle in (0, 90] degrees"),
        ));
    }
    if let Some(r) = s.physics.crack_exclusion {
        if !(r.is_finite() && r >= 0.0) {
            return Err(ls.error(
                &k(&["physics", "crack_exclusion"]),
                format!("= {r} must be a distance ≥ 0 (m)"),
            ));
        }
        if s.physics.crack_tracking.is_none() {
            return Err(ls.error(&k(&["physics", "crack_exclusion"]), "needs crack_tracking"));
        }
    }
    if let Some(r) = s.physics.open_edge_stiffness
        && !(r.is_finite() && (0.0..1.0).contains(&r))
    {
        return Err(ls.error(
            &k(&["physics", "open_edge_stiffness"]),
            format!("= {r} must be in [0, 1)"),
        ));
    }
    if let Some(t) = s.solver.tolerance {
        positive(ls, &k(&["solver", "tolerance"]), t)?;
    }
    if let Some(l @ (LinearChoice::Lu | LinearChoice::GmresAmg)) = s.solver.linear {
        return Err(ls.error(
            &k(&["solver", "linear"]),
            format!(
                "= \"{}\" is a solver of model \"cosserat\"; this model takes \"auto\", \
                 \"cholesky\" or \"cg-amg\"",
                if l == LinearChoice::Lu {
                    "lu"
                } else {
                    "gmres-amg"
                }
            ),
        ));
    }
    if let Some(t) = s.solver.threads
        && !(0..=1024).contains(&t)
    {
        return Err(ls.error(
            &k(&["solver", "threads"]),
            format!("= {t} must be in 0..=1024 (0: one thread per core)"),
        ));
    }
    if s.output.every < 1 {
        return Err(ls.error(
            &k(&["output", "every"]),
            format!("= {} must be ≥ 1", s.output.every),
        ));
    }
    if let Some(u) = &s.output.exact_displacement {
        let key = k(&["output", "exact_displacement"]);
        len_is(ls, &key, u.len(), d)?;
        for c in u {
            expr_ok(ls, &key, c, false)?;
        }
    }
    let flow = s.physics.flow == Some(true);
    let field_ok = |name: &str, key: Vec<KeyPart>| {
        crate::continuum::fields::Field::parse(name, d, flow)
            .map(|_| ())
            .map_err(|e| ls.error(&key, e))
    };
    let mut names = std::collections::BTreeSet::new();
    let extent = (s.grid.kind != GridKind::File)
        .then_some(s.grid.extent.as_ref())
        .flatten();
    for (i, p) in s.output.probe.iter().enumerate() {
        field_ok(&p.field, ki("output.probe", i, &["field"]))?;
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
        field_ok(&l.field, ki("output.line", i, &["field"]))?;
        len_is(ls, &ki("output.line", i, &["from"]), l.from.len(), d)?;
        len_is(ls, &ki("output.line", i, &["to"]), l.to.len(), d)?;
        point_inside(ls, &ki("output.line", i, &["from"]), &l.from, extent)?;
        point_inside(ls, &ki("output.line", i, &["to"]), &l.to, extent)?;
        line_points_and_name(ls, i, l)?;
    }
    check_wells(ls, d)?;
    check_sizes(ls, d)?;
    Ok(())
}

fn check_grid(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    if matches!(g.kind, GridKind::Triangles | GridKind::Voronoi) && d != 2 {
        return Err(ls.error(
            &key("kind"),
            format!("= \"{}\" is a 2D grid, the scene is {d}D", g.kind.as_str()),
        ));
    }
    if g.kind == GridKind::Tetrahedra && d != 3 {
        return Err(ls.error(
            &key("kind"),
            "= \"tetrahedra\" is a 3D grid, the scene is 2D",
        ));
    }
    if g.kind == GridKind::File {
        if g.path.is_none() {
            return Err(ls.error(&key("path"), "is required for kind = \"file\""));
        }
        return Ok(());
    }
    let Some(ext) = &g.extent else {
        return Err(ls.error(
            &key("extent"),
            format!("is required for kind = \"{}\"", g.kind.as_str()),
        ));
    };
    len_is(ls, &key("extent"), ext[0].len(), d)?;
    len_is(ls, &key("extent"), ext[1].len(), d)?;
    for a in 0..d {
        if !(ext[0][a].is_finite() && ext[1][a].is_finite() && ext[1][a] > ext[0][a]) {
            return Err(ls.error(&key("extent"), format!("needs min < max on axis {a}")));
        }
    }
    match (&g.cells, g.kind) {
        (None, _) => return Err(ls.error(&key("cells"), "is required")),
        (Some(CellCount::One(n)), GridKind::Voronoi) if *n >= 1 => {}
        (Some(CellCount::PerAxis(v)), kind) if kind != GridKind::Voronoi => {
            len_is(ls, &key("cells"), v.len(), d)?;
            if v.iter().any(|&n| n < 1) {
                return Err(ls.error(&key("cells"), format!("= {v:?} must all be ≥ 1")));
            }
        }
        (Some(c), kind) => {
            return Err(ls.error(&key("cells"), format!("= {c:?} does not fit kind = \"{}\" (one number for voronoi, one per axis otherwise)", kind.as_str())));
        }
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
    if g.diagonals.is_some() && g.kind != GridKind::Composite {
        return Err(ls.error(&key("diagonals"), "applies to composite grids only"));
    }
    if let Some(zone) = &g.mdem_zone {
        if g.kind != GridKind::File || d != 3 {
            return Err(ls.error(
                &key("mdem_zone"),
                "applies to 3D grids read from a file or a corner-point deck",
            ));
        }
        if let Select::Around(pb) = zone
            && (pb.path.is_empty()
                || pb.path.iter().any(|p| p.len() != 3)
                || pb.radius.is_nan()
                || pb.radius <= 0.0)
        {
            return Err(ls.error(
                &key("mdem_zone"),
                "= { around = { path = [[x, y, z], …], radius = r } } needs points of 3 \
                 coordinates and r > 0",
            ));
        }
        if let Some(r) = g.refine
            && !(0..=3).contains(&r)
        {
            return Err(ls.error(
                &key("refine"),
                format!("= {r}: the MDEM zone is refined 0 to 3 times (each ×8 tetrahedra)"),
            ));
        }
    } else if g.well_path.is_some() {
        return Err(ls.error(&key("well_path"), "needs mdem_zone"));
    }
    if let Some(p) = &g.well_path
        && p.iter().any(|p| p.len() != 3)
    {
        return Err(ls.error(&key("well_path"), "needs points of 3 coordinates"));
    }
    if g.well_size.is_some() && g.kind != GridKind::RoundWell {
        return Err(ls.error(&key("well_size"), "applies to round-well grids only"));
    }
    if matches!(g.kind, GridKind::Composite | GridKind::RoundWell) {
        for f in ["center", "zone_half_width", "refine", "well_radius"] {
            let present = match f {
                "center" => g.center.is_some(),
                "zone_half_width" => g.zone_half_width.is_some(),
                "refine" => g.refine.is_some(),
                _ => g.well_radius.is_some(),
            };
            if !present {
                return Err(ls.error(
                    &key(f),
                    format!("is required for kind = \"{}\"", g.kind.as_str()),
                ));
            }
        }
        if let Some(c) = &g.center
            && c.len() != 2
        {
            return Err(ls.error(
                &key("center"),
                format!(
                    "must have 2 components (in 3D: the x, y of the vertical well axis), got {}",
                    c.len()
                ),
            ));
        }
    }
    if g.kind == GridKind::RoundWell {
        check_round_well(ls, ext)?;
    }
    Ok(())
}

/// The round well's sizes, each error naming its key: positive sizes, a well inside the
/// zone with room for one interface spacing of triangles around it.
fn check_round_well(ls: &LoadedScene, ext: &[Vec<f64>; 2]) -> Result<(), SceneError> {
    let g = &ls.scene.grid;
    let key = |f: &str| k(&["grid", f]);
    let positive = |f: &str, v: Option<f64>| match v {
        Some(x) if !(x.is_finite() && x > 0.0) => {
            Err(ls.error(&key(f), format!("= {x} must be a size > 0")))
        }
        _ => Ok(()),
    };
    positive("zone_half_width", g.zone_half_width)?;
    positive("well_radius", g.well_radius)?;
    positive("well_size", g.well_size)?;
    let refine = g.refine.unwrap_or(0);
    if refine < 1 {
        return Err(ls.error(&key("refine"), format!("= {refine} must be ≥ 1")));
    }
    let Some(CellCount::PerAxis(n)) = &g.cells else {
        return Ok(());
    };
    let c = g.center.clone().unwrap_or_default();
    let p = |v: &[f64]| Point::<2>::new(v[0], v[1]);
    let mut spec = RoundWellSpec::new(
        p(&ext[0]),
        p(&ext[1]),
        [n[0].max(1) as usize, n[1].max(1) as usize],
        p(&c),
        g.zone_half_width.unwrap_or(0.0),
        refine as usize,
        g.well_radius.unwrap_or(0.0),
    );
    spec.well_size = g.well_size;
    if let Err(e) = spec.layout() {
        let m = e.to_string();
        let f = if m.contains("bigger than the refined zone") {
            "well_radius"
        } else if m.contains("well_size") {
            "well_size"
        } else {
            "zone_half_width"
        };
        return Err(ls.error(&key(f), m));
    }
    Ok(())
}

fn check_bc(ls: &LoadedScene, i: usize, bc: &Bc, d: usize) -> Result<(), SceneError> {
    let key = |f: &str| ki("bc", i, &[f]);
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
    }
    if let Some(p) = &bc.platen {
        len_is(ls, &ki("bc", i, &["platen", "force"]), p.force.len(), d)?;
        for c in &p.force {
            if let Component::Expr(s) = c
                && s != "free"
            {
                return Err(ls.error(
                    &ki("bc", i, &["platen", "force"]),
                    format!("= \"{s}\": platen forces are numbers or \"free\""),
                ));
            }
        }
        if bc.displacement.is_some() || bc.traction.is_some() {
            return Err(ls.error(
                &key("platen"),
                "cannot be combined with displacement or traction on the same boundary",
            ));
        }
    }
    if let Some(p) = &bc.pressure {
        expr_ok(ls, &key("pressure"), p, false)?;
    }
    if let Some(q) = &bc.flux {
        expr_ok(ls, &key("flux"), q, false)?;
        if bc.pressure.is_some() {
            return Err(ls.error(
                &key("flux"),
                "cannot be combined with pressure on the same boundary",
            ));
        }
    }
    let sides = ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"];
    if let Some(pos) = sides.iter().position(|&s| s == bc.boundary)
        && pos >= 2 * d
    {
        return Err(ls.error(
            &key("boundary"),
            format!("= \"{}\" does not exist in {d}D", bc.boundary),
        ));
    }
    Ok(())
}

fn check_wells(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    let mut names = std::collections::BTreeSet::new();
    for (i, w) in ls.scene.well.iter().enumerate() {
        let key = |f: &str| ki("well", i, &[f]);
        if w.name.is_empty() || !names.insert(w.name.as_str()) {
            return Err(ls.error(&key("name"), "must be a non-empty name used once"));
        }
        match (&w.at, w.cell) {
            (Some(at), None) => len_is(ls, &key("at"), at.len(), d)?,
            (None, Some(_)) => {}
            _ => {
                return Err(ls.error(
                    &ki("well", i, &[]),
                    "needs exactly one of at (a point) and cell (a cell index)",
                ));
            }
        }
        positive(ls, &key("radius"), w.radius)?;
        if let Some(sk) = w.skin
            && !sk.is_finite()
        {
            return Err(ls.error(&key("skin"), format!("= {sk} must be finite")));
        }
        match (w.rate, w.bottom_hole_pressure) {
            (Some(q), None) if q.is_finite() => {}
            (None, Some(p)) if p.is_finite() => {}
            (Some(_), None) => return Err(ls.error(&key("rate"), "must be finite")),
            (None, Some(_)) => {
                return Err(ls.error(&key("bottom_hole_pressure"), "must be finite"));
            }
            _ => {
                return Err(ls.error(
                    &ki("well", i, &[]),
                    "needs exactly one of rate and bottom_hole_pressure",
                ));
            }
        }
    }
    Ok(())
}

/// Bound steps, output series and generated grids before anything is allocated
/// ([`crate::common::limits`]).
fn check_sizes(ls: &LoadedScene, d: usize) -> Result<(), SceneError> {
    use crate::common::limits::{
        MAX_CELLS, MAX_STEPS, factor_note, fits_in_memory, run_bytes_of, run_text,
    };
    let s = &ls.scene;
    if let Some(sch) = &s.schedule {
        let n = step_count_f64(sch);
        let key = if sch.dt.is_some() {
            k(&["schedule", "dt"])
        } else {
            k(&["schedule", "steps"])
        };
        if n > MAX_STEPS as f64 {
            return Err(ls.error(
                &key,
                format!(
                    "gives {n:.3e} steps up to end_time = {}, more than the {MAX_STEPS} a run \
                     may take",
                    sch.end_time
                ),
            ));
        }
        // Output series kept in memory: the written times, probe columns and line rows
        // (8 bytes per number, about 24 in the CSV text).
        let written = n / s.output.every.max(1) as f64 + 2.0;
        let numbers: f64 = 1.0
            + s.output.probe.len() as f64
            + s.output
                .line
                .iter()
                .map(|l| l.points as f64 * (d as f64 + 2.0))
                .sum::<f64>();
        fits_in_memory(
            written * numbers * 32.0,
            &format!("{n:.3e} steps with these probes and lines"),
        )
        .map_err(|e| ls.error(&key, e))?;
    }
    let g = &s.grid;
    let per_axis: Vec<f64> = match &g.cells {
        Some(CellCount::PerAxis(v)) => v.iter().map(|&n| n as f64).collect(),
        Some(CellCount::One(n)) => vec![*n as f64],
        None => return Ok(()),
    };
    let boxes: f64 = per_axis.iter().product();
    let corners: f64 = per_axis.iter().map(|n| n + 1.0).product();
    let (cells, nodes) = match g.kind {
        GridKind::Cartesian => (boxes, corners),
        GridKind::Triangles => (2.0 * boxes, corners),
        GridKind::Tetrahedra => (6.0 * boxes, corners),
        GridKind::Voronoi => (boxes, 2.0 * boxes),
        GridKind::Composite | GridKind::RoundWell => {
            // The far field plus the refined zone (about (2 w / h · refine)² squares of
            // two triangles), extruded over cells[2] layers in 3D.
            let (nx, ny) = (per_axis[0], per_axis.get(1).copied().unwrap_or(1.0));
            let refine = g.refine.unwrap_or(1).max(1) as f64;
            let ext = g.extent.as_ref();
            let hx = ext.map_or(1.0, |e| (e[1][0] - e[0][0]) / nx);
            let zone = (2.0 * g.zone_half_width.unwrap_or(0.0) / hx).ceil() + 1.0;
            let fine = (zone * refine) * (zone * refine);
            let (layers, per_layer) = if d == 3 {
                (per_axis.get(2).copied().unwrap_or(1.0), 3.0)
            } else {
                (1.0, 1.0)
            };
            (
                (nx * ny + 2.0 * fine) * layers * per_layer,
                (nx * ny + fine) * (layers + 1.0),
            )
        }
        GridKind::File => return Ok(()),
    };
    let key = k(&["grid", "cells"]);
    if cells > MAX_CELLS as f64 {
        return Err(ls.error(
            &key,
            format!("asks for {cells:.3e} cells, more than the {MAX_CELLS} a grid may have"),
        ));
    }
    let flow = s.physics.flow == Some(true);
    let unknowns = d as f64 * nodes + if flow { cells } else { 0.0 };
    let (bytes, factor) = run_bytes_of(d, cells, unknowns, factors(ls, d, unknowns));
    fits_in_memory(bytes, &format!("asks for {}", run_text(cells, unknowns)))
        .map_err(|e| ls.error(&key, format!("{e}{}", factor_note(factor))))
}

/// Whether a `d`-dimensional run of the scene with about `equations` unknowns factors a
/// matrix (a direct solve): the flow coupled to the mechanics, or the mechanics solved
/// by the sparse Cholesky (`linear = "cholesky"`, or `"auto"` on a small 3D system).
pub(crate) fn factors(ls: &LoadedScene, d: usize, equations: f64) -> bool {
    use crate::common::sections::{CouplingChoice, MechanicsSolver};
    let s = &ls.scene;
    let flow = s.physics.flow == Some(true);
    if flow && s.physics.coupling.unwrap_or_default() != CouplingChoice::None {
        return true;
    }
    if s.solver.mechanics.unwrap_or_default() == MechanicsSolver::Explicit {
        return false;
    }
    match s.solver.linear.unwrap_or_default() {
        LinearChoice::Cholesky => true,
        LinearChoice::Auto => {
            let min = if d >= 3 {
                porofrac_sim::linear::AUTO_MIN_EQUATIONS_3D
            } else {
                porofrac_sim::linear::AUTO_MIN_EQUATIONS_2D
            };
            equations < min as f64
        }
        _ => false,
    }
}

/// In a continuum scene: the Cosserat-only keys are errors naming key and model, and a
/// missing `youngs_modulus` is reported as missing.
fn refuse_cosserat_keys(ls: &LoadedScene) -> Result<(), SceneError> {
    let s = &ls.scene;
    let cos = |path: Vec<KeyPart>| {
        ls.error(
            &path,
            format!(
                "is a key of model \"cosserat\", the scene's model is \"{}\"",
                ls.model()
            ),
        )
    };
    for (name, m) in &s.material {
        for (key, set) in [
            ("shear_modulus", m.shear_modulus.is_some()),
            ("cosserat_shear_modulus", m.cosserat_shear_modulus.is_some()),
            ("characteristic_length", m.characteristic_length.is_some()),
            ("couple_moduli", m.couple_moduli.is_some()),
            ("micro_inertia", m.micro_inertia.is_some()),
        ] {
            if set {
                return Err(cos(k(&["material", name, key])));
            }
        }
        if m.youngs_modulus.is_nan() {
            return Err(ls.error(&k(&["material", name, "youngs_modulus"]), "is missing"));
        }
    }
    for (i, bc) in s.bc.iter().enumerate() {
        if bc.rotation.is_some() {
            return Err(cos(ki("bc", i, &["rotation"])));
        }
        if bc.couple_traction.is_some() {
            return Err(cos(ki("bc", i, &["couple_traction"])));
        }
    }
    if s.loads.as_ref().is_some_and(|l| l.body_couple.is_some()) {
        return Err(cos(k(&["loads", "body_couple"])));
    }
    if s.solver.penalty.is_some() {
        return Err(cos(k(&["solver", "penalty"])));
    }
    if s.solver.stencil.is_some() {
        return Err(cos(k(&["solver", "stencil"])));
    }
    if s.solver.time_integration.is_some() {
        return Err(cos(k(&["solver", "time_integration"])));
    }
    if s.grid.diagonals == Some(DiagonalsChoice::Crossed) {
        return Err(cos(k(&["grid", "diagonals"])));
    }
    Ok(())
}
