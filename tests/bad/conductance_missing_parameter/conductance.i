begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = CMY K_A = 16 K_B = 200 Slope = 0.1 Hardness = 3e9
  end
end
