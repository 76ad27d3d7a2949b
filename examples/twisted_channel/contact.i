# The bar's outlet (z = 0.05) is periodic with its inlet (z = 0) after a quarter turn:
# the point (x, y, 0.05) of the outlet is the point (-y, x, 0) of the inlet. The map is
# given in Lua; its image of the outlet is tied to the inlet by a mortar tie with
# Lagrange multipliers (on the image, side A).
begin contact definition channel
  contact surface outlet_face contains outlet
  contact surface inlet_face contains inlet
  periodicity for outlet_face = mapped x_map = "-y" y_map = "x" z_map = "z - 0.05"
  begin enforcement
    enforcement for energy = tied
    side b variable temperature to temperature
  end
end
