//! Scenes of model "nscd" with initial velocities and spins (`[[particles.velocity]]`),
//! restitution (`[contact] restitution`) and wall reaction probes (`wall = NAME`),
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
