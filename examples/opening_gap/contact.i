# The base's top against the lid's bottom: air across the gap, conductance k / g with
# the gap as the lid's motion makes it. The faces are searched anew every 5 steps and
# refitted in between.
begin contact definition lift
  contact surface base_top contains base_top
  contact surface lid_bottom contains lid_bottom
  update search every 5 steps
  begin search options
    normal tolerance = 0.01
  end
  begin interaction
    side a base_top
    side b lid_bottom
  end
  begin enforcement air
    enforcement for energy = gap_conductance
    gap conductance coefficient = gas_gap k = 0.026 min_gap = 1e-5
  end
end
