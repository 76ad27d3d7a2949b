begin contact definition
  contact surface bottom contains base_bottom
  contact surface top contains base_top
  # The top is 1 above the bottom, not 1.02.
  periodicity for bottom = rectangular offset = 0 0 1.02
end
