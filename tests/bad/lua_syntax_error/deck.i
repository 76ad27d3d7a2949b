begin contact definition
  contact surface bottom contains base_bottom
  contact surface top contains base_top
  periodicity for bottom = mapped x_map = maps.lua:shift_x y_map = y z_map = "z + 1"
end
