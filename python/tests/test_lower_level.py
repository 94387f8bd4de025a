"""porofrac.grid and porofrac.laws: grids without a scene and local cell-law matrices,
checked against closed forms (patch test, rigid-body modes) and against `porofrac check`."""

import re
import subprocess

import numpy as np
import pytest

import porofrac

E, NU = 1.0, 0.3
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
MU = E / (2 * (1 + NU))


def null_dim(K, rel=1e-10):
    """Number of eigenvalues of the symmetric K below rel times the largest."""
    w = np.linalg.eigvalsh(K)
    return int(np.sum(np.abs(w) < rel * np.abs(w).max()))


def rigid_modes(points):
    """Translations and infinitesimal rotations as nodal displacement vectors."""
    p = np.asarray(points, dtype=float)
    n, d = p.shape
    modes = []
    for a in range(d):
        t = np.zeros((n, d))
        t[:, a] = 1
        modes.append(t.ravel())
    pairs = [(0, 1)] if d == 2 else [(0, 1), (1, 2), (0, 2)]
    for a, b in pairs:
        r = np.zeros((n, d))
        r[:, a], r[:, b] = -p[:, b], p[:, a]
        modes.append(r.ravel())
    return modes


def strain_energy_density_x2(eps):
    """ε:C:ε for isotropic C (plane strain in 2D)."""
    return 2 * MU * np.sum(eps * eps) + LAM * np.trace(eps) ** 2


SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
PENTAGON = [[0, 0], [2, 0], [2.5, 1.2], [1, 2], [-0.3, 1]]
EPS2 = np.array([[1e-3, 4e-4], [4e-4, -2e-3]])
EPS3 = np.array([[1e-3, 4e-4, -2e-4], [4e-4, -2e-3, 3e-4], [-2e-4, 3e-4, 5e-4]])
CUBE = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
CUBE_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [0, 4, 7, 3], [1, 2, 6, 5]]


def polygon_area(p):
    x, y = np.asarray(p, dtype=float).T
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def test_vem_unit_square_symmetric_three_rigid_modes():
    K = porofrac.laws.vem_stiffness(SQUARE, E=E, nu=NU)
    assert K.shape == (8, 8)
    np.testing.assert_allclose(K, K.T, atol=1e-14)
    assert null_dim(K) == 3
    for r in rigid_modes(SQUARE):
        assert np.abs(K @ r).max() < 1e-13


@pytest.mark.parametrize("points", [SQUARE, PENTAGON], ids=["square", "pentagon"])
def test_vem_patch_test_2d(points):
    # u = ε x: uᵀ K u = |Ω| ε:C:ε with plane-strain C.
    p = np.asarray(points, dtype=float)
    u = (p @ EPS2.T).ravel()
    K = porofrac.laws.vem_stiffness(points, E=E, nu=NU)
    expected = polygon_area(p) * strain_energy_density_x2(EPS2)
    assert u @ K @ u == pytest.approx(expected, rel=1e-12)


def test_vem_plane_stress_patch_test():
    p = np.asarray(SQUARE, dtype=float)
    u = (p @ EPS2.T).ravel()
    K = porofrac.laws.vem_stiffness(SQUARE, E=E, nu=NU, plane_stress=True)
    lam_star = 2 * LAM * MU / (LAM + 2 * MU)
    expected = 2 * MU * np.sum(EPS2 * EPS2) + lam_star * np.trace(EPS2) ** 2
    assert u @ K @ u == pytest.approx(expected, rel=1e-12)


def test_vem_polygon_order_follows_the_points():
    # The polygon given as node indices gives the matrix in the order of the points.
    perm = [2, 0, 3, 1]
    pts = np.asarray(SQUARE, dtype=float)[perm]
    inv = np.argsort(perm)
    K = porofrac.laws.vem_stiffness(pts, [int(i) for i in inv], E=E, nu=NU)
    K0 = porofrac.laws.vem_stiffness(SQUARE, E=E, nu=NU)
    dofs = np.ravel([[2 * i, 2 * i + 1] for i in perm])
    np.testing.assert_allclose(K, K0[np.ix_(dofs, dofs)], atol=1e-14)


