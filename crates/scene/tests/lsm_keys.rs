//! Keys of model "lsm", run through the library against closed forms and invariants:
//! whole sub-steps for an output interval that is a multiple of `[lsm] dt`, initial
//! velocities and spins (`[[particles.velocity]]`), a listed packing with a hole,
//! platens that stop or hold a force, `wall = "top" | "bottom" | "hole"` and cell `torque` probes, and
//! the bending moments of the contacts VTK files.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-lsmkeys-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/lsm/inline.toml")
}

/// A finished run: probe rows (time first), `summary.json` and the output folder (kept
/// until dropped).
struct Run {
    rows: Vec<Vec<f64>>,
    summary: serde_json::Value,
    out: PathBuf,
}

impl Drop for Run {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.out);
    }
}

fn run(name: &str, text: &str) -> Run {
    let scene = Scene::parse(text, &path(), LawRegistry::default()).unwrap();
    let out = out_dir(name);
    let summary = scene.run(&out, &mut Silent).unwrap();
    assert_eq!(summary.status, "ok");
    let rows = std::fs::read_to_string(out.join("probes.csv"))
        .map(|t| {
            t.lines()
                .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
                .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
                .collect()
        })
        .unwrap_or_default();
    let summary =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    Run { rows, summary, out }
}

fn error_of(text: &str) -> String {
    match Scene::parse(text, &path(), LawRegistry::default()) {
        Err(e) => e.to_string(),
        Ok(scene) => scene
            .run(&out_dir("bad"), &mut Silent)
            .unwrap_err()
            .to_string(),
    }
}

const HEAD: &str = "[scene]\nname = \"t\"\ndim = 2\nmodel = \"lsm\"\n";
const RHO: f64 = 2500.0;

fn probe(name: &str, field: &str, particle: usize) -> String {
    format!("[[output.probe]]\nname = \"{name}\"\nfield = \"{field}\"\nparticle = {particle}\n")
}

fn wall_probe(name: &str, field: &str, wall: &str) -> String {
    format!("[[output.probe]]\nname = \"{name}\"\nfield = \"{field}\"\nwall = \"{wall}\"\n")
}

/// A listed packing: `[particles]` with these centres, all of radius `r`.
fn list(centres: &[[f64; 2]], r: f64) -> String {
    let c: Vec<String> = centres
        .iter()
        .map(|c| format!("[{:?}, {:?}]", c[0], c[1]))
        .collect();
    let radii = vec![format!("{r:?}"); centres.len()];
    format!(
        "[particles]\nkind = \"list\"\ncentres = [{}]\nradii = [{}]\ndensity = {RHO:?}\n",
        c.join(", "),
        radii.join(", ")
    )
}

/// An output interval of exactly 10 `[lsm] dt` (1e-4 s over dt = 1e-5 s; the old
/// rounding up of the ratio, whose round-off alternates above and below 10, took 1055
/// sub-steps over 100 intervals): 1000 sub-steps in all, and as no interval can take
/// fewer than 10 (its ratio to dt is 10 up to round-off), every interval takes exactly
/// 10; `summary.json` reports the step used, dt itself.
#[test]
fn an_interval_of_ten_dt_takes_ten_sub_steps() {
    let dt = 1e-5;
    let text = format!(
        "{HEAD}{}[bonds]\nkn = 1.0e9\nks = 0.5e9\n[lsm]\ndt = {dt:?}\n\
         [schedule]\nend_time = 1.0e-2\ndt = 1.0e-4\n[output]\nvtk = false\n{}",
        list(&[[0.0, 0.0], [1.0, 0.0], [0.5, 0.866]], 0.5),
        probe("x", "x", 0),
    );
    // The test case is one the old count got wrong.
    let times: Vec<f64> = (0..=100)
        .map(|i| if i == 100 { 1.0e-2 } else { i as f64 * 1.0e-4 })
        .collect();
    let old: usize = times
        .windows(2)
        .map(|w| ((w[1] - w[0]) / dt).ceil() as usize)
        .sum();
    assert!(old > 1000, "old count {old}");
    let r = run("whole", &text);
    assert_eq!(r.summary["lsm_steps"], 1000);
    let used = r.summary["dt_used"].as_f64().unwrap();
    // dt up to the round-off of the output times (1e-2 s carries 1.7e-18 s).
    assert!((used - dt).abs() <= 1e-12 * dt, "dt_used {used}");
    assert_eq!(r.summary["dt"].as_f64().unwrap(), dt);
    assert_eq!(porofrac_scene::lsm::sub_steps(1e-4 * (1.0 + 4e-16), dt), 10);
    assert_eq!(porofrac_scene::lsm::sub_steps(1e-4 * (1.0 - 4e-16), dt), 10);
    assert_eq!(porofrac_scene::lsm::sub_steps(1e-4 * (1.0 + 1e-6), dt), 11);
    assert_eq!(porofrac_scene::lsm::sub_steps(0.25e-5, dt), 1);
}

