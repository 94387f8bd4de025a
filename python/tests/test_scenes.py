"""Scenes from files, text and dicts; keys set; every kind of error a Python exception
with the message of the command, its key, file and line."""

import subprocess
import tomllib

import pytest

import porofrac

PATCH = "scenes/patch_test.toml"


def command_error(porofrac_bin, scene, sets=()):
    args = [str(porofrac_bin), "check", str(scene)]
    for k, v in sets:
        args += ["--set", f"{k}={v}"]
    p = subprocess.run(args, capture_output=True, text=True)
    assert p.returncode != 0
    line = [x for x in p.stderr.splitlines() if x.startswith("error: ")][0]
    return line[len("error: ") :]


def line_of(text, needle):
    return next(i for i, l in enumerate(text.splitlines(), 1) if needle in l)


def test_load_from_toml_and_from_dict_agree(root):
    path = root / PATCH
    text = path.read_text()
    a = porofrac.Scene.load(path)
    b = porofrac.Scene.from_toml(text, path)
    c = porofrac.Scene.from_dict(tomllib.loads(text), path)
    assert a.to_dict() == b.to_dict() == c.to_dict() == tomllib.loads(text)
    ra = a.run(progress=False)
    rc = c.run(progress=False)
    assert ra.probes["ux_center"] == rc.probes["ux_center"]


def test_set_changes_the_dotted_key_and_to_toml_shows_it(root):
    s = porofrac.Scene.load(root / PATCH)
    s.set("material.rock.youngs_modulus", 2e10).set("bc.2.boundary", "xmax")
    d = tomllib.loads(s.to_toml())
    assert d["material"]["rock"]["youngs_modulus"] == 2e10
    assert d["bc"][1]["boundary"] == "xmax"
    assert s.overrides["material.rock.youngs_modulus"] == "20000000000.0"
    # The stress of the patch test scales with E.
    s0 = porofrac.Scene.load(root / PATCH).run(progress=False).probes["sxx_center"][0]
    s1 = s.run(progress=False).probes["sxx_center"][0]
    assert s1 == pytest.approx(20 * s0, rel=1e-12)
    assert s.run(progress=False).summary["overrides"]["material.rock.youngs_modulus"] == 2e10


def test_copies_are_independent(root):
    s = porofrac.Scene.load(root / PATCH)
    t = s.copy().set("material.rock.poisson_ratio", 0.2)
    assert s.overrides == {} and "material.rock.poisson_ratio" in t.overrides


def test_a_bad_value_is_a_scene_error_with_the_key_file_and_line(root, porofrac_bin, tmp_path):
    text = (root / PATCH).read_text().replace("poisson_ratio = 0.3", "poisson_ratio = 0.5")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(porofrac.SceneError) as e:
        porofrac.Scene.load(path)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.key == "material.rock.poisson_ratio"
    assert err.line == line_of(text, "poisson_ratio = 0.5")
    assert err.file == str(path)
    # The message the command prints.
    assert str(err) == command_error(porofrac_bin, path)


def test_a_bad_set_names_the_key_as_the_command_does(root, porofrac_bin):
    s = porofrac.Scene.load(root / PATCH).set("material.rock.poisson_ratio", 0.5)
    with pytest.raises(porofrac.SceneError) as e:
        s.check()
    assert e.value.line == 0
    assert "material.rock.poisson_ratio" in str(e.value)
    assert str(e.value) == command_error(
        porofrac_bin, root / PATCH, [("material.rock.poisson_ratio", "0.5")]
    )


def test_an_unknown_key_and_a_syntax_error_are_scene_errors(tmp_path):
    with pytest.raises(porofrac.SceneError) as e:
        porofrac.Scene.from_toml('[scene]\nname = "x"\ndim = 2\nbogus = 1\n', tmp_path / "u.toml")
    assert e.value.line == 4 and "bogus" in str(e.value)
    with pytest.raises(porofrac.SceneError) as e:
        porofrac.Scene.from_toml('[scene]\nname = "x\n', tmp_path / "s.toml")
    assert e.value.line == 2


def test_a_missing_file_is_a_scene_error(tmp_path):
    with pytest.raises(porofrac.SceneError) as e:
        porofrac.Scene.load(tmp_path / "nope.toml")
    assert "cannot read the scene file" in str(e.value)
    assert e.value.line == 0


def test_a_missing_mesh_fails_the_check_with_the_command_message(root, porofrac_bin, tmp_path):
    text = (root / PATCH).read_text()
    text = text.replace('kind = "cartesian"', 'kind = "file"\npath = "missing.msh"')
    text = "\n".join(
        l for l in text.splitlines() if not l.startswith(("extent", "cells", "seed", "perturb"))
    )
    path = tmp_path / "m.toml"
    path.write_text(text)
    with pytest.raises((porofrac.SceneError, porofrac.RunError)) as e:
        porofrac.Scene.load(path).check()
    assert str(e.value) == command_error(porofrac_bin, path)


def test_set_refuses_a_bad_key_and_an_unwritable_value(root):
    s = porofrac.Scene.load(root / PATCH)
    with pytest.raises(ValueError):
        s.set("material..rock", 1.0)
    with pytest.raises(ValueError):
        s.set("material.rock.youngs_modulus", object())


def test_check_describes_the_run(root):
    plan = porofrac.Scene.load(root / PATCH).check()
    assert plan["model"] == "continuum" and plan["dim"] == 2
    assert plan["counts"] == {"cells": 64, "nodes": 81, "unknowns": 98}


def test_help_and_version():
    import pydoc

    text = pydoc.render_doc(porofrac.Scene)
    for name in ("load", "from_toml", "from_dict", "set", "check", "run", "SI units"):
        assert name in text
    assert porofrac.__version__
    assert issubclass(porofrac.SceneError, ValueError)
    assert issubclass(porofrac.RunError, RuntimeError)


def test_the_heap_policy_of_the_command_applies_on_glibc():
    import platform

    applied = porofrac.retain_freed_memory()
    assert applied == (platform.system() == "Linux" and platform.libc_ver()[0] == "glibc")