def test_vem_unit_cube_3d():
    p = np.asarray(CUBE, dtype=float)
    K = porofrac.laws.vem_stiffness(CUBE, CUBE_FACES, E=E, nu=NU)
    assert K.shape == (24, 24)
    np.testing.assert_allclose(K, K.T, atol=1e-14)
    assert null_dim(K) == 6
    u = (p @ EPS3.T).ravel()
    assert u @ K @ u == pytest.approx(strain_energy_density_x2(EPS3), rel=1e-12)


TRIANGLE = [[0.1, 0.0], [1.3, 0.2], [0.4, 0.9]]
TETRA = [[0, 0, 0], [1.1, 0.1, 0], [0.2, 0.9, 0.1], [0.3, 0.2, 1.2]]


def triangle_area(p):
    return abs(polygon_area(p))


@pytest.mark.parametrize("law", ["mdem", "dem"])
def test_simplex_laws_symmetric_rigid_modes_2d(law):
    f = getattr(porofrac.laws, f"{law}_stiffness")
    K = f(TRIANGLE, E=E, nu=NU)
    assert K.shape == (6, 6)
    np.testing.assert_allclose(K, K.T, atol=1e-14)
    assert null_dim(K) == 3
    for r in rigid_modes(TRIANGLE):
        assert np.abs(K @ r).max() < 1e-13


@pytest.mark.parametrize("law", ["mdem", "dem"])
def test_simplex_laws_rigid_modes_3d(law):
    f = getattr(porofrac.laws, f"{law}_stiffness")
    K = f(TETRA, E=E, nu=NU)
    assert K.shape == (12, 12)
    np.testing.assert_allclose(K, K.T, atol=1e-14)
    assert null_dim(K) == 6


def test_mdem_equals_vem_on_a_triangle_and_passes_the_patch_test():
    Km = porofrac.laws.mdem_stiffness(TRIANGLE, E=E, nu=NU)
    Kv = porofrac.laws.vem_stiffness(TRIANGLE, E=E, nu=NU)
    np.testing.assert_allclose(Km, Kv, rtol=1e-12, atol=1e-14)
    u = (np.asarray(TRIANGLE) @ EPS2.T).ravel()
    expected = triangle_area(TRIANGLE) * strain_energy_density_x2(EPS2)
    assert u @ Km @ u == pytest.approx(expected, rel=1e-12)


def test_simplex_matrix_in_the_callers_order():
    # Clockwise input: the matrix is still in the order of the points given.
    cw = [TRIANGLE[0], TRIANGLE[2], TRIANGLE[1]]
    K = porofrac.laws.dem_stiffness(cw, E=E, nu=NU)
    K0 = porofrac.laws.dem_stiffness(TRIANGLE, E=E, nu=NU)
    dofs = [0, 1, 4, 5, 2, 3]
    np.testing.assert_allclose(K, K0[np.ix_(dofs, dofs)], atol=1e-14)


def test_dem_springs_act_along_edges():
    # Central forces: stretching edge (0, 1) alone loads nodes 0 and 1 along that edge.
    p = np.asarray(TRIANGLE)
    K = porofrac.laws.dem_stiffness(TRIANGLE, E=E, nu=NU)
    u = np.zeros(6)
    u[2:4] = p[1] - p[0]  # node 1 moves away from node 0 along the edge; node 2 fixed
    # Moving node 1 along edge 0-1 stretches that edge and changes edge 1-2; force on
    # node 0 comes from edge 0-1 only, so it is parallel to the edge.
    f0 = (K @ u)[0:2]
    e01 = p[1] - p[0]
    assert abs(f0[0] * e01[1] - f0[1] * e01[0]) < 1e-12 * np.linalg.norm(f0) * np.linalg.norm(e01)
    assert np.linalg.norm(f0) > 0


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: porofrac.laws.vem_stiffness([[0, 0], [1, 0]], E=E, nu=NU), "cell"),
        (lambda: porofrac.laws.vem_stiffness([[0, 0], [1, 0], [2, 0]], E=E, nu=NU), "cell"),
        (lambda: porofrac.laws.vem_stiffness(SQUARE, E=E, nu=0.5), "nu"),
        (lambda: porofrac.laws.vem_stiffness(CUBE, E=E, nu=NU), "faces"),
        (lambda: porofrac.laws.vem_stiffness(SQUARE, [0, 1, 2, 7], E=E, nu=NU), "cell"),
        (lambda: porofrac.laws.mdem_stiffness(SQUARE, E=E, nu=NU), "simplex"),
        (lambda: porofrac.laws.mdem_stiffness(TETRA, E=E, nu=NU, plane_stress=True), "plane_stress"),
        (lambda: porofrac.laws.vem_stiffness(np.zeros((5000, 2)), E=E, nu=NU), "at most"),
        (lambda: porofrac.laws.vem_stiffness([[0, 0], [1, np.nan], [0, 1]], E=E, nu=NU), "finite"),
    ],
)
def test_law_errors_name_the_argument(call, words):
    with pytest.raises(ValueError, match=words):
        call()


