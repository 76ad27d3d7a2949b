# The plates' interface carries the conductance of the C example plugin
# (plugins/examples/c_table): a table of h against contact pressure,
# Real Data = p0 h0 p1 h1 ... (Pa, W/m²K), read at the Co
ntact Pressure below:
# 2 MPa lies between 1 Mand 4 MPa (6500), so h = 5500 W/m²K.
# The library is looked for next to this deck (see problem.toml for how to build it).
begin contact definition joint
  contact surface base_face contains base_top
  contact surface cover_face contains cover_bottom
  begin interaction
    side a base_face
    side b cover_face
  end
  begin enforcement
    enforcement for energy = plugin library = "libseam_c_table.so" model = c_table
   nergy = plugin library = "libseam_c_table.so" model = c_table
    real data =  real data = 0 1000  1e6 5000  4e6 6500
    contact pressure = 2e6
  end
end
