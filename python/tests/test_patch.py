"""Patch tests through the package: a field linear in each part crosses the non-matching
cut of two scikit-fem boxes exactly (round-off), tied or through a conductance, and the
heat through the cut is the exact flux times the cut's area (1 m²)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg  # noqa: F401  (sp.linalg)

import seam
from skfem_two_boxes import SKFEM_OF_EXODUS, TwoBoxes, exact, solve_linear

# Round-off of a 189-node solve: the nodal values are O(1), the matrices' condition
# number O(1e2); 1e-11 leaves three decades above what is measured (3e-15).
ROUND_OFF = 1e-11


@pytest.fixture(scope="module")
def host():
    return TwoBoxes(n_a=3, n_b=4, k_a=2.0, k_b=5.0)


@pytest.mark.parametrize(
    "model, h",
    [
        ("tied_nitsche", 0.0),
        ("gap_conductance", 500.0),
        ("gap_conductance", 0.3),
        ("gap_conductance", 1e9),
        ("conductance", 40.0),
    ],
)
def test_linear_field_crosses_the_cut_exactly(host, model, h):
    e, u, u_exact = solve_linear(host, model, h)
    assert np.abs(u - u_exact).max() < ROUND_OFF
    _, q = exact(host, None if model == "tied_nitsche" else h)
    heat = e.heat(u)[0]
    assert heat.side_a == pytest.approx(-q, abs=1e-10)
    assert abs(heat.side_a + heat.side_b) < 1e-10


def test_the_triplets_and_the_csr_pattern_hold_the_same_matrix(host):
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", "gap_conductance", h=500.0)
    e.search()
    u = np.random.default_rng(1).random(host.n)
    c, v = e.contributions(u), e.evaluate(u)
    assert abs(c.jacobian - v.jacobian).max() < 1e-12 * abs(v.jacobian).max()
    assert np.abs(c.residual - v.residual).max() < 1e-12
    # Linear model: R = J u − load.
    assert np.abs(v.jacobian @ u - v.load - v.residual).max() < 1e-12
    # The pattern is kept until the next search.
    assert e.evaluate(2 * u).pattern == v.pattern
    e.search()
    assert e.evaluate(u).pattern == v.pattern + 1


def test_standard_mortar_tie_through_the_constraint_rows(host):
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", "tied_mortar", multipliers="standard")
    e.search()
    (tie,) = e.constraints()
    c = tie.matrix(host.n)
    m = c.shape[0]
    assert m == len(tie.multiplier_dofs) > 0
    u_exact, q = exact(host)
    # [K Cᵀ; C 0] [u; λ] = [0; g], u fixed on the outer boundary.
    saddle = sp.bmat([[host.K, c.T], [c, None]], format="csr")
    n = host.n
    free = np.setdiff1d(np.arange(n + m), host.boundary)
    x = np.zeros(n + m)
    x[host.boundary] = u_exact[host.boundary]
    rhs = np.concatenate([np.zeros(n), tie.rhs]) - saddle[:, host.boundary] @ x[host.boundary]
    x[free] = sp.linalg.spsolve(saddle[free][:, free].tocsc(), rhs[free])
    u, lam = x[:n], x[n:]
    assert np.abs(u - u_exact).max() < ROUND_OFF
    heat = tie.heat(lam)
    assert heat.side_a == pytest.approx(-q, abs=1e-9)
    fields = e.tie_point_fields(tie, lam)
    paired = np.asarray(fields.paired)
    # λ is the flux from A to B: −q everywhere on the cut.
    assert np.abs(fields.multiplier[paired] + q).max() < 1e-8


def test_dual_mortar_tie_condensed(host):
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", "tied_mortar", multipliers="dual")
    e.search()
    (tie,) = e.constraints()
    dofs, constants, t = tie.condensed(host.n)
    assert len(dofs) > 0
    # u = P ũ + g: P is the identity on the kept dofs and T on the condensed ones.
    n = host.n
    kept = np.setdiff1d(np.arange(n), dofs)
    mask = np.ones(n)
    mask[dofs] = 0.0
    rows_of_t = sp.csr_matrix((np.ones(len(dofs)), (dofs, np.arange(len(dofs)))), shape=(n, len(dofs)))
    p = (sp.diags(mask) + rows_of_t @ t).tocsr()
    g = np.zeros(n)
    g[dofs] = constants
    u_exact, q = exact(host)
    reduced = (p.T @ host.K @ p).tocsr()
    rhs = -(p.T @ (host.K @ g))
    fixed = host.boundary
    free = np.setdiff1d(kept, fixed)
    w = np.zeros(n)
    w[fixed] = u_exact[fixed]
    rhs_free = rhs[free] - reduced[free][:, fixed] @ w[fixed]
    w[free] = sp.linalg.spsolve(reduced[free][:, free].tocsc(), rhs_free)
    u = p @ w + g
    assert np.abs(u - u_exact).max() < ROUND_OFF
    lam = tie.dual_multipliers(host.K @ u)
    assert tie.heat(lam).side_a == pytest.approx(-q, abs=1e-9)


def test_a_deck_gives_the_same_tie(host):
    e = host.embedding()
    added = e.add_deck(
        """begin contact definition cut
  contact surface lower contains a_top
  contact surface upper contains b_bottom
  begin interaction
    side a lower
    side b upper
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 500
  end
