begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Radiation Emissivity_A = 0.8 Emisivity_B = 0.6
  end
end