/// Mass, inertia of a disk of radius r per metre.
fn mass(r: f64) -> (f64, f64) {
    let m = RHO * std::f64::consts::PI * r * r;
    (m, 0.5 * m * r * r)
}

/// A free disk keeps v and ω and moves by v t; a bonded pair turning as a rigid body
/// about its centre while it drifts keeps its momentum and angular momentum (to 1e-12
/// of their scale: velocity Verlet conserves both to round-off under forces that balance
/// their moments); a bonded pair of which one disk is spun up (the bond shears, bends
/// and stretches, the pair tumbles) keeps its angular momentum too.
#[test]
fn initial_velocities_and_spins_keep_momentum_and_angular_momentum() {
    let r = 0.5;
    let (m, inertia) = mass(r);
    // Disk 0 alone far away, disks 1 and 2 a bonded pair about [0, 0].
    let centres = [[20.0, 20.0], [-0.5, 0.0], [0.5, 0.0]];
    let columns = |k: usize| {
        ["x", "y", "vx", "vy", "omega"]
            .iter()
            .map(|f| probe(&format!("{f}{k}"), f, k))
            .collect::<String>()
    };
    let body = |velocity: &str| {
        format!(
            "{HEAD}{}[[particles.velocity]]\nparticles = [0]\nv = [1.5, -2.5]\nomega = 7.0\n\
             {velocity}[bonds]\nkn = 1.0e9\nks = 0.4e9\nkb = 1.0e6\n[lsm]\ndt = 2.0e-5\n\
             [schedule]\nend_time = 0.05\ndt = 1.0e-3\n[output]\nvtk = false\n{}{}{}",
            list(&centres, r),
            columns(0),
            columns(1),
            columns(2),
        )
    };
    // Rigid rotation at w about [0, 0] plus a drift [0.3, -0.2].
    let w = 40.0;
    let rigid = format!(
        "[[particles.velocity]]\nparticles = [1, 2]\nv = [\"0.3 - {w:?}*y\", \"-0.2 + {w:?}*x\"]\n\
         omega = {w:?}\n"
    );
    let spun = "[[particles.velocity]]\nparticles = [2]\nomega = 30.0\n";
    for (case, velocity) in [("rigid", rigid.as_str()), ("spun", spun)] {
        let run = run(case, &body(velocity));
        let rows = &run.rows;
        assert_eq!(run.summary["broken_bonds"], 0);
        let col = |row: &[f64], k: usize, f: usize| row[1 + 5 * k + f];
        let p = |row: &[f64], a: usize| [1, 2].map(|k| m * col(row, k, 2 + a)).iter().sum::<f64>();
        let l = |row: &[f64]| {
            [1, 2]
                .map(|k| {
                    m * (col(row, k, 0) * col(row, k, 3) - col(row, k, 1) * col(row, k, 2))
                        + inertia * col(row, k, 4)
                })
                .iter()
                .sum::<f64>()
        };
        let (p0, l0) = ([p(&rows[0], 0), p(&rows[0], 1)], l(&rows[0]));
        let scale_l = m * r * 30.0 + inertia * 30.0;
        let scale_p = m * 1.0;
        assert!(l0.abs() > 0.1 * scale_l, "{case}: L0 = {l0}");
        let mut moved = 0.0f64;
        for row in rows {
            let t = row[0];
            // The free disk.
            let want = [20.0 + 1.5 * t, 20.0 - 2.5 * t, 1.5, -2.5, 7.0];
            for (f, w) in want.iter().enumerate() {
                assert!(
                    (col(row, 0, f) - w).abs() <= 1e-12 * (1.0 + w.abs()),
                    "{case} t = {t}: free disk field {f} = {} against {w}",
                    col(row, 0, f)
                );
            }
            for a in 0..2 {
                assert!(
                    (p(row, a) - p0[a]).abs() <= 1e-12 * scale_p,
                    "{case} t = {t}: momentum {a} {} against {}",
                    p(row, a),
                    p0[a]
                );
            }
            assert!(
                (l(row) - l0).abs() <= 1e-12 * scale_l,
                "{case} t = {t}: angular momentum {} against {l0}",
                l(row)
            );
            moved = moved.max((col(row, 2, 4) - col(&rows[0], 2, 4)).abs());
        }
        if case == "spun" {
            // The spin was shared: disk 2 no longer turns at its initial rate.
            assert!(moved > 1.0, "spun: ω of disk 2 changed by {moved}");
        } else {
            // A rigid rotation stays one: the pair still turns at w.
            let last = rows.last().unwrap();
            assert!(
                (col(last, 1, 4) - w).abs() < 2e-2 * w,
                "rigid: ω = {}",
                col(last, 1, 4)
            );
        }
    }
}

