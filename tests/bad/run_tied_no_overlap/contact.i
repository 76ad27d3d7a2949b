begin contact definition
  # The base's bottom (z = 0) and the lid's top (z = 1.5) never meet.
  contact surface low contains base_bottom
  contact surface high contains lid_top
  begin enforcement
    enforcement for energy = tied_temperature
  end
end
