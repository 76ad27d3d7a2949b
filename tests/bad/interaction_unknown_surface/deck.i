begin contact definition
  contact surface top contains base_top
  contact surface lid contains lid_bottom
  begin interaction
    side a lid
    side b tpo
  end
end
