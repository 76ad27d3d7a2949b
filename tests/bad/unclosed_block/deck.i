begin contact definition main
  contact surface top contains block_1

  begin interaction top_bottom
    side a top
    side b bottom
  end interaction top_bottom
