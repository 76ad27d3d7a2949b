begin contact definition
  contact surface base_face contains base_top
  contact surface lid_face contains lid_bottom
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = contact_resistance
    gap conductance coefficient = cmy k_a = 16 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 3e9
    contact pressure = 1e6
  end
end