/// A listed 5 × 5 grid of disks (radius 0.5, spacing 1) with a hole of radius 0.6 at
/// the centre: the disks overlapping the hole (the centre one and its four neighbours
/// at distance 1 < 0.6 + 0.5) are cut, 20 remain, indexed in the listed order; the
/// pressure of the hole on the symmetric lining has no net force nor moment (to 1e-12 of
/// p a).
#[test]
fn a_listed_packing_takes_a_hole() {
    let mut centres = Vec::new();
    for j in -2..=2 {
        for i in -2..=2 {
            centres.push([f64::from(i), f64::from(j)]);
        }
    }
    let text = format!(
        "{HEAD}{}hole = {{ center = [0.0, 0.0], radius = 0.6 }}\n\
         [bonds]\nkn = 1.0e9\nks = 0.4e9\n[lsm]\ndt = 1.0e-5\n\
         [loading]\npressure_rate = 1.0e6\n\
         [schedule]\nend_time = 1.0e-3\ndt = 1.0e-4\n[output]\nvtk = false\n{}{}{}{}{}{}",
        list(&centres, 0.5),
        probe("x6", "x", 6),
        probe("y6", "y", 6),
        wall_probe("fx", "fx", "hole"),
        wall_probe("fy", "fy", "hole"),
        wall_probe("m", "torque", "hole"),
        "[[output.probe]]\nname = \"p\"\nfield = \"pressure\"\n",
    );
    let r = run("hole", &text);
    assert_eq!(r.summary["particles"], 20);
    let first = &r.rows[0];
    // Index 6 of the kept disks: the listed [-1, -1] (indices 0-5 are the first row and
    // [-2, -1]; [0, -1] was cut).
    assert_eq!((first[1], first[2]), (-1.0, -1.0));
    for row in &r.rows {
        let scale = row[6] * 0.6;
        for c in [3, 4, 5] {
            assert!(
                row[c].abs() <= 1e-12 * scale.max(1.0),
                "t = {}: {row:?}",
                row[0]
            );
        }
    }
    assert!(r.rows.last().unwrap()[6] > 0.0);
    assert!(
        error_of(&format!(
            "{HEAD}{}hole = {{ center = [0.0, 0.0], radius = -1.0 }}\n[bonds]\nkn = 1.0e9\n\
             [schedule]\nend_time = 1.0e-3\ndt = 1.0e-4\n",
            list(&centres, 0.5)
        ))
        .contains("particles.hole")
    );
}

