begin contact definition main
  contact surface top contains block_1
  contact surface bottom contains block_2
  begin enforcement mortar
    enforcement for energy = dash
    dash penalty factor = -10
  end
  begin interaction pair
    side a = top
    side b = bottom
    enforcement = mortar
  end
end
