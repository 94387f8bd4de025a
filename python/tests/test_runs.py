"""Runs from Python give the numbers of `porofrac run`, bit for bit; results are numpy
arrays; the GIL is released while a run steps; Ctrl-C stops a run with its partial
result; large fields are not copied."""

import csv
import json
import signal
import threading
import time

import numpy as np
import pytest

import porofrac

# Small versions of bundled scenes of every model: (scene, keys set).
SCENES = {
    "continuum": ("scenes/patch_test.toml", []),
    "hydrofrac": ("scenes/hydrofrac_seed.toml", [("schedule.end_time", "2.0")]),
    "nscd": ("scenes/nscd/column.toml", []),
    "lbm": (
        "scenes/lbm/taylor_green.toml",
        # 64 × 64 nodes, Δt = 0.244140625 s: 16 lattice steps in 4 output steps.
        [("lbm.spacing", "1.5625e-3"), ("schedule.end_time", "3.90625")],
    ),
    "cosserat": ("scenes/cosserat_shear_layer.toml", []),
    "lsm": ("scenes/lsm/brazilian.toml", [("schedule.end_time", "2e-4")]),
}

# Keys of summary.json that measure the machine, not the run: wall times, memory and
# throughputs.
MACHINE_KEYS = {"wall_seconds", "peak_memory_bytes", "mlups"}


def machine_key(k):
    return k in MACHINE_KEYS or k.endswith(("_seconds", "_per_second"))


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    header = [c.split(" [")[0] for c in rows[0]]
    data = np.array([[float(x) for x in r] for r in rows[1:]]).reshape(-1, len(header))
    return header, data


def scene_with(root, name):
    path, sets = SCENES[name]
    scene = porofrac.Scene.load(root / path)
    for k, v in sets:
        scene.set(k, float(v))
    return scene, root / path, sets


def without_machine(summary):
    return {k: v for k, v in summary.items() if not machine_key(k)}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_python_and_the_command_give_the_same_numbers(root, run_command, name):
    scene, path, sets = scene_with(root, name)
    result = scene.run(progress=False)
    out = run_command(path, sets)
    with open(out / "summary.json") as f:
        expected = json.load(f)
    # Every number of summary.json but the machine's (wall times, memory) is identical.
    assert without_machine(result.summary) == without_machine(expected)
    assert result.summary["status"] == "ok"
    # Probes: the same values at the same times, bit for bit (the CSV holds the
    # shortest round-trip form of every number).
    header, data = read_csv(out / "probes.csv")
    assert list(result.probes) == header
    for j, h in enumerate(header):
        np.testing.assert_array_equal(result.probes[h], data[:, j], err_msg=h)
        assert result.probes[h].dtype == np.float64
    # Lines: the rows of lines/<name>.csv.
    for line in scene.to_dict().get("output", {}).get("line", []):
        lh, ld = read_csv(out / "lines" / f"{line['name']}.csv")
        assert result.line_columns(line["name"]) == lh
        np.testing.assert_array_equal(result.lines[line["name"]], ld)
    # Nothing was written by the run kept in memory.
    assert result.out is None


def test_a_run_into_a_folder_writes_the_files_of_the_command(root, tmp_path):
    scene = porofrac.Scene.load(root / "scenes/patch_test.toml")
    result = scene.run(out=tmp_path / "o", progress=False)
    assert (tmp_path / "o" / "summary.json").exists()
    assert (tmp_path / "o" / "probes.csv").exists()
    assert result.out == str(tmp_path / "o")
    header, data = read_csv(tmp_path / "o" / "probes.csv")
    np.testing.assert_array_equal(result.probes[header[1]], data[:, 1])


