//! The fluid in cracks narrower than the lattice of a lattice solid scene
//! (`[injection] crack_flow = true`): the network of the broken bonds
//! ([`porofrac_particle_fluid::bond_cracks`]) — a cubic-law channel across each broken
//! bond's gap between the pores on its sides, joined to the lattice nodes at its mouths,
//! its pressure pushing the two disks apart.
//!
//! Keys: `crack_flow`, `crack_min_aperture` (m), `crack_viscosity` (m²/s) of
//! `[injection]`. Output: `summary.json` `crack_flow` (`channels`, `pores`, `mouths`, the
//! mass books in kg per metre of depth, the largest channel pressure and aperture, the
//! pore solve's sweeps and the seconds it took).

use porofrac_lsm::LatticeSolid;
use porofrac_particle_fluid::{BondCrackOptions, ParticleFluid};

use super::fluid::InjectionSection;
use crate::common::loaded::{LoadedScene, SceneError, k};
use crate::common::model::RunError;

/// Check the crack flow keys of `[injection]`.
pub fn check(ls: &LoadedScene, inj: &InjectionSection) -> Result<(), SceneError> {
    let key = |f: &str| k(&["injection", f]);
    let on = inj.crack_flow == Some(true);
    for (name, v) in [
        ("crack_min_aperture", inj.crack_min_aperture),
        ("crack_viscosity", inj.crack_viscosity),
    ] {
        let Some(v) = v else { continue };
        if !on {
            return Err(ls.error(&key(name), "applies with crack_flow = true only"));
        }
        if !(v.is_finite() && v > 0.0) {
            return Err(ls.error(&key(name), format!("= {v} must be a positive number")));
        }
    }
    if let (Some(w), Some(s)) = (inj.crack_min_aperture, ls.scene.lbm.as_ref())
        && w >= s.spacing
    {
        return Err(ls.error(
            &key("crack_min_aperture"),
            format!(
                "= {w} m is not below lbm.spacing = {} m: the crack channels carry the \
                 cracks narrower than the lattice",
                s.spacing
            ),
        ));
    }
    Ok(())
}

/// Attach the crack network to the coupling when `crack_flow = true`.
pub fn attach(
    ls: &LoadedScene,
    inj: &InjectionSection,
    pf: ParticleFluid,
    solid: &LatticeSolid,
) -> Result<ParticleFluid, RunError> {
    if inj.crack_flow != Some(true) {
        return Ok(pf);
    }
    let options = BondCrackOptions {
        min_aperture: inj
            .crack_min_aperture
            .unwrap_or(BondCrackOptions::default().min_aperture),
        viscosity: inj.crack_viscosity,
    };
    pf.with_crack_flow(solid, options).map_err(|e| {
        ls.error(&k(&["injection", "crack_flow"]), format!(": {e}"))
            .into()
    })
}

/// `summary.json` `crack_flow` (with the crack network).
pub fn summary(pf: &ParticleFluid, m: &mut serde_json::Map<String, serde_json::Value>) {
    let Some(c) = pf.crack_flow() else { return };
    let u = pf.units();
    let mass = u.density * u.dx * u.dx;
    let n = c.channels();
    let p_max = (0..n).map(|i| c.pressure(i)).fold(0.0, f64::max);
    let w_max = (0..n).map(|i| c.aperture(i, u)).fold(0.0, f64::max);
    let st = c.stats();
    m.insert(
        "crack_flow".into(),
        serde_json::json!({
            "channels": n,
            "pores": c.pores(),
            "mouths": c.mouths(),
            "pore_mass": c.pore_mass() * mass,
            "created_mass": c.created_mass() * mass,
            "to_lattice_mass": c.exchanged_mass() * mass,
            "mass_defect": (c.pore_mass() - c.created_mass() + c.exchanged_mass()) * mass,
            "max_pressure": p_max,
            "max_aperture": w_max,
            "max_sweeps": st.max_sweeps,
            "unconverged_steps": st.unconverged_steps,
            "pocket_mass": c.pockets().added_mass() * mass,
            "pocket_steps": c.pockets().topped(),
            "seconds": pf.stats().crack_seconds,
        }),
    );
}
