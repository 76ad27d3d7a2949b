"""seam: interface conditions for implicit finite-element heat-transfer hosts.

A host hands seam its mesh arrays (:class:`Builder`), adds interactions between its
surfaces (tied, gap conductance, contact resistance, periodic) in code or from a Sierra
contact deck, searches them, and at each Newton step asks for the interface terms at
its field: the Jacobian as a ``scipy.sparse.csr_matrix`` and the residual and load as
numpy arrays, in its own dof numbers.

Conventions (docs/embedding.md has them all):

* indices are 0-based: nodes are rows of the coordinate array, elements are numbered
  block after block in the order the blocks were given, dofs are the host's;
* element nodes and local sides follow Exodus II: a Hex8 lists its bottom face
  counter-clockwise seen from above, then the top face; sides are 1-based (Hex8 side 5
  is the bottom 0 3 2 1, side 6 the top 4 5 6 7);
* side A carries the integration points, side B is projected onto; heat is positive
  leaving a side, the gap positive open, fluxes from A to B;
* SI units: m, K, W, W/m/K (conductivity), W/m²/K (conductance), Pa, s;
* residuals follow R(u) = K u − F: add ``residual`` to R and ``jacobian`` to ∂R/∂u;
  for a linear model ``residual = jacobian @ u − load``.

Every failure raises a :class:`SeamError` subclass whose ``code`` is the status a C
host gets (``SEAM_ERR_*`` in seam.h), with ``message`` and ``help``.
"""

from seam._seam import (
    AlignSurface,
    ArgumentError,
    Builder,
    Contributions,
    Coverage,
    CutbackError,
    Cylindrical,
    DeckError,
    Embedding,
    EnforcementError,
    Evaluation,
    FaceFields,
    Heat,
    InternalError,
    Mapped,
    MeshError,
    NothingPairedError,
    OrderError,
    OtherRankError,
    PluginError,
    PointFields,
    PointState,
    Rectangular,
    SeamError,
    TieConstraints,
    __version__,
)

__all__ = [
    "AlignSurface",
    "ArgumentError",
    "Builder",
    "Contributions",
    "Coverage",
    "CutbackError",
    "Cylindrical",
    "DeckError",
    "Embedding",
    "EnforcementError",
    "Evaluation",
    "FaceFields",
    "Heat",
    "InternalError",
    "Mapped",
    "MeshError",
    "NothingPairedError",
    "OrderError",
    "OtherRankError",
    "PluginError",
    "PointFields",
    "PointState",
    "Rectangular",
    "SeamError",
    "TieConstraints",
    "__version__",
]
