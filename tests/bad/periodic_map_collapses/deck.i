begin contact definition
  contact surface bottom contains base_bottom
  contact surface top contains base_top
  # Every node of the bottom lands on one point of the top: the image "lands" on the
  # top and every point would pair, but the map is not a periodic map.
  periodicity for bottom = mapped x_map = collapse.lua:centre y_map = 0.5 z_map = "z + 1"
end
