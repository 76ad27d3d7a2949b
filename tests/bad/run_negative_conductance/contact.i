begin contact definition
  contact surface lid_face contains lid_bottom
  contact surface base_face contains base_top
  begin enforcement
    enforcement for energy = contact_resistance
    gap conductance coefficient = constant h = -5
  end
end
