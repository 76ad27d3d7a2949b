begin contact definition
  # Side set interface_a holds the tops of elements 108, 110, 112 and 114; with them
  # dead (see args) the surface has no face left, which is an error.
  contact surface top contains interface_a
end
