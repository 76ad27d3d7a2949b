# The interface of the two-block example, enforced by a gap conductance.
# Visualize Contact: seam run writes the contact fields (out/contact.vtu and nodal
# variables in out/results.exo); Output Rule = verbose adds the lid's faces to contact.vtu.
begin contact definition two_blocks
  contact surface interface_base contains base_top
  contact surface interface_lid contains lid_bottom
  visualize contact
  output rule = verbose
  begin interaction
    side a interface_base
    side b interface_lid
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 500
  end
end
