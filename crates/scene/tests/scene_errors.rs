//! The messages of bad keys and values, on their exact text: an unknown key with the
//! nearest valid one, a key of another model, a type error with the unit, an untagged
//! value in words, a choice that is not one of the words, and errors in `--set`.

use std::path::Path;

use porofrac_scene::common::overrides::Override;
use porofrac_scene::{LawRegistry, Scene};

const BASE: &str = r#"[scene]
name = "errors"
dim = 2

[grid]
kind = "cartesian"
extent = [[0.0, 0.0], [1.0, 1.0]]
cells = [4, 4]

[[region]]
name = "rock"
select = { all = true }
law = "vem"
material = "rock"

[material.rock]
youngs_modulus = 1.0e9
poisson_ratio = 0.3

[[bc]]
boundary = "ymin"
displacement = [0.0, 0.0]
[[bc]]
boundary = "ymax"
traction = [0.0, -1e6]
"#;

fn error(text: &str) -> String {
    match Scene::parse(text, Path::new("scene.toml"), LawRegistry::default()) {
        Ok(_) => panic!("the scene was accepted"),
        Err(e) => e.to_string(),
    }
}

fn error_with(text: &str, set: &[&str]) -> String {
    let dir = std::env::temp_dir().join(format!("porofrac_scene_errors_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("scene{}.toml", set.len()));
    std::fs::write(&path, text).unwrap();
    let o: Vec<Override> = set.iter().map(|s| Override::parse(s).unwrap()).collect();
    match Scene::load_with_overrides(&path, LawRegistry::default(), &o) {
        Ok(_) => panic!("the scene was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_base_scene_is_valid() {
    Scene::parse(BASE, Path::new("scene.toml"), LawRegistry::default()).unwrap();
}

#[test]
fn an_unknown_section_gets_the_nearest_one() {
    let text = format!("{BASE}\n[shedule]\nend_time = 1.0\n");
    assert_eq!(
        error(&text),
        "scene.toml:27: unknown section `shedule`; did you mean `schedule`?"
    );
}

#[test]
fn an_unknown_key_gets_the_nearest_one_of_its_section() {
    let text = BASE.replace("cells = [4, 4]", "celss = [4, 4]");
    assert_eq!(
        error(&text),
        "scene.toml:8: unknown key `celss` in [grid]; did you mean `cells`?"
    );
    let text = BASE.replace("poisson_ratio = 0.3", "poisson = 0.3");
    assert_eq!(
        error(&text),
        "scene.toml:18: unknown key `poisson` in [material.rock]; did you mean `poisson_ratio`?"
    );
}

#[test]
fn a_key_of_another_model_names_it() {
    // `[particles]` is a shared section of the particle models; `[contact]` is nscd's.
    let text = format!("{BASE}\n[contact]\nmu = 0.3\n");
    assert_eq!(
        error(&text),
        "scene.toml:27: contact belongs to model \"nscd\", not \"continuum\""
    );
    // A key of a shared section that one model reads.
    let text = format!("{BASE}\n[solver]\npenalty = 1.0\n");
    assert_eq!(
        error(&text),
        "scene.toml:28: solver.penalty belongs to model \"cosserat\", not \"continuum\""
    );
    let text = BASE.replace(
        "poisson_ratio = 0.3",
        "poisson_ratio = 0.3\nmicro_inertia = 1e-4",
    );
    assert_eq!(
        error(&text),
        "scene.toml:19: material.rock.micro_inertia belongs to model \"cosserat\", not \"continuum\""
    );
}

#[test]
fn a_type_error_names_the_key_and_the_unit() {
    let text = BASE.replace("youngs_modulus = 1.0e9", "youngs_modulus = \"1 GPa\"");
    assert_eq!(
        error(&text),
        "scene.toml:17: material.rock.youngs_modulus = \"1 GPa\": expected a number in Pa (write 1e9)"
    );
    let text = BASE.replace("poisson_ratio = 0.3", "poisson_ratio = \"0.3\"");
    assert_eq!(
        error(&text),
        "scene.toml:18: material.rock.poisson_ratio = \"0.3\": expected a number (write 0.3 without quotes)"
    );
}

#[test]
fn an_untagged_value_is_explained_in_words() {
    let text = BASE.replace("cells = [4, 4]", "cells = \"many\"");
    assert_eq!(
        error(&text),
        "scene.toml:8: grid.cells = \"many\": expected a number of cells per axis, e.g. [40, 20] (voronoi: one number)"
    );
}

#[test]
fn a_word_that_is_not_a_choice_gets_the_nearest() {
    let text = BASE.replace("kind = \"cartesian\"", "kind = \"cartesain\"");
    assert_eq!(
        error(&text),
        "scene.toml:6: grid.kind = \"cartesain\": expected one of \"cartesian\", \"triangles\", \"tetrahedra\", \"voronoi\", \"file\", \"composite\", \"round-well\"; did you mean \"cartesian\"?"
    );
}

#[test]
fn errors_in_overrides_name_the_option() {
    let e = error_with(BASE, &["material.rock.youngs_modulus=1 GPa"]);
    assert!(
        e.ends_with(": --set material.rock.youngs_modulus: material.rock.youngs_modulus = \"1 GPa\": expected a number in Pa (write 1e9)"),
        "{e}"
    );
    let e = error_with(BASE, &["material.rock.poisson_ratio=0.6"]);
    assert!(
        e.ends_with(
            ": --set material.rock.poisson_ratio: material.rock.poisson_ratio = 0.6 must be < 0.5"
        ),
        "{e}"
    );
    let e = error_with(BASE, &["bc.3.traction=[0, 1]"]);
    assert!(
        e.ends_with(": --set bc.3.traction: the scene has 2 `bc` entries, not 3"),
        "{e}"
    );
    let e = error_with(BASE, &["shedule.end_time=1.0"]);
    assert!(
        e.ends_with(
            ": --set shedule.end_time: unknown section `shedule`; did you mean `schedule`?"
        ),
        "{e}"
    );
    // A table made by an override, checked after the typed read.
    let e = error_with(BASE, &["schedule.end_time=1.0", "schedule.dt=-1"]);
    assert!(
        e.ends_with(": --set schedule.dt: schedule.dt = -1 must be > 0"),
        "{e}"
    );
    let e = error_with(BASE, &["schedule.end_time=1.0"]);
    assert!(
        e.ends_with(": --set schedule.end_time: schedule needs exactly one of dt and steps"),
        "{e}"
    );
    let e = error_with(BASE, &["grid.celss=[4, 4]"]);
    assert!(
        e.ends_with(": --set grid.celss: unknown key `celss` in [grid]; did you mean `cells`?"),
        "{e}"
    );
}

#[test]
fn overrides_change_the_scene_and_are_recorded() {
    let dir = std::env::temp_dir().join(format!("porofrac_scene_set_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, BASE).unwrap();
    let set: Vec<Override> = [
        "material.rock.youngs_modulus=2e10",
        "bc.2.traction=[0, -2e6]",
        "grid.kind=triangles",
    ]
    .iter()
    .map(|s| Override::parse(s).unwrap())
    .collect();
    let scene = Scene::load_with_overrides(&path, LawRegistry::default(), &set).unwrap();
    assert_eq!(scene.file().material["rock"].youngs_modulus, 2e10);
    assert_eq!(scene.file().grid.kind.as_str(), "triangles");
    let t = scene.file().bc[1].traction.as_ref().unwrap();
    assert_eq!(t[1], porofrac_scene::common::sections::NumOrExpr::Num(-2e6));
}
