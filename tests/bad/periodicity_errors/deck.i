begin contact definition main
  contact surface left contains ss_left
  contact surface right contains ss_right
  periodicity for left = rectangular offset = 1 0 0 z_map = "z"
  periodicity for right = cylindrical axis = 0 0 0 centre = 0 0 0 angle = 30
  periodicity for left = helical pitch = 2
  periodicity for right = align_surface
end
