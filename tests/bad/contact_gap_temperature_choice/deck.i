begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance h = 10
    contact gap temperature = hotter
  end
end