/// The values of the binary `DataArray` `name` of a `.vtp` text (base64 of a `UInt64`
/// byte count then little-endian `f64`s).
fn vtp_f64(text: &str, name: &str) -> Vec<f64> {
    let tag = format!("Name=\"{name}\"");
    let at = text.find(&tag).unwrap_or_else(|| panic!("{name} missing"));
    let body = &text[at..];
    let body = &body[body.find('>').unwrap() + 1..body.find("</DataArray>").unwrap()];
    let bytes = base64(body.trim());
    let count = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(count, bytes.len() - 8, "{name}: byte count header");
    bytes[8..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// Standard base64 (RFC 4648, `=` padding).
fn base64(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::new();
    for chunk in s.as_bytes().chunks(4) {
        let pad = chunk.iter().filter(|&&c| c == b'=').count();
        let mut n = 0u32;
        for &c in chunk {
            n = n << 6 | u32::from(if c == b'=' { 0 } else { value(c) });
        }
        let b = n.to_be_bytes();
        out.extend_from_slice(&b[1..4 - pad]);
    }
    out
}

/// Two free touching disks bonded with k_s = 0 and k_b, disk 1 spun at w: their relative
/// rotation φ obeys φ'' = −2 k_b/I φ, whose velocity-Verlet solution is
/// `φ_n = w dt sin(n ϑ)/sin ϑ`, `cos ϑ = 1 − k_b dt²/I`; the contacts VTK's
/// `bending_moment` of the bond is `k_b φ_n` (to 1e-9 of its amplitude), its normal and
/// tangential forces 0.
#[test]
fn contacts_vtk_carries_the_bending_moment_of_a_bent_bond() {
    let (r, kb, w, dt) = (0.5, 1.0e6, 2.0, 1.0e-4);
    let (_, inertia) = mass(r);
    let text = format!(
        "{HEAD}{}[[particles.velocity]]\nparticles = [1]\nomega = {w:?}\n\
         [bonds]\nkn = 1.0e9\nkb = {kb:?}\n[lsm]\ndt = {dt:?}\n\
         [schedule]\nend_time = 0.05\ndt = 5.0e-3\n",
        list(&[[0.0, 0.0], [1.0, 0.0]], r),
    );
    let run = run("bend", &text);
    let theta = (1.0 - kb * dt * dt / inertia).acos();
    let amplitude = kb * w * dt / theta.sin();
    let mut seen = 0.0f64;
    for k in 0..=10 {
        let file = run.out.join(format!("vtk/contacts_{k:04}.vtp"));
        let text = std::fs::read_to_string(&file).unwrap();
        let moment = vtp_f64(&text, "bending_moment");
        let n = (k * 50) as f64;
        let want = amplitude * (n * theta).sin();
        assert_eq!(moment.len(), 1, "{file:?}");
        assert!(
            (moment[0] - want).abs() <= 1e-9 * amplitude,
            "output {k}: M_b = {} against {want}",
            moment[0]
        );
        assert_eq!(vtp_f64(&text, "tangential_force"), [0.0]);
        seen = seen.max(moment[0].abs());
    }
    assert!(
        seen > 0.5 * amplitude,
        "largest moment {seen} of {amplitude}"
    );
}

/// A bonded pair tilted at (0.6, 0.8) between the platens (each disk one platen), the
/// platens stopping after δ = 1e-6 m at 1e-3 m/s: each disk has moved by exactly δ and
/// holds it; from the stop on the forces stay as they were at the stop. The top
/// platen's action on the rest, with the bond's normal force F_n = k_n (d − d₀) and
/// shear force F_s, is `F_n n + F_s t` and its moment about the platen's centre is
/// `−F_s d/2` (the lever of the shear force d less the bond's shear moment F_s d/2);
/// for small δ, `F_n = −1.6 k_n δ` and `F_s = −1.2 k_s δ` (to 1e-5). The bottom platen
/// feels the same moment about its own centre; the cell about disk 0's initial centre
/// `F_s d/2 − δ F_x`.
#[test]
fn platens_stop_where_asked_and_their_moments_match_the_bond() {
    let (kn, ks, delta) = (1.0e9, 0.4e9, 1.0e-6);
    let text = format!(
        "{HEAD}{}[bonds]\nkn = {kn:?}\nks = {ks:?}\n[lsm]\ndt = 1.0e-5\n\
         [loading]\nplatens = {{ velocity = 1.0e-3, thickness = 0.5, stop_displacement = {delta:?} }}\n\
         [schedule]\nend_time = 3.0e-3\ndt = 1.0e-4\n[output]\nvtk = false\n{}{}{}{}{}{}{}\
         [[output.probe]]\nname = \"cell\"\nfield = \"torque\"\ncell = {{ center = [0.0, 0.0], radius = 0.1 }}\n",
        list(&[[0.0, 0.0], [0.6, 0.8]], 0.5),
        probe("y0", "y", 0),
        probe("y1", "y", 1),
        probe("x1", "x", 1),
        wall_probe("fx", "fx", "top"),
        wall_probe("fy", "fy", "top"),
        wall_probe("mt", "torque", "top"),
        wall_probe("mb", "torque", "bottom"),
    );
    let r = run("stop", &text);
    let stop = r
        .rows
        .iter()
        .position(|row| row[0] >= 1.0e-3 - 1e-12)
        .unwrap();
    assert!(stop > 5);
    let held = &r.rows[stop];
    for row in &r.rows {
        let t = row[0];
        let s = (1.0e-3 * t).min(delta);
        assert!(
            (row[1] - s).abs() <= 1e-18 + 1e-12 * s,
            "t = {t}: y0 = {}",
            row[1]
        );
        assert!(
            (row[2] - (0.8 - s)).abs() <= 1e-14,
            "t = {t}: y1 = {}",
            row[2]
        );
        assert_eq!(row[3], 0.6);
        if t >= 1.0e-3 - 1e-12 {
            for c in 4..=8 {
                assert!(
                    (row[c] - held[c]).abs() <= 1e-12 * held[c].abs(),
                    "t = {t}: column {c} = {} against {} at the stop",
                    row[c],
                    held[c]
                );
            }
        }
    }
    // The bond at the stop.
    let e = [0.6, 0.8 - 2.0 * delta];
    let d = e[0].hypot(e[1]);
    let n = [e[0] / d, e[1] / d];
    let t = [-n[1], n[0]];
    let (fx, fy, mt, mb, cell) = (held[4], held[5], held[6], held[7], held[8]);
    // Split the action into its normal and shear parts.
    let f_n = fx * n[0] + fy * n[1];
    let f_s = fx * t[0] + fy * t[1];
    assert!(
        (f_n - kn * (d - 1.0)).abs() <= 1e-6 * kn * delta,
        "F_n {f_n}"
    );
    assert!(
        (f_n + 1.6 * kn * delta).abs() <= 1e-5 * kn * delta,
        "F_n {f_n}"
    );
    assert!(
        (f_s + 1.2 * ks * delta).abs() <= 1e-5 * ks * delta,
        "F_s {f_s}"
    );
    assert!(
        (mt + f_s * d / 2.0).abs() <= 1e-9 * ks * delta,
        "top moment {mt}"
    );
    assert!(
        (mb + f_s * d / 2.0).abs() <= 1e-9 * ks * delta,
        "bottom moment {mb}"
    );
    assert!(
        (cell - (f_s * d / 2.0 - delta * fx)).abs() <= 1e-9 * ks * delta,
        "cell moment {cell}"
    );
}

#[test]
fn bad_platen_stops_and_walls_are_named() {
    let pair = list(&[[0.0, 0.0], [0.6, 0.8]], 0.5);
    let tail = "[schedule]\nend_time = 1.0e-3\ndt = 1.0e-4\n";
    for (extra, want) in [
        (
            "[loading]\nplatens = { velocity = 1.0, thickness = 0.5, stop_displacement = 1.0, stop_time = 1.0 }\n".to_string(),
            "loading.platens",
        ),
        (
            "[loading]\nplatens = { velocity = 1.0, thickness = 0.5, stop_time = -1.0 }\n".to_string(),
            "stop_time = -1",
        ),
        (wall_probe("f", "fx", "top"), "needs [loading] platens"),
        (wall_probe("f", "fx", "hole"), "needs a pressurised hole"),
        (
            format!("[loading]\nplatens = {{ velocity = 1.0, thickness = 0.5 }}\n{}", wall_probe("f", "fx", "left")),
            "walls: top, bottom, hole",
        ),
        (
            format!("[loading]\nplatens = {{ velocity = 1.0, thickness = 0.5 }}\n{}", wall_probe("f", "omega", "top")),
            "fx, fy or torque",
        ),
    ] {
        let e = error_of(&format!("{HEAD}{pair}[bonds]\nkn = 1.0e9\n{tail}{extra}"));
        assert!(e.contains(want), "{want}: {e}");
    }
}

/// A column of five bonded disks between the platens (the end disks), three of them
/// free, locally damped: the platens stop after δ each and the column settles to the
/// static closed form, four springs k_n in series shortened by 2δ: the platen force
/// and the top platen's push on the rest are `k_n 2δ/4` (to 1e-6) and held there, the
/// middle disk stays on the axis and at the centre.
#[test]
fn an_elastic_column_holds_the_force_of_its_stopped_platens() {
    let (kn, delta) = (1.0e9, 1.0e-6);
    let centres: Vec<[f64; 2]> = (0..5).map(|k| [0.0, f64::from(k)]).collect();
    let text = format!(
        "{HEAD}{}[bonds]\nkn = {kn:?}\nks = 0.4e9\n[lsm]\ndt = 1.0e-5\ndamping = \"local\"\n\
         [loading]\nplatens = {{ velocity = 1.0e-3, thickness = 0.5, stop_time = 1.0e-3 }}\n\
         [schedule]\nend_time = 0.2\ndt = 1.0e-2\n[output]\nvtk = false\n\
         [[output.probe]]\nname = \"pf\"\nfield = \"platen_force\"\n{}{}{}{}",
        list(&centres, 0.5),
        wall_probe("fy", "fy", "top"),
        wall_probe("fx", "fx", "top"),
        probe("x2", "x", 2),
        probe("y2", "y", 2),
    );
    let r = run("column", &text);
    let want = kn * 2.0 * delta / 4.0;
    let last = r.rows.last().unwrap();
    assert!(
        (last[1] - want).abs() <= 1e-6 * want,
        "platen force {}",
        last[1]
    );
    assert!((last[2] + want).abs() <= 1e-6 * want, "top fy {}", last[2]);
    assert_eq!(last[3], 0.0);
    assert_eq!(last[4], 0.0);
    assert!((last[5] - 2.0).abs() <= 1e-12, "y2 {}", last[5]);
    // Settled before the end and held.
    let settled = &r.rows[r.rows.len() - 5];
    assert!(
        (settled[1] - want).abs() <= 1e-6 * want,
        "at t = {}: {}",
        settled[0],
        settled[1]
    );
}

/// `hold_force` on the column of the test above: the platens approach at `velocity` and
/// the servo holds the platen force at `F`. Four springs k_n in series between platens
/// that each moved `d` carry `k_n 2d/4`, so the platens stop at `d = 2F/k_n` (closed
/// form). The held force is `F` to 1e-6, its range over the last tenth of the run is
/// below 1e-6 F (no growing oscillation), and both platens moved `2F/k_n` to 1e-6.
#[test]
fn the_servo_holds_the_force_of_an_elastic_column() {
    let (kn, force) = (1.0e9, 500.0);
    let centres: Vec<[f64; 2]> = (0..5).map(|k| [0.0, f64::from(k)]).collect();
    let text = format!(
        "{HEAD}{}[bonds]\nkn = {kn:?}\nks = 0.4e9\n[lsm]\ndt = 1.0e-5\ndamping = \"local\"\n\
         [loading]\nplatens = {{ velocity = 1.0e-3, thickness = 0.5, hold_force = {force:?} }}\n\
         [schedule]\nend_time = 0.2\ndt = 1.0e-3\n[output]\nvtk = false\n\
         [[output.probe]]\nname = \"pf\"\nfield = \"platen_force\"\n{}{}{}",
        list(&centres, 0.5),
        wall_probe("fy", "fy", "top"),
        probe("ytop", "y", 4),
        probe("ybottom", "y", 0),
    );
    let r = run("servo", &text);
    let tol = 1e-6;
    let last = r.rows.last().unwrap();
    assert!(
        (last[1] - force).abs() <= tol * force,
        "platen force {}",
        last[1]
    );
    assert!((last[2] + force).abs() <= tol * force, "top fy {}", last[2]);
    let tail = &r.rows[r.rows.len() - r.rows.len() / 10..];
    let (lo, hi) = tail
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), row| {
            (a.min(row[1]), b.max(row[1]))
        });
    assert!(
        hi - lo <= tol * force,
        "force range {lo} .. {hi} over the last tenth"
    );
    let d = 2.0 * force / kn;
    assert!(
        ((4.0 - last[3]) - d).abs() <= tol * d,
        "top moved {}",
        4.0 - last[3]
    );
    assert!((last[4] - d).abs() <= tol * d, "bottom moved {}", last[4]);
    // The approach went at full speed: the force was still below F at half the time
    // the approach needs at `velocity` (d / velocity = 1 ms).
    let early = r.rows.iter().find(|row| row[0] >= 0.5e-3 - 1e-12).unwrap();
    assert!(early[1] < force, "at t = {}: {}", early[0], early[1]);
}

