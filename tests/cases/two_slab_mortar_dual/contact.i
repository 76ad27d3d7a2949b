begin contact definition
  contact surface lid_face contains lid_bottom
  contact surface base_face contains base_top
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = tied multipliers = dual
    side b variable temperature to temperature
  end
end
