begin contact definition
  contact surface top contains surface_1
  begin enforcement gap
    enforcement for energy gap_conductance
    gap conductance coefficient = constant h = 100
    Offset Voltage = Constant Value = 0.1
    Offset Solid Displacements = Constant Value = 0
    User Expression = "2 * h"
  end
end
