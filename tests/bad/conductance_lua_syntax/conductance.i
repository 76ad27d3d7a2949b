begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Lua "100 + * temp_a"
  end
end
