# The fit between shaft and sleeve: a Cooper-Mikic-Yovanovich contact conductance at the
# fit pressure (5 MPa), between the shaft's surface (side A) and the sleeve's bore.
begin contact definition shrink_fit
  contact surface shaft_face contains shaft_surface
  contact surface bore contains sleeve_bore
  visualize contact
  begin interaction
    side a shaft_face
    side b bore
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = cmy k_a = 45 k_b = 60 slope = 0.1 roughness = 1e-6 hardness = 2e9
    contact pressure = 5e6
  end
end