def test_a_run_in_memory_writes_nothing(root, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scene = porofrac.Scene.load(root / "scenes/patch_test.toml")
    scene.run(progress=False)
    assert list(tmp_path.iterdir()) == []


def test_the_patch_test_state_is_affine(root):
    # The patch test: every node moves by u = A x + b, every cell has the same stress.
    r = porofrac.Scene.load(root / "scenes/patch_test.toml").run(progress=False)
    g = r.grid
    assert g.dim == 2 and g.points.shape == (81, 3) and g.num_cells == 64
    a = np.array([[1e-3, 2e-4], [-5e-4, 3e-4]])
    b = np.array([1e-4, -2e-4])
    u = r.field("displacement")
    assert u.shape == (81, 2)
    np.testing.assert_allclose(u, g.points[:, :2] @ a.T + b, atol=1e-15)
    s = r.field("stress")
    assert s.shape == (64, 6)
    np.testing.assert_allclose(s - s[0], 0.0, atol=1e-6 * np.abs(s).max())
    assert set(np.unique(g.cell_types)) <= {5, 7, 9}
    assert g.offsets[-1] == len(g.connectivity)


def test_particles_and_lattices_are_arrays(root):
    scene, _, _ = scene_with(root, "nscd")
    r = scene.run(progress=False)
    p = r.particles()
    assert p["positions"].shape == (10, 2) and p["radii"].shape == (10,)
    np.testing.assert_array_equal(p["radii"], 0.5)
    # The bottom disk rests on the floor: its centre is at its radius, within 1 %.
    assert abs(p["positions"][0, 1] - 0.5) < 5e-3
    assert p["links"].shape[1] == 4 and len(p["normal_force"]) == len(p["links"])
    scene, _, _ = scene_with(root, "lbm")
    r = scene.run(progress=False)
    lat = r.lattice()
    assert lat["vx"].shape == (64, 64) and lat["pressure"].shape == (64, 64)
    # The Taylor–Green vortex: vx is odd in y about the box centre (sin(ky)) and its
    # peak decays from 1e-3 m/s.
    vmax = np.abs(lat["vx"]).max()
    assert 0.5e-3 < vmax < 1e-3


def test_the_gil_is_released_while_a_run_steps(root):
    scene, _, _ = scene_with(root, "lbm")
    scene.set("schedule.end_time", 39.0625)  # 160 lattice steps in 4 output steps
    counter = {"n": 0, "stop": False}

    def count():
        while not counter["stop"]:
            counter["n"] += 1
            time.sleep(0.001)

    steps_seen = []

    def progress(step, total, t):
        steps_seen.append((step, counter["n"]))

    t = threading.Thread(target=count)
    t.start()
    try:
        scene.run(progress=progress)
    finally:
        counter["stop"] = True
        t.join()
    # The second thread counted while the steps ran: between the first and the last
    # progress report its count went up.
    assert len(steps_seen) == 5
    assert steps_seen[-1][1] > steps_seen[0][1]


def test_ctrl_c_stops_a_run_with_its_partial_result(root):
    import _thread

    scene, _, _ = scene_with(root, "lbm")
    # 128 × 128 nodes, Δt = 0.06103515625 s; 250 lattice steps in 125 output steps.
    scene.set("lbm.spacing", 7.8125e-4)
    scene.set("schedule.end_time", 15.2587890625)
    scene.set("schedule.steps", 125)
    fired = []

    def progress(step, total, t):
        if step == 2 and not fired:
            fired.append(step)
            # As Ctrl-C does: a KeyboardInterrupt pending in the main thread, raised from
            # another thread; joined, so that it is pending before the run goes on however
            # late the thread is scheduled on a loaded machine.
            timer = threading.Timer(0.0, _thread.interrupt_main)
            timer.start()
            timer.join()
            time.sleep(0.05)

    # Python turns Ctrl-C into KeyboardInterrupt only if it inherited SIGINT unignored: a
    # test run started in the background by a non-interactive shell ignores it, and
    # `interrupt_main` then does nothing. The handler an interactive session has is set.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            scene.run(progress=progress)
    finally:
        signal.signal(signal.SIGINT, previous)
    partial = e.value.result
    assert isinstance(partial, porofrac.Result)
    assert partial.summary["status"].startswith("interrupted at t = ")
    n = len(partial.probes["time"])
    assert 3 <= n < 126
    assert partial.summary["steps"] == n - 1


def test_large_fields_are_not_copied(root):
    # A 2048 × 1024 lattice: 2.1 M nodes, so every field has 2.1 M values (16 MB); one
    # lattice step (Δt = 0.1 Δx² / ν).
    scene, _, _ = scene_with(root, "lbm")
    dx = 0.1 / 1024
    scene.set("lbm.extent", [[0.0, 0.0], [0.2, 0.1]])
    scene.set("lbm.spacing", dx)
    scene.set("schedule.end_time", 0.1 * dx * dx / 1e-6)
    scene.set("schedule.steps", 1)
    r = scene.run(progress=False)
    p = r.lattice(0)["pressure"]
    assert p.size >= 2_000_000
    # The numpy array holds the very buffer the run filled in Rust...
    address = r._inner.buffer_addresses[0]["lattice:pressure"]
    assert p.ctypes.data == address
    # ...and does not own a copy of it.
    assert not p.flags.owndata
    # Reading it twice gives the same memory.
    assert r.lattice(0)["pressure"].ctypes.data == address


def test_progress_is_reported_after_every_step(root):
    seen = []
    scene, _, _ = scene_with(root, "nscd")
    scene.run(progress=lambda step, total, t: seen.append((step, total, t)))
    assert [s for s, _, _ in seen] == list(range(len(seen)))
    assert seen[-1][0] == seen[-1][1] - 1
    assert seen[-1][2] == pytest.approx(0.05)


def test_a_progress_callback_that_raises_stops_the_run(root):
    scene, _, _ = scene_with(root, "nscd")

    def progress(step, total, t):
        if step == 3:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        scene.run(progress=progress)


def test_probes_frame_is_a_dataframe_indexed_by_time(root):
    pd = pytest.importorskip("pandas")
    scene, _, _ = scene_with(root, "nscd")
    r = scene.run(progress=False)
    f = r.probes_frame()
    assert isinstance(f, pd.DataFrame)
    np.testing.assert_array_equal(f.index.values, r.probes["time"])
    assert list(f.columns) == [k for k in r.probes if k != "time"]


def test_to_meshio_has_the_grid_and_fields(root):
    meshio = pytest.importorskip("meshio")
    r = porofrac.Scene.load(root / "scenes/patch_test.toml").run(progress=False)
    m = r.to_meshio()
    assert isinstance(m, meshio.Mesh)
    assert len(m.points) == 81
    assert sum(len(c.data) for c in m.cells) == 64
    np.testing.assert_array_equal(m.point_data["displacement"], r.field("displacement"))


def test_tqdm_progress_runs(root, capsys):
    pytest.importorskip("tqdm")
    scene, _, _ = scene_with(root, "nscd")
    r = scene.run(progress=True)
    assert r.summary["status"] == "ok"


def test_fields_false_keeps_probes_and_no_state(root):
    scene = porofrac.Scene.load(root / "scenes/patch_test.toml")
    full = scene.run(progress=False)
    light = scene.run(progress=False, fields=False)
    np.testing.assert_array_equal(light.probes["ux_center"], full.probes["ux_center"])
    assert light.grid is None and full.grid is not None
    with pytest.raises(ValueError):
        light.field("displacement")
