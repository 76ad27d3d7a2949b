"""Two boxes meshed apart in scikit-fem, joined by seam: tied, then through a gap
conductance.

The unit cube is cut at z = 1/2 into a lower part A (conductivity k_a, n_a cells per
edge) and an upper part B (k_b, n_b cells): their meshes do not match at the cut.
scikit-fem assembles each part's conduction matrix; seam adds the interface terms in
the host's dof numbers (part A's nodes first, then part B's). With the exact solution
on the outer boundary, a field linear in each part crosses the interface exactly:

* tied: u = x + 2y + g (z − 1/2) + 1 with k_a g_a = k_b g_b (the flux is continuous);
* gap conductance h: the same in A, and B's field lower by the jump q / h, where q is
  the flux through the interface (the heat flows from B to A: u grows with z).

Run: python python/examples/skfem_two_boxes.py (needs scikit-fem, scipy, seam).
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem
from skfem.models.poisson import laplace

import seam

# Exodus II local node k of a Hex8 is scikit-fem's local node SKFEM_OF_EXODUS[k]
# (scikit-fem orders its reference nodes (0,0,0), (0,1,0), (1,0,0), (0,0,1), (1,1,0),
# (0,1,1), (1,0,1), (1,1,1); Exodus goes round the bottom face, then the top).
SKFEM_OF_EXODUS = [0, 2, 4, 1, 3, 6, 7, 5]

CUT = 0.5


class TwoBoxes:
    """The host: two scikit-fem hex meshes, one conduction matrix, one dof per node."""

    def __init__(self, n_a=3, n_b=4, k_a=2.0, k_b=5.0):
        self.k_a, self.k_b = k_a, k_b
        line = lambda n, lo, hi: np.linspace(lo, hi, n + 1)
        self.parts = []
        for n, lo, hi, k in ((n_a, 0.0, CUT, k_a), (n_b, CUT, 1.0, k_b)):
            mesh = skfem.MeshHex.init_tensor(line(n, 0, 1), line(n, 0, 1), line(n, lo, hi))
            basis = skfem.Basis(mesh, skfem.ElementHex1())
            self.parts.append((mesh, k * laplace.assemble(basis)))
        (mesh_a, k_mat_a), (mesh_b, k_mat_b) = self.parts
        self.offset_b = mesh_a.nvertices
        self.coords = np.vstack([mesh_a.p.T, mesh_b.p.T])
        self.n = len(self.coords)
        self.K = sp.block_diag([k_mat_a, k_mat_b], format="csr")
        # The outer boundary: every boundary node of either part off the cut.
        boundary = []
        for part, (mesh, _) in enumerate(self.parts):
            offset = 0 if part == 0 else self.offset_b
            nodes = mesh.boundary_nodes()
            off_cut = ~np.isclose(mesh.p[2, nodes], CUT) | _on_side(mesh.p[:, nodes])
            boundary.append(nodes[off_cut] + offset)
        self.boundary = np.concatenate(boundary)

    def cut_faces(self, part):
        """The faces of `part` (0: A, 1: B) on the cut, as corner node lists."""
        mesh = self.parts[part][0]
        facets = mesh.facets_satisfying(lambda x: np.isclose(x[2], CUT), boundaries_only=True)
        return mesh.facets[:, facets].T + (0 if part == 0 else self.offset_b)

    def embedding(self, **builder):
        """seam over this host: blocks `a` and `b`, surfaces `a_top` and `b_bottom`."""
        b = seam.Builder(self.coords)
        for part, (name, k) in enumerate((("a", self.k_a), ("b", self.k_b))):
            mesh = self.parts[part][0]
            offset = 0 if part == 0 else self.offset_b
            b.block(name, "hex8", mesh.t[SKFEM_OF_EXODUS].T + offset, k)
        b.face_set("a_top", self.cut_faces(0)).face_set("b_bottom", self.cut_faces(1))
        b.dofs(np.arange(self.n)).fixed_nodes(self.boundary)
        for key, value in builder.items():
            getattr(b, key)(*value)
        return b.build()

    def solve(self, matrix, rhs, fixed_values):
        """Solve `matrix u = rhs` with u = fixed_values on the outer boundary."""
        u = np.zeros(self.n)
        u[self.boundary] = fixed_values
        free = np.setdiff1d(np.arange(self.n), self.boundary)
        a = matrix.tocsr()
        b = rhs[free] - a[free][:, self.boundary] @ u[self.boundary]
        u[free] = spla.spsolve(a[free][:, free].tocsc(), b)
        return u


def _on_side(p):
    """Points on the four side faces x, y ∈ {0, 1}."""
    return np.isclose(p[0], 0) | np.isclose(p[0], 1) | np.isclose(p[1], 0) | np.isclose(p[1], 1)


def exact(host, h=None):
    """The exact field at every node: tied (h None) or through gap conductance h."""
    g_a = 3.0
    g_b = g_a * host.k_a / host.k_b
    x, y, z = host.coords.T
    u = x + 2 * y + 1.0 + np.where(np.arange(host.n) < host.offset_b, g_a, g_b) * (z - CUT)
    if h is not None:
        # q_A = −k_a g_a leaves A through its top (normal +z) and equals h (u_A − u_B).
        jump = -host.k_a * g_a / h
        u[host.offset_b :] -= jump
    return u, host.k_a * g_a


def solve_linear(host, model, h=0.0, **interaction):
    """The host's linear solve with seam's interface terms (taken once at u = 0)."""
    e = host.embedding()
    e.add_interaction("a_top", "b_bottom", model, h=h, **interaction)
    e.search()
    terms = e.evaluate(np.zeros(host.n))
    u_exact, _ = exact(host, None if model.startswith("tied") else h)
    u = host.solve(host.K + terms.jacobian, terms.load, u_exact[host.boundary])
    return e, u, u_exact


def main():
    host = TwoBoxes()
    print(f"two boxes: {host.parts[0][0].nelements} + {host.parts[1][0].nelements} hexes, {host.n} nodes")
    for label, model, h in (
        ("tied (Nitsche)", "tied_nitsche", 0.0),
        ("gap conductance h = 500 W/m²/K", "gap_conductance", 500.0),
    ):
        e, u, u_exact = solve_linear(host, model, h)
        heat = e.heat(u)[0]
        _, q = exact(host, h if model == "gap_conductance" else None)
        # Heat leaving A through the unit-area cut: the flux k_a g_a flows into A (−q).
        print(
            f"{label}: max |u − u_exact| = {np.abs(u - u_exact).max():.2e} K, "
            f"heat leaving A {heat.side_a:.12f} W (exact {-q:.1f}), "
            f"A + B = {heat.side_a + heat.side_b:.1e} W"
        )


if __name__ == "__main__":
    main()
