# The die's back side (side A) pressed against the heat sink's base (side B), without
# grease: the interface conductance is Cooper–Mikic–Yovanovich's for the two solids
# (k_A silicon, k_B aluminium), a combined surface slope and roughness, the softer
# solid's microhardness, at a clamping pressure of 0.5 MPa:
#   h = 1.25 k_s (m/σ) (p/H)^0.95 with k_s = 2 k_A k_B / (k_A + k_B).
# Visualize Contact writes the die's contact faces (gap, contact fraction, interface
# flux) to out/contact.vtu and to out/results.exo.
begin contact definition package
  contact surface die_back contains chip_top
  contact surface sink_base contains sink_bottom
  visualize contact
  begin interaction
    side a die_back
    side b sink_base
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = cmy k_a = 150 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 1e9
    contact pressure = 5e5
  end
end