end
""",
        name="cut.i",
    )
    assert added == [0]
    e.search()
    terms = e.evaluate(np.zeros(host.n))
    u_exact, q = exact(host, 500.0)
    u = host.solve(host.K + terms.jacobian, terms.load, u_exact[host.boundary])
    assert np.abs(u - u_exact).max() < ROUND_OFF


def test_coverage_and_fields_of_a_fully_paired_cut(host):
    e, u, _ = solve_linear(host, "gap_conductance", 500.0)
    cov = e.coverage(0)
    assert cov.paired_points == cov.points > 0
    assert cov.area == pytest.approx(1.0, abs=1e-12)
    assert cov.paired_area == pytest.approx(1.0, abs=1e-12)
    assert len(cov.unpaired_reasons) == 0
    points = e.point_fields(0, u)
    assert points.x.shape == (cov.points, 3)
    assert np.all(points.paired)
    assert np.all(points.side_a_side == 6)  # scikit-fem's top faces are Exodus side 6
    assert np.all(points.side_b_side == 5)
    # The flux from A to B is −k_a g_a = −6 W/m² everywhere; jump q/h = 0.012 K.
    assert np.abs(points.flux + 6.0).max() < 1e-9
    assert np.abs(points.temp_b - points.temp_a - 0.012).max() < 1e-11
    faces = e.face_fields(0, u, side_b=True)
    assert np.all(np.isclose(faces.fraction, 1.0))
    assert np.abs(faces.flux + 6.0).max() < 1e-9
    assert set(np.asarray(faces.surface)) == {0, 1}


def test_periodic_tie_with_a_jump_across_a_box(host):
    """Box A's faces x = 1 and x = 0 tied through the map x ↦ x − 1 with the jump
    u(1, y, z) − u(0, y, z) = 0.7 K: the field 2y + 3z + 0.7x is exact, and 0.7 k_a W/m²
    flows in through x = 1 over its 0.5 m²."""
    mesh, k_mat = host.parts[0]

    def faces(x0):
        f = mesh.facets_satisfying(lambda x: np.isclose(x[0], x0), boundaries_only=True)
        return mesh.facets[:, f].T

    e = (
        seam.Builder(mesh.p.T)
        .block("a", "hex8", mesh.t[SKFEM_OF_EXODUS].T, host.k_a)
        .face_set("east", faces(1.0))
        .face_set("west", faces(0.0))
        .dofs(np.arange(mesh.nvertices))
        .build()
    )
    jump = 0.7
    e.add_interaction("east", "west", "tied_nitsche", offset=jump, periodic=seam.Rectangular((-1.0, 0.0, 0.0)))
    e.search()
    terms = e.evaluate(np.zeros(mesh.nvertices))
    x, y, z = mesh.p
    u_exact = 2 * y + 3 * z + jump * x
    fixed = np.flatnonzero(np.isclose(y, 0) | np.isclose(y, 1) | np.isclose(z, 0) | np.isclose(z, 0.5))
    free = np.setdiff1d(np.arange(mesh.nvertices), fixed)
    a = (k_mat + terms.jacobian).tocsr()
    u = u_exact.copy()
    u[free] = sp.linalg.spsolve(
        a[free][:, free].tocsc(), terms.load[free] - a[free][:, fixed] @ u_exact[fixed]
    )
    assert np.abs(u - u_exact).max() < ROUND_OFF
    assert e.heat(u)[0].side_a == pytest.approx(-jump * host.k_a * 0.5, abs=1e-10)
