# The three contacts of a spot weld, each joining both equations. The conductances are
# tables of the contact's mean temperature: electrical in S/m², thermal in W/m²K.
begin contact definition electrode_top
  contact surface top_tip contains top_tip
  contact surface top_sheet_up contains top_sheet_up
  begin interaction
    side a top_tip
    side b top_sheet_up
  end
  begin enforcement thermal
    enforcement for energy = gap_conductance
    gap conductance coefficient = table of temperature = 300 1e5 1000 3e5
  end
  begin enforcement electrical
    enforcement for voltage = gap_conductance
    gap conductance coefficient = table of temperature = 300 5e9 1000 2e10
  end
end

begin contact definition faying
  contact surface top_sheet_down contains top_sheet_down
  contact surface bottom_sheet_up contains bottom_sheet_up
  begin interaction
    side a top_sheet_down
    side b bottom_sheet_up
  end
  begin enforcement thermal
    enforcement for energy = gap_conductance
    gap conductance coefficient = table of temperature = 300 5e4 1000 2e5
  end
  begin enforcement electrical
    enforcement for voltage = gap_conductance
    gap conductance coefficient = table of temperature = 300 1e9 1000 5e9
  end
end

begin contact definition electrode_bottom
  contact surface bottom_tip contains bottom_tip
  contact surface bottom_sheet_down contains bottom_sheet_down
  begin interaction
    side a bottom_tip
    side b bottom_sheet_down
  end
  begin enforcement thermal
    enforcement for energy = gap_conductance
    gap conductance coefficient = table of temperature = 300 1e5 1000 3e5
  end
  begin enforcement electrical
    enforcement for voltage = gap_conductance
    gap conductance coefficient = table of temperature = 300 5e9 1000 2e10
  end
end