/// `hold_force` is refused with a stop key, when not positive and with `[lbm]`, naming
/// the key.
#[test]
fn bad_hold_forces_are_named() {
    let pair = list(&[[0.0, 0.0], [0.0, 1.0]], 0.5);
    let tail = "[schedule]\nend_time = 1.0e-3\ndt = 1.0e-4\n";
    let lbm = "[lbm]\nextent = [[-1.0, -1.0], [1.0, 2.0]]\nspacing = 0.1\ndensity = 1000.0\n\
               viscosity = 0.76\ntau = 0.6\n";
    for (extra, want) in [
        (
            "platens = { velocity = 1.0, thickness = 0.5, hold_force = 1.0, stop_time = 1.0 }\n",
            "hold_force and stop_time",
        ),
        (
            "platens = { velocity = 1.0, thickness = 0.5, hold_force = 1.0, stop_displacement = 1.0 }\n",
            "hold_force and stop_displacement",
        ),
        (
            "platens = { velocity = 1.0, thickness = 0.5, hold_force = 0.0 }\n",
            "hold_force = 0 must be",
        ),
        (
            "platens = { velocity = 1.0, thickness = 0.5, hold_force = -5.0 }\n",
            "hold_force = -5 must be",
        ),
    ] {
        let e = error_of(&format!(
            "{HEAD}{pair}[bonds]\nkn = 1.0e9\n{tail}[loading]\n{extra}"
        ));
        assert!(
            e.contains("loading.platens") && e.contains(want),
            "{want}: {e}"
        );
    }
    let e = error_of(&format!(
        "{HEAD}{pair}[bonds]\nkn = 1.0e9\n{tail}{lbm}[loading]\n\
         platens = {{ velocity = 1.0, thickness = 0.5, hold_force = 1.0 }}\n"
    ));
    assert!(
        e.contains("loading.platens") && e.contains("hold_force is not available with [lbm]"),
        "{e}"
    );
}
