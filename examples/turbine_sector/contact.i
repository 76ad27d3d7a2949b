# Cylindrical periodicity of the turbine-disk sector: the cut face at θ = 0, turned by
# 30° about the disk axis (z), lands on the cut face at θ = 30°; the two are tied by a
# mortar tie with Lagrange multipliers (on the image of cut_start, side A).
begin contact definition sector
  contact surface start contains cut_start
  contact surface end contains cut_end
  periodicity for start = cylindrical axis = 0 0 1 center = 0 0 0 angle = 30
  begin enforcement
    enforcement for energy = tied
    side b variable temperature to temperature
  end
end
