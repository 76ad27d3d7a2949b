# The bolted overlap of the two bars: one interaction, with an enforcement for each
# equation it joins.
begin contact definition joint
  contact surface a_joint contains a_joint
  contact surface b_joint contains b_joint
  begin interaction
    side a a_joint
    side b b_joint
  end
  begin enforcement thermal
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 5000
  end
  begin enforcement electrical
    enforcement for voltage = gap_conductance
    gap conductance coefficient = constant h = 8e7
  end
end
