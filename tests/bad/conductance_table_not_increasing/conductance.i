begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Table Of Gap = 0 1000 1e-3 100 1e-3 50
  end
end
