begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Radiation Emissivity_A = 1.5 Emissivity_B = 0.6
  end
end
