//! Scenes of model "nscd" with initial velocities and spins (`[[particles.velocity]]`),
//! restitution (`[contact] restitution`), wall reaction probes (`wall = NAME`) and a
//! wall's own friction (`[[wall]] mu`),
//! through the library, against closed forms; bad input refused with the key named.

use std::path::{Path, PathBuf};

use porofrac_scene::{LawRegistry, Scene, Silent};

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("porofrac-nscdf-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd/inline.toml")
}

/// Run a scene text; the probe rows (time first) and `summary.json`.
fn run(name: &str, text: &str) -> (Vec<Vec<f64>>, serde_json::Value) {
    let scene = Scene::parse(text, &path(), LawRegistry::default()).unwrap();
    let out = out_dir(name);
    let summary = scene.run(&out, &mut Silent).unwrap();
    assert_eq!(summary.status, "ok");
    let rows = std::fs::read_to_string(out.join("probes.csv"))
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time"))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let json =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
    (rows, json)
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

const HEAD: &str = "[scene]\nname = \"t\"\ndim = 2\nmodel = \"nscd\"\n";

fn probe(name: &str, field: &str, particle: usize) -> String {
    format!("[[output.probe]]\nname = \"{name}\"\nfield = \"{field}\"\nparticle = {particle}\n")
}

/// Three free disks without gravity, given velocities by a box, by index and by an
/// expression of the centre, and spins: each keeps its velocity and spin exactly
/// (momentum and angular momentum of a free rigid body), and moves by v t (to 1e-12).
#[test]
fn free_disks_keep_their_initial_velocities_and_spins() {
    let text = format!(
        "{HEAD}[particles]\nkind = \"list\"\ncentres = [[0.0, 0.0], [5.0, 0.0], [10.0, 3.0]]\n\
         radii = [0.5, 0.5, 0.5]\ndensity = 1000.0\n\
         [[particles.velocity]]\nv = [\"0.1*x\", \"-0.2*y\"]\nomega = 1.0\n\
         [[particles.velocity]]\nregion = [[-1.0, -1.0], [1.0, 1.0]]\nv = [2.0, -1.0]\n\
         [[particles.velocity]]\nparticles = [1]\nomega = -3.0\n\
         [nscd]\ngravity = [0.0, 0.0]\n[schedule]\nend_time = 0.1\ndt = 0.01\n\
         {}{}{}{}{}{}{}",
        probe("vx0", "vx", 0),
        probe("vy0", "vy", 0),
        probe("w0", "omega", 0),
        probe("w1", "omega", 1),
        probe("vx2", "vx", 2),
        probe("vy2", "vy", 2),
        probe("x2", "x", 2),
    );
    let (rows, json) = run("free", &text);
    assert_eq!(json["contacts"]["max"], 0);
    for r in &rows {
        let t = r[0];
        let want = [2.0, -1.0, 1.0, -3.0, 1.0, -0.6, 10.0 + t];
        for (k, w) in want.iter().enumerate() {
            assert!(
                (r[k + 1] - w).abs() < 1e-12 * (1.0 + w.abs()),
                "t = {t}, column {k}: {} against {w}",
                r[k + 1]
            );
        }
    }
    assert_eq!(rows.last().unwrap()[0], 0.1);
}

/// A ball dropped from 1 m above a floor with restitution e = ½ (every step probed):
/// the first upward velocity is e times the last downward one (to 1e-12), and the
/// reaction of the floor is 0 while it flies.
#[test]
fn restitution_of_the_contact_law_reaches_the_run() {
    let text = format!(
        "{HEAD}[particles]\nkind = \"list\"\ncentres = [[0.0, 1.1]]\nradii = [0.1]\n\
         density = 1000.0\n[[wall]]\nname = \"floor\"\nfrom = [-2.0, 0.0]\nto = [2.0, 0.0]\n\
         [contact]\nmu = 0.3\nrestitution = 0.5\n[nscd]\nmin_sweeps = 1\ntolerance = 1e-12\n\
         [schedule]\nend_time = 0.6\ndt = 1.0e-3\n[output]\nevery = 1000\nprobe_every = 1\n\
         {}[[output.probe]]\nname = \"floor\"\nfield = \"fy\"\nwall = \"floor\"\n",
        probe("vy", "vy", 0),
    );
    let (rows, _) = run("bounce", &text);
    let k = rows
        .windows(2)
        .position(|w| w[0][1] < 0.0 && w[1][1] > 0.0)
        .expect("a bounce");
    let (before, after) = (rows[k][1], rows[k + 1][1]);
    assert!((after + 0.5 * before).abs() < 1e-12, "{before} → {after}");
    assert!(before < -4.0, "arrival speed {before}");
    assert!(rows[k + 1][2] > 0.0, "the floor pushes during the impact");
    assert_eq!(rows[k + 3][2], 0.0, "no reaction in flight");
}

/// A disk launched at v₀ = 3 m/s without spin along a floor of its own friction μ_b =
/// 0.2 (the contact law's μ = 0.9): it slides with v = v₀ − μ_b g t, ω = −2 μ_b g t / r
/// while the floor pushes back with μ_b m g (to 1e-12 relative), until it rolls at
/// t* = v₀ / (3 μ_b g) = 0.51 s with v = 2v₀/3 and the floor's push 0 (to 1e-12). With
/// the law's μ it would roll from 0.11 s.
#[test]
fn a_wall_of_its_own_friction_brakes_a_sliding_disk() {
    let (v0, mu_b, r, g) = (3.0, 0.2, 0.5, 9.81);
    let rho = 1000.0;
    let m = rho * std::f64::consts::PI * r * r;
    let text = format!(
        "{HEAD}[particles]\nkind = \"list\"\ncentres = [[0.0, 0.5]]\nradii = [0.5]\n\
         density = {rho}\n[[particles.velocity]]\nv = [{v0}, 0.0]\n\
         [[wall]]\nname = \"floor\"\nfrom = [-10.0, 0.0]\nto = [10.0, 0.0]\nmu = {mu_b}\n\
         [contact]\nmu = 0.9\n[nscd]\nmin_sweeps = 1\ntolerance = 1e-12\n\
         [schedule]\nend_time = 0.8\ndt = 1.0e-3\n[output]\nevery = 1000\nprobe_every = 1\n\
         {}{}[[output.probe]]\nname = \"fx\"\nfield = \"fx\"\nwall = \"floor\"\n",
        probe("vx", "vx", 0),
        probe("w", "omega", 0),
    );
    let (rows, _) = run("brake", &text);
    let t_roll = v0 / (3.0 * mu_b * g);
    let (mut sliding, mut rolling) = (0, 0);
    for row in &rows[1..] {
        let (t, vx, w, fx) = (row[0], row[1], row[2], row[3]);
        if t < t_roll - 2e-3 {
            sliding += 1;
            let (v, spin) = (v0 - mu_b * g * t, -2.0 * mu_b * g * t / r);
            assert!((vx - v).abs() < 1e-12 * v0, "t = {t}: v {vx} against {v}");
            assert!(
                (w - spin).abs() < 1e-12 * v0 / r,
                "t = {t}: ω {w} against {spin}"
            );
            assert!(
                (fx + mu_b * m * g).abs() < 1e-12 * m * g,
                "t = {t}: floor fx {fx} against −μ_b m g {}",
                -mu_b * m * g
            );
        } else if t > t_roll + 2e-3 {
            rolling += 1;
            assert!((vx - 2.0 * v0 / 3.0).abs() < 1e-12 * v0, "t = {t}: v {vx}");
            assert!(
                (vx + w * r).abs() < 1e-12 * v0,
                "t = {t}: slip {}",
                vx + w * r
            );
            assert!(fx.abs() < 1e-12 * m * g, "t = {t}: floor fx {fx}");
        }
    }
    assert!(
        sliding > 400 && rolling > 250,
        "{sliding} sliding, {rolling} rolling steps"
    );
}

#[test]
fn bad_keys_are_named() {
    let one = "[particles]\nkind = \"list\"\ncentres = [[0.0, 0.5]]\nradii = [0.5]\n\
               density = 1000.0\n";
    let tail = "[schedule]\nend_time = 0.01\ndt = 0.001\n";
    let wall = "[[wall]]\nname = \"floor\"\nfrom = [-1.0, 0.0]\nto = [1.0, 0.0]\n";
    for (extra, want) in [
        (
            "[contact]\nrestitution = 1.5\n".to_string(),
            vec!["contact.restitution", "[0, 1]"],
        ),
        (
            "[contact]\nrestitution = 0.5\ncohesion = 1.0\nd_w = 0.01\n".to_string(),
            vec!["contact.restitution", "cohesive"],
        ),
        (
            format!("{wall}[[output.probe]]\nname = \"a\"\nfield = \"fy\"\nwall = \"roof\"\n"),
            vec!["output.probe[0].wall", "\"roof\"", "floor"],
        ),
        (
            format!("{wall}{wall}"),
            vec!["wall[1].name", "\"floor\"", "wall[0]"],
        ),
        (
            format!("{wall}mu = -0.1\n"),
            vec!["wall[0].mu", "≥ 0"],
        ),
        (
            format!("{wall}[[output.probe]]\nname = \"a\"\nfield = \"vx\"\nwall = \"floor\"\n"),
            vec!["output.probe[0].wall", "fx, fy or torque"],
        ),
        (
            "[[particles.velocity]]\nparticles = [0]\nregion = [[0.0, 0.0], [1.0, 1.0]]\nv = [1.0, 0.0]\n"
                .to_string(),
            vec!["particles.velocity[0]", "one of region"],
        ),
        (
            "[[particles.velocity]]\nparticles = [3]\nomega = 1.0\n".to_string(),
            vec!["particles.velocity[0].particles", "1 particles"],
        ),
        (
            "[[particles.velocity]]\nregion = [[0.0, 0.0], [1.0, 1.0]]\n".to_string(),
            vec!["particles.velocity[0]", "sets nothing"],
        ),
        (
            "[[particles.velocity]]\nv = [\"1/(x-x)\", 0.0]\n".to_string(),
            vec!["particles.velocity[0].v", "not finite"],
        ),
        (
            "[[particles.velocity]]\nv = [\"sin(\", 0.0]\n".to_string(),
            vec!["particles.velocity[0].v", "bad expression"],
        ),
    ] {
        let e = error_of(&format!("{HEAD}{one}{extra}{tail}"));
        for w in want {
            assert!(e.contains(w), "{w:?} not in: {e}");
        }
        assert!(e.contains("inline.toml"), "{e}");
    }
    // Model lsm reads [[particles.velocity]] too: this scene fails on its missing [bonds].
    let e = error_of(
        "[scene]\nname = \"t\"\ndim = 2\nmodel = \"lsm\"\n[particles]\nkind = \"list\"\n\
         centres = [[0.0, 0.5]]\nradii = [0.5]\ndensity = 1000.0\n\
         [[particles.velocity]]\nv = [1.0, 0.0]\n[schedule]\nend_time = 0.01\ndt = 0.001\n",
    );
    assert!(
        !e.contains("particles.velocity") && e.contains("bonds is missing"),
        "{e}"
    );
}

/// Three disks under gravity given velocities and spins: two by a rigid rotation
/// v = ω(−y, x), ω = 2 rad/s (an expression) with spin ω, the third overridden by index
/// with v = (1.5, 4) and spin −1. The state set at t = 0 has the momentum Σ m v and the
/// angular momentum about the origin Σ m x × v + I ω of those values (to 1e-12
/// relative); then each disk flies on its parabola x₀ + v₀ t − ½ g t² ĵ with
/// v₀ − g t ĵ, its spin unchanged (θ = ½ integrates a constant acceleration exactly:
/// to 1e-12).
#[test]
fn disks_set_in_flight_follow_their_parabolas() {
    let centres = [[0.0, 3.0], [4.0, 0.0], [-5.0, 2.0]];
    let (r, rho, w, g) = (0.5, 1000.0, 2.0, 9.81);
    let mut probes = String::new();
    for i in 0..3 {
        for f in ["x", "y", "vx", "vy", "omega"] {
            probes += &probe(&format!("{f}{i}"), f, i);
        }
    }
    let text = format!(
        "{HEAD}[particles]\nkind = \"list\"\ncentres = {centres:?}\nradii = [{r}, {r}, {r}]\n\
         density = {rho}\n\
         [[particles.velocity]]\nv = [\"-{w}*y\", \"{w}*x\"]\nomega = {w}\n\
         [[particles.velocity]]\nparticles = [2]\nv = [1.5, 4.0]\nomega = -1.0\n\
         [schedule]\nend_time = 0.5\ndt = 0.01\n[output]\nevery = 10\nprobe_every = 5\n{probes}"
    );
    let (rows, json) = run("parabola", &text);
    assert_eq!(json["contacts"]["max"], 0);
    let m = rho * std::f64::consts::PI * r * r;
    let inertia = 0.5 * m * r * r;
    let v0: Vec<[f64; 3]> = vec![
        [-w * centres[0][1], w * centres[0][0], w],
        [-w * centres[1][1], w * centres[1][0], w],
        [1.5, 4.0, -1.0],
    ];
    // Momentum and angular momentum of the state set at t = 0.
    let first = &rows[0];
    assert_eq!(first[0], 0.0);
    let (mut p, mut l, mut p_want, mut l_want) = ([0.0; 2], 0.0, [0.0; 2], 0.0);
    for i in 0..3 {
        let c = &first[1 + 5 * i..6 + 5 * i];
        p[0] += m * c[2];
        p[1] += m * c[3];
        l += m * (c[0] * c[3] - c[1] * c[2]) + inertia * c[4];
        let [x, y] = centres[i];
        let [vx, vy, om] = v0[i];
        p_want[0] += m * vx;
        p_want[1] += m * vy;
        l_want += m * (x * vy - y * vx) + inertia * om;
    }
    let scale = m * 10.0;
    for a in 0..2 {
        assert!(
            (p[a] - p_want[a]).abs() < 1e-12 * scale,
            "P {p:?}, {p_want:?}"
        );
    }
    assert!((l - l_want).abs() < 1e-12 * scale * 10.0, "L {l}, {l_want}");
    assert_eq!(rows.last().unwrap()[0], 0.5);
    for row in &rows {
        let t = row[0];
        for i in 0..3 {
            let c = &row[1 + 5 * i..6 + 5 * i];
            let [vx, vy, om] = v0[i];
            let want = [
                centres[i][0] + vx * t,
                centres[i][1] + vy * t - 0.5 * g * t * t,
                vx,
                vy - g * t,
                om,
            ];
            for (k, (got, want)) in c.iter().zip(want).enumerate() {
                assert!(
                    (got - want).abs() < 1e-12 * (1.0 + want.abs()),
                    "t = {t}, disk {i}, column {k}: {got} against {want}"
                );
            }
        }
    }
}

/// A column of five disks dropped from 2 mm gaps onto a floor whose centre is 0.3 m to
/// its left, settled (`settle_ratio`), then run at rest: the floor's probes read
/// fx = 0, fy = N m g and torque = 0.3 N m g about the floor's centre (to 1e-9 relative,
/// the solver's tolerance 1e-12 on the impulses). Every contact keeps an overlap of at
/// most h(1 − θ)v_n, v_n ≤ √(2 g (k + 1) · 2 mm) the speed at which disk k (from the
/// bottom) arrived after falling (k + 1) gaps (θ = ½, h = 1 ms).
#[test]
fn a_settled_column_weighs_on_its_floor() {
    let (n, r, a, rho) = (5, 0.05, 0.3, 2000.0);
    let centres: Vec<[f64; 2]> = (0..n)
        .map(|k| [a, r + 0.002 + (2.0 * r + 0.002) * k as f64])
        .collect();
    let text = format!(
        "{HEAD}[particles]\nkind = \"list\"\ncentres = {centres:?}\nradii = {:?}\n\
         density = {rho}\n[[wall]]\nname = \"floor\"\nfrom = [-1.0, 0.0]\nto = [1.0, 0.0]\n\
         [contact]\nmu = 0.3\n[nscd]\ntolerance = 1e-12\nmin_sweeps = 1\nmax_sweeps = 100000\n\
         settle_ratio = 1e-8\n\
         [schedule]\nend_time = 0.01\ndt = 1.0e-3\n[output]\nevery = 10\nprobe_every = 1\n\
         [[output.probe]]\nname = \"fx\"\nfield = \"fx\"\nwall = \"floor\"\n\
         [[output.probe]]\nname = \"fy\"\nfield = \"fy\"\nwall = \"floor\"\n\
         [[output.probe]]\nname = \"torque\"\nfield = \"torque\"\nwall = \"floor\"\n{}",
        vec![r; n],
        (0..n)
            .map(|i| probe(&format!("y{i}"), "y", i))
            .collect::<String>()
    );
    let (rows, json) = run("settled", &text);
    assert!(json["settling"]["steps"].as_u64().unwrap() > 10, "{json}");
    let weight = n as f64 * rho * std::f64::consts::PI * r * r * 9.81;
    assert_eq!(rows.len(), 11);
    for row in &rows[1..] {
        let [t, fx, fy, torque] = [row[0], row[1], row[2], row[3]];
        assert!(fx.abs() < 1e-9 * weight, "t = {t}: fx {fx}");
        assert!(
            (fy - weight).abs() < 1e-9 * weight,
            "t = {t}: fy {fy}, N m g {weight}"
        );
        assert!(
            (torque - a * weight).abs() < 1e-9 * a * weight,
            "t = {t}: torque {torque}, {}",
            a * weight
        );
    }
    let y = &rows.last().unwrap()[4..];
    for k in 0..n {
        let overlap = if k == 0 {
            r - y[0]
        } else {
            2.0 * r - (y[k] - y[k - 1])
        };
        let bound = 0.5 * 1e-3 * (2.0 * 9.81 * (k + 1) as f64 * 0.002).sqrt();
        assert!(
            (-1e-12..=bound).contains(&overlap),
            "contact {k}: overlap {overlap}, h(1 − θ)v_n ≤ {bound}"
        );
    }
}

/// Collects the solver's sweeps of every step.
#[derive(Default)]
struct Sweeps(Vec<usize>);

impl porofrac_scene::Observer for Sweeps {
    fn step(&mut self, report: &porofrac_scene::StepReport) {
        if report.step > 0 {
            self.0.push(report.iterations);
        }
    }
}

/// `min_sweeps` is a floor in a run, for each `ordering`: the bundled column with
/// `min_sweeps = 100` (its impulses at an exact fixed point after a few sweeps) does at
/// least 100 sweeps in every step, exactly 100 once warm-started at rest, and
/// `summary.json` says so (`sweeps.mean` ≥ 100; `contacts` last = mean = max = 10).
#[test]
fn min_sweeps_is_a_floor_in_every_ordering() {
    let column = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/nscd/column.toml"),
    )
    .unwrap();
    for ordering in ["sorted", "random", "coloured", "slabs"] {
        let text = column.replace(
            "min_sweeps = 1\n",
            &format!("min_sweeps = 100\nordering = \"{ordering}\"\n"),
        );
        assert_ne!(text, column);
        let scene = Scene::parse(&text, &path(), LawRegistry::default()).unwrap();
        let out = out_dir(&format!("floor-{ordering}"));
        let mut sweeps = Sweeps::default();
        let summary = scene.run(&out, &mut sweeps).unwrap();
        assert_eq!(summary.status, "ok");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        std::fs::remove_dir_all(&out).unwrap();
        let s = &sweeps.0;
        assert_eq!(s.len(), 50, "{ordering}");
        assert!(s.iter().all(|&k| k >= 100), "{ordering}: {s:?}");
        assert!(s[5..].iter().all(|&k| k == 100), "{ordering}: {s:?}");
        let mean = json["sweeps"]["mean"].as_f64().unwrap();
        let want = s.iter().sum::<usize>() as f64 / s.len() as f64;
        assert!(
            mean >= 100.0 && (mean - want).abs() < 1e-12,
            "{ordering}: {mean}"
        );
        for key in ["last", "max"] {
            assert_eq!(json["contacts"][key], 10, "{ordering}: contacts.{key}");
        }
        assert_eq!(json["contacts"]["mean"], 10.0, "{ordering}");
    }
}
