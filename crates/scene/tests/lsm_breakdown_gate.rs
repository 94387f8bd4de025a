//! Dry breakdown of the flooded borehole on every packing of five, against the
//! thick-walled cylinder estimate `p_b = σ_t (b² − a²)/(b² + a²)` with the recipe's
//! σ_t = 3.44 MPa: the mean Brazilian strength of disks of radius 20 r_max (caps 0.2 R
//! thick) over seeds 1–5, 3.44 ± 0.42 MPa (`crates/lsm/tests/calibration_scatter.rs`),
//! the size at which it has settled (4.58 MPa at 10 r_max, 3.70 at 15).
//!
//! The gate (breakdown, the wall crack reaching 2a, within ±20 % of p_b on each of seeds
//! 1–5, on `scenes/lsm/borehole_flooded.toml` with b = 22 m and with b = 12 m, a = 3 m,
//! and the crack traced through the pores it opens, the faces of the bond network
//! (`[loading] crack_across_pores = true`, added here)) is missed: measured with
//! `LSM_GEOMETRY_PORES=1 LSM_GEOMETRY_CALIBRATE=0 scripts/lsm_breakdown_geometry.sh 3.44e6
//! 22 1 2 3 4 5` 1.635, 1.100, 1.178, 1.433, 1.440 (1.36 ± 0.22, 2 of 5), with b = 12 m
//! 0.896, 0.865, 0.922, 0.909, 1.283 (0.98 ± 0.17, 4 of 5). Seeds 1 and 4 at b = 22 m
//! break no bond at all below 1.30 and 1.14 p_b, so no crack rule brings them within
//! +20 %; from b = 22 m to 12 m the lattice's breakdown pressure falls to 0.67 ± 0.13 of
//! itself, the closed form to 0.92. The hole is not large against the lattice's
//! characteristic length: K_Ic ≈ 15.8 MPa√m from a pressurised notch (crack traced
//! through faces), ℓ = (K_Ic/σ_t)²/π = 6.7 m, a/ℓ = 0.45 (docs/models/lsm.md, "Toughness and the size of
//! the hole"). As bundled (cracks joined through shared disks): 1.42 ± 0.14 (0 of 5) and
//! 1.10 ± 0.17 (3 of 5). Ignored with these numbers.

use std::path::Path;

use porofrac_scene::{LawRegistry, Scene, Silent};

/// The recipe's tensile strength (Pa).
const SIGMA_T: f64 = 3.44e6;

/// Breakdown / p_b of the bundled flooded rock with outer radius `b` and packing `seed`.
fn ratio(b: f64, seed: u64) -> f64 {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lsm/borehole_flooded.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let scene = text
        .replace("radius = 22.0 }", &format!("radius = {b:.1} }}"))
        .replace("seed = 1\n", &format!("seed = {seed}\n"))
        .replace(
            "flood_cracks = true\n",
            "flood_cracks = true\ncrack_across_pores = true\n",
        );
    assert!(scene.contains("crack_across_pores = true"));
    let out = std::env::temp_dir().join(format!(
        "porofrac-lsmgate-{}-{b}-{seed}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    Scene::parse(&scene, Path::new("gate.toml"), LawRegistry::default())
        .unwrap()
        .run(&out, &mut Silent)
        .unwrap();
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let a = s["breakdown_extent"].as_f64().unwrap() / 2.0;
    let pb = SIGMA_T * (b * b - a * a) / (b * b + a * a);
    let bd = s["breakdown_pressure"].as_f64().unwrap_or(f64::NAN);
    bd / pb
}

#[test]
#[ignore = "misses the gate: breakdown 1.36 ± 0.22 p_b (b = 22 m, 2 of 5; seeds 1 and 4 break no bond below 1.30 and 1.14 p_b) and 0.98 ± 0.17 (b = 12 m, 4 of 5) with the recipe's σ_t, a/ℓ = 0.45; ten runs of 10-250 s"]
fn flooded_breakdown_within_20_percent_on_every_packing_and_geometry() {
    let mut misses = Vec::new();
    for b in [22.0, 12.0] {
        for seed in 1..=5 {
            let r = ratio(b, seed);
            eprintln!("b = {b} m, seed {seed}: breakdown {r:.3} p_b");
            if r.is_nan() || (r - 1.0).abs() >= 0.2 {
                misses.push((b, seed, r));
            }
        }
    }
    assert!(
        misses.is_empty(),
        "outside ±20 % (b, seed, ratio): {misses:?}"
    );
}