def test_generated_grids_counts_and_measures():
    g = porofrac.grid.cartesian([0, 0], [2, 1], [4, 2])
    assert (g.dim, g.num_cells, len(g.points)) == (2, 8, 15)
    assert g.volumes.sum() == pytest.approx(2.0, rel=1e-14)
    np.testing.assert_allclose(g.centroids[0], [0.25, 0.25], rtol=1e-14)
    assert set(g.cell_types.tolist()) == {9}
    t = porofrac.grid.triangles([0, 0], [1, 1], [3, 2])
    assert t.num_cells == 12 and set(t.cell_types.tolist()) == {5}
    assert t.volumes.sum() == pytest.approx(1.0, rel=1e-14)
    h = porofrac.grid.tetrahedra([0, 0, 0], [1, 2, 3], [2, 2, 2])
    assert h.volumes.sum() == pytest.approx(6.0, rel=1e-13)
    assert h.centroids.shape == (h.num_cells, 3)
    c = porofrac.grid.cartesian([0, 0, 0], [1, 1, 1], [2, 3, 4])
    assert (c.num_cells, len(c.points)) == (24, 3 * 4 * 5)
    v = porofrac.grid.voronoi([0, 0], [1, 1], 30, seed=7)
    assert v.num_cells == 30
    assert v.volumes.sum() == pytest.approx(1.0, rel=1e-12)
    w = porofrac.grid.voronoi([0, 0], [1, 1], 30, seed=7)
    np.testing.assert_array_equal(v.points, w.points)


def test_grid_sizes_refused_before_allocating():
    with pytest.raises(ValueError, match="cells"):
        porofrac.grid.cartesian([0, 0], [1, 1], [10**6, 10**6])
    with pytest.raises(ValueError, match="cells"):
        porofrac.grid.cartesian([0, 0, 0], [1, 1, 1], [2**40, 2**40, 2**40])
    with pytest.raises(ValueError, match="cells"):
        porofrac.grid.cartesian([0, 0], [1, 1], [0, 3])
    with pytest.raises(ValueError, match="lo"):
        porofrac.grid.cartesian([1, 0], [0, 1], [2, 2])
    with pytest.raises(ValueError, match="triangles"):
        porofrac.grid.triangles([0, 0, 0], [1, 1, 1], [2, 2, 2])


def check_counts(porofrac_bin, scene):
    out = subprocess.run(
        [str(porofrac_bin), "check", str(scene)], check=True, capture_output=True, text=True
    ).stdout
    m = re.search(r"(\d+) cells(?:, (\d+) nodes)?", out)
    assert m, out
    return int(m.group(1)), (int(m.group(2)) if m.group(2) else None)


def test_read_deck_has_the_counts_porofrac_check_prints(root, porofrac_bin):
    cells, nodes = check_counts(porofrac_bin, root / "scenes/corner_point/injection.toml")
    g = porofrac.grid.read(root / "scenes/corner_point/faulted.grdecl")
    assert (g.dim, g.num_cells, len(g.points)) == (3, cells, nodes)
    assert np.all(g.volumes > 0)


def test_read_mesh_has_the_counts_porofrac_check_prints(root, porofrac_bin):
    cells, _ = check_counts(porofrac_bin, root / "scenes/cosserat_plate_hole.toml")
    g = porofrac.grid.read(root / "scenes/meshes/cosserat_plate_hole.vtu", dim=2)
    assert (g.dim, g.num_cells) == (2, cells)
    assert np.all(g.volumes > 0)


def test_read_errors(root, tmp_path):
    with pytest.raises(ValueError, match="dim"):
        porofrac.grid.read(root / "scenes/meshes/cosserat_plate_hole.vtu")
    with pytest.raises(ValueError, match="missing.msh"):
        porofrac.grid.read(tmp_path / "missing.msh", dim=2)
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnonsense\n")
    with pytest.raises(ValueError, match="bad.msh"):
        porofrac.grid.read(bad, dim=2)
