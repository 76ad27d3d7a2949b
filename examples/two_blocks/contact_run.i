# The interface of the two-block example, enforced by a gap conductance.
begin contact definition two_blocks
  contact surface interface_base contains base_top
  contact surface interface_lid contains lid_bottom
  begin interaction
    side a interface_base
    side b interface_lid
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 500
  end
end
