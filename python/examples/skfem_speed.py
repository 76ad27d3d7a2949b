"""Where a Python host's time goes: scikit-fem's assembly and scipy's solve against seam.

The two boxes of skfem_two_boxes.py, finer (by default 32³ + 40³ hexes, 104 858 nodes),
joined by a gap conductance (h = 500 W/m²/K). The host assembles its conduction matrix
with scikit-fem, seam builds its embedding, searches and evaluates the interface terms
once (the model is linear), and scipy solves with conjugate gradients (Jacobi
preconditioner, relative residual 1e-10). Prints each phase's wall time and the error
against the exact solution.

Run: python python/examples/skfem_speed.py [N_A N_B] (a release build of seam: pip
install ./python).
"""

import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from skfem_two_boxes import TwoBoxes, exact


def main(n_a=32, n_b=40, h=500.0):
    clock = {}
    t = time.perf_counter()
    host = TwoBoxes(n_a=n_a, n_b=n_b)  # meshes and scikit-fem's assembly of K
    clock["host: mesh + assembly (scikit-fem)"] = time.perf_counter() - t

    t = time.perf_counter()
    e = host.embedding()
    clock["seam: Builder.build (checks, faces)"] = time.perf_counter() - t
    t = time.perf_counter()
    e.add_interaction("a_top", "b_bottom", "gap_conductance", h=h)
    e.search()
    clock["seam: add_interaction + search"] = time.perf_counter() - t
    t = time.perf_counter()
    terms = e.evaluate(np.zeros(host.n))
    clock["seam: evaluate (CSR to scipy)"] = time.perf_counter() - t

    t = time.perf_counter()
    u_exact, _ = exact(host, h)
    a = (host.K + terms.jacobian).tocsr()
    fixed = host.boundary
    free = np.setdiff1d(np.arange(host.n), fixed)
    u = np.zeros(host.n)
    u[fixed] = u_exact[fixed]
    a_ff = a[free][:, free]
    b = terms.load[free] - a[free][:, fixed] @ u[fixed]
    jacobi = sp.diags(1.0 / a_ff.diagonal())
    u[free], info = spla.cg(a_ff, b, rtol=1e-10, M=jacobi, maxiter=20000)
    clock["host: Dirichlet rows + CG solve (scipy)"] = time.perf_counter() - t
    assert info == 0, info

    print(f"{host.n} unknowns, {e.coverage(0).points} contact points")
    for phase, seconds in clock.items():
        print(f"  {phase:42s} {seconds:7.3f} s")
    seam_s = sum(s for p, s in clock.items() if p.startswith("seam"))
    host_s = sum(s for p, s in clock.items() if p.startswith("host"))
    print(f"  seam {seam_s:.3f} s against the host's {host_s:.3f} s ({100 * seam_s / host_s:.1f} %)")
    print(f"  max |u − u_exact| = {np.abs(u - u_exact).max():.2e} K (CG to 1e-10)")


if __name__ == "__main__":
    main(*map(int, sys.argv[1:3]))
