begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Lua File = "h.lua" Function = h
  end
end
