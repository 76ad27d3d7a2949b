begin contact definition main
  contact surface top contains block_1
  contact surface bottom contains block_2
  begin enforcement tied
    enforcement for energy = tied_temperature
    normal tolerance = 0.01
  end
  begin interaction top_bottom
    side a top
    side b bottom
    enforcement = tied
  end
end
