begin contact definition
  contact surface lid_face contains lid_bottom
  contact surface base_face contains base_top
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = lua "10 + 0.5*(temp_a + temp_b)"
  end
end
