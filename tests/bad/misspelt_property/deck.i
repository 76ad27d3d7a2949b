begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 10
    gap conductence coefficient = constant h = 5
  end
end
